"""Experiment 13 (issue 26, item 4): impinge's signed Euclidean distances beside the peers a biomechanics
user compares with, on the same vertices and poses, one thread each, in one run:
- impinge: both radial scans and both distance scans of a pose (Joint.detect_pose; the times from its summary,
  each scan single-threaded);
- Open3D (Debian python3-open3d 0.16): RaycastingScene(nthreads=1).compute_signed_distance (closest point by
  Embree, sign by one ray's crossings), the scene built once per bone and the other bone's vertices moved
  into its frame;
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
  meta.json
Every shared hip with a subject.json under --data, or (without it) the generated hip with a 2 mm cam.
Poses: rest and 10 poses up to 110 deg flexion (issue 26's); --quick: rest and 2 poses at 0.5 deg maps.

usage: exp_13_distance_peers --out DIR [--data DIR] [--quick]
(build/experiments/exp_13_distance_peers runs this file with the module on PYTHONPATH)"""
import csv
import json
import os
import statistics
import time

import numpy as np
from experiment_support import experiment_args, write_meta

import impinge

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


def main():
    d, data, quick = experiment_args("13_distance_peers", __doc__)
    resolution = 0.5 if quick else 0.1
    reps = 3 if quick else 5
    poses = [(0, 0, 0)] + [(-10 + 12 * k, (k % 3 - 1) * 10, (k % 4 - 1.5) * 10) for k in range(10)]
    if quick:
        poses = poses[:1] + poses[5:7]
    rows = []
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
                return pelvis_scene.compute_signed_distance(tb).numpy(), femur_scene.compute_signed_distance(ts).numpy()
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
    with open(os.path.join(d, "distance_peers.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
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
                      "VTK); whole processes: median and quartiles of alternated runs",
               parameters={"resolution_deg": resolution, "scheme": "equiangular",
                           "distance_reach_mm": "6 (the largest --levels threshold)", "poses_deg": poses,
                           "whole_process": {
                               "subject": subject, "repetitions": 3 if quick else 5,
                               "impinge": "impinge distance (1 pose) / impinge motion (N poses), CLI defaults, "
                                          "--neutral scan --joint-centre femoral-head; per pose: Joint.detect_pose at "
                                          "OMP_NUM_THREADS 1, 2",
                               "open3d": "a Python process: import, load both meshes, build both RaycastingScenes, "
                                         "compute_signed_distance of every vertex at every pose, write"}},
               versions={"open3d": __import__("open3d").__version__, "vtk": vtk.vtkVersion.GetVTKVersion()})


if __name__ == "__main__":
    main()
