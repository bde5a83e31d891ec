"""01_lut_memory: thesis Table 2 beside the formula and the measured allocation.

Reads RESULTS/01_lut_memory/lut_memory.csv; writes table.tex and memory.pdf/png."""
import numpy as np
import matplotlib.pyplot as plt

from common import experiment_dir, read_csv, save, write_table

d = experiment_dir("01_lut_memory")
df = read_csv(d, "lut_memory.csv")
MiB = 1024.0 * 1024.0

rows = []
for p, g in df.groupby("precision_deg", sort=False):
    dbl = g[g.storage == "double"].iloc[0]
    flt = g[g.storage == "float"].iloc[0]
    rows.append([f"{p:g}", f"{int(dbl.nodes):,}", f"{int(dbl.thesis_nodes):,}", f"{dbl.thesis_memory_mb:g}",
                 f"{dbl.bytes_formula / MiB:.3f}", f"{dbl.bytes_allocated / MiB:.3f}",
                 f"{flt.bytes_allocated / MiB:.3f}", f"{dbl.rss_growth_bytes / MiB:.3f}"])
write_table(d, "table", ["$p$ (deg)", "nodes", "thesis nodes", "thesis MB", "formula MiB (double)",
                         "allocated MiB (double)", "allocated MiB (float)", "RSS growth MiB (double)"], rows)

fig, ax = plt.subplots(figsize=(5, 3.4))
for storage, marker in (("double", "o"), ("float", "s")):
    g = df[df.storage == storage]
    ax.loglog(g.precision_deg, g.bytes_allocated / MiB, marker=marker, label=f"impinge, {storage} (allocated)")
g = df[df.storage == "double"]
ax.loglog(g.precision_deg, g.thesis_memory_mb, "k+", markersize=12, label="thesis Table 2 (double)")
ax.set_xlabel("precision p (deg)")
ax.set_ylabel("map memory (MiB)")
ax.invert_xaxis()
ax.grid(True, which="both", alpha=0.3)
ax.legend(fontsize=8)
save(fig, d, "memory")
