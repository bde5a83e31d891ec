"""16_resection_planning: how much bone `impinge plan` removes against cams of known size, where, what it restores,
and how long it takes (issue 50).

Reads RESULTS/16_resection_planning/{generated,added_cam,ir90,plan_times,published}.csv; writes table_plans.tex,
volume_vs_cam.pdf/png, limits_restored.pdf/png, macros.tex. Without shared hips (no data) the added-cam and ir90
parts are empty and their macros "--"."""
import matplotlib.pyplot as plt
import numpy as np

from common import experiment_dir, read_csv, save, write_macros, write_table

d = experiment_dir("16_resection_planning")
gen = read_csv(d, "generated.csv")
cam = read_csv(d, "added_cam.csv")
ir = read_csv(d, "ir90.csv")
pub = read_csv(d, "published.csv")
times = read_csv(d, "plan_times.csv")


def f(x, n=1):
    return "--" if x is None or (isinstance(x, float) and np.isnan(x)) else f"{x:.{n}f}"


def per_plan(frame, key):
    """One row per plan (a plan's bone figures repeat on each of its targets' rows)."""
    return frame.drop_duplicates(subset=key)


macros = {}
# Generated cams: the cams that limit a motion, and their plans.
planned = gen[gen.volume_mm3 > 0]
plans = per_plan(planned, ["cam_mm"])
macros["RPgenCams"] = ", ".join(f"{c:g}" for c in sorted(gen.cam_mm.unique()))
macros["RPgenLimitingCams"] = ", ".join(f"{c:g}" for c in plans.cam_mm) if len(plans) else "none"
macros["RPgenNonLimitingCams"] = ", ".join(f"{c:g}" for c in sorted(set(gen.cam_mm) - set(plans.cam_mm))) or "none"
ratio = plans.volume_mm3 / plans.cam_volume_mm3
macros["RPgenRatioLow"], macros["RPgenRatioHigh"] = f(ratio.min(), 2), f(ratio.max(), 2)
macros["RPgenShareLow"], macros["RPgenShareHigh"] = f(100 * plans.on_cam_share.min(), 0), f(100 * plans.on_cam_share.max(), 0)
macros["RPgenTargets"], macros["RPgenMet"] = str(len(planned)), str(int(planned.met.sum()))
over = planned.limit_after_deg - planned.limit_free_deg
macros["RPgenOverLow"], macros["RPgenOverHigh"] = f(over.min()), f(over.max())


def timed(kind, scale=1.0, n=0):
    """(median, lower quartile, upper quartile, repetitions, plan) of a timed plan (plan_times.csv), "--" when absent."""
    t = times[times.kind == kind].plan_ms / scale
    if not len(t):
        return "--", "--", "--", "0", "--"
    return (f(t.median(), n), f(t.quantile(0.25), n), f(t.quantile(0.75), n), str(len(t)),
            times[times.kind == kind].plan.iloc[0])


(macros["RPgenMs"], macros["RPgenMsQlow"], macros["RPgenMsQhigh"], macros["RPtimingReps"],
 macros["RPgenTimedPlan"]) = timed("generated")

