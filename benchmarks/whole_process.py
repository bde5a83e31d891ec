"""Whole processes and single poses beside Open3D, in one run (issue 52, item 4).

The job: every vertex of both bones gets its signed Euclidean distance to the other bone's surface (impinge: within
the distances' reach, every other vertex proven beyond it; Open3D: every vertex), the femur at the scan pose or at
each pose of a motion. Measured as a new user runs it:
  process  whole processes, alternated (impinge, Open3D, impinge, ...): `impinge distance` (one pose) or
           `impinge motion` (N poses) with the CLI's defaults and --neutral scan --joint-centre femoral-head, against
           a Python process that imports Open3D, loads both meshes, builds both RaycastingScenes and queries every
           vertex at every pose (RaycastingScene.compute_signed_distance), and writes the distances;
  pose     per pose in one process, at 1 and 2 threads: impinge.Joint.detect_pose (OMP_NUM_THREADS) against Open3D's
           two queries of every vertex (compute_signed_distance(nthreads=...): the scene's nthreads sets its build
           only). This is the naive user's way; experiment 13's three_ways.csv sets it beside a competent user's
           KD-tree cull and beside impinge's own vertex set (issue 82, item 3).
Medians and quartiles over --repeats runs, on the native meshes and on the same meshes subdivided 4x (Open3D's
midpoint subdivision); --quick: 1 and 10 poses, native meshes only. Experiment 13 runs it (run()).

Writes OUT/whole_process.csv (job, mesh, poses, threads, tool, median_s, q1_s, q3_s, runs) and OUT/meta.json. A job
longer than 30 s is run once; an Open3D job expected to take over 20 s is left out (runs 0, times NaN).
usage: PYTHONPATH=build/python /usr/bin/python3 benchmarks/whole_process.py --out DIR [--data DIR] [--subject NAME]
       [--repeats 5] [--quick]"""
import csv
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CLI = os.environ.get("IMPINGE_CLI", os.path.join(ROOT, "build", "impinge"))
PY = "/usr/bin/python3"
LONG_S = 30.0   # a whole-process job longer than this is run once
# An Open3D job expected to take longer than this is left out: Open3D's time grows with the poses (its time per pose
# at fewer poses gives it), so a longer job repeats that measurement (issue 82 item 7: 100 poses on the subdivided
# meshes took Open3D about 4 of the full run's minutes; with 60 s, 100 poses on the native meshes, 23 s a run, and
# 10 on the subdivided ones, 18 s, still took 3.4 of its 65 minutes in five runs each).
SKIP_S = 20.0

OPEN3D_JOB = r'''
import sys, numpy as np, open3d as o3d
femur, pelvis, motion, out = sys.argv[1:5]
def load(p):
    m = o3d.io.read_triangle_mesh(p)
    return np.asarray(m.vertices), np.asarray(m.triangles, dtype=np.uint32)
Vf, Ff = load(femur); Vp, Fp = load(pelvis)
def scene(V, F):
    s = o3d.t.geometry.RaycastingScene()
    s.add_triangles(o3d.core.Tensor(V.astype(np.float32)), o3d.core.Tensor(F))
    return s
sf, sp = scene(Vf, Ff), scene(Vp, Fp)
poses = np.load(motion)  # k x 4 x 4: the femur's rigid motions (input frame)
res = []
for T in poses:
    R, t = T[:3, :3], T[:3, 3]
    df = sp.compute_signed_distance(o3d.core.Tensor((Vf @ R.T + t).astype(np.float32))).numpy()
    dp = sf.compute_signed_distance(o3d.core.Tensor(((Vp - t) @ R).astype(np.float32))).numpy()
    res.append((df.min(), dp.min()))
np.save(out, np.asarray(res))
'''


def arg(name, default=None):
    return sys.argv[sys.argv.index(name) + 1] if name in sys.argv else default


def stats(xs):
    return float(np.median(xs)), float(np.percentile(xs, 25)), float(np.percentile(xs, 75))


