"""08_distance_maps: gap statistics on the real joints and the generated model, map images
(thesis Fig. 31), colour-mapped renders of both bones (Fig. 41-42), RSID beside USID (Fig. 50).

Reads RESULTS/08_distance_maps/gap_statistics.csv, vertex_gaps.csv, clock_faces.csv,
radial_vs_distance.csv, radial_vs_distance_vertices.csv and the
render_<subject>_<body>.ply meshes the driver wrote; writes table_radial_vs_distance.tex,
radial_vs_distance.pdf (the radial gap against the Euclidean distance, issue 26), table_finest.tex, table_convergence.tex,
table_acetabulum.tex, table_usid.tex, table_schemes.tex, min_gap.pdf, levels.pdf, maps_<subject>.pdf (map images with colour bars), render_<subject>.pdf (shaded, with the clock face), macros.tex."""
import json
import os
import re

import numpy as np
import pandas as pd
import matplotlib.pyplot as plt

from common import experiment_dir, precision_axis, read_csv, save, write_macros, write_table
from render import REPORT_LEVELS_MM, draw, level_key, level_rgb, read_gap_ply

d = experiment_dir("08_distance_maps")
allst = read_csv(d, "gap_statistics.csv")
st = allst[allst.scheme == "equiangular"]
hx = allst[allst.scheme == "helix"]
vg = read_csv(d, "vertex_gaps.csv")
with open(os.path.join(d, "meta.json")) as f:
    meta = json.load(f)
finest = st.precision_deg.min()
subjects = list(dict.fromkeys(st.subject))

# Table: finest precision, exact mode, both scans per subject.
rows = []
for s in subjects:
    for scan in ("ball", "socket"):
        r = st[(st.subject == s) & (st.precision_deg == finest) & (st["mode"] == "exact") & (st.scan == scan)].iloc[0]
        rows.append([s, scan, f"{int(r.vertices_tested):,}", f"{int(r.vertices_no_surface):,}",
                     f"{int(r.vertices_beyond_reach):,}", f"{r.min_gap_mm:.2f}", f"{int(r.vertices_penetrating)}",
                     f"{r.area_penetrating_mm2:.1f}", f"{r.head_radius_mm:.2f}", f"{r.sphere_fit_rms_mm:.2f}"])
write_table(d, "table_finest", ["subject", "scan", "tested", "no surface", "beyond reach", "min gap (mm)",
                                "pen. vertices", "pen. area (mm$^2$)", "head $r$ (mm)", "fit RMS (mm)"], rows,
            align="llrrrrrrrr")

def ms_spread(r, what):
    """'median (lower quartile-upper quartile)' ms of a row's sampling or detection (alternated rounds)."""
    return f"{r[what + '_ms']:.1f} ({r[what + '_q25_ms']:.1f}-{r[what + '_q75_ms']:.1f})"


def ns_spread(r):
    """ns per look-up: median (quartiles) of the row's detection over its look-ups."""
    per = r.detection_ns_per_lookup / r.detection_ms if r.detection_ms > 0 else np.nan
    return f"{r.detection_ns_per_lookup:.0f} ({r.detection_q25_ms * per:.0f}-{r.detection_q75_ms * per:.0f})"


# Table: min gap and penetration against precision and mode (ball scan).
rows = []
for s in subjects:
    for (p, mode), g in st[(st.subject == s) & (st.scan == "ball")].groupby(["precision_deg", "mode"], sort=False):
        r = g.iloc[0]
        sock = st[(st.subject == s) & (st.scan == "socket") & (st.precision_deg == p) & (st["mode"] == mode)].iloc[0]
        lin = "" if np.isnan(r.linear_vs_exact_p95_abs_mm) else f"{r.linear_vs_exact_p95_abs_mm:.4f}"
        rows.append([s, f"{p:g}", mode, f"{r.min_gap_mm:.3f}", f"{sock.min_gap_mm:.3f}", f"{int(r.vertices_penetrating)}",
                     ms_spread(r, "sampling"), ms_spread(sock, "sampling"), ns_spread(r), lin])
write_table(d, "table_convergence", ["subject", "$p$", "mode", "ball min gap", "socket min gap", "ball pen.",
                                     "femur map ms", "pelvis map ms", "ns/lookup", "lin-exact p95"], rows,
            align="lrlrrrrrrr")

