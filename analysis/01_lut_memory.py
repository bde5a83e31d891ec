"""01_lut_memory: thesis Tables 2, 6, 7 and Fig. 49's counts beside the formula and the
measured allocation; node density against latitude for both schemes.

Reads RESULTS/01_lut_memory/{lut_memory,helix_match,density}.csv; writes table.tex,
table_helix.tex, table_match.tex, memory.pdf/png, density.pdf/png, macros.tex."""
import matplotlib.pyplot as plt

from common import density_uniformity, experiment_dir, read_csv, resolution_text, save, write_macros, write_table

d = experiment_dir("01_lut_memory")
df = read_csv(d, "lut_memory.csv")
match = read_csv(d, "helix_match.csv")
dens = read_csv(d, "density.csv")
MiB = 1024.0 * 1024.0


def rows_for(scheme):
    rows = []
    for p, g in df[df.scheme == scheme].groupby("matched_precision_deg", sort=False):
        dbl = g[g.storage == "double"].iloc[0]
        flt = g[g.storage == "float"].iloc[0]
        res = f"{p:g}" if scheme == "equiangular" else f"{int(dbl.resolution)}"
        rows.append([res, f"{int(dbl.nodes):,}", f"{int(dbl.thesis_nodes):,}", f"{dbl.thesis_memory_mb:g}",
                     f"{dbl.bytes_formula / MiB:.3f}", f"{dbl.bytes_allocated / MiB:.3f}",
                     f"{flt.bytes_allocated / MiB:.3f}", f"{dbl.rss_growth_bytes / MiB:.3f}"])
    return rows


hdr = ["nodes", "thesis nodes", "thesis MB", "formula MiB (double)", "allocated MiB (double)",
       "allocated MiB (float)", "RSS growth MiB (double)"]
write_table(d, "table", ["$p$ (deg)"] + hdr, rows_for("equiangular"))
write_table(d, "table_helix", ["$k$"] + hdr, rows_for("helix"))
write_table(d, "table_match", ["$p$ (deg)", "grid equator nodes", "$k$", "thesis $k$", "helix spacing (deg)",
                               "helix equator nodes", "thesis", "$w = k^2$", "grid nodes", "$w$ / grid"],
            [[f"{r.precision_deg:g}", f"{int(r.equiangular_equator_nodes):,}", f"{int(r.turns):,}",
              f"{int(r.thesis_turns):,}", f"{r.helix_node_spacing_deg:.5f}", f"{r.helix_equator_nodes:.1f}",
              f"{int(r.thesis_helix_equator_nodes):,}", f"{int(r.helix_nodes):,}", f"{int(r.equiangular_nodes):,}",
              f"{r.node_ratio:.4f}"] for r in match.itertuples()])

fig, ax = plt.subplots(figsize=(5.5, 3.6))
for scheme, marker in (("equiangular", "o"), ("helix", "^")):
    for storage, ls in (("double", "-"), ("float", "--")):
        g = df[(df.scheme == scheme) & (df.storage == storage)]
        ax.loglog(g.matched_precision_deg, g.bytes_allocated / MiB, ls, marker=marker, label=f"{scheme}, {storage}")
for scheme, c in (("equiangular", "k"), ("helix", "r")):
    g = df[(df.scheme == scheme) & (df.storage == "double")]
    ax.loglog(g.matched_precision_deg, g.thesis_memory_mb, c + "+", markersize=12, label=f"thesis, {scheme}")
ax.set_xlabel("precision p (deg; helix at the matched k)")
ax.set_ylabel("map memory allocated (MiB)")
ax.invert_xaxis()
ax.grid(True, which="both", alpha=0.3)
ax.legend(fontsize=7)
save(fig, d, "memory")

fig, ax = plt.subplots(figsize=(5.5, 3.2))
for (scheme, res), g in dens.groupby(["scheme", "resolution"], sort=False):
    ax.semilogy((g.phi_low_deg + g.phi_high_deg) / 2, g.nodes_per_sr, label=f"{scheme} ({res:g})")
ax.set_xlabel("polar angle phi (deg)")
ax.set_ylabel("nodes per steradian")
ax.grid(True, alpha=0.3)
ax.legend(fontsize=8)
save(fig, d, "density")

