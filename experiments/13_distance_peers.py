"""Experiment 13 (issue 26, item 4): impinge's signed Euclidean distances beside the peers a biomechanics
user compares with, on the same vertices and poses, one thread each, in one run:
- impinge: both radial scans and both distance scans of a pose (Joint.detect_pose; the times from its summary,
  each scan single-threaded);
- Open3D (Debian python3-open3d 0.16): RaycastingScene.compute_signed_distance(nthreads=1) (closest point by
  Embree, sign by one ray's crossings), the scene built once per bone and the other bone's vertices moved
  into its frame (a query's nthreads, not the scene's, sets the query's threads: its default takes every core);
- VTK 9 (Debian python3-vtk9): vtkImplicitPolyDataDistance.FunctionValue over the same points.
The vertices are those impinge gives a distance at that pose (within the reach of the other bone: every
vertex that the bounds cannot prove farther). Agreement: the largest |difference| from impinge's distance and
the vertices whose sign differs from impinge's (its sign: the angle-weighted pseudo-normal, the winding
number where that cannot be trusted; casters/signed_distance.hpp).

Outputs (OUT/13_distance_peers/):
  whole_process.csv   whole processes (1, 10, 100, 1,000 poses; --quick 1 and 10) and single poses at 1 and 2
                      threads, impinge beside Open3D, medians and quartiles (benchmarks/whole_process.py, issue 52)
  distance_peers.csv  subject x pose: vertices, impinge's radial and distance scan times (ms, medians of the
                      repetitions; the distance scans' quartiles), Open3D's (median, quartiles; impinge and Open3D
                      alternated, one run of each per round, and Open3D's time over impinge's distance scans
                      paired round by round: median and quartiles) and VTK's on the same vertices, their largest
                      difference from impinge's distances (mm) and their sign disagreements
  three_ways.csv      subject x pose x threads (1, 2): Open3D three ways against impinge (issue 82, item 3), in
                      5 paired rounds, the order rotated round by round: impinge.Joint.detect_pose (set_threads; the
                      wall time of the call that returns the distances) against Open3D (a) on every vertex of both
                      bones (a naive user), (b) on the vertices a scipy cKDTree on the other bone's vertices keeps
                      within the reach plus that bone's longest edge (a competent user: the trees built once per bone,
                      kdtree_build_ms, outside the per-pose time like the scenes and impinge's maps; the posing, the
                      query and Open3D's distances of the kept vertices in it), (c) on impinge's own vertex set
                      (which a user cannot know beforehand); each posing the vertices in its time; median and
                      quartiles of each time and of each ratio Open3D / impinge round by round (its least and
                      largest too: impinge faster in every round when ratio_*_min > 1); the cull checked
                      against impinge: culled_lost (impinge's vertices the cull dropped), culled_max_diff_mm (and
                      culled_max_diff_same_sign_mm, where the signs agree) and culled_sign_disagreements (Open3D's
                      distances of the kept vertices against impinge's)
  meta.json
Every shared hip with a subject.json under --data, or (without it) the generated hip with a 2 mm cam.
Poses: rest and 10 poses up to 110 deg flexion (issue 26's); --quick: rest and 2 poses at 0.5 deg maps, the three
ways at the first of the 2 (both thread counts on the first hip, one thread on the others).

usage: exp_13_distance_peers --out DIR [--data DIR] [--quick]
(build/experiments/exp_13_distance_peers runs this file with the module on PYTHONPATH)"""
import csv
import json
import os
import statistics
import time

# OpenMP threads that wait between parallel regions sleep instead of spinning (read when libgomp loads, so before
# impinge and Open3D, which share it; the subprocesses inherit it; OMP_WAIT_POLICY set outside wins). On a 2-core
# machine that another job shares, spinning made a second thread wait for a core: on 2026-11-29 impinge's pose at
# 2 threads took 8.0 ms spinning against 2.6 ms sleeping, and Open3D's signed distance of 245 points 48 ms against
# 0.6 ms (its sign step, compute_occupancy; count_intersections alone did not stall), in steps of a scheduler tick:
# the ratios followed the machine's load, not the tools.
os.environ.setdefault("OMP_WAIT_POLICY", "passive")