# Figure: min gap vs precision.
fig, axes = plt.subplots(1, 2, figsize=(8, 3.2), sharey=False)
colour = {s: f"C{k}" for k, s in enumerate(subjects)}
for ax, scan in zip(axes, ("ball", "socket")):
    for s in subjects:
        for mode, ls in (("exact", "-"), ("linear", "--")):
            g = st[(st.subject == s) & (st.scan == scan) & (st["mode"] == mode)].sort_values("precision_deg")
            ax.semilogx(g.precision_deg, g.min_gap_mm, ls, marker="o", markersize=3, color=colour[s])
    ax.set_title(f"{scan} scan")
    ax.set_xlabel("precision p (deg)")
    ax.set_ylabel("minimum gap (mm)")
    ax.invert_xaxis()
    precision_axis(ax, st.precision_deg)
    ax.axhline(0, color="k", lw=0.5)
    ax.grid(True, alpha=0.3)
# One legend beside the panels: a colour per subject, a line style per mode.
from matplotlib.lines import Line2D  # noqa: E402
fig.legend(handles=[Line2D([], [], color=colour[s], marker="o", markersize=3, label=s) for s in subjects] +
           [Line2D([], [], color="k", ls=ls, label=mode) for mode, ls in (("exact", "-"), ("linear", "--"))],
           loc="center right", fontsize=7, frameon=False)
save(fig, d, "min_gap", rect=(0, 0, 0.8, 1))

# Figure: impingement levels (area share) at the finest precision, exact mode.
levels = ["level_none", "level_yellow", "level_orange", "level_red", "level_purple"]
colours = ["#28aa3c", "#ffe600", "#ff8c00", "#dc1414", "#8c00c8"]
fig, ax = plt.subplots(figsize=(6, 3))
labels, bottoms = [], None
data = []
for s in subjects:
    for scan in ("ball", "socket"):
        r = st[(st.subject == s) & (st.precision_deg == finest) & (st["mode"] == "exact") & (st.scan == scan)].iloc[0]
        labels.append(f"{s}\n{scan}")
        data.append([r[l] for l in levels])
data = np.array(data, dtype=float)
bottom = np.zeros(len(labels))
for k, l in enumerate(levels):
    ax.bar(range(len(labels)), data[:, k], bottom=bottom, color=colours[k], label=l.replace("level_", ""))
    bottom += data[:, k]
ax.set_xticks(range(len(labels)))
ax.set_xticklabels(labels, fontsize=6)
ax.set_ylabel("tested vertices")
ax.legend(fontsize=6, ncol=5)
save(fig, d, "levels")

JOINT_WINDOW_MM = 20.0  # the map images' colour range beyond the nearest surface

# Map images (thesis Fig. 31) with axes and colour bars: the driver's grey PNGs turned back into
# distances by their scale (map_images.csv: grey 40 = nearest_mm, 255 = farthest_mm, 0 = no surface).
if os.path.exists(os.path.join(d, "map_images.csv")):
    import matplotlib.image as mpimg
    imgs = read_csv(d, "map_images.csv")
    for s_, g in imgs[imgs.scheme == "equiangular"].groupby("subject", sort=False):
        fig, axes = plt.subplots(1, 2, figsize=(9.5, 2.7))
        for ax, body, title in zip(axes, ("socket", "ball"), ("pelvis (socket) map", "femur (ball) map")):
            r = g[g.body == body]
            if not len(r):
                ax.axis("off")
                continue
            r = r.iloc[0]
            grey = np.round(mpimg.imread(os.path.join(d, r.file)) * 255.0)
            if grey.ndim == 3:
                grey = grey[..., 0]
            dist = np.ma.masked_where(grey == 0, r.nearest_mm + (grey - 40.0) / 215.0 * (r.farthest_mm - r.nearest_mm))
            cmap = plt.get_cmap("viridis").copy()
            cmap.set_bad("0.85")
            # The colours span the joint (the nearest surface and 20 mm beyond it: the head, the acetabulum and
            # its rim); farther surfaces (the femoral shaft, the ilium) take the last colour.
            im = ax.imshow(dist, cmap=cmap, extent=(0, 360, 180, 0), aspect="auto", interpolation="nearest",
                           vmin=r.nearest_mm, vmax=min(r.farthest_mm, r.nearest_mm + JOINT_WINDOW_MM))
            ax.set_xlabel("azimuth theta (deg)")
            ax.set_ylabel("polar angle phi (deg)")
            ax.set_xticks(range(0, 361, 90))
            ax.set_yticks(range(0, 181, 45))
            ax.set_title(f"{s_}: {title}, {r.resolution:g} deg (grey: no surface)", fontsize=8)
            fig.colorbar(im, ax=ax, label="radial distance (mm)", extend="max")
        save(fig, d, f"maps_{s_}")

