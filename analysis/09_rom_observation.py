"""09_rom_observation: thesis sec. 5.2 (Tables 11-13) on our hips, ROM limits with an exact check,
ROM maps, published values beside ours, sensitivity and cost.

Reads RESULTS/09_rom_observation/*.csv (and the observation_*.ply cup meshes); writes
table_observation.tex, table_limits.tex, table_published.tex, table_sensitivity.tex, table_extra.tex,
table_layered.tex, table_envelope.tex, table_methods.tex, table_method_sensitivity.tex,
rom_map.pdf, limits_vs_normal.pdf (every limit in the anterior pelvic plane beside the published bony and living ranges), medial_<subject>_<patient>.pdf
(Tables 12-13's panels), macros.tex."""
import os
import warnings

import numpy as np

import matplotlib
import matplotlib.colors
import matplotlib.patches
import matplotlib.pyplot as plt

from common import (THESIS_ROM_ZONES, experiment_dir, in_clock_zones, read_csv, save, timing_text, write_macros,
                    write_table)
from render import draw, level_key, level_rgb, plot_coordinates, read_gap_ply

d = experiment_dir("09_rom_observation")
obs = read_csv(d, "observation.csv")
lim = read_csv(d, "rom_limits.csv")
rmap = read_csv(d, "rom_map.csv")
sens = read_csv(d, "sensitivity.csv")
tim = read_csv(d, "timing.csv")
xa = read_csv(d, "extra_articular.csv")
lay = read_csv(d, "layered.csv")
env = read_csv(d, "envelope.csv")
pub = read_csv(d, "published.csv")
meth = read_csv(d, "methods.csv") if os.path.exists(os.path.join(d, "methods.csv")) else None
bony = read_csv(d, "bony.csv") if os.path.exists(os.path.join(d, "bony.csv")) else None
t11 = read_csv(d, "thesis_table11.csv")
subjects = list(dict.fromkeys(lim.subject))


def span(values, fmt):
    """'low--high' of a Series at the format fmt, or the one value when both read the same (one subject timed, or
    equal to the printed digits)."""
    lo, hi = format(values.min(), fmt), format(values.max(), fmt)
    return lo if lo == hi else f"{lo}--{hi}"


def exact_over_vertex_range(t):
    """The exact search's time over the per-vertex one across the subjects that timed both (timing.csv's
    exact_over_per_vertex), as the appendix's clause: a range, or the one subject when only one was timed."""
    r = t[t.exact_over_per_vertex.notna()] if "exact_over_per_vertex" in t else t.iloc[0:0]
    if len(r) == 0:
        return "not timed on any subject"
    lo, hi = f"{r.exact_over_per_vertex.min():.1f}", f"{r.exact_over_per_vertex.max():.1f}"
    if len(r) == 1:
        return f"timed on {r.subject.iloc[0]} alone"
    return f"{lo} times on every subject" if lo == hi else f"{lo}--{hi} times across the {len(r)} subjects"


def f(x, n=1):
    if np.isnan(x):
        return "--"
    return "$\\infty$" if np.isinf(x) else f"{x:.{n}f}"


# Table 11's extremities on our hips (thesis Tables 12-13: red < 2 mm, blue > 6 mm).
rows = []
for r in obs.itertuples():
    red = r.socket_area_0to2_mm2 + r.socket_area_penetrating_mm2
    rows.append([r.subject, r.patient, r.motion.replace("_", " "), f(r.angle_deg),
                 f(min(r.ball_min_gap_mm, r.socket_min_gap_mm), 2), f(red, 0), f(r.socket_area_over6_mm2, 0),
                 f(r.socket_closest_clock_h)])
write_table(d, "table_observation", ["subject", "patient", "extremity", "angle", "min gap", "red mm$^2$",
                                     "blue mm$^2$", "clock h"], rows, align="lllrrrrr")

# Limits with the exact check.
rows = []
for r in lim.itertuples():
    rows.append([r.subject, r.motion.replace("_", " "), f(r.limit_deg), r.limited_by if isinstance(r.limited_by, str) else "",
                 f(r.pelvis_clock_h), f(r.femur_clock_h), f(r.exact_gap_before_mm, 3), f(r.exact_gap_after_mm, 3),
                 r.validated])
write_table(d, "table_limits", ["subject", "motion", "limit", "where", "socket h", "femur h", "exact $-0.5^\\circ$",
                                "exact $+0.5^\\circ$", "confirmed"], rows, align="llrlrrrrl")

# Published values beside ours.
rows = []
for p in pub.itertuples():
    for s in subjects:
        ours = lim[(lim.subject == s) & (lim.motion == p.compare_with)].limit_deg.iloc[0]
        rows.append([p.group, f(p.value_deg), s, f(ours), p.source])