import numpy as np  # noqa: E402
from experiment_support import experiment_args, write_meta  # noqa: E402

import impinge  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def o3d_scene(V, F):
    import open3d as o3d
    mesh = o3d.t.geometry.TriangleMesh()
    mesh.vertex.positions = o3d.core.Tensor(np.ascontiguousarray(V, dtype=np.float32))
    mesh.triangle.indices = o3d.core.Tensor(np.ascontiguousarray(F, dtype=np.int32))
    scene = o3d.t.geometry.RaycastingScene(nthreads=1)
    scene.add_triangles(mesh)
    return scene


def vtk_distance(V, F):
    import vtk
    from vtk.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray, vtk_to_numpy
    pts = vtk.vtkPoints()
    pts.SetData(numpy_to_vtk(np.ascontiguousarray(V, dtype=np.float64), deep=True))
    cells = vtk.vtkCellArray()
    conn = np.hstack([np.full((len(F), 1), 3), F]).astype(np.int64).ravel()
    cells.SetCells(len(F), numpy_to_vtkIdTypeArray(conn, deep=True))
    poly = vtk.vtkPolyData()
    poly.SetPoints(pts)
    poly.SetPolys(cells)
    d = vtk.vtkImplicitPolyDataDistance()
    d.SetInput(poly)

    def evaluate(Q):
        out = vtk.vtkDoubleArray()
        d.FunctionValue(numpy_to_vtk(np.ascontiguousarray(Q, dtype=np.float64), deep=True), out)
        return vtk_to_numpy(out).copy()
    return evaluate


def median_ms(fn, n):
    times = []
    for _ in range(n):
        t0 = time.perf_counter()
        fn()
        times.append((time.perf_counter() - t0) * 1e3)
    return statistics.median(times)


def subjects(data):
    """(name, Joint options, femur (V, F), pelvis (V, F)) of every shared hip, or the generated one."""
    out = []
    if data and os.path.isdir(data):
        for name in sorted(os.listdir(data)):
            path = os.path.join(data, name, "subject.json")
            if not os.path.isfile(path):
                continue
            with open(path) as f:
                info = json.load(f)
            folder = os.path.dirname(path)
            out.append((name, {"subject": path}, impinge.load_mesh(os.path.join(folder, info["femur"])),
                        impinge.load_mesh(os.path.join(folder, info["pelvis"]))))
    if not out:
        h = impinge.generated_hip(triangles=12000, cam_mm=2.0)
        out.append(("generated", {"femur": h["femur"], "pelvis": h["pelvis"], "neutral": "scan"}, h["femur"], h["pelvis"]))
    return out


def disagreements(a, b):
    return int(np.count_nonzero(np.sign(a) != np.sign(b)))


THREE_WAY_THREADS = (1, 2)  # impinge's and Open3D's threads in the three-way comparison (issue 82, item 3)
THREE_WAY_ROUNDS = 5        # its paired rounds per pose and thread count (--quick too: a ratio needs its spread)


def paired_rounds(fns, rounds):
    """Wall times (ms) of each of `fns`, one run of each per round for `rounds` rounds, the order rotated round by
    round (so that no tool always runs first after another's caches): times[k][i] is fns[k]'s run in round i, and
    times[a][i] / times[b][i] is a ratio paired round by round."""
    times = [[0.0] * rounds for _ in fns]
    for i in range(rounds):
        for k in [(i + m) % len(fns) for m in range(len(fns))]:
            t0 = time.perf_counter()
            fns[k]()
            times[k][i] = (time.perf_counter() - t0) * 1e3
    return times