# Acetabular orientation and scan pose per real subject (clock_faces.csv).
clk = read_csv(d, "clock_faces.csv")
anat = clk[clk.neutral == "anatomical"]
write_table(d, "table_acetabulum",
            ["subject", "head $r$", "acetabular $r$", "rim $r$", "inclination", "anteversion", "scan flexion",
             "scan adduction", "scan IR"],
            [[r.subject, f"{r.head_radius_mm:.1f}", f"{r.acetabular_radius_mm:.1f}", f"{r.rim_radius_mm:.1f}",
              f"{r.inclination_deg:.1f}", f"{r.anteversion_deg:.1f}", f"{r.scan_flexion_deg:.1f}",
              f"{r.scan_adduction_deg:.1f}", f"{r.scan_internal_rotation_deg:.1f}"] for r in anat.itertuples()])

# Shaded renders (render.py): both bones at the scan pose in the pelvic frame, anterior and lateral
# views, and the socket's medial view with the acetabular clock face (thesis Fig. 42-43, Tables 12-13).
for s in subjects:
    row = clk[clk.subject == s].iloc[0]
    clock = None
    if row.neutral == "anatomical":
        clock = {"centre": [row.centre_x_mm, row.centre_y_mm, row.centre_z_mm],
                 "twelve": [row.twelve_x, row.twelve_y, row.twelve_z],
                 "three": [row.three_x, row.three_y, row.three_z], "radius_mm": row.rim_radius_mm}
    bodies = {}
    for b in ("ball", "socket"):
        V, F, _, gap = read_gap_ply(os.path.join(d, f"render_{s}_{b}.ply"))
        rgb = level_rgb(gap, b == "ball")
        if row.neutral == "scan":  # generated: scan axes (RAS) -> (X anterior, Y superior, Z right)
            V = V[:, [1, 2, 0]]
        bodies[b] = (V, F, rgb)
    cup = (row.rim_radius_mm + 3.0) if clock else row.head_radius_mm + 8.0
    fig = plt.figure(figsize=(10, 3.6))
    for k, (view, names) in enumerate((("anterior", ("ball", "socket")), ("lateral", ("ball", "socket")),
                                       ("acetabulum_medial", ("socket",)))):
        ax = fig.add_subplot(1, 3, k + 1, projection="3d")
        draw(ax, [bodies[n] for n in names], view, row.side, clock if view != "anterior" else None,
             radius=cup if view == "acetabulum_medial" else 60.0)
    fig.suptitle(f"{s}: impingement levels at the scan pose", fontsize=9)
    level_key(fig)
    save(fig, d, f"render_{s}")

# Thesis Fig. 42 (sec. 3.4): on its CT hip the impinged socket regions lie at 12-4 and 8-9 o'clock. Ours: the
# clock hour of every socket vertex within 2 mm (the thesis' red) at the scan pose, per real subject, and the
# share of them inside the thesis' hours (beside the share of the clock face those hours cover).
THESIS_FIG42_HOURS = [(0, 4), (8, 9)]  # 12-4 and 8-9 o'clock
red_rows = []
for row in clk[clk.neutral == "anatomical"].itertuples():
    V, _, _, gap = read_gap_ply(os.path.join(d, f"render_{row.subject}_socket.ply"))
    v = V[gap <= REPORT_LEVELS_MM[2]] - np.array([row.centre_x_mm, row.centre_y_mm, row.centre_z_mm])
    hours = (np.degrees(np.arctan2(v @ np.array([row.three_x, row.three_y, row.three_z]),
                                   v @ np.array([row.twelve_x, row.twelve_y, row.twelve_z]))) / 30) % 12
    counts = np.histogram(hours, bins=12, range=(0, 12))[0]
    inside = sum(((hours >= a) & (hours < b)).sum() for a, b in THESIS_FIG42_HOURS)
    main = [h for h in range(12) if len(hours) and counts[h] >= 0.1 * len(hours)]
    red_rows.append({"subject": row.subject, "red_vertices": len(hours),
                     "share_in_thesis_hours": inside / len(hours) if len(hours) else np.nan,
                     "thesis_hours_share_of_clock": sum(b - a for a, b in THESIS_FIG42_HOURS) / 12,
                     "main_hours": " ".join(f"{12 if h == 0 else h}-{h + 1}" for h in main)})
