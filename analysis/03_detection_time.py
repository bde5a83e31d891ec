"""03_detection_time: thesis Tables 4 and 9 beside ours, peers on the same vertices, throughput.

Reads RESULTS/03_detection_time/detection.csv, detection_runs.csv and throughput.csv (every time a median over
alternated rounds, with its quartiles; ratios paired round by round); writes table4_9.tex (generated
models at the thesis' triangle levels), table_real.tex (every real subject, pushed pose),
table_throughput.tex, table_schemes.tex (every registered scheme), detection_time.pdf/png, macros.tex."""
import numpy as np
import matplotlib.pyplot as plt

from common import experiment_dir, median_quartiles, read_csv, save, timing_text, write_macros, write_table

d = experiment_dir("03_detection_time")
t = read_csv(d, "detection.csv")
thr = read_csv(d, "throughput.csv")
runs = read_csv(d, "detection_runs.csv")
labels = {"rsid": "RSID", "usid": "USID", "embree_radial": "Embree rtcIntersect1",
          "embree_radial_packet8": "Embree rtcIntersect8", "cgal_radial": "CGAL first hit",
          "fcl_collide": "FCL collide", "fcl_first_contact": "FCL first contact", "fcl_distance": "FCL distance", "pairwise": "pair-wise"}


def fmt(ms):
    if ms is None or np.isnan(ms):
        return "--"
    if ms >= 100:
        return f"{ms:,.0f}"
    return f"{ms:.1f}" if ms >= 10 else (f"{ms:.2f}" if ms >= 1 else f"{ms:.3f}")


def spread(g, method, res=None):
    """A time cell with its spread: 'median (lower quartile-upper quartile)' ms over the alternated rounds."""
    med, lo, hi = (get(g, method, res, c) for c in ("time_ms", "time_q25_ms", "time_q75_ms"))
    return timing_text(med, lo, hi, get(g, method, res, "runs"), fmt)


def paired(subject, pose, num, den, num_res=None, den_res=None):
    """(median, lower quartile, upper quartile) of num's time over den's, round by round (detection_runs.csv)."""
    def rounds(method, res):
        r = runs[(runs.subject == subject) & (runs.pose == pose) & (runs.method == method)]
        if res is not None:
            r = r[np.isclose(r.resolution, res)]
        return r.set_index("round").time_ms
    return median_quartiles(rounds(num, num_res) / rounds(den, den_res))


def get(g, method, res=None, col="time_ms"):
    r = g[g.method == method]
    if res is not None:
        r = r[np.isclose(r.resolution, res)]
    return r[col].iloc[0] if len(r) else np.nan


p_table = 0.5
k_table = t[(t.method == "usid")].resolution.min()  # helix matched to the coarser precision

# Tables 4 and 9: generated models, pushed pose (contact), thesis beside ours.
rows = []
for s in ["generated-300", "generated-1k", "generated-3k", "generated-12k"]:
    g = t[(t.subject == s) & (t.pose == "pushed_3mm")]
    if not len(g):
        continue
    rows.append([s.replace("generated-", ""), f"{int(g.femur_triangles.iloc[0]):,}",
                 fmt(get(g, "pairwise", col="thesis_ms")), spread(g, "pairwise"),
                 fmt(get(g, "fcl_collide", col="thesis_ms")), spread(g, "fcl_collide"),
                 fmt(get(g, "rsid", col="thesis_ms")), spread(g, "rsid", p_table),
                 fmt(get(g, "usid", col="thesis_ms")), spread(g, "usid", k_table),
                 spread(g, "embree_radial"), spread(g, "cgal_radial")])
write_table(d, "table4_9", ["level", "triangles", "pair-wise thesis", "pair-wise ours", "RAPID thesis", "FCL ours",
                            "RSID thesis", "RSID ours", "USID thesis", "USID ours", "Embree", "CGAL"], rows,
            align="lrrrrrrrrrrr", stack=True)

# Real subjects, both poses: every method; per pose ms and ns per vertex.
rows = []
for (s, pose), g in t[~t.generated.astype(bool)].groupby(["subject", "pose"], sort=False):
    nv = int(get(g, "rsid", 0.1, "vertices"))
    rows.append([s, pose.replace("_", " "), f"{nv:,}", spread(g, "rsid", 0.5), spread(g, "rsid", 0.1),
                 spread(g, "usid", k_table), spread(g, "embree_radial"), spread(g, "embree_radial_packet8"),
                 spread(g, "cgal_radial"), spread(g, "fcl_collide"), f"{get(g, 'fcl_collide', col='result'):.0f}",
                 spread(g, "fcl_distance"), spread(g, "pairwise"), f"{get(g, 'rsid', 0.1, 'result'):.2f}"])
