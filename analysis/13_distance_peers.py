"""13_distance_peers: impinge's signed Euclidean distances beside Open3D's and VTK's on the same vertices and
poses, one thread each (issue 26, item 4).

Reads RESULTS/13_distance_peers/distance_peers.csv; writes table_peers.tex (per subject, medians over poses),
peers_time.pdf (time per pose per tool and subject), macros.tex."""
import json
import os

import matplotlib.pyplot as plt
import numpy as np

from common import experiment_dir, read_csv, save, write_macros, write_table

d = experiment_dir("13_distance_peers")
t = read_csv(d, "distance_peers.csv")
subjects = list(dict.fromkeys(t.subject))
t["both_ms"] = t.impinge_radial_ms + t.impinge_distance_ms
t["open3d_over_distance"] = t.open3d_ms / t.impinge_distance_ms
t["vtk_over_distance"] = t.vtk_ms / t.impinge_distance_ms


def f(x, n=2):
    return "--" if not np.isfinite(x) else f"{x:.{n}f}"


rows = []
for s in subjects:
    g = t[t.subject == s]
    rows.append([s, str(len(g)), f"{g.vertices.median():.0f}", f(g.impinge_radial_ms.median()),
                 f(g.impinge_distance_ms.median()), f(g.open3d_ms.median()), f(g.vtk_ms.median(), 1),
                 f(g.open3d_over_distance.median(), 1), f"{g.vtk_max_diff_mm.max():.0e}",
                 f"{g.open3d_max_diff_mm.max():.2g}", str(int(g.open3d_sign_disagreements.sum())),
                 str(int(g.vtk_sign_disagreements.sum()))])
write_table(d, "table_peers", ["subject", "poses", "vertices", "radial ms", "distance ms", "Open3D ms", "VTK ms",
                               "Open3D / distance", "VTK max diff mm", "Open3D max diff mm", "Open3D signs",
                               "VTK signs"], rows, align="lrrrrrrrrrrr")

fig, ax = plt.subplots(figsize=(7, 3.2))
x = np.arange(len(subjects))
w = 0.2
for k, (col, label) in enumerate([("impinge_radial_ms", "impinge radial"), ("impinge_distance_ms", "impinge distance"),
                                  ("open3d_ms", "Open3D"), ("vtk_ms", "VTK")]):
    ax.bar(x + (k - 1.5) * w, [t[t.subject == s][col].median() for s in subjects], w, label=label)
ax.set_xticks(x, subjects)
ax.set_yscale("log")
ax.set_ylabel("ms per pose (both bones, one thread)")
ax.legend(fontsize=7)
save(fig, d, "peers_time")

wrong = t.groupby("subject").open3d_sign_disagreements.sum()
with open(os.path.join(d, "meta.json")) as fm:
    versions = json.load(fm)["versions"]
write_macros(d, "macros", {
    "PEERsubjects": str(len(subjects)),
    "PEERposes": str(int(t.groupby("subject").size().max())),
    "PEERopenOverDistanceRange": f"{t.groupby('subject').open3d_over_distance.median().min():.1f}--"
                                 f"{t.groupby('subject').open3d_over_distance.median().max():.1f}",
    "PEERopenOverBothRange": f"{(t.open3d_ms / t.both_ms).groupby(t.subject).median().min():.1f}--"
                             f"{(t.open3d_ms / t.both_ms).groupby(t.subject).median().max():.1f}",
    "PEERvtkOverDistanceRange": f"{t.groupby('subject').vtk_over_distance.median().min():.0f}--"
                                f"{t.groupby('subject').vtk_over_distance.median().max():.0f}",
    "PEERvtkMaxDiff": f"{t.vtk_max_diff_mm.max():.0e}".replace("e-0", "\\times 10^{-").replace("e-", "\\times 10^{-") + "}",
    "PEERvtkSigns": str(int(t.vtk_sign_disagreements.sum())),
    "PEERopenSigns": str(int(t.open3d_sign_disagreements.sum())),
    "PEERopenSignSubjects": str(int((wrong > 0).sum())),
    "PEERopenMaxDiff": f"{t.open3d_max_diff_mm.max():.2f}",
    "PEERtenfoldPoses": str(int((t.open3d_over_distance >= 10).sum())),
    "PEERallPoses": str(len(t)),
    "PEERopenVersion": versions["open3d"],
    "PEERvtkVersion": versions["vtk"],
})
