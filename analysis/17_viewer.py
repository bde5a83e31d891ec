"""17_viewer: impinge view's pictures as the thesis showed Joint3D's, and its speed (issue 79).

Reads RESULTS/17_viewer/{images,latency}.csv and the PNGs images.csv names; writes fig44.pdf/png (three display modes
x three views, the thesis' Figure 44), fig36.pdf/png (the page, Figure 36), fig42.pdf/png (per hip: both bones from
anterior and lateral, the acetabulum from medial, at the scan pose), extremities.pdf/png (the acetabulum at each
motion's ROM limit, Tables 12-13), fig41.pdf/png (the levels on both bones past the first hip's first ROM limit, with
the page's legend: the thesis' Figure 41, from levels.csv) and macros.tex (the first hip's data path, draw, first
frame and export; Figure 41's pose and levels)."""
import os
import re

import matplotlib.pyplot as plt
import numpy as np
from PIL import Image

from common import experiment_dir, read_csv, save, write_macros

d = experiment_dir("17_viewer")
images = read_csv(d, "images.csv")
latency = read_csv(d, "latency.csv")


def crop(path):
    """The picture without the page's empty background around the bones (a margin of 12 pixels kept)."""
    a = np.asarray(Image.open(os.path.join(d, path)).convert("RGB"))
    ink = np.abs(a.astype(int) - [244, 244, 242]).sum(axis=2) > 12
    ink[-40:, :330] = False  # the pose line in the corner
    ys, xs = np.nonzero(ink)
    if len(xs) == 0:
        return a
    return a[max(0, ys.min() - 12):ys.max() + 12, max(0, xs.min() - 12):xs.max() + 12]


def grid(rows, row_labels, col_labels, stem, width=7.0):
    n_r, n_c = len(rows), max(len(r) for r in rows)
    fig, axes = plt.subplots(n_r, n_c, figsize=(width, width * n_r / n_c * 0.85), squeeze=False)
    for i, r in enumerate(rows):
        for j in range(n_c):
            ax = axes[i][j]
            ax.axis("off")
            if j < len(r) and r[j] is not None:
                ax.imshow(crop(r[j]))
            if i == 0 and j < len(col_labels):
                ax.set_title(col_labels[j], fontsize=8)
        axes[i][0].text(-0.04, 0.5, row_labels[i], transform=axes[i][0].transAxes, rotation=90, ha="right",
                        va="center", fontsize=8)
    fig.tight_layout()
    save(fig, d, stem)


def file_of(**match):
    sel = images
    for k, v in match.items():
        sel = sel[sel[k] == v]
    return sel.file.iloc[0] if len(sel) else None


f44 = images[images.figure == "Fig. 44"]
views, displays = ["anterior", "medial", "oblique"], ["filled", "lines", "blending"]
grid([[file_of(figure="Fig. 44", view=v, display=m) for m in displays] for v in views], views,
     ["filled polygons", "lines", "blending"], "fig44")

fig = plt.figure(figsize=(7.0, 4.7))
ax = fig.add_axes([0, 0, 1, 1])
ax.axis("off")
ax.imshow(np.asarray(Image.open(os.path.join(d, file_of(figure="Fig. 36")))))
save(fig, d, "fig36", rect=(0, 0, 1, 1))

hips = list(dict.fromkeys(images.hip))
grid([[file_of(figure="Fig. 42", hip=h, view=v) for v in ("anterior", "lateral", "medial")] for h in hips], hips,
     ["anterior", "lateral", "acetabulum, medial"], "fig42", width=6.0)

motions = ["flexion", "abduction", "internal_rotation_90_flexion", "external_rotation"]
ext = images[images.figure == "Tables 12-13"]
grid([[file_of(figure="Tables 12-13", hip=h, file=f"extremity_{h}_{m}.png") for m in motions] for h in hips], hips,
     ["flexion", "abduction", "IR at 90 flexion", "external rotation"], "extremities")