def timed(cmd, env=None):
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, capture_output=True, env=env)
    return time.perf_counter() - t0


def rotation(flexion, adduction, rotation_deg):
    """A rigid motion of the femur about the head centre (a test pose; both tools get the same ones)."""
    a, b, c = np.radians([flexion, adduction, rotation_deg])
    rx = np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])
    ry = np.array([[np.cos(b), 0, np.sin(b)], [0, 1, 0], [-np.sin(b), 0, np.cos(b)]])
    rz = np.array([[np.cos(c), -np.sin(c), 0], [np.sin(c), np.cos(c), 0], [0, 0, 1]])
    return rz @ ry @ rx


def run(out, subject, repeats, quick):
    """Measure on the hip of `subject` (a subject.json) into OUT/whole_process.csv (the file comment)."""
    os.makedirs(out, exist_ok=True)
    sys.path.insert(0, os.path.join(ROOT, "build", "python"))
    import impinge
    import open3d as o3d

    name = os.path.basename(os.path.dirname(os.path.abspath(subject)))
    meshes = impinge.subject_meshes(subject)
    tmp = tempfile.mkdtemp(prefix="impinge-whole-")
    variants = [("native", meshes["femur"], meshes["pelvis"])]
    if not quick:
        sub = {}
        for part in ("femur", "pelvis"):
            m = o3d.io.read_triangle_mesh(meshes[part]).subdivide_midpoint(number_of_iterations=1)
            sub[part] = os.path.join(tmp, f"{part}_x4.ply")
            o3d.io.write_triangle_mesh(sub[part], m)
        variants.append(("subdivided_4x", sub["femur"], sub["pelvis"]))
    centre = np.asarray(impinge.femoral_head_centre(subject=subject)["centre"])
    rows = []
    for mesh, femur, pelvis in variants:
        side = json.load(open(subject)).get("side", "right")
        frame = json.load(open(subject)).get("frame", "RAS")
        common = ["--ball", femur, "--socket", pelvis, "--side", side, "--frame", frame, "--neutral", "scan",
                  "--joint-centre", "femoral-head"]
        o3d_per_pose = None  # Open3D's time per pose at the last job, s
        for k in ((1, 10) if quick else (1, 10, 100, 1000)):
            rng = np.random.default_rng(k)
            angles = np.column_stack([rng.uniform(0, 60, k), rng.uniform(-10, 10, k), rng.uniform(-20, 20, k)])
            angles[0] = 0
            csv_path = os.path.join(tmp, f"motion_{k}.csv")
            with open(csv_path, "w") as f:
                f.write("time_s,flexion_deg,adduction_deg,internal_rotation_deg\n")
                for i, a in enumerate(angles):
                    f.write(f"{i * 0.01},{a[0]},{a[1]},{a[2]}\n")
            poses = []
            for a in angles:
                T = np.eye(4)
                R = rotation(*a)
                T[:3, :3], T[:3, 3] = R, centre - R @ centre
                poses.append(T)
            npy = os.path.join(tmp, f"poses_{k}.npy")
            np.save(npy, np.asarray(poses))
            ours = (["distance", "--pose", "0,0,0"] if k == 1 else ["motion", "--motion", csv_path, "--quiet",
                                                                    "--vtp-every", str(10 ** 9)])
            # Alternated runs; a job that takes longer than LONG_S is run once, and an Open3D job expected (from its
            # time per pose at fewer poses) to take longer than SKIP_S is left out (NaN, 0 runs): 1,000 poses on the
            # subdivided meshes would take Open3D about 17 min a run.
            t_imp, t_o3d = [], []
            run_o3d = o3d_per_pose is None or k * o3d_per_pose <= SKIP_S
            for _ in range(repeats):
                t_imp.append(timed([CLI] + ours + common + ["--out", os.path.join(tmp, "o")]))
                if run_o3d:
                    t_o3d.append(timed([PY, "-c", OPEN3D_JOB, femur, pelvis, npy, os.path.join(tmp, "o3d.npy")]))
                if max(t_imp + t_o3d) > LONG_S:
                    break
            if t_o3d:
                o3d_per_pose = float(np.median(t_o3d)) / k
            for tool, ts in (("impinge", t_imp), ("open3d", t_o3d)):
                rows.append(["process", mesh, k, 2, tool, *(stats(ts) if ts else (np.nan,) * 3), len(ts)])
            print(f"[whole_process] {mesh} {k} poses: impinge {np.median(t_imp):.3f} s, Open3D "
                  + (f"{np.median(t_o3d):.3f} s" if t_o3d else "left out (too long)"), flush=True)
        # Per pose, in one process, at 1 and 2 threads.
        for threads in (1, 2):
            env = dict(os.environ, OMP_NUM_THREADS=str(threads), PYTHONPATH=os.path.join(ROOT, "build", "python"))
            script = f'''
import time, json, numpy as np, impinge, open3d as o3d
j = impinge.Joint({femur!r}, {pelvis!r}, side={side!r}, frame={frame!r}, neutral="scan", joint_centre="femoral-head")
ts = []
for i in range({repeats * 10}):
    t0 = time.perf_counter(); j.detect_pose(30, 5, 10); ts.append(time.perf_counter() - t0)
V = {{p: np.asarray(o3d.io.read_triangle_mesh(f).vertices) for p, f in (("f", {femur!r}), ("p", {pelvis!r}))}}
F = {{p: np.asarray(o3d.io.read_triangle_mesh(f).triangles, dtype=np.uint32) for p, f in (("f", {femur!r}), ("p", {pelvis!r}))}}
def scene(V, F):
    s = o3d.t.geometry.RaycastingScene(nthreads={threads})
    s.add_triangles(o3d.core.Tensor(V.astype(np.float32)), o3d.core.Tensor(F))
    return s
sf, sp = scene(V["f"], F["f"]), scene(V["p"], F["p"])
to = []
for i in range({repeats}):
    t0 = time.perf_counter()
    sp.compute_signed_distance(o3d.core.Tensor(V["f"].astype(np.float32)), nthreads={threads})
    sf.compute_signed_distance(o3d.core.Tensor(V["p"].astype(np.float32)), nthreads={threads})
    to.append(time.perf_counter() - t0)
print(json.dumps({{"impinge": ts, "open3d": to}}))
'''
            r = subprocess.run([PY, "-c", script], check=True, capture_output=True, text=True, env=env)
            d = json.loads(r.stdout.strip().splitlines()[-1])
            for tool in ("impinge", "open3d"):
                rows.append(["pose", mesh, 1, threads, tool, *stats(d[tool]), len(d[tool])])
            print(f"[whole_process] {mesh} per pose, {threads} threads: impinge {1e3 * np.median(d['impinge']):.2f} "
                  f"ms, Open3D {1e3 * np.median(d['open3d']):.1f} ms", flush=True)
    with open(os.path.join(out, "whole_process.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["job", "mesh", "poses", "threads", "tool", "median_s", "q1_s", "q3_s", "runs"])
        w.writerows(rows)



def main():
    out = arg("--out")
    if out is None:
        sys.exit(__doc__)
    quick = "--quick" in sys.argv
    data = arg("--data", os.path.join(ROOT, "..", "shared", "data", "hips"))
    repeats = int(arg("--repeats", "3" if quick else "5"))
    subject = os.path.join(data, arg("--subject", "lhdl-ct"), "subject.json")
    run(out, subject, repeats, quick)
    import open3d as o3d
    name = os.path.basename(os.path.dirname(subject))
    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "HEAD"], capture_output=True, text=True).stdout.strip()
    json.dump({"benchmark": "whole_process", "subject": name, "repeats": repeats, "quick": quick, "git_commit": commit,
               "date": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()), "cores": os.cpu_count(),
               "open3d": o3d.__version__}, open(os.path.join(out, "meta.json"), "w"), indent=2)


if __name__ == "__main__":
    main()