write_table(d, "table_published", ["group (published)", "IR deg", "subject", "ours deg", "source"], rows,
            align="lrlrl")

# Every limit beside the published ranges of its motion (issue 81): in the anterior pelvic plane, the frame of
# clinical tools and of published simulated bony ROM (limit_app_deg; the limits' own frame where the APP could
# not be built), against the published simulated *bony* range of normal hips where one could be cited
# (bony_normal_deg: dashed) kept apart from the active range of living subjects (normal_deg, AAOS 1965,
# Kouyoumdjian et al. 2012: solid). A motion whose start is not reached is drawn at the foot, one past the
# living range (the capsule and ligaments usually end it first) hollow.
if "normal_deg" in lim.columns:
    app = "limit_app_deg" in lim.columns and lim.limit_app_deg.notna().any()
    value, status = ("limit_app_deg", "status_app") if app else ("limit_deg", "status")
    motions = list(dict.fromkeys(lim.motion))
    fig, ax = plt.subplots(figsize=(6.3, 4.4))  # printed at the text width: its 8 pt text stays 8 pt
    markers = "osD^v<>"
    for k, m in enumerate(motions):
        normal = lim[lim.motion == m].normal_deg.iloc[0]
        if not np.isnan(normal):
            ax.plot([k - 0.35, k + 0.35], [normal, normal], color="black", lw=2.5, zorder=1)
        bony_range = lim[lim.motion == m].bony_normal_deg.iloc[0] if "bony_normal_deg" in lim.columns else np.nan
        if not np.isnan(bony_range):
            ax.plot([k - 0.35, k + 0.35], [bony_range, bony_range], color="black", lw=1.5, ls="--", zorder=1)
        for i, s in enumerate(subjects):
            r = lim[(lim.subject == s) & (lim.motion == m)].iloc[0]
            x = k + (i - (len(subjects) - 1) / 2) * 0.15
            if getattr(r, status) == "not_reachable":
                ax.plot(x, 2, marker="x", color=f"C{i}", ms=7, zorder=2)
                continue
            y = getattr(r, value) if getattr(r, status) != "free" else 150
            hollow = not np.isnan(normal) and (getattr(r, status) == "free" or y > normal)
            ax.plot(x, y, marker=markers[i % len(markers)], ms=6, zorder=2, color=f"C{i}",
                    markerfacecolor="none" if hollow else f"C{i}")
    ax.set_xticks(range(len(motions)))
    ax.set_xticklabels([m.replace("_90_flexion", " 90").replace("_", " ") for m in motions], rotation=30, ha="right",
                       fontsize=8)
    ax.set_ylabel("bony limit, deg\n(" + ("anterior pelvic plane" if app else
                                           "pelvic frame: " + ", ".join(sorted(set(lim.pelvic_frame)))) + ")")
    ax.set_ylim(0, 155)
    for i, s in enumerate(subjects):
        ax.plot([], [], marker=markers[i % len(markers)], ls="none", color=f"C{i}", label=s)
    ax.plot([], [], color="black", lw=2.5, label="published normal (living, active)")
    ax.plot([], [], color="black", lw=1.5, ls="--", label="published bony (simulated, normal hips)")
    ax.plot([], [], marker="x", ls="none", color="gray", label="start not reached")
    ax.plot([], [], marker="o", ls="none", color="gray", markerfacecolor="none", label="past the living range")
    ax.legend(fontsize=8, ncol=3, loc="upper center", bbox_to_anchor=(0.5, -0.32))
    fig.tight_layout()
    save(fig, d, "limits_vs_normal")

# Sensitivity: largest |change| of a limit per subject, method and perturbation kind. A limit that
# appears or disappears (found in one run, none within the search range in the other) counts as an
# unbounded change. delta_deg is empty on both counts, so a limit that vanishes under the perturbation is told
# from one that is absent in both runs by the unperturbed run's limit (rom_limits.csv for the thesis' method,
# methods.csv for Puls et al.'s; issue 82: the tables dropped the vanishing ones).
BASE = {(r.subject, "femoral-head (thesis)", r.motion): r.limit_deg for r in lim.itertuples()}
if meth is not None:
    BASE.update({(r.subject, r.method, r.motion): r.limit_deg for r in meth.itertuples()})


def changes(g):
    v = g.delta_deg.abs().copy()
    v[g.limit_deg.isna() != g.delta_deg.isna()] = np.inf
    base = np.array([BASE.get((r.subject, r.method, r.motion), np.nan) for r in g.itertuples()], dtype=float)
    v[g.limit_deg.isna().to_numpy() & np.isfinite(base)] = np.inf
    return v