def quartiles(xs, name, unit="", extremes=False):
    """{name_median, name_q25, name_q75}: the median and quartiles of xs (with extremes: name_min, name_max too)."""
    out = {f"{name}_median{unit}": float(np.median(xs)), f"{name}_q25{unit}": float(np.quantile(xs, 0.25)),
           f"{name}_q75{unit}": float(np.quantile(xs, 0.75))}
    if extremes:
        out.update({f"{name}_min{unit}": float(np.min(xs)), f"{name}_max{unit}": float(np.max(xs))})
    return out


def longest_edge(V, F):
    """The longest edge (mm) of the mesh (V: n x 3, F: m x 3)."""
    e = np.concatenate([V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 1]], V[F[:, 0]] - V[F[:, 2]]])
    return float(np.sqrt((e * e).sum(axis=1).max()))


class Culler:
    """A competent Open3D user's pipeline (issue 82, item 3): a scipy cKDTree on each bone's vertices, built once per
    bone (build_ms), and per pose a query that keeps the other bone's vertices with a vertex of this bone within
    reach + this bone's longest edge: every vertex within the reach of the surface (its closest point lies on a
    triangle, whose nearest corner is at most one edge farther), so that none of impinge's vertices is lost."""

    def __init__(self, femur_V, femur_F, pelvis_V, pelvis_F, reach):
        from scipy.spatial import cKDTree
        t0 = time.perf_counter()
        self.femur_tree, self.pelvis_tree = cKDTree(femur_V), cKDTree(pelvis_V)
        self.build_ms = (time.perf_counter() - t0) * 1e3
        self.femur_bound = reach + longest_edge(femur_V, femur_F)
        self.pelvis_bound = reach + longest_edge(pelvis_V, pelvis_F)

    def keep(self, femur_in_pelvis, pelvis_in_femur, threads):
        """(femur vertices, pelvis vertices) that can be within reach: indices into the posed vertices given."""
        db, _ = self.pelvis_tree.query(femur_in_pelvis, k=1, distance_upper_bound=self.pelvis_bound, workers=threads)
        ds, _ = self.femur_tree.query(pelvis_in_femur, k=1, distance_upper_bound=self.femur_bound, workers=threads)
        return np.flatnonzero(np.isfinite(db)), np.flatnonzero(np.isfinite(ds))


