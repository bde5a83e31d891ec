"""10_error_vs_runtime: |gap error| against CGAL's exact radial gap beside query time, sampling time
and memory, for every scheme, mode and resolution; Pareto figures; where the errors concentrate.

Reads RESULTS/10_error_vs_runtime/error_runtime.csv and vertex_errors.csv; writes table_main.tex
(first real subject, rest pose, every configuration), table_peers.tex, pareto_time_memory.pdf,
pareto_sampling.pdf, error_map.pdf (per-vertex errors over the sphere),
equal_error.csv with table_equal_error.tex (every scheme at equal error, issue 12), macros.tex.

equal_error.csv: for every real subject, scheme, storage, mode (exact: the maps alone;
exact_refined: with the exact look-ups at depth discontinuities), metric (p95 or max |gap error| at
the scan pose) and target (1e-2, 1e-3, 1e-4 mm), the bytes of both maps, the query ns per vertex and
the sampling ms at which the scheme reaches the target. The resolutions are a sweep, so these are
interpolated between the two resolutions that bracket the target, log-linearly in error against
bytes (query and sampling time at the same fraction of the step, log-linearly too); `how` says
`interpolated`, `coarsest` (already met at the coarsest resolution: an upper bound) or `not_reached`
(not met at the finest: empty values). Storage `dense` or `sparse` (exact mode only: the same errors,
other bytes and query times)."""
import numpy as np
import matplotlib.pyplot as plt

from common import experiment_dir, read_csv, save, write_macros, write_table

d = experiment_dir("10_error_vs_runtime")
t = read_csv(d, "error_runtime.csv")
v = read_csv(d, "vertex_errors.csv")
if "storage" not in t:
    t["storage"] = "dense"
peers = ("embree_radial", "embree_radial_packet8", "cgal_radial")
maps_all = t[~t.scheme.isin(peers)]
maps = maps_all[maps_all.storage == "dense"]  # the tables and figures below; sparse rows: equal_error
real = t[~t.generated.astype(bool)]
subj = real.subject.iloc[0] if len(real) else t.subject.iloc[0]
# The headline node spacing: 0.1 deg, or the finest of a quick run (2, 1 and 0.5 deg only), so that
# every table and macro the section uses exists in a quick run too.
HEAD_P = 0.1 if np.isclose(maps.precision_deg, 0.1).any() else float(maps.precision_deg.min())


def e(x):
    return "--" if np.isnan(x) else (f"{x:.2g}" if x < 0.01 else f"{x:.3f}")


def ns_spread(r, digits=0):
    """'median (lower quartile-upper quartile)' ns per vertex of a row's query over its repetitions."""
    return (f"{r.query_ns_per_vertex:,.{digits}f} ({r.query_ns_q25:,.{digits}f}-{r.query_ns_q75:,.{digits}f})"
            if np.isfinite(r.query_ns_q25) else f"{r.query_ns_per_vertex:,.{digits}f}")


# Table: first subject, rest pose, every scheme x mode x resolution.
rows = []
g0 = maps[(maps.subject == subj) & (maps.pose == "rest")]
for _, r in g0.sort_values(["scheme", "mode", "precision_deg"], ascending=[True, True, False]).iterrows():
    rows.append([r.scheme, r["mode"], f"{r.resolution:g}", e(r.max_abs_mm), e(r.p99_abs_mm), e(r.p95_abs_mm),
                 e(r.median_abs_mm), f"{int(r.mismatched)}", ns_spread(r, 1),
                 f"{r.sampling_ms:.1f}" + ("*" if r.get("sampling_runs", 0) == 1 else ""),
                 f"{r.bytes / 2**20:.1f}"])
write_table(d, "table_main", ["scheme", "mode", "res.", "max", "p99", "p95", "median", "mism.", "ns/vertex",
                              "sampling ms", "MiB"], rows, align="llrrrrrrrrr",
            caption=r"Every configuration of experiment 10 on \ErrSubject, scan pose: |gap error| (mm) statistics "
                    r"against CGAL, vertices where one side finds no surface (mism.), query ns per vertex (median and quartiles "
                    r"of the repetitions), sampling ms (median of the repetitions; *: one run, at node spacings under "
                    r"0.5$^\circ$, where a fill takes seconds) and MiB of both maps.", label="tab:error-main")

