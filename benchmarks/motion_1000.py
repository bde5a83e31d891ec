"""Time `impinge motion` on a 1,000-frame OpenSim motion (issue 11's criterion: under 2 s on lhdl-ct at
0.1 deg, sampling included).

usage: /usr/bin/python3 benchmarks/motion_1000.py [SUBJECT_JSON] [--resolution DEG] [--repetitions N]
       [-- MORE OPTIONS OF impinge motion, e.g. --distances off --layers 0]
Writes a synthetic ROM trial (flexion 0..90, adduction -10..10, internal rotation -20..20 deg as
sines, 100 Hz) as an OpenSim .mot file in a temporary folder, runs build/impinge motion on it N times
(default 5) without VTP files and with the default ones, and prints the medians of the total wall time
and of its parts from summary.json."""
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
args = [a for a in sys.argv[1:]]
subject = args[0] if args and not args[0].startswith("--") else os.path.join(root, "..", "shared", "data", "hips",
                                                                            "lhdl-ct", "subject.json")
res = args[args.index("--resolution") + 1] if "--resolution" in args else "0.1"
extra_args = args[args.index("--") + 1:] if "--" in args else []  # more options of impinge motion
reps = int(args[args.index("--repetitions") + 1]) if "--repetitions" in args else 5
d = tempfile.mkdtemp(prefix="impinge_motion_")
mot = os.path.join(d, "rom.mot")
with open(mot, "w") as f:
    f.write("rom\nversion=1\nnRows=1000\nnColumns=4\ninDegrees=yes\nendheader\n")
    f.write("time\thip_flexion_r\thip_adduction_r\thip_rotation_r\n")
    for i in range(1000):
        t = i / 100.0
        f.write(f"{t:.2f}\t{45 + 45 * math.sin(2 * math.pi * t / 5):.6f}\t{10 * math.sin(2 * math.pi * t / 3):.6f}\t"
                f"{20 * math.sin(2 * math.pi * t / 4):.6f}\n")
for label, extra in (("no VTP files", ["--vtp-every", "1000000"]), ("default VTP files", [])):
    totals, parts = [], {}
    for _ in range(reps):
        out = os.path.join(d, "out")
        subprocess.run([os.path.join(root, "build", "impinge"), "motion", "--subject", subject, "--motion", mot,
                        "--resolution", res, "--quiet", "--out", out] + extra + extra_args, check=True)
        with open(os.path.join(out, "summary.json")) as f:
            t = json.load(f)["timings_ms"]
        totals.append(t["total"])
        for k, v in t.items():
            parts.setdefault(k, []).append(v)
    med = {k: statistics.median(v) for k, v in parts.items()}
    print(f"{label}: 1000 frames at {res} deg, median total {statistics.median(totals):.0f} ms over {reps} runs "
          f"(sampling {med['femur_sampling'] + med['pelvis_sampling']:.0f} ms, frames {med['frames']:.0f} ms, "
          f"detection {med['detection_total']:.0f} ms, output {med['output']:.0f} ms)")
