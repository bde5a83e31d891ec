"""05_slice_sampling: thesis sec. 3.5.2 (Fig. 46) reproduced for any head size and slice
thickness, and the staircase test of the "refining beyond ~1.5 deg does not help" claim.

Reads RESULTS/05_slice_sampling/{slices,nyquist,staircase}.csv; writes dphi.pdf/png,
nyquist.tex, staircase.pdf/png, table_staircase.tex, macros.tex."""
import matplotlib.pyplot as plt

from common import experiment_dir, read_csv, save, write_macros, write_table

d = experiment_dir("05_slice_sampling")
sl = read_csv(d, "slices.csv")
ny = read_csv(d, "nyquist.csv")
st = read_csv(d, "staircase.csv")

fig, ax = plt.subplots(figsize=(5.5, 3.2))
g = sl[(sl.radius_mm == 22) & (sl.slice_mm == 1.25)].dropna()
ax.bar(g.slice, g.dphi_deg, color="tab:blue")
ax.set_xlabel("slice i (1.25 mm, 44 mm head)")
ax.set_ylabel("delta phi_i (deg)")
ax.grid(True, axis="y", alpha=0.3)
save(fig, d, "dphi")

rows = []
for t, g in ny.groupby("slice_mm"):
    rows.append([f"{t:g}"] + [f"{v:.2f}" for v in g.sort_values("radius_mm").nyquist_precision_deg])
write_table(d, "nyquist", ["slice (mm)"] + [f"$r$ = {r:g}" for r in sorted(ny.radius_mm.unique())], rows)

fig, ax = plt.subplots(figsize=(5.5, 4.6))
ax.loglog(st.precision_deg, st.vs_sphere_rms_mm, "o-", label="map vs smooth sphere (RMS)")
ax.loglog(st.precision_deg, st.vs_staircase_rms_mm, "s-", label="map vs staircase (RMS)")
ax.loglog(st.precision_deg, st.gap_vs_smooth_rms_mm, "^-", label="socket-scan gap vs smooth truth (RMS)")
ax.axhline(st.staircase_vs_sphere_rms_mm.iloc[0], color="k", ls=":", label="staircase vs sphere (RMS)")
ax.axvline(st.nyquist_precision_deg.iloc[0], color="r", ls="--", label="slice Nyquist precision")
ax.set_xlabel("precision p (deg)")
ax.set_ylabel("mm")
ax.invert_xaxis()
ax.grid(True, which="both", alpha=0.3)
fig.legend(*ax.get_legend_handles_labels(), loc="lower center", ncol=1, frameon=False)
save(fig, d, "staircase", rect=(0, 0.36, 1, 1))

write_table(d, "table_staircase", ["$p$ (deg)", "vs sphere RMS", "vs sphere max", "vs staircase RMS",
                                   "vs staircase max", "gap error RMS", "gap error max"],
            [[f"{r.precision_deg:g}", f"{r.vs_sphere_rms_mm:.3f}", f"{r.vs_sphere_max_mm:.3f}",
              f"{r.vs_staircase_rms_mm:.4f}", f"{r.vs_staircase_max_mm:.3f}", f"{r.gap_vs_smooth_rms_mm:.3f}",
              f"{r.gap_vs_smooth_max_mm:.3f}"] for r in st.itertuples()])
th = ny[(ny.radius_mm == 22) & (ny.slice_mm == 1.25)].iloc[0]
best = st.loc[st.gap_vs_smooth_rms_mm.idxmin()]
write_macros(d, "macros", {
    "SSmin": f"{th.min_dphi_deg:.2f}", "SSnyq": f"{th.nyquist_precision_deg:.2f}",
    "SSslices": f"{int(th.slices_per_side)}", "SSbest": f"{best.precision_deg:g}",
    "SSfloor": f"{st.staircase_vs_sphere_rms_mm.iloc[0]:.3f}",
    "SSfinest": f"{st.precision_deg.min():g}", "SSfinestGap": f"{st.gap_vs_smooth_rms_mm.iloc[-1]:.3f}",
    "SSbestGap": f"{best.gap_vs_smooth_rms_mm:.3f}",
})
