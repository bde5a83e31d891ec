"""06_conchoid_sampling: thesis sec. 5.1 -- curve length, Table 10, Fig. 58-59, approximations,
and weighted vs equiangular vs helix sampling at equal node count on a conchoid joint.

Reads RESULTS/06_conchoid_sampling/{length,table10,angles,equal_nodes}.csv; writes
table_length.tex, table10.tex, angles.pdf/png, table_equal.tex, equal.pdf/png, fig57.pdf/png (the thesis' Fig. 57:
Table 10's four rays on the conchoid, original dashed and adjusted solid, from the experiment's a and b), macros.tex."""
import json
import os

import matplotlib.pyplot as plt
import numpy as np

from common import experiment_dir, read_csv, save, write_macros, write_table

d = experiment_dir("06_conchoid_sampling")
ln = read_csv(d, "length.csv")
t10 = read_csv(d, "table10.csv")
an = read_csv(d, "angles.csv")
eq = read_csv(d, "equal_nodes.csv")

write_table(d, "table_length", ["variant", "length (mm)", "length / $b$", "rel. error"],
            [[r.variant, f"{r.length_mm:.4f}", f"{r.length_over_b:.4f}", f"{100 * r.rel_error_vs_exact:+.3f}%"]
             for r in ln.itertuples()], align="lrrr")
write_table(d, "table10", ["$i$", "original", "thesis", "Eq. 16", "exact", "Eq. 16 adj.", "exact adj."],
            [[f"{int(r.i)}", f"{r.original_deg:.0f}", f"{r.thesis_adjusted_deg:.0f}", f"{r.eq16_deg:.2f}",
              f"{r.exact_deg:.2f}", f"{r.eq16_adjustment_deg:+.2f}", f"{r.exact_adjustment_deg:+.2f}"]
             for r in t10.itertuples()])

fig, axes = plt.subplots(1, 2, figsize=(5.2, 2.9))
axes[0].plot(an.original_deg, an.original_deg, label="original (equiangular)")
axes[0].plot(an.original_deg, an.eq16_deg, label="Eq. 16")
axes[0].plot(an.original_deg, an.exact_deg, "--", label="exact inversion")
axes[0].set_xlabel("original phi (deg)")
axes[0].set_ylabel("ray angle (deg)")
axes[0].legend(handlelength=1.5, loc="lower right")
axes[1].plot(an.original_deg, an.eq16_adjustment_deg, label="Eq. 16")
axes[1].plot(an.original_deg, an.exact_adjustment_deg, "--", label="exact inversion")
axes[1].set_xlabel("original phi (deg)")
axes[1].set_ylabel("adjustment (deg)")

for ax in axes:
    ax.grid(True, alpha=0.3)
save(fig, d, "angles")

write_table(d, "table_equal", ["scheme", "res.", "nodes", "hip-region nodes", "max (mm)", "p95 (mm)", "RMS (mm)"],
            [[r.scheme, f"{r.resolution:g}", f"{int(r.nodes):,}", f"{int(r.hip_region_nodes):,}", f"{r.max_mm:.2e}",
              f"{r.p95_mm:.2e}", f"{r.rms_mm:.2e}"] for r in eq.itertuples()], align="llrrrrr")
fig, ax = plt.subplots(figsize=(3.3, 2.9))
for scheme, g in eq.groupby("scheme", sort=False):
    ax.loglog(g.nodes, g.max_mm, "o-", label=scheme)
ax.set_xlabel("nodes")
ax.set_ylabel("max radial error (mm)")
ax.grid(True, which="both", alpha=0.3)
ax.legend(handlelength=1.5)
save(fig, d, "equal")

def span(v):
    lo, hi = f"{v.min():.2f}", f"{v.max():.2f}"
    return lo if lo == hi else f"{lo}--{hi}"


ratio_c = (eq[eq.scheme == "conchoid"].max_mm.values / eq[eq.scheme == "equiangular"].max_mm.values)
ratio_h = (eq[eq.scheme == "helix"].max_mm.values / eq[eq.scheme == "equiangular"].max_mm.values)
# Thesis Fig. 53: equal-angle rays from three origins cut the hip curve into unequal segments.
seg = read_csv(d, "segments.csv")
seg = seg[seg.ray_to_deg - seg.ray_from_deg > 0.999]  # whole 1-deg segments (the last one is cut short)
names = {"conchoid_origin": "conchoid's origin (thesis Fig. 53 b)", "object_centroid": "area centroid (Fig. 53 a)",
         "object_extent_middle": "middle of the extent (Fig. 53 a)"}