# Every registered scheme at equal largest node spacing (schemes.csv, issue 12).
sch = read_csv(d, "schemes.csv")
rows = []
for (name, unit), g in sch.groupby(["scheme", "resolution_name"], sort=False):
    g = g.set_index("spacing_deg")
    rows.append([name, unit.replace("_", " ")] + [resolution_text(g.resolution[p]) for p in (1.0, 0.1)] +
                [f"{int(g.nodes[p]):,}" for p in (1.0, 0.1)] + [f"{g.nodes_over_equiangular[0.1]:.2f}"])
write_table(d, "table_schemes", ["scheme", "resolution", "at 1 deg", "at 0.1 deg", "nodes, 1 deg", "nodes, 0.1 deg",
                                 "/ equiangular"], rows, align="llrrrrr")
# Dense against sparse storage (sparse.csv, issue 12): the pelvis and femur maps of every subject.
spr = read_csv(d, "sparse.csv")
spr["ratio"] = spr.sparse_bytes / spr.dense_bytes
fin = spr.spacing_deg.min()
rows = []
for (sub, body), g in spr[spr.spacing_deg == fin].groupby(["subject", "body"], sort=False):
    g = g.set_index("scheme")
    rows.append([sub, body] + [f"{g.ratio[sc]:.2f}" if sc in g.index else "--" for sc in sch.scheme.unique()] +
                [f"{g.nodes_covered['equiangular'] / g.nodes['equiangular']:.2f}"])
write_table(d, "table_sparse", ["subject", "body"] + list(sch.scheme.unique()) + ["covered"], rows,
            align="ll" + "r" * (len(sch.scheme.unique()) + 1))
pel = spr[(spr.body == "pelvis") & (spr.scheme == "equiangular") & (spr.spacing_deg == fin) &
          ~spr.subject.str.startswith("generated")]
fem = spr[(spr.body == "femur") & (spr.spacing_deg == fin)]
eq1 = df[(df.scheme == "equiangular") & (df.matched_precision_deg == 1)].iloc[0]
hx1 = df[(df.scheme == "helix") & (df.matched_precision_deg == 1)].iloc[0]
fine = match.iloc[-1]


hx_share, hx_peak = density_uniformity(dens[dens.scheme == "helix"])  # thesis Fig. 47; claims.py's rule too
eq_share, eq_peak = density_uniformity(dens[dens.scheme == "equiangular"])
hx_share, eq_share = 100 * hx_share, 100 * eq_share
write_macros(d, "macros", {
    "LMhxUniformShare": f"{hx_share:.3f}", "LMhxUniformPeak": f"{hx_peak:.1f}",
    "LMeqUniformShare": f"{eq_share:.0f}", "LMeqUniformPeak": f"{eq_peak:,.0f}",
    "LMeqOne": f"{int(eq1.nodes):,}", "LMhxOne": f"{int(hx1.nodes):,}",
    "LMratioFine": f"{fine.node_ratio:.4f}", "LMkFine": f"{int(fine.turns):,}",
    "LMratioMin": f"{match.node_ratio.min():.2f}", "LMratioMax": f"{match.node_ratio.max():.2f}",
    "LMhxEquatorFiner": f"{match.iloc[-2].helix_equator_nodes:,.1f}",
    "LMhxEquatorFinest": f"{fine.helix_equator_nodes:,.1f}",
    "LMoctOverEq": f"{sch[(sch.scheme == 'octahedral') & (sch.spacing_deg == 0.1)].nodes_over_equiangular.iloc[0]:.2f}",
    "LMhpxOverEq": f"{sch[(sch.scheme == 'healpix') & (sch.spacing_deg == 0.1)].nodes_over_equiangular.iloc[0]:.2f}",
    "LMspFinest": f"{fin:g}",
    "LMspPelvisMin": f"{pel.ratio.min():.2f}" if len(pel) else "--",
    "LMspPelvisMax": f"{pel.ratio.max():.2f}" if len(pel) else "--",
    "LMspFemurMin": f"{fem.ratio.min():.2f}",
    "LMspAllMin": f"{spr[spr.spacing_deg == fin].ratio.min():.2f}",
    "LMspAllMax": f"{spr[spr.spacing_deg == fin].ratio.max():.2f}",
})
