"""11_extreme_cases: stiff and extreme cases against exact references (issue 15).

Case 1, depth discontinuities: reads RESULTS/11_extreme_cases/discontinuities.csv; writes
table_discontinuities.tex and macros.tex."""
import numpy as np

from common import experiment_dir, read_csv, write_macros, write_table

d = experiment_dir("11_extreme_cases")
t = read_csv(d, "discontinuities.csv")


def e(x):
    return "--" if np.isnan(x) else (f"{x:.2g}" if x < 0.01 else f"{x:.3f}")


rows = []
for (s, scheme), g in t.groupby(["subject", "scheme"], sort=False):
    a, b = g[g.method == "maps"].iloc[0], g[g.method == "refined"].iloc[0]
    rows.append([s, scheme, e(a.max_abs_mm), e(b.max_abs_mm), f"{int(a.over_tolerance)}", f"{int(b.over_tolerance)}",
                 f"{int(a.mask_skipped)}", f"{int(b.mask_skipped)}", f"{int(a.surface_mismatched)}",
                 f"{int(b.surface_mismatched)}", f"{b.refined_per_pose:.0f}", f"{a.query_ns_per_vertex:.1f}",
                 f"{b.query_ns_per_vertex:.1f}", f"{b.query_ns_per_vertex / a.query_ns_per_vertex:.2f}",
                 "pass" if b.max_abs_mm <= 0.05 and b.mask_skipped == 0 else "fail"])
write_table(d, "table_discontinuities",
            ["subject", "scheme", "max maps", "max ref.", ">0.05 maps", ">0.05 ref.", "skipped maps",
             "skipped ref.", "mism. maps", "mism. ref.", "refined/pose", "ns maps", "ns ref.", "ratio", ""], rows,
            align="llrrrrrrrrrrrrl")

real = t[t.generated == 0]
ref, maps = real[real.method == "refined"], real[real.method == "maps"]
eq = real[real.scheme == "equiangular"]
ratio = (eq[eq.method == "refined"].set_index("subject").query_ns_per_vertex /
         eq[eq.method == "maps"].set_index("subject").query_ns_per_vertex)
allref = t[t.method == "refined"]
write_macros(d, "macros", {
    "ExtPoses": f"{int(t.poses.max())}",
    "ExtMapsMaxMin": e(maps.max_abs_mm.min()), "ExtMapsMaxMax": e(maps.max_abs_mm.max()),
    "ExtRefMax": e(ref.max_abs_mm.max()), "ExtRefMaxAll": e(allref.max_abs_mm.max()),
    "ExtMapsSkipped": f"{int(maps.mask_skipped.sum())}", "ExtRefSkipped": f"{int(ref.mask_skipped.sum())}",
    "ExtRefOver": f"{int(allref.over_tolerance.sum())}",
    "ExtRatioMin": f"{ratio.min():.2f}", "ExtRatioMax": f"{ratio.max():.2f}",
    "ExtRatioWorst": ratio.idxmax(),
    "ExtMarkMsMax": f"{eq[eq.method == 'refined'].marking_ms.max():.0f}",
    "ExtMarkMsGenericMax": f"{real[(real.method == 'refined') & (real.scheme != 'equiangular')].marking_ms.max():.0f}"
    if len(real[(real.method == 'refined') & (real.scheme != 'equiangular')]) else "--",
    "ExtCompared": f"{int(ref.compared.sum()):,}",
    "ExtPass": f"{int(((allref.max_abs_mm <= 0.05) & (allref.mask_skipped == 0)).sum())}",
    "ExtRows": f"{len(allref)}",
})
print(f"11_extreme_cases: wrote tables to {d}")