# Peers and the headline configuration (equiangular 0.1 exact) per subject and pose.
rows = []
for (s, pose), g in t.groupby(["subject", "pose"], sort=False):
    r = g[(g.scheme == "equiangular") & (g["mode"] == "exact") & np.isclose(g.precision_deg, HEAD_P)]
    emb = g[g.scheme == "embree_radial"]
    cg = g[g.scheme == "cgal_radial"]
    if not len(r):
        continue
    r = r.iloc[0]
    en = emb.query_ns_per_vertex.iloc[0] if len(emb) else np.nan
    cn = cg.query_ns_per_vertex.iloc[0] if len(cg) else np.nan
    rows.append([s, pose.replace("_", " "), f"{int(r.vertices):,}", e(r.p95_abs_mm), e(r.max_abs_mm),
                 ns_spread(r, 1), ns_spread(emb.iloc[0]) if len(emb) else "--", ns_spread(cg.iloc[0]) if len(cg) else "--",
                 f"{en / r.query_ns_per_vertex:.1f}",
                 f"{cn / r.query_ns_per_vertex:.0f}",
                 e(emb.p95_abs_mm.iloc[0]) if len(emb) else "--"])
write_table(d, "table_peers", ["subject", "pose", "vertices", "p95 (mm)", "max (mm)", "ns/vertex", "Embree ns",
                               "CGAL ns", "Embree / ours", "CGAL / ours", "Embree p95"], rows,
            align="llrrrrrrrrr")

# Pareto figures: p95 error against query time and against memory, rest pose, first subject.
markers = {"equiangular": "o", "helix": "s", "helix-eq10": "v", "conchoid": "^", "octahedral": "D",
           "healpix": "h", "fibonacci": "*"}
# The Pareto fronts: error against query time and memory (one figure, two panels sharing the error axis) and
# against sampling time. A colour and marker per scheme, a line style per mode; the legends below the panels.
from matplotlib.lines import Line2D
schemes = list(dict.fromkeys(g0.scheme))
colour = {s: f"C{k}" for k, s in enumerate(schemes)}
style = {"exact": "-", "exact_refined": ":", "linear": "--"}


def pareto_panel(ax, xcol, xlabel):
    """One Pareto panel; returns the (handle, name) pairs of its modes and peers."""
    for (scheme, mode), g in g0.groupby(["scheme", "mode"]):
        g = g.sort_values("precision_deg")
        ax.loglog(g[xcol], g.p95_abs_mm.clip(lower=1e-7), marker=markers.get(scheme, "o"), color=colour[scheme],
                  ls=style.get(mode, "--"), markersize=4)
    second = [(Line2D([], [], color="0.3", ls=ls), mode.replace("_", " ")) for mode, ls in style.items()
              if (g0["mode"] == mode).any()]
    if xcol == "query_ns_per_vertex":
        for pname, mk in (("embree_radial", "P"), ("cgal_radial", "X")):
            g = t[(t.subject == subj) & (t.pose == "rest") & (t.scheme == pname)]
            if len(g):
                ax.loglog(g[xcol], g.p95_abs_mm.clip(lower=1e-7), mk, color="k", markersize=8)
                second.append((Line2D([], [], color="k", marker=mk, ls="", markersize=6), pname.replace("_", " ")))
    ax.axhline(0.05, color="r", lw=0.6, ls=":")
    ax.set_xlabel(xlabel)
    ax.grid(True, which="both", lw=0.3)
    return second


def pareto_legends(fig, second):
    fig.legend([Line2D([], [], color=colour[s], marker=markers.get(s, "o"), markersize=4) for s in schemes],
               schemes, title="scheme", loc="lower center", bbox_to_anchor=(0.5, 0.17), ncol=4, frameon=False)
    fig.legend([h for h, _ in second], [n for _, n in second], title="mode, peers", loc="lower center",
               bbox_to_anchor=(0.5, 0.0), ncol=min(len(second), 3), frameon=False)