rows = []
for s in subjects:
    for method in dict.fromkeys(sens.method):
        g = sens[(sens.subject == s) & (sens.method == method)]
        for kind, sel in (("COR moved 1 mm", g.variant.str.startswith("cor")),
                          ("resolution", g.variant.str.startswith("res"))):
            if sel.sum() == 0:
                continue
            v = changes(g[sel])
            rows.append([s, method, kind, f(v.median(), 2), f(v.max(), 1), str(int(sel.sum()))])
write_table(d, "table_sensitivity", ["subject", "method", "perturbation", "median $|\\Delta|$ deg",
                                     "max $|\\Delta|$ deg", "runs"], rows, align="lllrrr")

# Puls et al.'s four joint-centre methods side by side: the limits, and the worst change of each
# limit under a 1 mm move of the initial COR (6 directions).
# Without the shared hips (no methods.csv, no mc22 pair) the prose's numbers read "--".
method_macros = {k: "--" for k in ["ROMeqSensMax", "ROMeqSensWorstSubject", "ROMeqSensWithinThree", "ROMmethodSubjects",
                                   "ROMfhSensMax", "ROMfhSensVanish", "ROMeqSensMedian", "ROMeqSensOverThree",
                                   "ROMeqSensLimits", "ROMeqSensOverThreeList", "ROMfhSensMedian",
                                   "ROMeqSensWithinThreeLimits"]}
if meth is not None:
    order = ["femoral-head", "acetabular", "combined", "equidistant"]
    msubjects = list(dict.fromkeys(meth.subject))
    rows = []
    for s in msubjects:
        for motion in dict.fromkeys(meth.motion):
            g = meth[(meth.subject == s) & (meth.motion == motion)].set_index("method")
            rows.append([s, motion.replace("_", " ")] + [f(g.limit_deg.get(m, np.nan), 0) for m in order])
    write_table(d, "table_methods", ["subject", "motion"] + order, rows, align="llrrrr")
    cor = sens[sens.variant.str.startswith("cor") & sens.method.isin(order)]
    # The subjects whose COR was moved (--quick: the first alone; the full run: every subject of methods.csv).
    csubjects = [s for s in msubjects if s in set(cor.subject)]
    rows = []
    for s in csubjects:
        worst = [changes(cor[(cor.subject == s) & (cor.method == m)]).max() for m in order]
        rows.append([s] + [f(w) for w in worst])
    write_table(d, "table_method_sensitivity", ["subject"] + [m + " max $|\\Delta|$ deg" for m in order], rows,
                align="lrrrr")
    eq = cor[cor.method == "equidistant"]
    fh = cor[cor.method == "femoral-head"]
    per_subject = {s: changes(eq[eq.subject == s]).max() for s in csubjects}
    method_macros.update({
        "ROMeqSensMax": f(max(per_subject.values())),
        "ROMeqSensWorstSubject": max(per_subject, key=per_subject.get),
        "ROMeqSensWithinThree": str(sum(1 for v in per_subject.values() if v <= 3)),
        "ROMmethodSubjects": str(len(csubjects)),
        "ROMfhSensMax": f(changes(fh)[np.isfinite(changes(fh))].max()),
        "ROMfhSensVanish": str(int(np.isinf(changes(fh)).sum())),
        "ROMeqSensMedian": f(changes(eq).median(), 2),
        "ROMfhSensMedian": f(changes(fh).median()),
    })
    # The limits a 1 mm move changes by more than 3 deg, by subject (the prose names them).
    worst = eq.assign(change=changes(eq)).groupby(["subject", "motion"], sort=False).change.max()
    over = worst[worst > 3]
    method_macros.update({
        "ROMeqSensOverThree": str(len(over)), "ROMeqSensLimits": str(len(worst)),
        "ROMeqSensWithinThreeLimits": str(len(worst) - len(over)),
        "ROMeqSensOverThreeList": "; ".join(
            f"\\texttt{{{s}}}: " + ", ".join(m.replace("_", " ") for m in over[s].index)
            for s in dict.fromkeys(over.index.get_level_values(0))) or "none",
    })

# The thesis' ROM observation (sec. 5.2, Tables 12-13), with a verdict: red zones at 1-2 o'clock for
# patient A, at 1-3 and 7 o'clock for patient B. Ours: the clock hour of the socket's closest point at
# each extremity, on every subject, within half an hour of the thesis' zones. Reproduced when at least
# three quarters of the extremities fall there, partly when at least a quarter, else not.

def verdict(share):
    return "reproduced" if share >= 0.75 else "partly reproduced" if share >= 0.25 else "not reproduced"


