"""impinge's distances against the peers a biomechanics user compares with (issue 26, item 4), on the same
vertices and poses, one thread each, in one run:
- impinge: both radial scans and both distance scans of a pose (Joint.detect_pose; times from its summary);
- Open3D 0.16 (Debian python3-open3d): RaycastingScene.compute_signed_distance (closest point by Embree, sign
  by one ray's crossings), with the scene built once per bone and the other bone's vertices moved into its
  frame;
- VTK 9 (Debian python3-vtk9): vtkImplicitPolyDataDistance.FunctionValue over the same points.
The vertices are those impinge gives a distance at that pose (within the reach of the other bone). Prints,
per pose, the times (medians of --repetitions runs) and the largest difference from impinge's distances, and
with --out writes them as CSV.

usage: /usr/bin/python3 benchmarks/distance_peers.py [SUBJECT_JSON] [--resolution DEG] [--repetitions N]
       [--no-vtk] [--out CSV]
(PYTHONPATH=build/python)"""
import csv
import os
import statistics
import sys
import time

import numpy as np

import impinge

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
args = sys.argv[1:]
subject = args[0] if args and not args[0].startswith("--") else os.path.join(root, "..", "shared", "data", "hips",
                                                                            "lhdl-ct", "subject.json")
res = float(args[args.index("--resolution") + 1]) if "--resolution" in args else 0.1
reps = int(args[args.index("--repetitions") + 1]) if "--repetitions" in args else 5
out_csv = args[args.index("--out") + 1] if "--out" in args else None
with_vtk = "--no-vtk" not in args

import open3d as o3d  # noqa: E402  (after the arguments: --help needs neither)

import json  # noqa: E402

with open(subject) as f:
    info = json.load(f)
folder = os.path.dirname(os.path.abspath(subject))
femur_V, femur_F = impinge.load_mesh(os.path.join(folder, info["femur"]))
pelvis_V, pelvis_F = impinge.load_mesh(os.path.join(folder, info["pelvis"]))
j = impinge.Joint(subject=subject, resolution=res)


def o3d_scene(V, F):
    mesh = o3d.t.geometry.TriangleMesh()
    mesh.vertex.positions = o3d.core.Tensor(V.astype(np.float32))
    mesh.triangle.indices = o3d.core.Tensor(F.astype(np.int32))
    try:
        scene = o3d.t.geometry.RaycastingScene(nthreads=1)
    except TypeError:  # older Open3D: no thread count
        scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(mesh)
    return scene


def vtk_distance(V, F):
    import vtk
    from vtk.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray
    pts = vtk.vtkPoints()
    pts.SetData(numpy_to_vtk(V.astype(np.float64), deep=True))
    cells = vtk.vtkCellArray()
    conn = np.hstack([np.full((len(F), 1), 3), F]).astype(np.int64).ravel()
    cells.SetCells(len(F), numpy_to_vtkIdTypeArray(conn, deep=True))
    poly = vtk.vtkPolyData()
    poly.SetPoints(pts)
    poly.SetPolys(cells)
    d = vtk.vtkImplicitPolyDataDistance()
    d.SetInput(poly)

    def evaluate(Q):
        from vtk.util.numpy_support import vtk_to_numpy
        inp = numpy_to_vtk(np.ascontiguousarray(Q, dtype=np.float64), deep=True)
        out = vtk.vtkDoubleArray()
        d.FunctionValue(inp, out)
        return vtk_to_numpy(out).copy()
    return evaluate


def median_time(fn, n):
    times = []
    for _ in range(n):
        t0 = time.perf_counter()
        fn()
        times.append((time.perf_counter() - t0) * 1e3)
    return statistics.median(times)


pelvis_scene, femur_scene = o3d_scene(pelvis_V, pelvis_F), o3d_scene(femur_V, femur_F)
if with_vtk:
    pelvis_vtk, femur_vtk = vtk_distance(pelvis_V, pelvis_F), vtk_distance(femur_V, femur_F)
cor = np.asarray(j.cor)
poses = [(0, 0, 0)] + [(-10 + 12 * k, (k % 3 - 1) * 10, (k % 4 - 1.5) * 10) for k in range(10)]
rows = []
for pose in poses:
    R, t = j.femur_pose(*pose)
    impinge_radial, impinge_distance = [], []
    for _ in range(reps):
        r = j.detect_pose(*pose)
        s = r["summary"]
        impinge_radial.append(s["ball_detection_ms"] + s["socket_detection_ms"])
        impinge_distance.append(s["ball_distance_ms"] + s["socket_distance_ms"])
    bd, sd = r["ball_distance_mm"], r["socket_distance_mm"]
    bi, si = np.flatnonzero(np.isfinite(bd)), np.flatnonzero(np.isfinite(sd))
    # Femur vertices posed into the pelvis' frame; pelvis vertices into the femur's (its scene stays put).
    qb = (femur_V[bi] - cor) @ R.T + cor + t
    qs = (pelvis_V[si] - cor - t) @ R + cor
    tb, ts = o3d.core.Tensor(qb.astype(np.float32)), o3d.core.Tensor(qs.astype(np.float32))

    def run_open3d():
        return pelvis_scene.compute_signed_distance(tb).numpy(), femur_scene.compute_signed_distance(ts).numpy()
    o3d_ms = median_time(run_open3d, reps)
    ob, os_ = run_open3d()
    row = {"pose_deg": "%g,%g,%g" % pose, "vertices": len(bi) + len(si),
           "impinge_radial_ms": statistics.median(impinge_radial),
           "impinge_distance_ms": statistics.median(impinge_distance),
           "open3d_ms": o3d_ms,
           "open3d_max_diff_mm": float(max(np.max(np.abs(ob - bd[bi]), initial=0), np.max(np.abs(os_ - sd[si]), initial=0))),
           "open3d_sign_disagreements": int(np.count_nonzero(np.sign(ob) != np.sign(bd[bi])) +
                                            np.count_nonzero(np.sign(os_) != np.sign(sd[si])))}
    if with_vtk:
        vtk_ms = median_time(lambda: (pelvis_vtk(qb), femur_vtk(qs)), max(1, reps // 5))
        vb, vs = pelvis_vtk(qb), femur_vtk(qs)
        row.update({"vtk_ms": vtk_ms,
                    "vtk_max_diff_mm": float(max(np.max(np.abs(vb - bd[bi]), initial=0), np.max(np.abs(vs - sd[si]), initial=0))),
                    "vtk_sign_disagreements": int(np.count_nonzero(np.sign(vb) != np.sign(bd[bi])) +
                                                  np.count_nonzero(np.sign(vs) != np.sign(sd[si])))})
    rows.append(row)
    print(", ".join(f"{k} {v:.4g}" if isinstance(v, float) else f"{k} {v}" for k, v in row.items()), flush=True)
both = [r["impinge_radial_ms"] + r["impinge_distance_ms"] for r in rows]
print(f"median over poses: impinge radial {statistics.median(r['impinge_radial_ms'] for r in rows):.3f} ms, "
      f"radial + distance {statistics.median(both):.3f} ms, Open3D {statistics.median(r['open3d_ms'] for r in rows):.3f} ms "
      f"(Open3D / impinge distance: {statistics.median(r['open3d_ms'] / r['impinge_distance_ms'] for r in rows):.2f}x)")
if out_csv:
    with open(out_csv, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
