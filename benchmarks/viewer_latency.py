"""impinge view's data path and draw, measured apart (issue 79's "Fast"), in Debian's headless Chromium.

usage: /usr/bin/python3 benchmarks/viewer_latency.py [SUBJECT_JSON] [--resolution DEG] [--poses N] [--out DIR]
       [-- MORE OPTIONS OF impinge view]
Starts build/impinge view on the subject (default: ../shared/data/hips/lhdl-ct, at 0.1 deg; distances on, the
default), opens the page in headless Chromium (SwiftShader), and times N poses (default 200) along a slider-like
path: from the page's request to the new values in its colour buffer (request, detection, transfer, decode,
colouring; not the draw), one pose after another. Then times 30 draws of the page as it opens (both bones, the
pelvis cropped to the acetabulum; one colour-buffer upload and one render, waited for by reading a pixel back) - a
software renderer's time here, far less on a graphics card. Prints the medians and 95th percentiles and writes them,
with the machine and the triangles drawn, to OUT/viewer_latency.json (default: a temporary folder)."""
import json
import os
import signal
import statistics
import subprocess
import sys
import tempfile
import time

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
args = sys.argv[1:]
extra = args[args.index("--") + 1:] if "--" in args else []
args = args[:args.index("--")] if "--" in args else args
subject = args[0] if args and not args[0].startswith("--") else os.path.join(root, "..", "shared", "data", "hips",
                                                                            "lhdl-ct", "subject.json")
res = args[args.index("--resolution") + 1] if "--resolution" in args else "0.1"
n = int(args[args.index("--poses") + 1]) if "--poses" in args else 200
out = args[args.index("--out") + 1] if "--out" in args else tempfile.mkdtemp(prefix="impinge_viewer_latency_")


def quantile(xs, q):
    xs = sorted(xs)
    return xs[min(len(xs) - 1, int(round(q * (len(xs) - 1))))]


t0 = time.time()
server = subprocess.Popen([os.path.join(root, "build", "impinge"), "view", "--subject", subject, "--resolution", res,
                           "--no-browser", *extra], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
try:
    url = server.stdout.readline().split()[-1]
    setup_s = time.time() - t0
    from selenium import webdriver
    from selenium.webdriver.chrome.options import Options
    o = Options()
    for a in ("--headless=new", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--no-sandbox",
              "--window-size=1200,800"):
        o.add_argument(a)
    d = webdriver.Chrome(options=o)
    d.set_script_timeout(600)
    d.get(url)
    while not d.execute_script("return window.__impinge.ready || window.__impinge.error"):
        time.sleep(0.05)
    first_s = time.time() - t0
    poses = [[30 + 60 * k / n, 10 * ((k % 20) / 20 - 0.5), 40 * (k / n - 0.5)] for k in range(n)]
    data = d.execute_async_script("window.__impinge.timePoses(arguments[0]).then(arguments[1])", poses)
    draw = d.execute_script("return window.__impinge.timeDraws(30)")
    drawn = d.execute_script("return window.__impinge.trianglesDrawn")
    scene = d.execute_script("return window.__impinge.scene")
    d.quit()
finally:
    server.send_signal(signal.SIGINT)
    server.wait(timeout=30)
triangles = scene["femur_triangles"] + scene["pelvis_triangles"]
vertices = scene["femur_vertices"] + scene["pelvis_vertices"]
r = {"subject": subject, "resolution": res, "poses": n, "vertices": vertices, "triangles": triangles,
     "bytes_per_pose": 9 * vertices, "server_ready_s": setup_s, "first_coloured_frame_s": first_s,
     "data_path_median_ms": statistics.median(data), "data_path_p95_ms": quantile(data, 0.95),
     "poses_per_second": 1000 / statistics.mean(data),
     "triangles_drawn": drawn, "draw_median_ms": statistics.median(draw), "draw_p95_ms": quantile(draw, 0.95),
     "cores": os.cpu_count(), "renderer": "headless Chromium, SwiftShader (software WebGL2)"}
os.makedirs(out, exist_ok=True)
with open(os.path.join(out, "viewer_latency.json"), "w") as f:
    json.dump(r, f, indent=1)
print(f"{os.path.basename(os.path.dirname(subject))} at {res} deg, {vertices} vertices, {triangles} triangles: "
      f"data path median {r['data_path_median_ms']:.1f} ms, p95 {r['data_path_p95_ms']:.1f} ms "
      f"({r['poses_per_second']:.0f} poses/s); draw of {drawn} triangles median {r['draw_median_ms']:.0f} ms, p95 {r['draw_p95_ms']:.0f} ms; "
      f"first coloured frame {first_s:.1f} s after the command; {out}/viewer_latency.json")
