"""15_morphology: each shared hip's morphology beside the published normal ranges, and its ROM limits beside the
morphology (issue 49).

Reads RESULTS/15_morphology/{morphology,limits,published}.csv; writes table_morphology.tex, alpha_by_hour.pdf/png,
ir90_vs_morphology.pdf/png, macros.tex. With no hips (no shared data) it writes the macros as "--" and no figures."""
import matplotlib.pyplot as plt
import numpy as np

from common import experiment_dir, read_csv, save, write_macros, write_table

d = experiment_dir("15_morphology")
mo_all = read_csv(d, "morphology.csv")
lim = read_csv(d, "limits.csv")
pub = read_csv(d, "published.csv")
generated = mo_all[mo_all.subject.str.startswith("generated")]
mo = mo_all[~mo_all.subject.str.startswith("generated")]
hips = list(mo.subject)


def f(x, n=1):
    return "--" if x is None or (isinstance(x, float) and np.isnan(x)) else f"{x:.{n}f}"


def normal_text(p):
    lo, hi = p.low, p.high
    if np.isnan(lo):
        return f"$\\le {hi:g}$"
    if np.isnan(hi):
        return f"$\\ge {lo:g}$"
    return f"{lo:g}--{hi:g}"


def outside(p, v):
    return (not np.isnan(p.low) and v < p.low) or (not np.isnan(p.high) and v > p.high)


# The table: every published quantity for every hip, marked (*) where it lies outside the normal range.
rows = []
names = {"alpha_max_deg": "alpha angle, largest (deg)", "head_neck_offset_ratio": "head-neck offset ratio",
         "neck_shaft_angle_deg": "neck-shaft angle (deg)",
         "version_posterior_condylar_deg": "femoral version, post. condylar (deg)",
         "radiographic_inclination_deg": "acetabular inclination (deg)",
         "radiographic_anteversion_deg": "acetabular anteversion (deg)",
         "lateral_centre_edge_deg": "lateral centre-edge angle (deg)",
         "anterior_centre_edge_deg": "anterior centre-edge angle (deg)"}
for p in pub.itertuples():
    digits = 2 if "ratio" in p.quantity else 1
    cells = []
    for h in hips:
        v = float(mo[mo.subject == h][p.quantity].iloc[0])
        cells.append(f(v, digits) + ("*" if outside(p, v) else ""))
    rows.append([names.get(p.quantity, p.quantity)] + cells + [normal_text(p), p.source.split(",")[0]])
for key, label, digits in (("head_radius_mm", "head radius (mm)", 1), ("sphericity_max_mm", "head asphericity, max (mm)", 1),
                           ("acetabular_radius_mm", "acetabular radius (mm)", 1), ("head_coverage", "head coverage (share)", 2)):
    rows.append([label] + [f(float(mo[mo.subject == h][key].iloc[0]), digits) for h in hips] + ["", ""])
write_table(d, "table_morphology", ["measure"] + hips + ["normal", "source"], rows, align="l" + "r" * len(hips) + "ll")

macros = {}
def count_outside(quantity, side):
    p = next(q for q in pub.itertuples() if q.quantity == quantity)
    bound = p.high if side == "high" else p.low
    vals = mo[quantity].astype(float)
    return int((vals > bound).sum() if side == "high" else (vals < bound).sum())