fig, axes = plt.subplots(1, 2, figsize=(6.5, 4.6), sharey=True)
second = pareto_panel(axes[0], "query_ns_per_vertex", "query time (ns per vertex)")
pareto_panel(axes[1], "bytes", "memory of both maps (bytes)")
axes[0].set_ylabel("p95 |gap error| (mm)")
fig.suptitle(f"{subj}, rest pose (error floor clipped at 1e-7 mm)")
pareto_legends(fig, second)
save(fig, d, "pareto_time_memory", rect=(0, 0.37, 1, 1))
fig, ax = plt.subplots(figsize=(6.5, 4.4))
second = pareto_panel(ax, "sampling_ms", "sampling both maps (ms)")
ax.set_ylabel("p95 |gap error| (mm)")
ax.set_title(f"{subj}, rest pose")
pareto_legends(fig, second)
save(fig, d, "pareto_sampling", rect=(0, 0.38, 1, 1))

# Where the errors are: per-vertex errors of equiangular 0.1 exact over (theta, phi).
fig, ax = plt.subplots(figsize=(7, 3.4))
vv = v[v.subject == subj]
if not len(vv):  # a quick run measures per-vertex errors at other settings
    ax.text(0.5, 0.5, f"no per-vertex errors of {subj} at this setting in this run", transform=ax.transAxes,
            ha="center", va="center", fontsize=9)
sc = ax.scatter(vv.theta_deg, vv.phi_deg, c=np.log10(vv.error_mm.clip(lower=1e-7)), s=3, cmap="viridis")
big = vv[vv.stencil_spread_mm > 2]
ax.scatter(big.theta_deg, big.phi_deg, s=12, facecolors="none", edgecolors="r", lw=0.5,
           label="stencil spans > 2 mm (depth jump)")
ax.invert_yaxis()
ax.set_xlabel("theta (deg)")
ax.set_ylabel("phi (deg)")
ax.legend(fontsize=7, loc="lower right")
fig.colorbar(sc, label="log10 |error| (mm)")
save(fig, d, "error_map")

# Macros for the text.
macros = {"ErrSubject": subj}
h = g0[(g0.scheme == "equiangular") & (g0["mode"] == "exact") & np.isclose(g0.precision_deg, HEAD_P)]
if len(h):
    h = h.iloc[0]
    emb = t[(t.subject == subj) & (t.pose == "rest") & (t.scheme == "embree_radial")]
    cg = t[(t.subject == subj) & (t.pose == "rest") & (t.scheme == "cgal_radial")]
    macros.update({"ErrPninetyFive": e(h.p95_abs_mm), "ErrMax": e(h.max_abs_mm), "ErrNs": f"{h.query_ns_per_vertex:.1f}",
                   "ErrNsQlow": f"{h.query_ns_q25:.1f}", "ErrNsQhigh": f"{h.query_ns_q75:.1f}",
                   "ErrRuns": f"{int(h.timing_runs)}",
                   "ErrVertices": f"{int(h.vertices):,}", "ErrCompared": f"{int(h.compared):,}",
                   "ErrLarge": f"{int(h.large_errors)}", "ErrAtJump": f"{int(h.at_discontinuity)}"})
    if len(emb):
        macros["ErrEmbreeNs"] = f"{emb.query_ns_per_vertex.iloc[0]:.0f}"
        macros["ErrEmbreeNsQlow"] = f"{emb.query_ns_q25.iloc[0]:.0f}"
        macros["ErrEmbreeNsQhigh"] = f"{emb.query_ns_q75.iloc[0]:.0f}"
        macros["ErrEmbreeRatio"] = f"{emb.query_ns_per_vertex.iloc[0] / h.query_ns_per_vertex:.1f}"
    if len(cg):
        macros["ErrCgalNs"] = f"{cg.query_ns_per_vertex.iloc[0]:,.0f}"
        macros["ErrCgalNsQlow"] = f"{cg.query_ns_q25.iloc[0]:,.0f}"
        macros["ErrCgalNsQhigh"] = f"{cg.query_ns_q75.iloc[0]:,.0f}"
        macros["ErrCgalRatio"] = f"{cg.query_ns_per_vertex.iloc[0] / h.query_ns_per_vertex:.0f}"