write_table(d, "table_real", ["subject", "pose", "vertices", "RSID 0.5", "RSID 0.1", "USID", "Embree", "Embree x8",
                              "CGAL", "FCL collide", "contacts", "FCL distance", "pair-wise", "min gap (mm)"], rows,
            align="llrrrrrrrrrrrr", stack=True)

rows = []
for (s, m, r), g in thr[thr.method.isin(["rsid", "usid"])].groupby(["subject", "method", "resolution"], sort=False):
    a, b = g[g.threads == 1].iloc[0], g[g.threads == 2].iloc[0]

    def rate(x):  # poses/s at the median, with the quartiles of the time turned into rates
        n = x.poses * 1000.0
        return f"{n / x.time_ms:,.0f} ({n / x.time_q75_ms:,.0f}-{n / x.time_q25_ms:,.0f})"
    rows.append([s, labels.get(m, m), f"{r:g}", rate(a), rate(b), f"{b.poses_per_s / a.poses_per_s:.2f}"])
write_table(d, "table_throughput", ["subject", "method", "resolution", "poses/s, 1 thread", "poses/s, 2 threads",
                                    "speed-up"], rows, align="llrrrr")

# Every registered scheme on the real subjects (pushed pose, matched to 0.1 deg): one pose's detection
# and the throughput over random poses, one thread (issue 12: a new scheme appears here unasked).
peer_methods = set(labels) - {"rsid", "usid"}
schemes = [m for m in dict.fromkeys(t.method) if m not in peer_methods]
rows = []
real = t[~t.generated.astype(bool) & (t.pose == "pushed_3mm")]
for s_, g in real.groupby("subject", sort=False):
    base = get(g, "rsid", 0.1)
    for m in schemes:
        r = g[(g.method == m) & np.isclose(g.spacing_deg, 0.1)]
        if len(r) == 0:
            continue
        r = r.iloc[0]
        tp = thr[(thr.subject == s_) & (thr.method == m) & np.isclose(thr.spacing_deg, 0.1) & (thr.threads == 1)]
        res = f"{int(r.resolution):,}" if float(r.resolution).is_integer() else f"{r.resolution:.4g}"
        # The time with its quartiles, and its ratio to RSID's round by round (paired: the same rounds).
        q = paired(s_, r.pose, m, "rsid", r.resolution, 0.1)
        rows.append([s_, labels.get(m, m), res, timing_text(r.time_ms, r.time_q25_ms, r.time_q75_ms, r.runs, fmt),
                     f"{r.ns_per_vertex:.1f}",
                     "1 (itself)" if m == "rsid" else timing_text(q[0], q[1], q[2], None, lambda x: f"{x:.2f}")
                     if np.isfinite(base) and base > 0 else "--",
                     f"{tp.poses_per_s.iloc[0]:,.0f}" if len(tp) else "--"])
write_table(d, "table_schemes", ["subject", "scheme", "resolution", "ms per pose", "ns/vertex", "/ RSID",
                                 "poses/s (random)"], rows, align="llrrrrr")

# Figure: ms per pose (both scans) against triangles per model, pushed pose, log-log.
fig, ax = plt.subplots(figsize=(6.5, 3.8))
gen = t[t.generated.astype(bool) & (t.pose == "pushed_3mm")]
for m, res in [("rsid", p_table), ("rsid", 0.1), ("usid", k_table), ("embree_radial", None), ("cgal_radial", None),
               ("fcl_collide", None), ("pairwise", None)]:
    g = gen[gen.method == m]
    if res is not None:
        g = g[np.isclose(g.resolution, res)]
    g = g.sort_values("femur_triangles")
    if len(g):
        ax.errorbar(g.femur_triangles, g.time_ms, yerr=[g.time_ms - g.time_q25_ms, g.time_q75_ms - g.time_ms],
                    marker="o", markersize=3, capsize=2, label=labels[m] + (f" {res:g}" if res is not None else ""))
        ax.set_xscale("log")
        ax.set_yscale("log")