macros["MOhips"] = str(len(hips))
if hips:
    macros["MOcamHips"] = str(count_outside("alpha_max_deg", "high"))
    macros["MOlowOffsetHips"] = str(count_outside("head_neck_offset_ratio", "low"))
    macros["MOpincerHips"] = str(count_outside("lateral_centre_edge_deg", "high"))
    macros["MOdysplasticHips"] = str(count_outside("lateral_centre_edge_deg", "low"))
    macros["MOalphaMaxLow"], macros["MOalphaMaxHigh"] = f(mo.alpha_max_deg.min()), f(mo.alpha_max_deg.max())
    macros["MOlceLow"], macros["MOlceHigh"] = f(mo.lateral_centre_edge_deg.min()), f(mo.lateral_centre_edge_deg.max())
    macros["MOasphericityHigh"] = f(mo.sphericity_max_mm.max())
    if {"mc22", "mc22-left"} <= set(hips):
        r, l = mo[mo.subject == "mc22"].iloc[0], mo[mo.subject == "mc22-left"].iloc[0]
        macros["MOversionLR"] = f(l.version_posterior_condylar_deg - r.version_posterior_condylar_deg)
        macros["MOversionTeLR"] = f(l.version_transepicondylar_deg - r.version_transepicondylar_deg)
        macros["MOlceLR"] = f(l.lateral_centre_edge_deg - r.lateral_centre_edge_deg)
        macros["MOacetVersionLR"] = f(l.radiographic_anteversion_deg - r.radiographic_anteversion_deg)
    app = lim[(lim.pelvic_frame == "app") & (lim.motion == "internal_rotation_90_flexion")]
    reached = app[app.status == "limited"]
    macros["MOirNinetyReached"] = str(len(reached))
    macros["MOirNinetyLow"] = f(reached.limit_deg.min()) if len(reached) else "--"
    macros["MOirNinetyHigh"] = f(reached.limit_deg.max()) if len(reached) else "--"
    macros["MOsoftTissueFirst"] = str(int(lim[lim.pelvic_frame == "app"].soft_tissue_first.sum()))
    macros["MOlimitsApp"] = str(int((lim.pelvic_frame == "app").sum()))
    macros["MOnotReachable"] = str(int((lim.status == "not_reachable").sum()))
else:
    for k in ("MOcamHips", "MOlowOffsetHips", "MOpincerHips", "MOdysplasticHips", "MOalphaMaxLow", "MOalphaMaxHigh",
              "MOlceLow", "MOlceHigh", "MOasphericityHigh", "MOirNinetyReached", "MOirNinetyLow", "MOirNinetyHigh",
              "MOsoftTissueFirst", "MOlimitsApp", "MOnotReachable"):
        macros[k] = "--"
for k in ("MOversionLR", "MOversionTeLR", "MOlceLR", "MOacetVersionLR"):
    macros.setdefault(k, "--")
# The generated cams: the alpha angle and the internal rotation the cam leaves (ROM map at 0 and 20 deg flexion).
def gen_ir(subject, flexion):
    r = lim[(lim.subject == subject) & (lim.motion == f"internal_rotation_map_{flexion}_flexion")]
    return float(r.limit_deg.iloc[0]) if len(r) else float("nan")


cams = sorted(generated.subject, key=lambda x: float(x.replace("generated-cam", "")))
if cams:
    lo, hi = cams[0], cams[-1]
    macros["MOgenCamLow"], macros["MOgenCamHigh"] = lo.replace("generated-cam", ""), hi.replace("generated-cam", "")
    macros["MOgenAlphaLow"] = f(float(generated[generated.subject == lo].alpha_max_deg.iloc[0]))
    macros["MOgenAlphaHigh"] = f(float(generated[generated.subject == hi].alpha_max_deg.iloc[0]))
    macros["MOgenIrZeroLow"], macros["MOgenIrZeroHigh"] = f(gen_ir(lo, 0)), f(gen_ir(hi, 0))
    macros["MOgenIrTwentyLow"], macros["MOgenIrTwentyHigh"] = f(gen_ir(lo, 20)), f(gen_ir(hi, 20))
    # A limit the ROM map leaves NaN (in contact already without rotation, or free to 150 deg: the map does not say
    # which) is said so, not printed as a number.
    for key, flex in (("MOgenIrZeroText", 0), ("MOgenIrTwentyText", 20)):
        v0, v = gen_ir(lo, flex), gen_ir(hi, flex)
        if np.isfinite(v) and np.isfinite(v0):
            verb = "falls" if v < v0 else "rises" if v > v0 else "stays"
            macros[key] = f"{verb} from {f(v0)}$^\\circ$ to {f(v)}$^\\circ$ at {flex}$^\\circ$ flexion"
        else:
            macros[key] = (f"at {flex}$^\\circ$ flexion, from {f(v0)}$^\\circ$, has no value on the ROM map (its NaN: "
                           "in contact already without rotation, or free to 150$^\\circ$; the map does not say which)")
    # The cams that lower the rotation by less than 2 deg at both flexions, and by how much at most.
    drops = {c: max(gen_ir(lo, fl) - gen_ir(c, fl) for fl in (0, 20)) for c in cams[1:]}
    small = [c for c, dv in drops.items() if np.isfinite(dv) and dv < 2]
    macros["MOgenSmallCamsText"] = (
        f"Cams of {' and '.join(c.replace('generated-cam', '') for c in small)}~mm lower it by at most "
        f"{f(max(drops[c] for c in small))}$^\\circ$, until the bump reaches the rim's path." if small else
        "Every cam lowers it by 2$^\\circ$ or more.")