pd.DataFrame(red_rows, columns=["subject", "red_vertices", "share_in_thesis_hours", "thesis_hours_share_of_clock",
                                "main_hours"]).to_csv(os.path.join(d, "red_clock_hours.csv"), index=False)

# The clinical angles (README figure): one real femur posed from anatomical neutral, pelvic frame.
if os.path.exists(os.path.join(d, "poses.csv")) and len(read_csv(d, "poses.csv")):
    ps = read_csv(d, "poses.csv")
    subj = next(s for s in subjects if os.path.exists(os.path.join(d, f"poses_{s}_pelvis.ply")))
    side = clk[clk.subject == subj].iloc[0].side
    Vp, Fp, _, _ = read_gap_ply(os.path.join(d, f"poses_{subj}_pelvis.ply"))
    pelvis = (Vp, Fp, np.full((len(Vp), 3), 0.82))
    fig = plt.figure(figsize=(11, 5.6))
    for k, r in enumerate(ps.itertuples()):
        Vf, Ff, _, _ = read_gap_ply(os.path.join(d, f"poses_{subj}_{r.pose}.ply"))
        femur = (Vf, Ff, np.tile([0.86, 0.72, 0.52], (len(Vf), 1)))
        for row, view in enumerate(("anterior", "lateral")):
            ax = fig.add_subplot(2, len(ps), row * len(ps) + k + 1, projection="3d")
            label = (f"flexion {r.flexion_deg:g}, adduction {r.adduction_deg:g}, IR {r.internal_rotation_deg:g}"
                     if row == 0 else "")
            draw(ax, [pelvis, femur], view, side, None, radius=260.0, extent=170.0,
                 title=(label + "\n" if label else "") + f"{view} view")
    fig.suptitle(f"{subj} ({side} hip): clinical angles from anatomical neutral (ISB joint coordinate system); "
                 "femur tan, pelvis grey", fontsize=9)
    save(fig, d, f"poses_{subj}")

# RSID beside USID (thesis Fig. 50): same precision (helix at the matched k), same mode.
rows = []
def versus(eb, es, ob, os_):
    """Columns comparing another scheme's ball and socket rows (ob, os_) with the equiangular grid's
    (eb, es): both min gaps, the ball gaps' p95 and max difference, sampling ms of both bones (the sum of their
    medians), ns per look-up of the ball scan (median and quartiles of the alternated rounds, ns_spread), and the
    bytes ratio of both maps."""
    return [f"{eb.min_gap_mm:.3f}", f"{ob.min_gap_mm:.3f}", f"{ob.vs_equiangular_p95_abs_mm:.4f}",
            f"{ob.vs_equiangular_max_abs_mm:.2f}", f"{(eb.sampling_ms + es.sampling_ms):.0f}",
            f"{(ob.sampling_ms + os_.sampling_ms):.0f}", ns_spread(eb), ns_spread(ob), f"{(ob.map_bytes + os_.map_bytes) / (eb.map_bytes + es.map_bytes):.3f}"]


def row_of(t, s_, scan, p, mode):
    return t[(t.subject == s_) & (t.scan == scan) & (t.precision_deg == p) & (t["mode"] == mode)].iloc[0]


rows = []
for s_ in subjects:
    for (p, mode), g in hx[(hx.subject == s_) & (hx.scan == "ball")].groupby(["precision_deg", "mode"], sort=False):
        h = g.iloc[0]
        rows.append([s_, f"{p:g} / {int(h.resolution)}", mode] +
                    versus(row_of(st, s_, "ball", p, mode), row_of(st, s_, "socket", p, mode), h,
                           row_of(hx, s_, "socket", p, mode)))
write_table(d, "table_usid", ["subject", "$p$ / $k$", "mode", "RSID min", "USID min", "p95 $|\\Delta|$",
                              "max $|\\Delta|$", "RSID ms", "USID ms", "RSID ns", "USID ns", "bytes ratio"], rows,
            align="llrrrrrrrrrr", stack=True)

fig, ax = plt.subplots(figsize=(5.5, 3.4))
for s_ in subjects:
    g = hx[(hx.subject == s_) & (hx.scan == "ball") & (hx["mode"] == "exact")].sort_values("precision_deg")
    ax.loglog(g.precision_deg, g.vs_equiangular_p95_abs_mm, marker="o", label=s_)
ax.set_xlabel("precision p (deg; helix at matched k)")
precision_axis(ax, allst.precision_deg)
ax.set_ylabel("p95 |USID - RSID| (mm)")
ax.set_title("ball gap, exact mode")
ax.invert_xaxis()
ax.grid(True, which="both", alpha=0.3)
fig.legend(*ax.get_legend_handles_labels(), loc="center right", frameon=False)
save(fig, d, "usid_vs_rsid", rect=(0, 0, 0.68, 1))