lin = g0[(g0.scheme == "equiangular") & (g0["mode"] == "linear")]
if len(lin):
    f = lin[lin.precision_deg == lin.precision_deg.min()].iloc[0]
    macros["ErrLinearFinestPninetyFive"] = e(f.p95_abs_mm)
    macros["ErrFinest"] = f"{f.precision_deg:g}"
# The headline configuration on every subject and pose: error and speed against the peers.
heads, emb_r, cg_r, emb_err = [], [], [], []
for (s_, pose), g in t.groupby(["subject", "pose"], sort=False):
    r_ = g[(g.scheme == "equiangular") & (g["mode"] == "exact") & np.isclose(g.precision_deg, HEAD_P)]
    if not len(r_):
        continue
    heads.append(r_.p95_abs_mm.iloc[0])
    for peer, out in (("embree_radial", emb_r), ("cgal_radial", cg_r)):
        pr = g[g.scheme == peer]
        if len(pr):
            out.append(pr.query_ns_per_vertex.iloc[0] / r_.query_ns_per_vertex.iloc[0])
    pe = g[g.scheme == "embree_radial"]
    if len(pe):
        emb_err.append(pe.p95_abs_mm.iloc[0])
if heads:
    macros["ErrPninetyFiveMin"], macros["ErrPninetyFiveMax"] = e(min(heads)), e(max(heads))
    macros["ErrTargetOrders"] = f"{np.floor(np.log10(0.05 / max(heads))):.0f}"
if emb_r:
    macros["ErrEmbreeRatioMin"], macros["ErrEmbreeRatioMax"] = f"{min(emb_r):.1f}", f"{max(emb_r):.1f}"
    # Where the Embree ratio stands against the 10x target in this run, in words the data support.
    macros["ErrEmbreeTargetText"] = ("above it on every subject and pose in this run" if min(emb_r) >= 10 else
                                     "below it on some subjects or poses in this run" if max(emb_r) >= 10 else
                                     "below it on every subject in this run")
if cg_r:
    macros["ErrCgalRatioMin"], macros["ErrCgalRatioMax"] = f"{min(cg_r):.0f}", f"{max(cg_r):.0f}"
if emb_err:
    macros["ErrEmbreeOwnPninetyFiveMax"] = e(max(emb_err))
# Helix against the equiangular grid at matched resolutions (exact mode, every subject and pose).
hx_mem, hx_ns = [], []
for (s_, pose), g in maps[maps["mode"] == "exact"].groupby(["subject", "pose"], sort=False):
    for p_ in g[g.scheme == "equiangular"].precision_deg.unique():
        a_ = g[(g.scheme == "equiangular") & np.isclose(g.precision_deg, p_)]
        b_ = g[(g.scheme == "helix") & np.isclose(g.precision_deg, p_)]
        if len(a_) and len(b_):
            hx_mem.append(b_.bytes.iloc[0] / a_.bytes.iloc[0])
            hx_ns.append(b_.query_ns_per_vertex.iloc[0] / a_.query_ns_per_vertex.iloc[0])
if hx_mem:
    lo, hi = f"{100 * (1 - max(hx_mem)):.0f}", f"{100 * (1 - min(hx_mem)):.0f}"
    macros["ErrHelixSavesPercent"] = lo if lo == hi else f"{lo}--{hi}"
    macros["ErrHelixNsRatioMin"], macros["ErrHelixNsRatioMax"] = f"{min(hx_ns):.1f}", f"{max(hx_ns):.1f}"