for col, mk, name in [("rsid", "s", "thesis RSID"), ("fcl_collide", "^", "thesis RAPID"), ("pairwise", "x", "thesis pair-wise")]:
    g = gen[(gen.method == col)].drop_duplicates("subject").sort_values("femur_triangles")
    ax.loglog(g.femur_triangles, g.thesis_ms, mk, color="k", markersize=5, label=name)
ax.set_xlabel("triangles per model")
ax.set_ylabel("ms per pose (both scans)")
ax.grid(True, which="both", lw=0.3)
# Two legends (at most 8 entries each) right of the axes: ours above, the thesis' markers below.
handles, names = ax.get_legend_handles_labels()
ours = [(h, n) for h, n in zip(handles, names) if not n.startswith("thesis")]
thesis = [(h, n) for h, n in zip(handles, names) if n.startswith("thesis")]
fig.legend(*zip(*ours), title="ours", loc="upper right", bbox_to_anchor=(1.0, 1.0), frameon=False)
fig.legend(*zip(*thesis), title="thesis", loc="lower right", bbox_to_anchor=(1.0, 0.0), frameon=False)
save(fig, d, "detection_time", rect=(0, 0, 0.7, 1))

# Numbers for the text: the first real subject, pushed pose; without real subjects, the largest generated model.
real = t[~t.generated.astype(bool)]
if not len(real):
    real = t[t.subject == t.loc[t.femur_triangles.idxmax(), "subject"]]
macros = {}
if len(real):
    s = real.subject.iloc[0]
    g = real[(real.subject == s) & (real.pose == "pushed_3mm")]
    g0 = real[(real.subject == s) & (real.pose == "rest")]
    rs, emb, cg, fcl = get(g, "rsid", 0.1), get(g, "embree_radial"), get(g, "cgal_radial"), get(g, "fcl_collide")
    macros.update({"DetSubject": s, "DetVertices": f"{int(get(g, 'rsid', 0.1, 'vertices')):,}",
                   "DetRsidMs": fmt(rs), "DetRsidNs": f"{get(g, 'rsid', 0.1, 'ns_per_vertex'):.1f}",
                   "DetEmbreeNs": f"{get(g, 'embree_radial', col='ns_per_vertex'):.0f}",
                   "DetCgalNs": f"{get(g, 'cgal_radial', col='ns_per_vertex'):,.0f}",
                   "DetFclMs": fmt(fcl), "DetFclContacts": f"{get(g, 'fcl_collide', col='result'):.0f}",
                   "DetFclFirstMs": fmt(get(g, "fcl_first_contact")),
                   "DetUsidMs": fmt(get(g, "usid", k_table)),
                   "DetRsidMsQlow": fmt(get(g, "rsid", 0.1, "time_q25_ms")),
                   "DetRsidMsQhigh": fmt(get(g, "rsid", 0.1, "time_q75_ms")),
                   "DetRuns": f"{int(get(g, 'rsid', 0.1, 'runs'))}",
                   "DetFclDistance": f"{get(g0, 'fcl_distance', col='result'):.3f}",
                   "DetRsidMinGapRest": f"{get(g0, 'rsid', 0.1, 'result'):.3f}"})
    # Ratios to RSID paired round by round (the methods of a pose ran alternately), with their quartiles.
    for name, method, digits in (("Fcl", "fcl_collide", 0), ("FclFirst", "fcl_first_contact", 1),
                                 ("Embree", "embree_radial", 1), ("Cgal", "cgal_radial", 0)):
        med, lo, hi = paired(s, "pushed_3mm", method, "rsid", None, 0.1)
        macros.update({f"Det{name}OverRsid": f"{med:.{digits}f}", f"Det{name}OverRsidQlow": f"{lo:.{digits}f}",
                       f"Det{name}OverRsidQhigh": f"{hi:.{digits}f}"})
# FCL against RSID (0.1 deg) at the pushed pose on every model: where each of FCL's two queries is the faster.
fcl_all_faster, fcl_first_faster = [], []
for s_, g in t[t.pose == "pushed_3mm"].groupby("subject", sort=False):
    r_ = get(g, "rsid", 0.1)
    if np.isfinite(r_):
        if get(g, "fcl_collide") < r_:
            fcl_all_faster.append(s_)
        if get(g, "fcl_first_contact") < r_:
            fcl_first_faster.append(s_)