# Table: every other registered scheme beside the equiangular grid at the same node spacing, exact
# mode, at the finest spacing it was run at (issue 12: the driver loops over the registry).
ot = allst[~allst.scheme.isin(["equiangular", "helix"])]
rows = []
other_p = ot.precision_deg.min() if len(ot) else np.nan
for s_ in subjects:
    if st[(st.subject == s_) & (st.precision_deg == other_p) & (st["mode"] == "exact")].empty:
        continue
    for name, g in ot[(ot.subject == s_) & (ot.precision_deg == other_p)].groupby("scheme", sort=False):
        res = g.resolution.iloc[0]
        rows.append([s_, name, f"{int(res)}" if res == int(res) else f"{res:.4g}"] +
                    versus(row_of(st, s_, "ball", other_p, "exact"), row_of(st, s_, "socket", other_p, "exact"),
                           row_of(g, s_, "ball", other_p, "exact"), row_of(g, s_, "socket", other_p, "exact")))
write_table(d, "table_schemes", ["subject", "scheme", "resolution", "equiang. min", "min gap", "p95 $|\\Delta|$",
                                 "max $|\\Delta|$", "equiang. ms", "ms", "equiang. ns", "ns", "bytes ratio"], rows,
            align="llrrrrrrrrrr", stack=True)
others = ot[(ot.precision_deg == other_p) & (ot.scan == "ball")]

# The radial gap of the thesis against the Euclidean distance (issue 26): table and scatter.
rv = read_csv(d, "radial_vs_distance.csv")
rvv = read_csv(d, "radial_vs_distance_vertices.csv")
rows = []
for _, r in rv.iterrows():
    rows.append([r.subject, r.pose, r.scan, f"{int(r.vertices_both):,}", f"{int(r.differ_1mm):,}",
                 f"{int(r.differ_1mm_articular)}/{int(r.differ_1mm_intra_articular)}/{int(r.differ_1mm_extra_articular)}",
                 f"{r.max_abs_diff_mm:.1f}", f"{int(r.distance_without_gap):,}", f"{int(r.inside_by_distance)}",
                 f"{int(r.inside_missed_by_gap)}", f"{r.min_gap_mm:.2f}", f"{r.min_distance_mm:.2f}",
                 f"{r.area_penetrating_gap_mm2:.0f}", f"{r.area_penetrating_distance_mm2:.0f}"])
write_table(d, "table_radial_vs_distance",
            ["subject", "pose", "scan", "both", "$>1$ mm", "art./intra/extra", "max (mm)", "no gap", "inside",
             "missed", "min gap", "min dist.", "pen. area gap", "pen. area dist."], rows, align="lllrrrrrrrrrrr")