# Real femurs with an added cam.
cam_plans = cam[cam.motion != "none"]
hips_cam = sorted(cam.subject.unique())
macros["RPcamHips"] = str(len(hips_cam))
macros["RPcamHeight"] = f(float(cam.cam_mm.iloc[0]), 0) if len(cam) else "--"
macros["RPcamNoEffect"] = str(int((cam.motion == "none").sum()))
if len(cam_plans):
    p = per_plan(cam_plans, ["subject"])
    # The plans that cut (a plan that removes nothing has no volume ratio or share on the cam to give).
    cut = p[p.volume_mm3 > 0]
    r = cut.volume_mm3 / cut.cam_volume_mm3
    macros["RPcamTargets"], macros["RPcamMet"] = str(len(cam_plans)), str(int(cam_plans.met.sum()))
    macros["RPcamRatioLow"], macros["RPcamRatioHigh"] = (f(r.min(), 2), f(r.max(), 2)) if len(cut) else ("--", "--")
    macros["RPcamShareLow"], macros["RPcamShareHigh"] = ((f(100 * cut.on_cam_share.min(), 0),
                                                         f(100 * cut.on_cam_share.max(), 0)) if len(cut) else ("--", "--"))
    uncut = sorted(p[p.volume_mm3 <= 0].subject)
    macros["RPcamUncutText"] = (f" where it cut ({', '.join(uncut)}: nothing removed, the target not met)" if uncut
                                else "")
    less, more = int((r < 1).sum()), int((r >= 1).sum())
    hips = "hip" if len(cut) == 1 else "hips"
    if not len(cut):
        macros["RPcamLessText"] = ""
    elif more == 0:
        macros["RPcamLessText"] = (
            "The plan removes less than the cam because only the part of the cam that meets the rim along the "
            "target motions has to go; a surgeon who removes the whole bump removes more than a motion needs.")
    elif less == 0:
        macros["RPcamLessText"] = (f"The plan removes more than the cam on the {len(cut)} {hips} it cuts: bone "
                                   "beyond the cam meets the rim too.")
    else:
        macros["RPcamLessText"] = (
            f"The plan removes less than the cam on {less} of {len(cut)} {hips}, where only the part of the cam that "
            f"meets the rim along the target motions has to go, and more on {more}, where bone beyond the cam meets "
            "the rim too.")
    macros["RPcamCheckedSame"] = str(int((np.abs(cam_plans.limit_after_deg - cam_plans.limit_checked_deg) < 1e-9).sum()))
    restored = cam_plans[cam_plans.met == 1]
    macros["RPcamRestoredHips"] = str(restored.subject.nunique())
    macros["RPcamVolumeLow"], macros["RPcamVolumeHigh"] = f(p.cam_volume_mm3.min(), 0), f(p.cam_volume_mm3.max(), 0)
else:
    for k in ("RPcamTargets", "RPcamMet", "RPcamRatioLow", "RPcamRatioHigh", "RPcamShareLow", "RPcamShareHigh",
              "RPcamCheckedSame", "RPcamRestoredHips", "RPcamVolumeLow", "RPcamVolumeHigh"):
        macros[k] = "--"
    macros["RPcamUncutText"] = macros["RPcamLessText"] = ""

# Internal rotation at 90 deg flexion + 10 deg.
macros["RPirHips"] = str(ir.subject.nunique())
for resect in ("femur", "both"):
    rows = ir[ir.resect == resect]
    key = "Femur" if resect == "femur" else "Both"
    macros[f"RPir{key}Met"] = str(int(rows.met.sum())) if len(rows) else "--"
    vol = rows.femur_volume_mm3 + rows.pelvis_volume_mm3
    macros[f"RPir{key}VolumeLow"] = f(vol.min(), 0) if len(rows) else "--"
    macros[f"RPir{key}VolumeHigh"] = f(vol.max(), 0) if len(rows) else "--"
# Why a plan fell short of its target (plans that met it may still carry a note about a contact they cleared).
short = ir[ir.met == 0]
head_blocked = int(short.note.fillna("").str.contains("articular surface").sum())
depth_blocked = int(short.note.fillna("").str.contains("safety depth").sum())
# The sentence on the plans that fall short, empty when every plan meets its target.
macros["RPirShortText"] = (
    f" Where it does not, the plan says why: of the {len(short)} {'plan that falls' if len(short) == 1 else 'plans that fall'} "
    f"short, the contact reaches the head inside the labrum line in {head_blocked}, and the depth needed passes the "
    f"safety depth or the bone's thickness in {depth_blocked}." if len(short) else "")
