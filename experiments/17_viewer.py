"""17_viewer: impinge view, the thesis' Joint3D (section 3.4) in the browser, photographed as the thesis showed it
and timed (issue 79).

usage: exp_17_viewer --out DIR [--data DIR] [--quick]
Runs build/impinge view on each hip (the shared hips with --data; always the generated hip with a 2 mm cam) and
drives its page in Debian's headless Chromium (SwiftShader). Writes to OUT/17_viewer/:
- images.csv (hip, figure, view, display, pose, file, the share of the drawing's pixels showing a bone and the share
  in a level's colour) and the PNGs it names: Figure 36 (the page: a right hip from anterior), Figure 44 (filled,
  lines and blending x anterior, medial and oblique views at a pose, the first hip), Figure 42's three views
  (anterior and lateral with both bones, the acetabulum from medial) and Tables 12-13's extremity images (the
  acetabulum from medial at each of four motions' ROM limits) per hip, and Figure 41 (the first hip pushed past its
  first ROM limit, as the thesis pushed the head into the socket to show the colours: the acetabulum from medial, the
  femur from anterior, and the page's legend of the levels);
- levels.csv: Figure 41's pose and, per bone and level (the page's levels: 255 not tested), its vertices;
- latency.csv per hip: the data path (a pose asked to its values in the page's colour buffer: request, detection,
  transfer, decode, colouring) over many poses, the draw (one colour upload and one render of the page as it opens:
  both bones, the pelvis cropped to the acetabulum; triangles_drawn; waited for by reading a pixel back), the first coloured frame after the command starts, and the size, poses, writing time and load time
  (from disk, no server) of a --export file;
- meta.json."""
import csv
import os
import signal
import statistics
import subprocess
import tempfile
import time

from experiment_support import ROOT, experiment_args, write_meta

import impinge

CLI = os.path.join(ROOT, "build", "impinge")
EXTREMITY_MOTIONS = ("flexion", "abduction", "internal_rotation_90_flexion", "external_rotation")
FIG41_PAST_DEG = 10.0  # Figure 41's pose: this far past the first ROM limit along its motion


def quantile(xs, q):
    xs = sorted(xs)
    return xs[min(len(xs) - 1, int(round(q * (len(xs) - 1))))]


def browser():
    from selenium import webdriver
    from selenium.webdriver.chrome.options import Options
    o = Options()
    for a in ("--headless=new", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--no-sandbox",
              "--window-size=1280,860", "--hide-scrollbars"):
        o.add_argument(a)
    d = webdriver.Chrome(options=o)
    d.set_script_timeout(900)
    return d


