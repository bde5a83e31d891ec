"""Cost of the Python binding per pose, against the C++ Joint::detect loop, in one process.

usage: PYTHONPATH=build/python /usr/bin/python3 benchmarks/python_overhead.py [DATA_DIR] [--out CSV]
On lhdl-ct (else a generated hip) at 0.1 deg, exact mode: the median time of one detect() call from
Python (a fresh result dict with numpy arrays each call), of the C++ loop (Joint::detect into reused
buffers, measured inside the module), and of motion() over 1,000 poses from Python against the same
1,000 poses looped in C++ (timed inside the module). Prints the ratios; with --out writes them as CSV (one row per measurement)."""
import os
import statistics
import sys
import time

import numpy as np

import impinge


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    out = sys.argv[sys.argv.index("--out") + 1] if "--out" in sys.argv else None
    data = args[0] if args else "../shared/data/hips"
    path = os.path.join(data, "lhdl-ct")
    if os.path.exists(os.path.join(path, "femur_r.ply")):
        lps = np.diag([-1.0, -1.0, 1.0])
        V, F = impinge.load_mesh(os.path.join(path, "femur_r.ply"))
        P, G = impinge.load_mesh(os.path.join(path, "pelvis.ply"))
        j, name = impinge.Joint((V @ lps, F), (P @ lps, G), resolution=0.1), "lhdl-ct"
    else:
        h = impinge.generated_hip(triangles=12000, cam_mm=2.0)
        j, name = impinge.Joint(h["femur"], h["pelvis"], neutral="scan", resolution=0.1), "generated-12k"
    R = j.femur_rotation(30, 10, 5)
    reps = 11
    py_ns, cpp_ns = [], []
    for _ in range(reps):
        cpp_ns.append(j._bench_detect_ns(R, 200))
        ts = []
        for _ in range(200):
            t0 = time.perf_counter_ns()
            j.detect(R)
            ts.append(time.perf_counter_ns() - t0)
        py_ns.append(statistics.median(ts))
    angles = np.column_stack([np.linspace(0, 90, 1000), np.linspace(-5, 10, 1000), np.linspace(-10, 20, 1000)])
    motion_ns, loop_ns = [], []
    for _ in range(reps):
        t0 = time.perf_counter_ns()
        j.motion(angles)
        motion_ns.append(time.perf_counter_ns() - t0)
        loop_ns.append(j._bench_motion_ns(angles))
    rows = [("detect_per_pose", statistics.median(py_ns), statistics.median(cpp_ns)),
            ("motion_1000_poses", statistics.median(motion_ns), statistics.median(loop_ns))]
    for what, p, c in rows:
        print(f"{name} 0.1 deg exact, {what}: Python {p / 1e3:.1f} us, C++ {c / 1e3:.1f} us, ratio {p / c:.3f} "
              f"(medians of {reps} runs)")
    if out:
        with open(out, "w") as f:
            f.write("subject,measurement,python_ns,cpp_ns,ratio,repetitions\n")
            for what, p, c in rows:
                f.write(f"{name},{what},{p:.0f},{c:.0f},{p / c:.4f},{reps}\n")


if __name__ == "__main__":
    main()