def three_ways(j, pose, scenes, culler, threads, rounds, impinge_set):
    """One row of three_ways.csv (the file comment): at `threads` threads, impinge's detect_pose against Open3D
    (a) on every vertex, (b) on the vertices a KD-tree cull keeps, (c) on impinge's own vertex set, in paired,
    rotated rounds; the ratios Open3D / impinge round by round; the cull checked against impinge's distances.
    scenes: (pelvis scene, femur scene); impinge_set: (femur indices, pelvis indices) with a distance at the pose."""
    import open3d as o3d
    femur_V, pelvis_V = (np.asarray(j.meshes[b][0]) for b in ("femur", "pelvis"))
    R, t = j.femur_pose(*pose)
    cor = np.asarray(j.cor)
    pelvis_scene, femur_scene = scenes
    bi, si = impinge_set

    def posed(fi, pi):
        # The femur's vertices into the pelvis' frame, the pelvis' into the femur's (each scene stays put).
        return (femur_V[fi] - cor) @ R.T + cor + t, (pelvis_V[pi] - cor - t) @ R + cor

    def open3d(qb, qs):
        return (pelvis_scene.compute_signed_distance(o3d.core.Tensor(qb.astype(np.float32)), nthreads=threads).numpy(),
                femur_scene.compute_signed_distance(o3d.core.Tensor(qs.astype(np.float32)), nthreads=threads).numpy())

    every = slice(None)
    out = {}

    def competent():
        qb, qs = posed(every, every)
        kb, ks = culler.keep(qb, qs, threads)
        out["culled"] = (kb, ks, *open3d(qb[kb], qs[ks]))

    fns = [lambda: j.detect_pose(*pose), lambda: open3d(*posed(every, every)), competent,
           lambda: open3d(*posed(bi, si))]
    before = impinge.get_threads()
    impinge.set_threads(threads)
    try:
        for f in fns[:1] + fns[2:]:  # warm-up ((a) queries the scenes that (b) and (c) warm: its run would cost most)
            f()
        times = paired_rounds(fns, rounds)
        r = j.detect_pose(*pose)
    finally:
        impinge.set_threads(before)
    kb, ks, ob, os_ = out["culled"]
    lost, worst, worst_same, signs = 0, 0.0, 0.0, 0
    for ours, kept, theirs in ((r["femur_distance_mm"], kb, ob), (r["pelvis_distance_mm"], ks, os_)):
        have = np.flatnonzero(np.isfinite(ours))
        at = np.searchsorted(kept, have)
        found = (at < len(kept)) & (kept[np.minimum(at, len(kept) - 1)] == have)
        lost += int((~found).sum())
        a, b = ours[have[found]], theirs[at[found]]
        worst = max(worst, float(np.max(np.abs(a - b), initial=0)))
        same = np.sign(a) == np.sign(b)
        worst_same = max(worst_same, float(np.max(np.abs(a[same] - b[same]), initial=0)))
        signs += disagreements(a, b)
    imp = np.asarray(times[0])
    row = {"threads": threads, "rounds": rounds, "vertices_every": len(femur_V) + len(pelvis_V),
           "vertices_culled": len(kb) + len(ks), "vertices_impinge": len(bi) + len(si),
           "reach_mm": float(j.setup["distance_reach_mm"]), "cull_bound_femur_tree_mm": culler.femur_bound,
           "cull_bound_pelvis_tree_mm": culler.pelvis_bound, "kdtree_build_ms": culler.build_ms,
           **quartiles(imp, "impinge", "_ms")}
    for k, way in ((1, "every"), (2, "culled"), (3, "own")):
        row.update(quartiles(times[k], f"open3d_{way}", "_ms"))
        row.update(quartiles(np.asarray(times[k]) / imp, f"ratio_{way}", extremes=True))
    row.update({"culled_lost": lost, "culled_max_diff_mm": worst, "culled_max_diff_same_sign_mm": worst_same,
                "culled_sign_disagreements": signs})
    return row