def serve(subject, resolution):
    t0 = time.time()
    p = subprocess.Popen([CLI, "view", "--subject", subject, "--resolution", str(resolution), "--no-browser"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line = p.stdout.readline()
    if not line.startswith("impinge view: http://"):
        p.kill()
        raise SystemExit(f"impinge view on {subject}: {line!r} {p.stderr.read()}")
    return p, line.split()[-1], t0


def wait(d, script, timeout=600):
    t0 = time.time()
    while time.time() - t0 < timeout:
        v = d.execute_script(script)
        if v:
            return v
        time.sleep(0.05)
    raise SystemExit(f"timed out: {script}")


def shares(png):
    """(share of pixels off the page's background, share in a saturated colour: a level's or the ramp's)."""
    import io

    import numpy as np
    from PIL import Image
    a = np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(int)
    background = (np.abs(a - [244, 244, 242]).sum(axis=2) > 12)
    saturated = (a.max(axis=2) - a.min(axis=2)) > 60
    return float(background.mean()), float(saturated.mean())


def page_state(d, display="filled", femur=True, pelvis=True, crop=True, colour="levels", clock=True):
    d.execute_script(
        "const s = (id, v) => { const e = document.getElementById(id); if (e.type === 'checkbox') e.checked = v; "
        "else e.value = v; (e.onchange || (() => {}))(); };"
        "s('display', arguments[0]); s('show-femur', arguments[1]); s('show-pelvis', arguments[2]);"
        "s('crop', arguments[3]); s('colour', arguments[4]); s('show-clock', arguments[5]);",
        display, femur, pelvis, crop, colour, clock)


def shoot(d, folder, name, rows, hip, figure, view, display, pose, whole_page=False):
    d.execute_script("window.__impinge.setView(arguments[0]);"
                     "document.getElementById('status').style.visibility = arguments[1] ? 'visible' : 'hidden'",
                     view, whole_page)
    time.sleep(0.3)
    d.execute_script("return new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)))")
    png = d.get_screenshot_as_png() if whole_page else d.find_element("css selector", "#view canvas").screenshot_as_png
    with open(os.path.join(folder, name), "wb") as f:
        f.write(png)
    bone, coloured = shares(png)
    rows.append([hip, figure, view, display, *pose, name, round(bone, 4), round(coloured, 4)])


def fig41(d, folder, rows, levels, hip, rom):
    """Thesis Figure 41: the levels' colours on both bones at a pose past the first ROM limit (the bones overlap, so
    every level shows), and the page's legend of them (cropped from the whole page)."""
    motion = next((m for m in EXTREMITY_MOTIONS if rom.get(m, {}).get("pose_at_limit_deg")), None)
    if motion is None:
        return
    r = rom[motion]
    start, at, limit = r.get("start_deg") or [0.0, 0.0, 0.0], r["pose_at_limit_deg"], r["limit_deg"]
    scale = (limit + FIG41_PAST_DEG) / limit if limit else 1.0
    pose = tuple(round(s_ + (a - s_) * scale, 2) for s_, a in zip(start, at))
    set_pose(d, pose)
    t = [float(x) for x in d.execute_script("return window.__impinge.scene.levels_thresholds_mm")]
    ranges = [f">{t[0]:.3g}"] + [f"{a:.3g}-{b:.3g}" for a, b in zip(t[:-1], t[1:])] + [f"<={t[-1]:.3g}"]
    for bone, femur, pelvis, view in (("pelvis", False, True, "lateral"), ("femur", True, False, "anterior")):
        page_state(d, femur=femur, pelvis=pelvis, clock=False)
        shoot(d, folder, f"fig41_{bone}.png", rows, hip, "Fig. 41", view, "filled", pose)
        counts = d.execute_script("const c = {}; for (const x of window.__impinge.frame[arguments[0]].level) "
                                  "c[x] = (c[x] || 0) + 1; return c;", bone)
        for lv in [*range(len(ranges)), 255]:  # every level, shown or not (255: not tested)
            levels.append([hip, motion, *pose, bone, lv, ranges[lv] if lv < len(ranges) else "not tested",
                           int(counts.get(str(lv), 0))])
    page_state(d)
    png = d.get_screenshot_as_png()
    box = d.execute_script("const r = ['legend', 'legend-labels', 'legend-note'].map(i => "
                           "document.getElementById(i).getBoundingClientRect()); const dpr = window.devicePixelRatio;"
                           "return [Math.min(...r.map(b => b.left)) * dpr, r[0].top * dpr, "
                           "Math.max(...r.map(b => b.right)) * dpr, r[2].bottom * dpr];")
    import io

    from PIL import Image
    Image.open(io.BytesIO(png)).crop(tuple(int(round(x)) for x in box)).save(os.path.join(folder, "fig41_legend.png"))
    rows.append([hip, "Fig. 41", "legend", "levels", *pose, "fig41_legend.png", 0.0, 0.0])


def set_pose(d, pose):
    d.execute_async_script("window.__impinge.setPose(arguments[0], arguments[1], arguments[2]).then(arguments[3])",
                           *pose)


def main():
    d_out, data, quick = experiment_args("17_viewer", __doc__)
    resolution = 0.5 if quick else 0.1
    hips = sorted(h for h in os.listdir(data) if os.path.exists(os.path.join(data, h, "subject.json"))) \
        if data and os.path.isdir(data) else []
    if quick:
        hips = hips[:1]
    gen = os.path.join(tempfile.mkdtemp(prefix="impinge_exp17_"), "generated")  # an input, not a result
    subprocess.run([CLI, "generate", "--triangles", "12000", "--cam", "2", "--out", gen], check=True,
                   capture_output=True)
    subjects = [(h, os.path.join(data, h, "subject.json")) for h in hips] + [("generated", os.path.join(gen,
                                                                                                       "subject.json"))]
    images, latency, levels = [], [], []
    d = browser()
    try:
        for k, (hip, subject) in enumerate(subjects):
            print(f"[17_viewer] {hip}", flush=True)
            p, url, t0 = serve(subject, resolution)
            try:
                d.get(url)
                wait(d, "return window.__impinge.ready || window.__impinge.error")
                error = d.execute_script("return window.__impinge.error")
                if error:
                    raise SystemExit(f"impinge view on {hip}: the page failed: {error}")
                first_s = time.time() - t0
                pose = (60.0, 10.0, 20.0)
                set_pose(d, pose)
                if k == 0:  # Figure 36: the page; Figure 44: three display modes x three views
                    page_state(d)
                    shoot(d, d_out, "fig36.png", images, hip, "Fig. 36", "anterior", "filled", pose, whole_page=True)
                    for view in ("anterior", "medial", "oblique"):
                        for display in ("filled", "lines", "blending"):
                            page_state(d, display=display)
                            shoot(d, d_out, f"fig44_{view}_{display}.png", images, hip, "Fig. 44", view, display, pose)
                # Figure 42: at the scan pose, both bones from anterior and lateral, the acetabulum from medial.
                zero = (0.0, 0.0, 0.0)
                set_pose(d, zero)
                for view, femur in (("anterior", True), ("lateral", True), ("medial", False)):
                    page_state(d, femur=femur)
                    shoot(d, d_out, f"fig42_{hip}_{view}.png", images, hip, "Fig. 42", view, "filled", zero)
                # Tables 12-13: the acetabulum from medial at each motion's ROM limit.
                rom = wait(d, "return window.__impinge.rom || (document.getElementById('rom-state').textContent"
                              ".startsWith('computing') ? null : [])")  # [] when the ROM search failed (said)
                rom = {r["motion"]: r for r in rom}
                if k == 0:
                    fig41(d, d_out, images, levels, hip, rom)
                for motion in EXTREMITY_MOTIONS:
                    at = rom.get(motion, {}).get("pose_at_limit_deg")
                    if not at:
                        continue
                    set_pose(d, at)
                    page_state(d, femur=False)
                    shoot(d, d_out, f"extremity_{hip}_{motion}.png", images, hip, "Tables 12-13", "medial",
                          "filled", tuple(at))
                # Speed: the data path and the draw, measured apart.
                n = 40 if quick else 200
                poses = [[30 + 60 * i / n, 10 * ((i % 20) / 20 - 0.5), 40 * (i / n - 0.5)] for i in range(n)]
                data_ms = d.execute_async_script("window.__impinge.timePoses(arguments[0]).then(arguments[1])", poses)
                page_state(d)  # the page as it opens: both bones, the pelvis cropped to the acetabulum
                d.execute_script("window.__impinge.setView('anterior')")
                draw_ms = d.execute_script("return window.__impinge.timeDraws(arguments[0])", 10 if quick else 30)
                drawn = d.execute_script("return window.__impinge.trianglesDrawn")
                scene = d.execute_script("return window.__impinge.scene")
            finally:
                p.send_signal(signal.SIGINT)
                p.wait(timeout=60)
            export = os.path.join(d_out, f"export_{hip}.html")
            t1 = time.time()
            r = subprocess.run([CLI, "view", "--subject", subject, "--resolution", str(resolution), "--export",
                                export], capture_output=True, text=True, check=True)
            export_s = time.time() - t1
            export_poses = int(r.stdout.split("(")[1].split()[0])
            export_mb = os.path.getsize(export) / 1e6
            t2 = time.time()  # the file opened from disk, with no server, until its first pose is coloured
            d.get("file://" + os.path.abspath(export))
            wait(d, "return window.__impinge && (window.__impinge.ready || window.__impinge.error)")
            export_load_s = time.time() - t2
            os.remove(export)  # its size and load time are the figures; the file itself is not kept
            latency.append([hip, resolution, scene["femur_vertices"] + scene["pelvis_vertices"],
                            scene["femur_triangles"] + scene["pelvis_triangles"], n,
                            round(statistics.median(data_ms), 3), round(quantile(data_ms, 0.95), 3),
                            drawn, round(statistics.median(draw_ms), 3), round(quantile(draw_ms, 0.95), 3),
                            round(first_s, 3),
                            round(export_mb, 3), export_poses, round(export_s, 3), round(export_load_s, 3)])
    finally:
        d.quit()
    with open(os.path.join(d_out, "images.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["hip", "figure", "view", "display", "flexion_deg", "adduction_deg", "internal_rotation_deg",
                    "file", "bone_share", "coloured_share"])
        w.writerows(images)
    with open(os.path.join(d_out, "levels.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["hip", "motion", "flexion_deg", "adduction_deg", "internal_rotation_deg", "bone", "level",
                    "range_mm", "vertices"])
        w.writerows(levels)
    with open(os.path.join(d_out, "latency.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["hip", "resolution_deg", "vertices", "triangles", "poses", "data_path_median_ms",
                    "data_path_p95_ms", "triangles_drawn", "draw_median_ms", "draw_p95_ms", "first_coloured_frame_s",
                    "export_mb",
                    "export_poses", "export_s", "export_load_s"])
        w.writerows(latency)
    write_meta(d_out, "17_viewer", quick=quick, data_folder=data if hips else None,
               timing="wall clock in the page (performance.now) and of the command; each hip once: medians and 95th "
                      "percentiles over its poses and draws",
               parameters={"resolution_deg": resolution, "fig41_past_limit_deg": FIG41_PAST_DEG, "subjects": hips + ["generated (12k triangles, 2 mm cam)"],
                           "renderer": "headless Chromium, SwiftShader (software WebGL2)", "window": "1280x860"},
               versions={"chromium": subprocess.run(["chromium", "--version"], capture_output=True,
                                                    text=True).stdout.strip()})


if __name__ == "__main__":
    main()