tot = maps[maps.pose == "rest"]
macros["ErrLargeTotal"] = f"{int(tot.large_errors.sum()):,}"
macros["ErrJumpTotal"] = f"{int(tot.at_discontinuity.sum()):,}"
macros["ErrPoleTotal"] = f"{int(tot.near_pole.sum()):,}"
macros["ErrSeamTotal"] = f"{int(tot.near_seam.sum()):,}"
# Exact look-ups at depth discontinuities (issue 15): maps alone against maps + ray casts, 0.1 deg.
fine = maps[np.isclose(maps.precision_deg, HEAD_P)]  # every scheme at its 0.1 deg equivalent
ex = fine[fine["mode"] == "exact"]
rf = fine[fine["mode"] == "exact_refined"]
if len(rf):
    rows = []
    for (s_, scheme), g in fine.groupby(["subject", "scheme"], sort=False):
        a, b = g[g["mode"] == "exact"], g[g["mode"] == "exact_refined"]
        if not len(a) or not len(b):
            continue
        rows.append([s_, scheme, e(a.max_abs_mm.max()), e(b.max_abs_mm.max()), f"{int(a.mismatched.sum())}",
                     f"{int(b.mismatched.sum())}", f"{a.query_ns_per_vertex.median():.1f}",
                     f"{b.query_ns_per_vertex.median():.1f}",
                     f"{b.query_ns_per_vertex.median() / a.query_ns_per_vertex.median():.2f}"])
    write_table(d, "table_refined", ["subject", "scheme", "max, maps", "max, refined", "mism., maps",
                                     "mism., refined", "ns, maps", "ns, refined", "ratio"], rows,
                align="llrrrrrrr")
    eq_a, eq_b = ex[ex.scheme == "equiangular"], rf[rf.scheme == "equiangular"]
    ratio = (eq_b.groupby("subject").query_ns_per_vertex.median() /
             eq_a.groupby("subject").query_ns_per_vertex.median()).dropna()
    real = ~fine.subject.str.startswith("generated")
    macros.update({
        "RefMapsMaxMax": e(ex[real[ex.index]].max_abs_mm.max()),
        "RefMaxMax": e(rf.max_abs_mm.max()),
        "RefRealMaxMax": e(rf[real[rf.index]].max_abs_mm.max()),  # the shared hips alone (the README quotes it)
        "RefRatioMin": f"{ratio.min():.2f}", "RefRatioMax": f"{ratio.max():.2f}",
        "RefMismatchedMaps": f"{int(ex.mismatched.sum())}", "RefMismatchedRefined": f"{int(rf.mismatched.sum())}",
    })
# Every scheme at equal error (issue 12): interpolated between the resolutions of the sweep.
TARGETS = (1e-2, 1e-3, 1e-4)
# Every macro the text uses, "--" until the data give it (no real subject, or a target not reached).
for k in ("EqErrBestAny", "EqErrBestAnyBytesRatio", "EqErrBestAnyNsRatio", "EqErrEqSparseBytesRatio",
          "EqErrEqSparseNsRatio", "EqErrBestNewScheme", "EqErrBestNewBytesRatio", "EqErrBestNewNsRatio",
          "EqErrNewBytesRatioMin", "EqErrNewBytesRatioMax", "EqErrNewNsRatioMin", "EqErrNewNsRatioMax",
          "EqErrHelixBytesRatioMin", "EqErrHelixBytesRatioMax", "EqErrHelixNsRatioMin", "EqErrHelixNsRatioMax",
          "EqErrTargetVerdict", "EqErrBestNewNsRatioFine", "EqErrBestPerSubjectBytesRatioMin",
          "EqErrBestPerSubjectBytesRatioMax", "EqErrBestPerSubjectNsRatioMin", "EqErrBestPerSubjectNsRatioMax",
          "EqErrBestPerSubjectSchemes", "EqErrByteTargetHolds"):
    macros.setdefault(k, "--")
eq_rows = []
rest = maps_all[(maps_all.pose == "rest") & ~maps_all.generated.astype(bool) &
                maps_all["mode"].isin(["exact", "exact_refined"])]