def main():
    d, data, quick = experiment_args("13_distance_peers", __doc__)
    resolution = 0.5 if quick else 0.1
    reps = 3 if quick else 5
    poses = [(0, 0, 0)] + [(-10 + 12 * k, (k % 3 - 1) * 10, (k % 4 - 1.5) * 10) for k in range(10)]
    if quick:
        poses = poses[:1] + poses[5:7]
    rows, ways, three_way_s = [], [], 0.0
    for name, options, (femur_V, femur_F), (pelvis_V, pelvis_F) in subjects(data):
        print(f"[13_distance_peers] {name}", flush=True)
        ball = options.pop("femur", None)
        socket = options.pop("pelvis", None)
        j = impinge.Joint(ball, socket, resolution=resolution, distances=True, **options)
        # The peers get the Joint's own meshes: those read, less what the reading removed (a speck inside a bone:
        # mesh hygiene), so that per-vertex indices agree.
        (femur_V, femur_F), (pelvis_V, pelvis_F) = (tuple(np.asarray(a) for a in j.meshes[b])
                                                    for b in ("femur", "pelvis"))
        pelvis_scene, femur_scene = o3d_scene(pelvis_V, pelvis_F), o3d_scene(femur_V, femur_F)
        pelvis_vtk, femur_vtk = vtk_distance(pelvis_V, pelvis_F), vtk_distance(femur_V, femur_F)
        cor = np.asarray(j.cor)
        import open3d as o3d
        # The three ways' scenes (the same meshes) and the competent user's KD-trees, built once per bone.
        culler = Culler(femur_V, femur_F, pelvis_V, pelvis_F, float(j.setup["distance_reach_mm"]))
        for pose in poses:
            R, t = j.femur_pose(*pose)
            r = j.detect_pose(*pose)  # warm-up, and the vertices within reach that the peers are given
            bd, sd = r["femur_distance_mm"], r["pelvis_distance_mm"]
            bi, si = np.flatnonzero(np.isfinite(bd)), np.flatnonzero(np.isfinite(sd))
            # Femur vertices posed into the pelvis' frame; pelvis vertices into the femur's (its scene stays put).
            qb = (femur_V[bi] - cor) @ R.T + cor + t
            qs = (pelvis_V[si] - cor - t) @ R + cor
            tb, ts = o3d.core.Tensor(qb.astype(np.float32)), o3d.core.Tensor(qs.astype(np.float32))

            def run_open3d():
                # nthreads=1: the scene's nthreads sets its build only; a query's own default (0) takes every core.
                return (pelvis_scene.compute_signed_distance(tb, nthreads=1).numpy(),
                        femur_scene.compute_signed_distance(ts, nthreads=1).numpy())
            run_open3d()
            # impinge and Open3D alternated, one run of each per round, so that their ratio is paired round by round.
            radial, distance, o3d_runs = [], [], []
            for _ in range(reps):
                s = j.detect_pose(*pose)["summary"]
                radial.append(s["femur_detection_ms"] + s["pelvis_detection_ms"])
                distance.append(s["femur_distance_ms"] + s["pelvis_distance_ms"])
                t0 = time.perf_counter()
                run_open3d()
                o3d_runs.append((time.perf_counter() - t0) * 1e3)
            o3d_ms = statistics.median(o3d_runs)
            paired = np.asarray(o3d_runs) / np.asarray(distance)
            ob, os_ = run_open3d()
            vtk_ms = median_ms(lambda: (pelvis_vtk(qb), femur_vtk(qs)), 1 if quick else 3)
            vb, vs = pelvis_vtk(qb), femur_vtk(qs)
            diff = lambda x, y: float(np.max(np.abs(x - y), initial=0))  # noqa: E731
            rows.append({
                "subject": name, "flexion_deg": pose[0], "adduction_deg": pose[1], "internal_rotation_deg": pose[2],
                "vertices": len(bi) + len(si),
                "impinge_radial_ms": statistics.median(radial),
                "impinge_distance_ms": statistics.median(distance),
                "impinge_distance_q25_ms": float(np.quantile(distance, 0.25)),
                "impinge_distance_q75_ms": float(np.quantile(distance, 0.75)),
                "open3d_ms": o3d_ms,
                "open3d_q25_ms": float(np.quantile(o3d_runs, 0.25)),
                "open3d_q75_ms": float(np.quantile(o3d_runs, 0.75)),
                "open3d_over_distance_paired": float(np.median(paired)),
                "open3d_over_distance_q25": float(np.quantile(paired, 0.25)),
                "open3d_over_distance_q75": float(np.quantile(paired, 0.75)),
                "vtk_ms": vtk_ms,
                "open3d_max_diff_mm": max(diff(ob, bd[bi]), diff(os_, sd[si])),
                "vtk_max_diff_mm": max(diff(vb, bd[bi]), diff(vs, sd[si])),
                "open3d_sign_disagreements": disagreements(ob, bd[bi]) + disagreements(os_, sd[si]),
                "vtk_sign_disagreements": disagreements(vb, bd[bi]) + disagreements(vs, sd[si]),
            })
            # --quick: one pose per hip, two threads on the first hip only (the three ways cost about 4 s a pose and
            # thread count on lhdl-ct, most of it Open3D on every vertex).
            first_hip = not ways or ways[0]["subject"] == name
            for threads in (THREE_WAY_THREADS if not quick else () if pose != poses[1] else
                            THREE_WAY_THREADS if first_hip else THREE_WAY_THREADS[:1]):
                t0 = time.perf_counter()
                ways.append({"subject": name, "flexion_deg": pose[0], "adduction_deg": pose[1],
                             "internal_rotation_deg": pose[2],
                             **three_ways(j, pose, (pelvis_scene, femur_scene), culler, threads, THREE_WAY_ROUNDS,
                                          (bi, si))})
                three_way_s += time.perf_counter() - t0
    print(f"[13_distance_peers] Open3D three ways: {len(ways)} poses and thread counts, {three_way_s:.1f} s", flush=True)
    for file, table in (("distance_peers.csv", rows), ("three_ways.csv", ways)):
        tmp = os.path.join(d, f".{file}.{os.getpid()}.tmp")
        with open(tmp, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(table[0]))
            w.writeheader()
            w.writerows(table)
        os.replace(tmp, os.path.join(d, file))
    # Whole processes and single poses at 1 and 2 threads beside Open3D (benchmarks/whole_process.py): lhdl-ct, or
    # without the shared data a generated hip of 100,000 triangles.
    import subprocess
    import sys
    import tempfile
    sys.path.insert(0, os.path.join(ROOT, "benchmarks"))
    import whole_process
    subject = os.path.join(data, "lhdl-ct", "subject.json") if data else ""
    if not os.path.exists(subject):
        g = tempfile.mkdtemp(prefix="impinge-exp13-")
        subprocess.run([whole_process.CLI, "generate", "--triangles", "100000", "--cam", "2", "--out", g],
                       check=True, capture_output=True)
        subject = os.path.join(g, "subject.json")
    print(f"[13_distance_peers] whole processes beside Open3D: {subject}", flush=True)
    whole_process.run(d, subject, 3 if quick else 5, quick)
    assert os.path.exists(os.path.join(d, "whole_process.csv"))  # written by whole_process.run
    import vtk
    write_meta(d, "13_distance_peers", quick=quick, data_folder=data if data and os.path.isdir(data) else None,
               repetitions=reps,
               timing="median wall time after one warm-up run, one thread each (impinge's scans, Open3D nthreads=1, "
                      "VTK); whole processes: median and quartiles of alternated runs; OMP_WAIT_POLICY="
                      f"{os.environ.get('OMP_WAIT_POLICY')} (the file comment)",
               parameters={"resolution_deg": resolution, "scheme": "equiangular",
                           "distance_reach_mm": "the largest --levels threshold (three_ways.csv: reach_mm)",
                           "poses_deg": poses,
                           "three_ways": {"threads": list(THREE_WAY_THREADS), "rounds": THREE_WAY_ROUNDS,
                                          "cull": "scipy.spatial.cKDTree on the other bone's vertices, query k=1 "
                                                  "with distance_upper_bound = reach + that bone's longest edge",
                                          "impinge": "Joint.detect_pose wall time (impinge.set_threads)",
                                          "open3d": "compute_signed_distance(nthreads=threads)"},
                           "whole_process": {
                               "subject": subject, "repetitions": 3 if quick else 5,
                               "open3d_left_out_over_s": whole_process.SKIP_S,
                               "impinge": "impinge distance (1 pose) / impinge motion (N poses), CLI defaults, "
                                          "--neutral scan --joint-centre femoral-head; per pose: Joint.detect_pose at "
                                          "OMP_NUM_THREADS 1, 2",
                               "open3d": "a Python process: import, load both meshes, build both RaycastingScenes, "
                                         "compute_signed_distance of every vertex at every pose, write"}},
               versions={"open3d": __import__("open3d").__version__, "vtk": vtk.vtkVersion.GetVTKVersion(),
                         "scipy": __import__("scipy").__version__})


if __name__ == "__main__":
    main()