rv_subjects = list(dict.fromkeys(rvv.subject))
n_panels = max(1, len(rv_subjects))
n_cols = min(3, n_panels)
n_rows = -(-n_panels // n_cols)
fig, axes = plt.subplots(n_rows, n_cols, figsize=(6.5, 2.3 * n_rows + 0.6), sharex=True, sharey=True, squeeze=False)
pose_colour = {"scan": "#1f77b4", "flexion90": "#ff7f0e", "extension20": "#2ca02c"}
for ax, s_ in zip(axes.flat, rv_subjects):
    for pose, c in pose_colour.items():
        g = rvv[(rvv.subject == s_) & (rvv.pose == pose) & np.isfinite(rvv.gap_mm)]
        ax.scatter(np.clip(g.gap_mm, -10, 10), g.distance_mm, s=1, color=c, alpha=0.4, label=pose, rasterized=True)
    ax.plot([-10, 10], [-10, 10], "k-", lw=0.5)
    ax.axhline(0, color="k", lw=0.3)
    ax.axvline(0, color="k", lw=0.3)
    ax.set_xlim(-10.5, 10.5)
    ax.set_ylim(-4, 6.5)
    ax.set_title(s_)
for ax in axes.flat[len(rv_subjects):]:
    ax.set_visible(False)
fig.supxlabel("radial gap (mm; clipped at $\\pm$10)")
fig.supylabel("Euclidean distance (mm)")
handles, labels = axes[0][0].get_legend_handles_labels()
fig.legend(handles, labels, markerscale=8, loc="lower right", bbox_to_anchor=(0.98, 0.12) if n_rows * n_cols > n_panels
           else (0.98, 0.0), title="pose")
save(fig, d, "radial_vs_distance")
both = rv.vertices_both.sum()

pen = st[(st.precision_deg == finest) & (st["mode"] == "exact") & (st.scan == "ball")]

def pose_words(pose):
    """A pose's name as words: "extension20" -> "20 deg extension", "scan" -> "the scan pose"."""
    m = re.fullmatch(r"([a-z]+?)(\d+)", pose)
    return f"{m.group(2)} deg {m.group(1)}" if m else f"the {pose} pose"


# The README's example of the two parting (issue 81, item 7): on a shared hip, the vertex inside the other bone (by
# the distance) whose radial gap reads deepest past its distance.
inner = rvv[~rvv.subject.str.startswith("generated") & (rvv.distance_mm < 0) & np.isfinite(rvv.gap_mm)]
deep = inner.loc[(inner.gap_mm - inner.distance_mm).idxmin()] if len(inner) else None
deep_macros = ({"RDdeepWhere": f"{deep.subject} at {pose_words(deep.pose)}",
                "RDdeepBone": "femur" if deep.scan == "ball" else "pelvis",
                "RDdeepDistance": f"{-deep.distance_mm:.2f}", "RDdeepGap": f"{deep.gap_mm:.1f}"} if deep is not None
               else {k: "--" for k in ("RDdeepWhere", "RDdeepBone", "RDdeepDistance", "RDdeepGap")})

# USID beside RSID (thesis Fig. 50): the largest per-vertex difference of the matched helix, any mode, and exact.
usid = allst[(allst.scheme == "helix") & (allst.vs_equiangular_compared > 0)]
write_macros(d, "macros", {
    "DMusidMax": f"{usid.vs_equiangular_max_abs_mm.max():.2f}" if len(usid) else "--",
    "DMusidMaxExact": f"{usid[usid['mode'] == 'exact'].vs_equiangular_max_abs_mm.max():.3f}" if len(usid) else "--",
    "RDvertices": f"{int(both):,}",
    "RDdifferShare": f"{100 * rv.differ_1mm.sum() / max(both, 1):.1f}",
    "RDmaxDiff": f"{rv.max_abs_diff_mm.max():.1f}",
    "RDwithoutGap": f"{int(rv.distance_without_gap.sum()):,}",
    "RDinside": f"{int(rv.inside_by_distance.sum()):,}",
    "RDmissed": f"{int(rv.inside_missed_by_gap.sum()):,}",
    # Where the penetrating area differs between the two quantities (more than 1 mm^2 or 1 %).
    "RDareaDiffers": (lambda dif: (f"on {len(dif)} of {len(rv)} rows ("
                                   + ", ".join(f"{r.subject} {r.pose.replace('_', ' ')} {'femur' if r.scan == 'ball' else 'pelvis'}: "
                                               f"{r.area_penetrating_gap_mm2:.0f} against {r.area_penetrating_distance_mm2:.0f}~mm$^2$"
                                               for r in dif.itertuples()) + ")") if len(dif) else "on no row")(
        rv[(rv.area_penetrating_gap_mm2 - rv.area_penetrating_distance_mm2).abs() >
           np.maximum(1.0, 0.01 * rv[["area_penetrating_gap_mm2", "area_penetrating_distance_mm2"]].max(axis=1))]),
    "RDreach": f"{meta['parameters']['radial_vs_distance']['reach_mm']:g}",
    "RDprecision": f"{meta['parameters']['radial_vs_distance']['precision_deg']:g}",
    "DMfinest": f"{finest:g}",
    "DMsubjects": str(len(subjects)),
    "DMotherSpacing": f"{other_p:g}",
    "DMotherSchemes": str(others.scheme.nunique()),
    "DMotherPninetyFiveMax": f"{others.vs_equiangular_p95_abs_mm.max():.4f}",
    "DMpenetratingSubjects": str(int((pen.vertices_penetrating > 0).sum())),
    "DMinclinationRange": (f"{anat.inclination_deg.min():.0f}--{anat.inclination_deg.max():.0f}" if len(anat) else "n/a"),
    "DMrimRmsRange": (f"{anat.rim_plane_rms_mm.min():.1f}--{anat.rim_plane_rms_mm.max():.1f}" if len(anat) else "n/a"),
    "DManteversionRange": (f"{anat.anteversion_deg.min():.0f}--{anat.anteversion_deg.max():.0f}" if len(anat) else "n/a"),
    **deep_macros,
})