obs_macros = {}
for patient, zones in THESIS_ROM_ZONES.items():
    g = obs[obs.patient == patient]
    hits = sum(in_clock_zones(h, zones) for h in g.socket_closest_clock_h if np.isfinite(h))
    posterior = sum(7.5 <= h <= 11.5 for h in g.socket_closest_clock_h if np.isfinite(h))
    obs_macros[f"ROMobs{patient}InZone"] = str(hits)
    # The thesis shows its clock faces "horizontally reversed": read that way, our hour h is its 12 - h.
    obs_macros[f"ROMobs{patient}InZoneReversed"] = str(sum(in_clock_zones((12 - h) % 12, zones)
                                                          for h in g.socket_closest_clock_h if np.isfinite(h)))
    obs_macros[f"ROMobs{patient}Poses"] = str(len(g))
    obs_macros[f"ROMobs{patient}Posterior"] = str(posterior)
    obs_macros[f"ROMobs{patient}Verdict"] = verdict(hits / max(len(g), 1))

# Left against right (issue 29): mc22's two hips (the same pelvis) under the default method, for the
# motions the issue names, and the bony measures that can explain a difference.
lr_macros = {"ROMlr" + k: "--" for k in ["WithinTen", "Compared", "RightCoverage", "LeftCoverage", "RightInclination",
                                         "LeftInclination", "RightScanGap", "LeftScanGap", "RightNeutralGap",
                                         "LeftNeutralGap"]}
lr_macros.update(ROMlrCoverageCompare="--", ROMlrSteepCompare="--", ROMlrPincerText="")
if meth is not None and {"mc22", "mc22-left"} <= set(meth.subject):
    eqm = meth[meth.method == "equidistant"].set_index(["subject", "motion"])
    rows, diffs = [], []
    for motion in ["flexion", "abduction", "internal_rotation_90_flexion", "fadir", "extension", "adduction",
                   "internal_rotation", "external_rotation", "external_rotation_90_flexion"]:
        right, left = eqm.limit_deg.get(("mc22", motion), np.nan), eqm.limit_deg.get(("mc22-left", motion), np.nan)
        # None on either side: equal; a limit on one side only: an infinite difference.
        diff = 0.0 if np.isnan(right) and np.isnan(left) else abs(right - left) if np.isfinite(right - left) else np.inf
        if motion in ("flexion", "abduction", "internal_rotation_90_flexion", "fadir"):
            diffs.append(diff)
        rows.append([motion.replace("_", " "), f(right, 0), f(left, 0), f(diff, 0),
                     eqm.contact_class.get(("mc22", motion), "").replace("_", " ") if np.isfinite(right) else "",
                     eqm.contact_class.get(("mc22-left", motion), "").replace("_", " ") if np.isfinite(left) else ""])
    write_table(d, "table_left_right", ["motion", "right", "left", "$|\\Delta|$", "right: contact", "left: contact"],
                rows, align="lrrrll")
    lr_macros.update({
        "ROMlrWithinTen": str(sum(1 for x in diffs if x <= 10)),
        "ROMlrCompared": str(len(diffs)),
    })
    if bony is not None and {"mc22", "mc22-left"} <= set(bony.subject):
        b = bony.set_index("subject")
        cols = [("head_radius_mm", "head radius mm", 1), ("acetabular_radius_mm", "acetabular radius mm", 1),
                ("inclination_deg", "inclination deg", 0), ("anteversion_deg", "anteversion deg", 0),
                ("median_coverage_deg", "median coverage deg", 0), ("notch_coverage_deg", "notch coverage deg", 0),
                ("scan_pose_min_gap_mm", "least gap, scan pose, mm", 2), ("neutral_min_gap_mm", "least gap, neutral, mm", 2)]
        rows = [[label, f(b.loc["mc22", c], n), f(b.loc["mc22-left", c], n)] for c, label, n in cols]
        write_table(d, "table_bony", ["measure", "right (mc22)", "left (mc22-left)"], rows, align="lrr")
        lr_macros.update({
            "ROMlrRightCoverage": f(b.loc["mc22", "median_coverage_deg"], 0),
            "ROMlrLeftCoverage": f(b.loc["mc22-left", "median_coverage_deg"], 0),
            "ROMlrRightInclination": f(b.loc["mc22", "inclination_deg"], 0),
            "ROMlrLeftInclination": f(b.loc["mc22-left", "inclination_deg"], 0),
            "ROMlrRightScanGap": f(b.loc["mc22", "scan_pose_min_gap_mm"], 2),
            "ROMlrLeftScanGap": f(b.loc["mc22-left", "scan_pose_min_gap_mm"], 2),
            "ROMlrRightNeutralGap": f(b.loc["mc22", "neutral_min_gap_mm"], 3),
            "ROMlrLeftNeutralGap": f(b.loc["mc22-left", "neutral_min_gap_mm"], 3),
        })
        # The comparisons the text draws, from the same numbers (within 1 deg: about the same).
        dc = b.loc["mc22", "median_coverage_deg"] - b.loc["mc22-left", "median_coverage_deg"]
        di = b.loc["mc22", "inclination_deg"] - b.loc["mc22-left", "inclination_deg"]
        lr_macros.update({
            "ROMlrCoverageCompare": ("covers about as much of the head" if abs(dc) <= 1 else
                                     "covers more of the head" if dc > 0 else "covers less of the head"),
            "ROMlrSteepCompare": "about as steep" if abs(di) <= 1 else "less steep" if di < 0 else "steeper",
            "ROMlrPincerText": (": a less steep socket, reaching farther over the head laterally, meets the neck "
                                "sooner, as in pincer morphology" if di < -1 else ""),
        })

