"""12_sphere_fit: sphere fits against ground truth on synthetic heads; the real femurs' fits,
their stability and the residual over the head (thesis Fig. 39).

Reads RESULTS/12_sphere_fit/{synthetic,real,residuals}.csv; writes synthetic.pdf/png,
table_synthetic.tex, table_real.tex, residuals_<subject>.pdf/png, macros.tex."""
import matplotlib.pyplot as plt
import numpy as np

from common import experiment_dir, latex_escape, read_csv, save, write_macros, write_table

d = experiment_dir("12_sphere_fit")
syn = read_csv(d, "synthetic.csv")
real = read_csv(d, "real.csv")
res = read_csv(d, "residuals.csv")

fig, axes = plt.subplots(1, 3, figsize=(7.5, 3.2), sharey=True)
for ax, cam in zip(axes, sorted(syn.cam_mm.unique())):
    for method, g in syn[(syn.cam_mm == cam) & (syn.noise_mm == 0.3)].groupby("method"):
        m = g.groupby("coverage_deg").centre_error_mm.max()
        ax.semilogy(m.index, m.values, "o-", label=method)
    ax.set_title(f"cam {cam:g} mm, noise 0.3 mm")
    ax.grid(True, which="both", alpha=0.3)
axes[0].set_ylabel("max centre error (mm)")
fig.supxlabel("head coverage half-angle (deg)")
axes[0].legend(loc="upper right")
save(fig, d, "synthetic")

rows = []
for (method, noise, cam), g in syn.groupby(["method", "noise_mm", "cam_mm"]):
    m = g.groupby("coverage_deg").centre_error_mm.max()
    rows.append([method, f"{noise:g}", f"{cam:g}"] + [f"{m.get(c, np.nan):.3f}" for c in sorted(syn.coverage_deg.unique())])
write_table(d, "table_synthetic", ["method", "noise (mm)", "cam (mm)"] +
            [f"{c:g} deg" for c in sorted(syn.coverage_deg.unique())], rows, align="lrrrrrr")

rows = []
for s, g in real.groupby("subject", sort=False):
    dflt = g[(g.proximal_extent_mm == 70) & (g.inlier_threshold_mm == 1.0)].iloc[0]
    rows.append([s, f"{dflt.cx_mm:.2f}, {dflt.cy_mm:.2f}, {dflt.cz_mm:.2f}", f"{dflt.radius_mm:.3f}",
                 f"{dflt.rms_mm:.3f}", f"{int(dflt.inliers)}", f"{g.shift_from_default_mm.max():.3f}",
                 f"{g.radius_mm.max() - g.radius_mm.min():.3f}"])
write_table(d, "table_real", ["subject", "centre (RAS, mm)", "radius (mm)", "RMS (mm)", "inliers",
                              "max centre shift (mm)", "radius range (mm)"], rows, align="llrrrrr")

for s, g in res.groupby("subject", sort=False):
    fig, ax = plt.subplots(figsize=(5.5, 3.2))
    sc = ax.scatter(g.theta_deg, g.phi_deg, c=g.residual_mm, s=1, cmap="coolwarm", vmin=-1.5, vmax=1.5)
    ax.invert_yaxis()
    ax.set_xlabel("theta about the fitted centre (deg)")
    ax.set_ylabel("phi (deg)")
    ax.set_title(f"{s}: vertex distance to the fitted sphere", fontsize=8)
    fig.colorbar(sc, ax=ax, label="residual (mm)")
    save(fig, d, f"residuals_{s}")

clean = syn[(syn.cam_mm == 0) & (syn.noise_mm == 0.3) & (syn.coverage_deg == 90)]
geo = clean[clean.method == "geometric"].centre_error_mm.max()
alg = clean[clean.method == "algebraic"].centre_error_mm.max()
cam4 = syn[(syn.cam_mm == 4) & (syn.noise_mm == 0.3) & (syn.coverage_deg == 90)]
realsubs = real[~real.subject.str.startswith("generated")]
write_macros(d, "macros", {
    "SFgeoHemi": f"{geo:.3f}", "SFalgHemi": f"{alg:.3f}",
    # An upper bound as the prose states it ("at most"): rounded up, never down.
    "SFautoCam": f"{np.ceil(cam4[cam4.method == 'automatic'].centre_error_mm.max() * 1000) / 1000:.3f}",
    "SFgeoCam": f"{cam4[cam4.method == 'geometric'].centre_error_mm.max():.3f}",
    "SFrealShift": (f"{realsubs.shift_from_default_mm.max():.2f}" if len(realsubs) else "n/a"),
    # The subject of that largest shift, from the same rows (issue 82: the prose named mc22 where it is mc22-left).
    "SFrealShiftSubject": (latex_escape(realsubs.loc[realsubs.shift_from_default_mm.idxmax(), "subject"])
                           if len(realsubs) else "n/a"),
})