else:
    for k in ("MOgenCamLow", "MOgenCamHigh", "MOgenAlphaLow", "MOgenAlphaHigh", "MOgenIrZeroLow", "MOgenIrZeroHigh",
              "MOgenIrTwentyLow", "MOgenIrTwentyHigh", "MOgenIrZeroText", "MOgenIrTwentyText",
              "MOgenSmallCamsText"):
        macros[k] = "--"
write_macros(d, "macros", macros)

if hips:
    # The alpha angle around the head-neck junction, every hip.
    fig, ax = plt.subplots(figsize=(6, 4.2))
    hours = np.arange(1, 13)
    for i, h in enumerate(hips):
        r = mo[mo.subject == h].iloc[0]
        ax.plot(hours, [r[f"alpha_{k}h_deg"] for k in hours], "o-", color=f"C{i}", label=h, ms=4)
    cam = next(q for q in pub.itertuples() if q.quantity == "alpha_max_deg").high
    ax.axhline(cam, color="black", lw=1, ls="--", label=f"cam above {cam:g} deg (Noetzli 2002)")
    ax.set_xticks(hours)
    ax.set_xlabel("head-neck clock hour (12 superior, 3 anterior)")
    ax.set_ylabel("alpha angle (deg)")
    fig.legend(*ax.get_legend_handles_labels(), loc="lower center", ncol=2, frameon=False)
    ax.grid(alpha=0.3)
    save(fig, d, "alpha_by_hour", rect=(0, 0.2, 1, 1))

    # Internal rotation at 90 deg flexion (anterior pelvic plane) against the alpha angle and the femoral version;
    # and the generated cams' internal rotation (ROM map) against their alpha angle.
    fig, axes = plt.subplots(1, 3, figsize=(8, 3.6))
    for ax, key, label in ((axes[0], "alpha_max_deg", "largest alpha angle (deg)"),
                           (axes[1], "version_posterior_condylar_deg", "femoral version (deg)")):
        for i, h in enumerate(hips):
            row = lim[(lim.subject == h) & (lim.pelvic_frame == "app") & (lim.motion == "internal_rotation_90_flexion")]
            x = float(mo[mo.subject == h][key].iloc[0])
            if row.status.iloc[0] == "limited":
                ax.plot(x, row.limit_deg.iloc[0], "o", color=f"C{i}", label=h)
            else:
                ax.plot(x, 0, "x", color=f"C{i}", label=f"{h} (start not reached)")
        ax.set_xlabel(label)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("IR at 90 deg flexion, APP (deg)")
    handles, labels = axes[1].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower left", bbox_to_anchor=(0.0, 0.0), ncol=2, frameon=False)
    ax = axes[2]
    for flexion, marker in ((0, "o-"), (20, "s-")):
        xs = [float(generated[generated.subject == c].alpha_max_deg.iloc[0]) for c in cams]
        ys = [gen_ir(c, flexion) for c in cams]
        ax.plot(xs, ys, marker, color=f"C{4 + flexion // 20}", label=f"generated cams, {flexion} deg flexion")
    ax.set_xlabel("largest alpha angle (deg)")
    ax.set_ylabel("internal rotation (deg, ROM map)")
    fig.legend(*ax.get_legend_handles_labels(), loc="lower right", bbox_to_anchor=(1.0, 0.0), frameon=False)
    ax.grid(alpha=0.3)
    save(fig, d, "ir90_vs_morphology", rect=(0, 0.2, 1, 1))