def models(names):
    return ", ".join(f"\\texttt{{{n}}}" for n in names) if names else "no model"


macros["DetFclAllFasterOn"] = models(fcl_all_faster)
macros["DetFclFirstFasterOn"] = models(fcl_first_faster)
# The thesis' finding (the OBB tree faster than RSID at 12k triangles) read with each of FCL's queries: reversed
# where FCL is the slower on the 12k model, as the thesis found where it is the faster.
for key, faster in (("DetFclAllVerdict", fcl_all_faster), ("DetFclFirstVerdict", fcl_first_faster)):
    macros[key] = ("FCL is the faster, as the thesis found" if "generated-12k" in faster else
                   "RSID is the faster, the thesis' order reversed" if "generated-12k" in set(t.subject) else "--")
# Against the thesis (generated levels, pushed pose): RSID at the table's precision, USID over RSID.
gen_p = t[t.generated.astype(bool) & (t.pose == "pushed_3mm")]
rsid_vs_thesis, usid_over_rsid = [], []
for s_, g in gen_p.groupby("subject", sort=False):
    ours, theirs = get(g, "rsid", p_table), get(g, "rsid", col="thesis_ms")
    if np.isfinite(ours) and np.isfinite(theirs) and ours > 0:
        rsid_vs_thesis.append(theirs / ours)
pushed = t[t.pose == "pushed_3mm"]
for s_, g in pushed.groupby("subject", sort=False):
    u, r_ = get(g, "usid", k_table), get(g, "rsid", p_table)
    if np.isfinite(u) and np.isfinite(r_) and r_ > 0:
        usid_over_rsid.append(u / r_)
g12 = gen_p[gen_p.subject == "generated-12k"]
th_ratio = get(g12, "usid", col="thesis_ms") / get(g12, "rsid", col="thesis_ms") if len(g12) else np.nan
macros["DetRsidThesisMin"] = f"{min(rsid_vs_thesis):.0f}" if rsid_vs_thesis else "n/a"
macros["DetRsidThesisMax"] = f"{max(rsid_vs_thesis):.0f}" if rsid_vs_thesis else "n/a"
macros["DetUsidOverRsidMin"] = f"{min(usid_over_rsid):.1f}" if usid_over_rsid else "n/a"
macros["DetUsidOverRsidMax"] = f"{max(usid_over_rsid):.1f}" if usid_over_rsid else "n/a"
macros["DetThesisUsidOverRsid"] = f"{th_ratio:.1f}" if np.isfinite(th_ratio) else "n/a"
# Random poses against one repeated pose (cold against warm cache lines), and two threads.
for res, name in ((0.1, "Fine"), (0.5, "Coarse")):
    cold, warm = [], []
    for s_, g in thr[(thr.method == "rsid") & np.isclose(thr.resolution, res) & (thr.threads == 1)].groupby("subject"):
        w = get(t[(t.subject == s_) & (t.pose == "pushed_3mm")], "rsid", res)
        if np.isfinite(w) and w > 0:
            cold.append(1000.0 / g.poses_per_s.iloc[0] / w)
    macros[f"DetColdOverWarm{name}Verdict"] = ("n/a" if not cold else "cheaper" if max(cold) < 1 else
                                                "dearer" if min(cold) > 1 else "cheaper on some subjects, dearer on others")
    macros[f"DetColdOverWarm{name}Min"] = f"{min(cold):.2g}" if cold else "n/a"
    macros[f"DetColdOverWarm{name}Max"] = f"{max(cold):.2g}" if cold else "n/a"
    nodes = (180 / res + 1) * (360 / res)
    macros[f"DetMapMB{name}"] = f"{nodes * 4 / 1e6:.0f}"
ups = []
for (s_, m, r_), g in thr.groupby(["subject", "method", "resolution"], sort=False):
    ups.append(g[g.threads == 2].poses_per_s.iloc[0] / g[g.threads == 1].poses_per_s.iloc[0])
macros["DetTwoThreadsMin"] = f"{min(ups):.1f}" if ups else "n/a"
macros["DetTwoThreadsMax"] = f"{max(ups):.1f}" if ups else "n/a"
write_macros(d, "macros", macros)
print(f"03_detection_time: wrote tables and figure to {d}")