for (s_, scheme, mode, storage), g in rest.groupby(["subject", "scheme", "mode", "storage"], sort=False):
    g = g.sort_values("bytes")
    for metric, col in (("p95", "p95_abs_mm"), ("max", "max_abs_mm")):
        err = g[col].to_numpy(float)
        by, ns, sm = (g[c].to_numpy(float) for c in ("bytes", "query_ns_per_vertex", "sampling_ms"))
        for target in TARGETS:
            row = dict(subject=s_, scheme=scheme, storage=storage, mode=mode, metric=metric, target_mm=target,
                       bytes=np.nan, query_ns_per_vertex=np.nan, sampling_ms=np.nan, how="not_reached")
            if len(err) and err[0] <= target:
                row.update(bytes=by[0], query_ns_per_vertex=ns[0], sampling_ms=sm[0], how="coarsest")
            else:
                for i in range(1, len(err)):
                    if err[i - 1] > target >= err[i]:
                        f = (np.log(target) - np.log(err[i - 1])) / (np.log(max(err[i], 1e-12)) - np.log(err[i - 1]))

                        def lerp(a):
                            return float(np.exp(np.log(a[i - 1]) + f * (np.log(a[i]) - np.log(a[i - 1]))))
                        row.update(bytes=lerp(by), query_ns_per_vertex=lerp(ns), sampling_ms=lerp(sm),
                                   how="interpolated")
                        break
            eq_rows.append(row)
import pandas as pd
eqe = pd.DataFrame(eq_rows, columns=["subject", "scheme", "storage", "mode", "metric", "target_mm", "bytes",
                                     "query_ns_per_vertex", "sampling_ms", "how"])
eqe.to_csv(f"{d}/equal_error.csv", index=False)
write_table(d, "table_equal_error", ["subject", "scheme", "storage", "MiB", "/ equiangular", "ns/vertex",
                                     "/ equiangular", "sampling ms"], [], align="lllrrrrr")
