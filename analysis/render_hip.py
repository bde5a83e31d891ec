"""Shaded renders of an `impinge distance` output folder (called by `impinge distance --render`).

usage: /usr/bin/python3 analysis/render_hip.py OUT_DIR
Reads OUT_DIR/summary.json, femur_gaps.ply and pelvis_gaps.ply; writes OUT_DIR/render.png (anterior,
lateral and acetabulum medial views side by side) and render_<view>.png for each view. The bones are
shown in the pelvic frame (anatomical neutral) or the input frame's anatomical axes (scan
neutral), within 60 mm of the hip centre; the acetabular clock face is drawn when known."""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from render import draw, read_gap_ply, to_frame  # noqa: E402


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: render_hip.py OUT_DIR")
    d = sys.argv[1]
    with open(os.path.join(d, "summary.json")) as f:
        s = json.load(f)
    cor = np.array(s["map_centre_mm"], float)  # the pelvic frame's origin
    lps = s["input_frame"] == "LPS"
    if "frames" in s:
        p = s["frames"]["pelvis"]
        axes = np.column_stack([p["x_axis"], p["y_axis"], p["z_axis"]])
        a = s["frames"]["acetabulum"]
        clock = {"centre": to_frame(np.array([a["rim_centre_mm"]]), cor, axes)[0],
                 "twelve": np.array(a["clock_twelve"]) @ axes, "three": np.array(a["clock_three"]) @ axes,
                 "radius_mm": a["rim_radius_mm"]}
    else:  # scan neutral: the input frame's anatomical axes (x anterior, y superior, z right)
        ras = np.diag([-1.0, -1.0, 1.0]) if lps else np.eye(3)  # RAS -> input
        axes = np.column_stack([ras @ [0, 1, 0], ras @ [0, 0, 1], ras @ [1, 0, 0]])
        clock = None
    # The cup: within the rim radius plus 3 mm of the hip centre (or head radius + 8 mm without a rim).
    cup_radius = (clock["radius_mm"] + 3.0) if clock else ((s.get("head_radius_mm") or 25.0) + 8.0)
    bodies = {}
    for name in ("femur", "pelvis"):
        V, F, rgb, _ = read_gap_ply(os.path.join(d, f"{name}_gaps.ply"))
        bodies[name] = (to_frame(V, cor, axes), F, rgb)
    views = [("anterior", ["femur", "pelvis"]), ("lateral", ["femur", "pelvis"]), ("acetabulum_medial", ["pelvis"])]
    fig = plt.figure(figsize=(12, 4.2))
    for k, (view, names) in enumerate(views):
        for target in (fig.add_subplot(1, 3, k + 1, projection="3d"), None):
            if target is None:
                f1 = plt.figure(figsize=(4.5, 4.5))
                target = f1.add_subplot(1, 1, 1, projection="3d")
            draw(target, [bodies[n] for n in names], view, s["side"], clock if view != "anterior" else None,
                 radius=cup_radius if view == "acetabulum_medial" else 60.0)
            if target.figure is not fig:
                target.figure.savefig(os.path.join(d, f"render_{view}.png"), dpi=130)
                plt.close(target.figure)
    pose = s.get("pose_deg", [0, 0, 0])
    fig.suptitle(f"flexion {pose[0]:g}, adduction {pose[1]:g}, internal rotation {pose[2]:g} deg "
                 f"({s['neutral']} neutral); colours: impingement levels", fontsize=9)
    fig.savefig(os.path.join(d, "render.png"), dpi=130)
    plt.close(fig)


if __name__ == "__main__":
    main()