fig, ax = plt.subplots(figsize=(5.5, 3.2))
longer = {}
for origin, g in seg.groupby("origin", sort=False):
    rel = g.length_mm / g.length_mm.min()
    longer[origin] = 100 * (rel.max() - 1)
    ax.plot(0.5 * (g.phi_from_deg + g.phi_to_deg), rel, label=names.get(origin, origin))
ax.set_xlabel("position on the hip curve: conchoid angle phi (deg)")
ax.set_ylabel("segment length / shortest")
ax.grid(True, alpha=0.3)
ax.legend()
save(fig, d, "segments")
# Thesis Fig. 57: the 30 deg rays of Table 10 on the conchoid r = a + b cos(phi) (Eq. 11), original (dashed) and
# adjusted by Eq. 16 (solid), from the conchoid's origin; the segments each pair of rays cuts from the hip curve.
meta = json.load(open(os.path.join(d, "meta.json")))
a_mm, b_mm = meta["parameters"]["a_mm"], meta["parameters"]["b_mm"]


def on_curve(phi_deg):
    p = np.radians(phi_deg)
    r = a_mm + b_mm * np.cos(p)
    return r * np.sin(p), r * np.cos(p)


def arc(p0_deg, p1_deg):
    p = np.linspace(np.radians(p0_deg), np.radians(p1_deg), 2001)
    return np.trapz(np.sqrt(a_mm ** 2 + b_mm ** 2 + 2 * a_mm * b_mm * np.cos(p)), p)


fig, ax = plt.subplots(figsize=(4.6, 3.0))
x, y = on_curve(np.linspace(0, 180, 721))
ax.plot(x, y, color="0.75", lw=0.8)
x, y = on_curve(np.linspace(0, 90, 361))
ax.plot(x, y, color="k", lw=1.4, label="hip curve ($\\phi \\leq 90^\\circ$)")
for r in t10.itertuples():
    for angle, style, colour in ((r.original_deg, "--", "C0"), (r.eq16_deg, "-", "C3")):
        px, py = on_curve(angle)
        ax.plot([0, px], [0, py], style, color=colour, lw=1.0)
        ax.plot([px], [py], "o", color=colour, ms=3)
ax.plot([], [], "--", color="C0", label="original (30$^\\circ$ apart)")
ax.plot([], [], "-", color="C3", label="adjusted (Eq. 16)")
ax.plot([0], [0], "k+", ms=6)
ax.set_aspect("equal")
ax.set_xlabel("mm")
ax.set_ylabel("mm")
ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1), fontsize=7)
ax.grid(True, alpha=0.3)
save(fig, d, "fig57")
seg_orig = [arc(p0, p1) for p0, p1 in zip(t10.original_deg[:-1], t10.original_deg[1:])]
seg_adj = [arc(p0, p1) for p0, p1 in zip(t10.eq16_deg[:-1], t10.eq16_deg[1:])]
exact_len = ln.iloc[0]
write_macros(d, "macros", {
    "CSfigOrig": ", ".join(f"{x:.1f}" for x in seg_orig), "CSfigAdj": ", ".join(f"{x:.1f}" for x in seg_adj),
    "CSsegOrigin": f"{longer['conchoid_origin']:.0f}", "CSsegCentroid": f"{longer['object_centroid']:.0f}",
    "CSsegExtent": f"{longer['object_extent_middle']:.0f}",
    "CSlenOverB": f"{exact_len.length_over_b:.3f}", "CSlen": f"{exact_len.length_mm:.2f}",
    "CSmaxAdjEq": f"{an.eq16_adjustment_deg.min():.2f}", "CSmaxAdjExact": f"{an.exact_adjustment_deg.min():.2f}",
    "CSmaxAdjAt": f"{an.loc[an.exact_adjustment_deg.idxmin()].original_deg:.1f}",
    "CSratioConchoid": span(ratio_c),
    "CSratioHelix": span(ratio_h),
    "CSthesisClosed": f"{ln.iloc[2].length_over_b:.4f}",
    "CSrelAonefifteen": f"{100 * abs(ln.iloc[1].rel_error_vs_exact):.2f}",
    "CSrelClosed": f"{100 * abs(ln.iloc[2].rel_error_vs_exact):.2f}",
    "CSteqOne": f"{t10.eq16_deg[1]:.2f}", "CSteqTwo": f"{t10.eq16_deg[2]:.2f}", "CSteqThree": f"{t10.eq16_deg[3]:.2f}",
    "CStexOne": f"{t10.exact_deg[1]:.2f}", "CStexTwo": f"{t10.exact_deg[2]:.2f}",
})