if eq_rows:
    # Table: at p95 <= 1e-3 mm, maps alone (exact), every subject: each scheme against the equiangular grid.
    rows, best, best_any = [], {}, {}
    sel = eqe[(eqe["mode"] == "exact") & (eqe.metric == "p95") & np.isclose(eqe.target_mm, 1e-3)]
    for s_, g in sel.groupby("subject", sort=False):
        ref = g[(g.scheme == "equiangular") & (g.storage == "dense")]
        if not len(ref) or ref.how.iloc[0] == "not_reached":
            continue
        rb, rn = ref.bytes.iloc[0], ref.query_ns_per_vertex.iloc[0]
        for _, r in g.sort_values("bytes").iterrows():
            if r.how == "not_reached":
                rows.append([s_, r.scheme, r.storage, "--", "--", "--", "--", "--"])
                continue
            rows.append([s_, r.scheme, r.storage, f"{r.bytes / 2**20:.1f}", f"{r.bytes / rb:.2f}",
                         f"{r.query_ns_per_vertex:.1f}", f"{r.query_ns_per_vertex / rn:.2f}", f"{r.sampling_ms:.0f}"])
            if r.scheme not in ("equiangular", "helix", "helix-eq10", "conchoid") and r.storage == "dense":
                best.setdefault(s_, []).append((r.bytes / rb, r.query_ns_per_vertex / rn, r.scheme))
            if r.scheme != "equiangular" or r.storage != "dense":
                best_any.setdefault(s_, []).append((r.bytes / rb, r.query_ns_per_vertex / rn, f"{r.scheme} ({r.storage})"))
    write_table(d, "table_equal_error", ["subject", "scheme", "storage", "MiB", "/ equiangular", "ns/vertex",
                                         "/ equiangular", "sampling ms"], rows, align="lllrrrrr")
    if subj in best_any:
        b = min(best_any[subj])
        macros.update({"EqErrBestAny": b[2], "EqErrBestAnyBytesRatio": f"{b[0]:.2f}",
                       "EqErrBestAnyNsRatio": f"{b[1]:.2f}"})
        sp = [x for x in best_any[subj] if x[2] == "equiangular (sparse)"]
        if sp:
            macros.update({"EqErrEqSparseBytesRatio": f"{sp[0][0]:.2f}", "EqErrEqSparseNsRatio": f"{sp[0][1]:.2f}"})
    if subj in best:
        b = min(best[subj])
        macros.update({"EqErrBestNewScheme": b[2], "EqErrBestNewBytesRatio": f"{b[0]:.2f}",
                       "EqErrBestNewNsRatio": f"{b[1]:.2f}"})
        # The same scheme's query time at 0.1 deg (maps of tens of MB, out of the caches), against the
        # equiangular grid's: where its three cache lines per look-up show.
        fine = maps[(maps.subject == subj) & (maps.pose == "rest") & (maps["mode"] == "exact") &
                    np.isclose(maps.precision_deg, HEAD_P)]
        fn, fe = fine[fine.scheme == b[2]], fine[fine.scheme == "equiangular"]
        if len(fn) and len(fe):
            macros["EqErrBestNewNsRatioFine"] = f"{fn.query_ns_per_vertex.iloc[0] / fe.query_ns_per_vertex.iloc[0]:.1f}"
        # Issue 12's target: a new scheme at <= 0.65 times the bytes with <= 1.5 times the query time.
        # The verdict gives the best scheme's ratios to three places, so that a ratio that rounds to
        # the target in the tables is not mistaken for meeting it.
        met = [x for x in best[subj] if x[0] <= 0.65 and x[1] <= 1.5]
        macros["EqErrTargetVerdict"] = (
            f"{met[0][2]} meets it ({met[0][0]:.3f} times the bytes, {met[0][1]:.2f} times the query time)" if met
            else f"no new scheme meets both (the best, {b[2]}, needs {b[0]:.3f} times the bytes at {b[1]:.2f} "
                 "times the query time)")
    # The best new scheme (least bytes) of every subject: the target's reading on the other subjects.
    per = [min(v_) for v_ in best.values() if v_]
    if per:
        macros["EqErrBestPerSubjectBytesRatioMin"] = f"{min(x[0] for x in per):.2f}"
        macros["EqErrBestPerSubjectBytesRatioMax"] = f"{max(x[0] for x in per):.2f}"
        macros["EqErrBestPerSubjectNsRatioMin"] = f"{min(x[1] for x in per):.2f}"
        macros["EqErrBestPerSubjectNsRatioMax"] = f"{max(x[1] for x in per):.2f}"
        macros["EqErrBestPerSubjectSchemes"] = ", ".join(sorted({x[2] for x in per}))
        # Where the byte target (<= 0.65 times the bytes) holds, whatever the query time.
        held = [s_ for s_, v_ in best.items() if v_ and min(v_)[0] <= 0.65]
        macros["EqErrByteTargetHolds"] = (f"on {len(held)} of {len(per)} subjects ({', '.join(held)})" if held
                                          else f"on none of the {len(per)} subjects")
    allb = [x for v_ in best.values() for x in v_]
    if allb:
        macros["EqErrNewBytesRatioMin"] = f"{min(x[0] for x in allb):.2f}"
        macros["EqErrNewBytesRatioMax"] = f"{max(x[0] for x in allb):.2f}"
        macros["EqErrNewNsRatioMin"] = f"{min(x[1] for x in allb):.1f}"
        macros["EqErrNewNsRatioMax"] = f"{max(x[1] for x in allb):.1f}"
    # The helix at equal error: bytes and query time against the equiangular grid, every subject.
    hx = []
    for s_, g in sel.groupby("subject", sort=False):
        g = g[g.storage == "dense"]
        a_, b_ = g[g.scheme == "equiangular"], g[g.scheme == "helix"]
        if len(a_) and len(b_) and (a_.how.iloc[0] != "not_reached") and (b_.how.iloc[0] != "not_reached"):
            hx.append((b_.bytes.iloc[0] / a_.bytes.iloc[0], b_.query_ns_per_vertex.iloc[0] / a_.query_ns_per_vertex.iloc[0]))
    if hx:
        macros["EqErrHelixBytesRatioMin"] = f"{min(x[0] for x in hx):.2f}"
        macros["EqErrHelixBytesRatioMax"] = f"{max(x[0] for x in hx):.2f}"
        macros["EqErrHelixNsRatioMin"] = f"{min(x[1] for x in hx):.1f}"
        macros["EqErrHelixNsRatioMax"] = f"{max(x[1] for x in hx):.1f}"
write_macros(d, "macros", macros)
print(f"10_error_vs_runtime: wrote tables and figures to {d}")