# ROM maps.
n_cols = min(2, len(subjects))
n_rows = -(-len(subjects) // n_cols)
fig, axes = plt.subplots(n_rows, n_cols, figsize=(6.5, 2.6 * n_rows + 0.9), sharex=True, sharey=True, squeeze=False)
for ax, s in zip(axes.flat, subjects):
    g = rmap[rmap.subject == s]
    fl, ad = sorted(g.flexion_deg.unique()), sorted(g.adduction_deg.unique())
    Z = np.full((len(ad), len(fl)), np.nan)
    state = np.full((len(ad), len(fl)), np.nan)  # 0: free to the search's end, 1: in contact at zero rotation
    for r in g.itertuples():
        Z[ad.index(r.adduction_deg), fl.index(r.flexion_deg)] = r.max_internal_rotation_deg
        state[ad.index(r.adduction_deg), fl.index(r.flexion_deg)] = {"free": 0, "contact_at_zero": 1}.get(r.status, np.nan)
    extent = [fl[0] - 2.5, fl[-1] + 2.5, ad[0] - 2.5, ad[-1] + 2.5]
    im = ax.imshow(Z, origin="lower", aspect="auto", extent=extent,
                   cmap="viridis", vmin=0, vmax=np.nanmax(rmap.max_internal_rotation_deg))
    # The cells without a limit get their own colours, so that neither reads as a value or as the other.
    ax.imshow(state, origin="lower", aspect="auto", extent=extent, vmin=0, vmax=1,
              cmap=matplotlib.colors.ListedColormap(["#d9d9d9", "#8b0000"]))
    ax.set_title(s)
for ax in axes.flat[len(subjects):]:
    ax.set_visible(False)
fig.supxlabel("flexion (deg)", y=0.065)
fig.supylabel("adduction (deg)")
fig.legend(handles=[matplotlib.patches.Patch(color="#d9d9d9", label="free to the search's end"),
                    matplotlib.patches.Patch(color="#8b0000", label="in contact at zero rotation")],
           loc="lower center", ncol=2, frameon=False)
fig.tight_layout(rect=(0, 0.08, 0.86, 1))
# The colour bar's own axes sit right of the panels; tight_layout (in save) leaves them where they are.
fig.colorbar(im, cax=fig.add_axes([0.88, 0.2, 0.025, 0.7]), label="largest internal rotation (deg)")
warnings.filterwarnings("ignore", message="This figure includes Axes that are not compatible with tight_layout")
save(fig, d, "rom_map", rect=(0, 0.08, 0.86, 1))

# Tables 12-13's panels: the cup from the medial side at each extremity, with the clock face.
clk = read_csv(d, "clock_faces.csv")
for s in clk.subject:
    row = clk[clk.subject == s].iloc[0]
    clock = {"centre": [row.centre_x_mm, row.centre_y_mm, row.centre_z_mm],
             "twelve": [row.twelve_x, row.twelve_y, row.twelve_z], "three": [row.three_x, row.three_y, row.three_z],
             "radius_mm": row.rim_radius_mm}
    for patient in ("A", "B"):
        files = [os.path.join(d, f"observation_{s}_{patient}_{m}.ply") for m in t11[t11.patient == patient].motion]
        if not all(os.path.exists(p) for p in files):
            continue
        fig = plt.figure(figsize=(8, 6.4))
        order = ["abduction", "internal_rotation", "extension", "adduction", "external_rotation", "flexion"]
        for k, m in enumerate(order):
            V, F, _, gap = read_gap_ply(os.path.join(d, f"observation_{s}_{patient}_{m}.ply"))
            rgb = level_rgb(gap, False)
            ang = t11[(t11.patient == patient) & (t11.motion == m)].angle_deg.iloc[0]
            ax = fig.add_subplot(2, 3, k + 1, projection="3d")
            # The panels differ little (the head turns about the socket's centre, so the joint space keeps its
            # width); the socket's closest point, marked, and the least gap in the title are what changes.
            finite = np.where(np.isfinite(gap))[0]
            closest = finite[np.argmin(gap[finite])] if len(finite) else None
            # The title gives the least gap of both scans, as Table 28 (table_observation) does (issue 82: it gave
            # the socket scan's alone); the star marks the socket's closest point.
            o = obs[(obs.subject == s) & (obs.patient == patient) & (obs.motion == m)]
            least = float(np.fmin(o.ball_min_gap_mm, o.socket_min_gap_mm).iloc[0]) if len(o) else np.nan
            draw(ax, [(V, F, rgb)], "acetabulum_medial", row.side, clock, radius=row.rim_radius_mm + 3,
                 title=f"{m.replace('_', ' ')} {ang:g} deg" +
                 (f"\nleast gap {least:.2f} mm" if np.isfinite(least) else ""))
            if closest is not None:
                p = plot_coordinates(V[closest][None])[0]
                ax.computed_zorder = False  # the star above the surface, not sorted behind it
                ax.scatter([p[0]], [p[1]], [p[2]], marker="*", s=140, color="k", edgecolors="w", linewidths=0.6,
                           zorder=12, depthshade=False)
        fig.suptitle(f"{s} at patient {patient}'s extremities (thesis Table {12 if patient == 'A' else 13}); star: the closest point")
        level_key(fig, skip=("apart, femur",))
        save(fig, d, f"medial_{s}_{patient}")

# Extra-articular impingement with layered maps (issue 14): the first contact of hidden vertices per
# motion, where it is, and the exact check; beside it the limit counting every vertex.
rows = []
for r in xa[xa.counted == "hidden"].itertuples():
    a = xa[(xa.counted == "all") & (xa.subject == r.subject) & (xa.motion == r.motion)].iloc[0]
    rows.append([r.subject, r.motion.replace("_", " "), f(a.limit_deg), a.limited_by if isinstance(a.limited_by, str) else "",
                 "--" if r.contact_at_start else f(r.limit_deg), r.limited_by if isinstance(r.limited_by, str) else "",
                 "femur" if r.ball_vertex else "pelvis", f(r.contact_radius_mm), f(r.exact_gap_before_mm, 2),
                 f(r.exact_gap_after_mm, 2), r.validated])
write_table(d, "table_extra", ["subject", "motion", "limit", "where", "hidden", "where", "vertex of", "radius mm",
                               "exact $-0.5^\\circ$", "exact $+0.5^\\circ$", "confirmed"], rows, align="llrlrllrrrl")
rows = []
for r in lay.itertuples():
    rows.append([r.subject, r.body, str(int(r.layers)), f"{r.layered_bytes / 2**20:.1f}", f"{r.single_bytes / 2**20:.1f}",
                 # "--" where the fillings were not timed (--quick: every subject but the first)
                 f"{f(r.layered_sampling_ms, 0)} ({f(r.layered_sampling_q25_ms, 0)}--{f(r.layered_sampling_q75_ms, 0)})"
                 if np.isfinite(r.layered_sampling_ms) else "--",
                 f(r.single_sampling_ms, 0), str(int(r.max_crossings)),
                 f"{100 * r.nodes_truncated / r.nodes:.2f}", str(int(r.nodes_not_alternating)), str(int(r.hidden_vertices))])
write_table(d, "table_layered", ["subject", "bone", "layers", "MiB", "single MiB", "ms (quartiles)", "single ms", "most crossings",
                                 "truncated \\%", "not alternating", "hidden vertices"], rows, align="llrrrrrrrrr")
hid = xa[(xa.counted == "hidden") & (xa.validated != "no_limit")]
far = hid[hid.limited_by == "extra_articular"]
far_ok = far[far.validated == "yes"]
xmotions = far_ok[far_ok.motion.str.contains("abduction|extension")]
by_layers = xa[xa.counted == "all"]
lim_all = by_layers[(by_layers.validated != "no_limit")]
first_lay = lay[lay.subject == lay.subject.iloc[0]]
slow = lay.groupby("subject").first()

# The ROM envelope: adaptive refinement beside the brute force.
rows = []
for r in env.itertuples():
    rows.append([r.subject, f"{int(r.poses):,}", f(100 * r.poses_scanned / r.poses), f(100 * r.poses_valid / r.poses),
                 f"{f(r.envelope_ms / 1000, 2)} ({f(r.envelope_q25_ms / 1000, 2)}--{f(r.envelope_q75_ms / 1000, 2)})",
                 f"{r.poses_per_core_second / 1000:.0f}k",
                 timing_text(r.brute_force_ms / 1000, r.brute_force_q25_ms / 1000, r.brute_force_q75_ms / 1000,
                             getattr(r, "brute_force_runs", r.timing_runs), lambda x: f(x, 1), sep="--"),
                 f(100 * r.poses_differ / r.poses, 2)])
write_table(d, "table_envelope", ["subject", "poses", "scanned \\%", "valid \\%", "time s (quartiles)", "poses/core-s",
                                  "every pose s", "differ \\%"], rows, align="lrrrrrrr")
# Kawasaki et al. 2007: 360 x 360 x 180 poses with adaptive refinement in 20 s on 64 PCs.
KAWASAKI_POSES_PER_PC_SECOND = 360 * 360 * 180 / (20 * 64)
e0 = env.iloc[0]

# Thesis Fig. 60-61: the generated hip without and with a cam (cam.csv): each limit, and the cam's height where
# the bones meet (on the cam: more than 0.5 mm, a quarter of its 2 mm).
cam_macros = {}
if os.path.exists(os.path.join(d, "cam.csv")):
    cam = read_csv(d, "cam.csv")
    without, with_cam = cam[cam.cam_mm == 0].set_index("motion"), cam[cam.cam_mm > 0].set_index("motion")
    rows, shrunk = [], 0
    for m in with_cam.index:
        a, b = without.limit_deg.get(m, np.nan), with_cam.limit_deg[m]
        shrunk += bool(b < a - 1 or (np.isfinite(b) and not np.isfinite(a)))
        out = with_cam.cam_height_at_contact_mm[m]
        rows.append([m.replace("_", " "), f(a), f(b), f(out, 2)])
    write_table(d, "table_cam", ["motion", "no cam (deg)", "2 mm cam (deg)", "cam's height at the contact (mm)"],
                rows, align="lrrr")
    femur = with_cam[np.isfinite(with_cam.cam_height_at_contact_mm)]
    cam_macros = {"ROMcamShrunk": str(shrunk), "ROMcamMotions": str(len(with_cam)), "ROMcamFemur": str(len(femur)),
                  "ROMcamOnCam": str(int((femur.cam_height_at_contact_mm > 0.5).sum()))}

ok = lim[lim.validated != "no_limit"]
t0 = tim.iloc[0]
first = subjects[0]
ir90 = lim[(lim.subject == first) & (lim.motion == "internal_rotation_90_flexion")].limit_deg.iloc[0]
write_macros(d, "macros", {
    "ROMresolution": f"{tim.resolution_deg.iloc[0]:g}",
    "ROMconfirmed": str(int((ok.validated == "yes").sum())),
    "ROMchecked": str(len(ok)),
    "ROMfirst": first,
    "ROMfirstSearchMs": f"{t0.search_ms:.0f}",
    "ROMfirstSearchMsQlow": f"{t0.search_q25_ms:.0f}",
    "ROMfirstSearchMsQhigh": f"{t0.search_q75_ms:.0f}",
    "ROMfirstSearchRuns": f"{int(t0.search_runs)}",
    "ROMfirstSamplingMs": f"{t0.sampling_ms:.0f}",
    "ROMfirstSamplingMsQlow": f"{t0.sampling_q25_ms:.0f}",
    "ROMfirstSamplingMsQhigh": f"{t0.sampling_q75_ms:.0f}",
    "ROMfirstSamplingRuns": f"{int(t0.sampling_runs)}",
    "ROMfirstEvaluations": f"{int(t0.evaluations)}",
    "ROMfirstPosesPerSecond": f"{t0.poses_per_second:.0f}",
    # The per-vertex test's search beside the exact one (timing.csv; "--" in a run without it).
    "ROMfirstSkipped": f"{100 * t0.share_skipped:.0f}" if np.isfinite(t0.get("share_skipped", np.nan)) else "--",
    "ROMfirstPerVertexMs": f"{t0.per_vertex_search_ms:.0f}" if "per_vertex_search_ms" in t0 else "--",
    "ROMfirstExactOverVertex": (f"{t0.exact_over_per_vertex:.1f} ({t0.exact_over_per_vertex_q25:.1f}--"
                                f"{t0.exact_over_per_vertex_q75:.1f})" if "exact_over_per_vertex" in t0 else "--"),
    "ROMexactOverVertexRange": exact_over_vertex_range(tim),
    "ROMfirstFclMs": f"{t0.fcl_collide_ms_per_pose:.2f}",
    "ROMfirstFclMsQlow": f"{t0.fcl_collide_q25_ms:.2f}",
    "ROMfirstFclMsQhigh": f"{t0.fcl_collide_q75_ms:.2f}",
    "ROMfirstFclRatio": f"{t0.fcl_over_ours:.0f}",
    "ROMfclRatioRange": f"{tim.fcl_over_ours.min():.0f}--{tim.fcl_over_ours.max():.0f}",
    "ROMthreads": str(int(t0.threads)),
    "ROMfirstIRninety": f(ir90),
    "ROMexcludedMax": str(int(tim.excluded_vertices.max())),
    "ROMsubjects": str(len(subjects)),
    "ROMlayers": str(int(lay.layers.iloc[0])),
    "ROMfclVerdict": "beyond" if t0.fcl_over_ours >= 50 else "short of",
    "ROMfclLowSubject": tim.subject.iloc[int(tim.fcl_over_ours.values.argmin())],
    "ROMfclLowEvaluations": str(int(tim.evaluations.iloc[int(tim.fcl_over_ours.values.argmin())])),
    "ROMenvStep": f"{e0.step_deg:g}",
    "ROMenvCoarse": str(int(e0.coarse_steps)),
    "ROMenvPoses": f"{int(e0.poses):,}".replace(",", "{,}"),
    "ROMenvFirstSeconds": f(e0.envelope_ms / 1000, 1),
    "ROMenvSecondsMax": f(env.envelope_ms.max() / 1000, 1),
    "ROMenvScannedRange": f"{100 * (env.poses_scanned / env.poses).min():.1f}--{100 * (env.poses_scanned / env.poses).max():.1f}",
    "ROMenvPerCoreMin": f"{env.poses_per_core_second.min() / 1000:.0f}k",
    "ROMenvKawasakiPerPc": f"{KAWASAKI_POSES_PER_PC_SECOND / 1000:.0f}k",
    # "at least": rounded down to a tenth.
    "ROMenvOverKawasakiMin": f"{np.floor(10 * env.poses_per_core_second.min() / KAWASAKI_POSES_PER_PC_SECOND) / 10:.1f}",
    "ROMenvDifferMax": f(100 * (env.poses_differ / env.poses).max(), 2),
    "ROMenvBruteMax": f(env.brute_force_ms.max() / 1000, 0),
    "ROMhiddenChecked": str(len(hid)),
    "ROMhiddenConfirmed": str(int((hid.validated == "yes").sum())),
    "ROMextraFound": str(len(far)),
    "ROMextraConfirmed": str(len(far_ok)),
    "ROMextraSubjects": str(far_ok.subject.nunique()),
    "ROMextraAbdExtConfirmed": str(len(xmotions)),
    "ROMextraAbdExtSubjects": str(xmotions.subject.nunique()),
    "ROMextraAbdExtList": ", ".join(f"\\texttt{{{r.subject}}} {r.motion.replace('_', ' ')} at {r.limit_deg:.1f}$^\\circ$"
                                    for r in xmotions.itertuples()) or "none",
    "ROMallLimitsExtra": str(int((lim_all.limited_by == "extra_articular").sum())),
    "ROMallLimitsChecked": str(len(lim_all)),
    "ROMallLimitsConfirmed": str(int((lim_all.validated == "yes").sum())),
    "ROMlayeredBytesRatio": f"{(lay.layered_bytes / lay.single_bytes).min():.1f}",
    # The layered map's spacing from its node count, (180/p + 1)(360/p) = nodes (the single-layer map's: ROMresolution).
    "ROMlayeredSpacing": f"{1 / ((-360 + (360 ** 2 + 4 * 64800 * float(lay.nodes.iloc[0])) ** 0.5) / (2 * 64800)):.2g}",
    "ROMlayeredSamplingMs": span(lay.layered_sampling_ms, ".0f"),
    "ROMlayeredSlowdown": span(slow.limits_ms_layered / slow.limits_ms_single, ".1f"),
    "ROMlayeredLimitsSingleMs": span(slow.limits_ms_single, ".1f"),
    "ROMlayeredLimitsLayeredMs": span(slow.limits_ms_layered, ".1f"),
    "ROMlayeredLimitsIqrMax": f"{100 * ((slow.limits_layered_q75_ms - slow.limits_layered_q25_ms) / slow.limits_ms_layered).max():.0f}",
    # The timed subjects' rounds (--quick times the first subject alone: the others' timing_runs 0, times empty).
    "ROMlayeredRuns": str(int(lay.timing_runs[lay.timing_runs > 0].min())),
    "ROMenvRuns": str(int(env.timing_runs.min())),
    "ROMlayeredNotAlternating": str(int(lay.nodes_not_alternating.sum())),
    "ROMlayeredTruncatedMax": f"{100 * (lay.nodes_truncated / lay.nodes).max():.1f}",
    **method_macros,
    **obs_macros,
    **lr_macros,
    **cam_macros,
})
