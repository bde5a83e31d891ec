"""07_helix_arc_length: Eq. 10 against the exact helix arc length; index errors it causes.

Reads RESULTS/07_helix_arc_length/{arc_length,index_errors}.csv; writes error.pdf/png,
steps.pdf/png, table.tex, macros.tex."""
import matplotlib.pyplot as plt
import numpy as np

from common import experiment_dir, read_csv, save, write_macros, write_table

d = experiment_dir("07_helix_arc_length")
arc = read_csv(d, "arc_length.csv")
idx = read_csv(d, "index_errors.csv")

fig, axes = plt.subplots(1, 2, figsize=(5.2, 3.1))
for k, g in arc.groupby("turns"):
    axes[0].plot(g.phi_deg, g.abs_error, label=f"k={int(k)}")
    axes[1].semilogy(g.phi_deg, np.abs(g.rel_error), label=f"k={int(k)}")
axes[0].set_ylabel("Eq. 10 T - exact s (unit sphere)")
axes[1].set_ylabel("|relative error|")
for ax in axes:
    ax.set_xlabel("polar angle phi (deg)")
    ax.grid(True, alpha=0.3)
fig.legend(*axes[0].get_legend_handles_labels(), loc="lower center", ncol=6, frameon=False, handlelength=1,
           columnspacing=0.8)
save(fig, d, "error", rect=(0, 0.1, 1, 1))

fig, ax = plt.subplots(figsize=(3.3, 3.1))
for k, g in arc.groupby("turns"):
    ax.plot(g.phi_deg, g.index_error_steps, label=f"k={int(k)}")
ax.set_xlabel("polar angle phi (deg)")
ax.set_ylabel("index error (node steps)")
ax.grid(True, alpha=0.3)
save(fig, d, "steps")

write_table(d, "table", ["$k$", "nodes", "exact $L$", "Eq. 10 $L$", "max index error (steps)",
                         "stencils differing", "nearest node differing", "max node diff",
                         "ns/locate exact", "ns/locate Eq. 10"],
            [[f"{int(r.turns)}", f"{int(r.nodes):,}", f"{r.total_length_exact:.6f}", f"{r.total_length_eq10:.1f}",
              f"{r.max_abs_index_error_steps:.3f}", f"{100 * r.fraction_differing:.2f}%",
              f"{100 * r.fraction_nearest_differing:.2f}%", f"{int(r.max_node_index_difference)}",
              f"{r.exact_ns_per_locate:.0f} ({r.exact_ns_q25:.0f}-{r.exact_ns_q75:.0f})",
              f"{r.eq10_ns_per_locate:.0f} ({r.eq10_ns_q25:.0f}-{r.eq10_ns_q75:.0f})"] for r in idx.itertuples()])
big = idx.iloc[-1]
# The self-consistent Eq. 10 helix (nodes placed by Eq. 10 too): its node spacing against the exact helix's.
selfc = read_csv(d, "self_consistent.csv")
fine = selfc[selfc.turns >= 229]
write_macros(d, "macros", {
    "HAselfMaxRatio": f"{selfc.max_spacing_ratio.max():.2f}",
    "HAselfShareMin": f"{100 * fine.share_within_10pct.min():.3f}",
    "HAselfKmin": f"{int(fine.turns.min())}",
    "HAkBig": f"{int(big.turns)}", "HAstepsBig": f"{big.max_abs_index_error_steps:.2f}",
    "HAdifferBig": f"{100 * big.fraction_differing:.1f}", "HAnearestBig": f"{100 * big.fraction_nearest_differing:.1f}",
})