macros["RPirMsHigh"] = f(ir.plan_ms.max(), 0) if len(ir) else "--"
macros["RPlhdlMs"], macros["RPlhdlMsQlow"], macros["RPlhdlMsQhigh"], _, timed_plan = timed("shared", 1000, 2)
# The timed shared hip's ir90 plan with both bones trimmed, in s (one run; the README quotes it).
both = ir[(ir.resect == "both") & (ir.subject == timed_plan.split(" ")[0])]
macros["RPlhdlBothS"] = f(both.plan_ms.iloc[0] / 1000, 1) if len(both) else "--"
vol = pub[pub.quantity == "arthroscopic_resection_volume_mm3"].iloc[0]
macros["RPpubVolumeLow"], macros["RPpubVolumeHigh"] = f(vol.low, 0), f(vol.high, 0)
# How many of the ir90 plans' volumes lie in the published range (issue 82: the prose said all, where one removes more).
ir_vol = ir.femur_volume_mm3 + ir.pelvis_volume_mm3
macros["RPirPlans"] = str(len(ir))
macros["RPirInRange"] = str(int(((ir_vol >= vol.low) & (ir_vol <= vol.high)).sum()))
macros["RPirVolumeMax"] = f(ir_vol.max(), 0) if len(ir) else "--"
write_macros(d, "macros", macros)

# The table: every plan on a real hip.
rows = []
for r in cam_plans.itertuples():
    rows.append([r.subject, "added cam", r.motion.replace("_", " "), f(r.limit_free_deg), f(r.limit_cam_deg),
                 f(r.limit_after_deg), "yes" if r.met else "no", f(r.volume_mm3, 0), f(r.deepest_cut_mm),
                 f(100 * r.on_cam_share, 0)])
for r in ir.itertuples():
    rows.append([r.subject, f"IR90 +10, {r.resect}", "IR at 90 flexion", f(r.limit_before_deg), f(r.target_deg),
                 f(r.limit_after_deg), "yes" if r.met else "no", f(r.femur_volume_mm3 + r.pelvis_volume_mm3, 0),
                 f(max(r.femur_deepest_cut_mm, r.pelvis_deepest_cut_mm)), ""])
write_table(d, "table_plans", ["hip", "plan", "motion", "limit before", "target", "after", "met", "volume (mm$^3$)",
                               "deepest cut (mm)", "on cam (\\%)"], rows, align="lllrrrlrrr")

# Planned volume against the cam's.
fig, ax = plt.subplots(figsize=(3.6, 3.4))
if len(plans):
    ax.plot(plans.cam_volume_mm3, plans.volume_mm3, "o", label="generated cams")
if len(cam_plans):
    p = per_plan(cam_plans, ["subject"])
    ax.plot(p.cam_volume_mm3, p.volume_mm3, "s", label="real femurs, added cam")
top = max([1.0] + list(gen.cam_volume_mm3) + list(cam.cam_volume_mm3.dropna()))
x = np.array([0, top * 1.1])
ax.plot(x, x, "k-", lw=1, label="the cam's volume")
ax.plot(x, 1.2 * x, "k--", lw=1, label="1.2 x the cam's volume")
ax.set_xlabel("cam volume (mm$^3$)")
ax.set_ylabel("planned resection (mm$^3$)")
ax.legend(loc="upper left", handlelength=1.5)
ax.grid(alpha=0.3)
save(fig, d, "volume_vs_cam")

# Limits: without the cam, with it, after the plan.
cases = [(f"gen {r.cam_mm:g} mm, {r.motion.replace('_', ' ')}", r.limit_free_deg, r.limit_cam_deg, r.limit_after_deg)
         for r in planned.itertuples()]
cases += [(f"{r.subject}, {r.motion.replace('_', ' ')}", r.limit_free_deg, r.limit_cam_deg, r.limit_after_deg)
          for r in cam_plans.itertuples()]
fig, ax = plt.subplots(figsize=(6.5, 1.2 + 0.32 * max(1, len(cases))))
if cases:
    y = np.arange(len(cases))
    ax.barh(y - 0.27, [c[1] for c in cases], 0.27, label="without the cam", color="0.7")
    ax.barh(y, [c[2] for c in cases], 0.27, label="with the cam", color="tab:red")
    ax.barh(y + 0.27, [c[3] for c in cases], 0.27, label="after the plan", color="tab:blue")
    ax.set_yticks(y)
    ax.set_yticklabels([c[0] for c in cases])
    ax.invert_yaxis()
ax.set_xlabel("ROM limit (deg)")
fig.legend(*ax.get_legend_handles_labels(), loc="upper center", ncol=3, frameon=False)
ax.grid(alpha=0.3, axis="x")
save(fig, d, "limits_restored", rect=(0, 0, 1, 1 - 0.45 / fig.get_size_inches()[1]))