# Figure 41: the acetabulum and the femur, each coloured by the levels at a pose past the ROM limit, and the page's
# legend below them.
levels = read_csv(d, "levels.csv") if os.path.exists(os.path.join(d, "levels.csv")) else None
f41 = {k: "--" for k in ("VWfOneMotion", "VWfOneHip", "VWfOnePose", "VWfOneRanges", "VWfOnePelvisLevels",
                          "VWfOneFemurLevels", "VWfOneLevels")}  # this run drew no Figure 41 (no ROM limit)
if levels is not None and len(levels) and file_of(figure="Fig. 41", file="fig41_legend.png"):
    fig = plt.figure(figsize=(6.0, 3.6))
    gs = fig.add_gridspec(2, 2, height_ratios=[4, 1.1])
    for j, (bone, title) in enumerate((("pelvis", "acetabulum, lateral (femur hidden)"),
                                       ("femur", "femur, anterior (pelvis hidden)"))):
        ax = fig.add_subplot(gs[0, j])
        ax.imshow(crop(f"fig41_{bone}.png"))
        ax.set_title(title, fontsize=8)
        ax.axis("off")
    ax = fig.add_subplot(gs[1, :])
    ax.imshow(np.asarray(Image.open(os.path.join(d, "fig41_legend.png")).convert("RGB")))
    ax.axis("off")
    fig.subplots_adjust(left=0.01, right=0.99, bottom=0.01, top=0.93, hspace=0.05, wspace=0.05)
    save(fig, d, "fig41", rect=(0, 0, 1, 1))
    lv = levels[levels.level != 255]
    first41 = levels.iloc[0]
    ranges = [re.sub(r"\d+\.\d+", lambda m: f"{float(m.group()):.3g}", r).replace("-", "--")
              for r in dict.fromkeys(lv.sort_values("level").range_mm)]
    shown = {b: sorted(g[g.vertices > 0].level.unique()) for b, g in lv.groupby("bone")}
    f41 = {"VWfOneMotion": str(first41.motion).replace("_", " "), "VWfOneHip": str(first41.hip).replace("_", r"\_"),
           "VWfOnePose": f"{first41.flexion_deg:g}, {first41.adduction_deg:g}, {first41.internal_rotation_deg:g}",
           "VWfOneRanges": ", ".join(ranges).replace("<=", r"$\le$").replace(">", "$>$"),
           "VWfOnePelvisLevels": str(len(shown.get("pelvis", []))), "VWfOneFemurLevels": str(len(shown.get("femur", []))),
           "VWfOneLevels": str(lv.level.nunique())}

first = latency.iloc[0]
macros = {
    "VWhip": str(first.hip).replace("_", r"\_"), "VWresolution": f"{first.resolution_deg:g}",
    "VWvertices": f"{int(first.vertices):,}", "VWtriangles": f"{int(first.triangles):,}", "VWposes": str(int(first.poses)),
    "VWmedianMs": f"{first.data_path_median_ms:.1f}", "VWpNinetyFiveMs": f"{first.data_path_p95_ms:.1f}",
    "VWposesPerSecond": f"{1000 / first.data_path_median_ms:.0f}",
    "VWdrawMedianMs": f"{first.draw_median_ms:.0f}", "VWtrianglesDrawn": f"{int(first.triangles_drawn):,}", "VWdrawPNinetyFiveMs": f"{first.draw_p95_ms:.0f}",
    "VWfirstFrameS": f"{first.first_coloured_frame_s:.1f}", "VWexportMB": f"{first.export_mb:.1f}",
    "VWexportPoses": str(int(first.export_poses)), "VWexportS": f"{first.export_s:.1f}",
    "VWexportLoadS": f"{first.export_load_s:.1f}",
    # The pictures of the bones (the legend's picture, view "legend", draws no bone).
    "VWhips": str(len(latency)), "VWimages": str(int((images.view != "legend").sum())),
    "VWmedianLow": f"{latency.data_path_median_ms.min():.1f}", "VWmedianHigh": f"{latency.data_path_median_ms.max():.1f}",
    "VWbareShareLow": f"{100 * images[images.view != 'legend'].bone_share.min():.0f}",
}
macros.update(f41)
write_macros(d, "macros", macros)
