"""14_studies: studies on Dask (issue 27): the local cluster against the serial run, scaling from one worker to
two, the per-task overhead, and the estimated wall time of a large study from the measured task times.

Reads RESULTS/14_studies/{equality,scaling,task_times,cohort_summary}.csv and meta.json; writes
table_scaling.tex, table_cohort.tex, studies_times.pdf, macros.tex."""
import json
import os

import matplotlib.pyplot as plt
import numpy as np

from common import experiment_dir, median_quartiles, read_csv, save, write_macros, write_table

d = experiment_dir("14_studies")
eq = read_csv(d, "equality.csv").iloc[0]
runs = read_csv(d, "scaling.csv")  # one row per round and run (workers 0: the control)
if "round" not in runs:
    runs["round"] = 0
# Per run, the median over the alternated rounds (and the quartiles of the wall time); ratios paired by round.
sc = runs.groupby("workers").median(numeric_only=True)
wall_q = runs.groupby("workers").wall_s.quantile([0.25, 0.75]).unstack()
by_round = runs.pivot_table(index="round", columns="workers", values="wall_s")
n_rounds = len(by_round)


def paired(num, den):
    """Median and quartiles of num's wall time over den's, round by round."""
    return median_quartiles(by_round[num] / by_round[den])


times = read_csv(d, "task_times.csv")
summary = read_csv(d, "cohort_summary.csv")
with open(os.path.join(d, "meta.json")) as f:
    meta = json.load(f)

one, two, control = sc.loc[1], sc.loc[2], sc.loc[0]  # workers 0: two shards in two processes, no Dask
ratio, ratio_lo, ratio_hi = paired(2, 1)
control_ratio, control_lo, control_hi = paired(0, 1)
efficiency = 1 / (2 * ratio)  # 1: two workers twice as fast
names = {1: "1 Dask worker", 2: "2 Dask workers", 0: "2 processes, no Dask"}
write_table(d, "table_scaling", ["run", "ROM tasks", "wall s (quartiles)", "tasks' own s", "mean task s", "overhead",
                                 "wall / 1 worker (quartiles)"],
            [[names[int(w)], str(int(r.tasks)), f"{r.wall_s:.1f} ({wall_q.loc[w, 0.25]:.1f}--{wall_q.loc[w, 0.75]:.1f})",
              f"{r.task_s:.1f}", f"{r.mean_task_s:.2f}", f"{100 * r.overhead:.1f}%",
              "1" if int(w) == 1 else "%.3f (%.3f--%.3f)" % paired(int(w), 1)] for w, r in sc.iterrows()])

# The cohort: per subject, the nominal value and the spread over the COR perturbations.
figures = [("rom", "limit_flexion_deg", "flexion limit (deg)"),
           ("rom", "limit_internal_rotation_90_flexion_deg", "IR at 90 flexion (deg)"),
           ("rom", "limit_fadir_deg", "FADIR limit (deg)"),
           ("motion", "min_distance_mm", "squat least distance (mm)")]
rows = []
for s in sorted(summary.subject.unique()):
    row = [s]
    for kind, fig, _ in figures:
        g = summary[(summary.subject == s) & (summary.kind == kind) & (summary.figure == fig)]
        if g.empty or not np.isfinite(g.iloc[0]["nominal"]):
            row.append("--")
            continue
        r = g.iloc[0]
        row.append(f"{r.nominal:.1f} ({r.p05:.1f} to {r.p95:.1f})")
    rows.append(row)
write_table(d, "table_cohort", ["subject"] + [label for _, _, label in figures], rows)
# The spread of the ROM limits over the perturbed centres (95th less 5th percentile): what the text says of it.
rom_rows = summary[(summary.kind == "rom") & summary.figure.isin([fig for kind, fig, _ in figures if kind == "rom"])]
# A percentile spread needs enough centres (the quick run draws one perturbation: 2 values a limit): none under 5.
SPREAD_MIN_CENTRES = 5
rom_rows = rom_rows[rom_rows.n - rom_rows.n_nan >= SPREAD_MIN_CENTRES]
spread = (rom_rows.p95 - rom_rows.p05).dropna()

fig, (a, b) = plt.subplots(1, 2, figsize=(8, 3.2))
kinds = ["rom", "motion", "distance"]
serial = times[times.run == "cohort-serial"]
a.boxplot([serial[serial.kind == k].time_s for k in kinds], widths=0.6)
a.set_xticks(range(1, len(kinds) + 1), kinds)
a.set_yscale("log")
a.set_ylabel("task time (s, one thread)")
a.set_title("cohort study, serial: task times per kind", fontsize=9)
b.bar(["1 worker", "2 workers"], [one.wall_s, two.wall_s], color=["0.6", "0.3"],
      yerr=[[one.wall_s - wall_q.loc[1, 0.25], two.wall_s - wall_q.loc[2, 0.25]],
            [wall_q.loc[1, 0.75] - one.wall_s, wall_q.loc[2, 0.75] - two.wall_s]], capsize=4)
b.bar(["1 worker", "2 workers"], [one.task_s, two.task_s / 2], fill=False, edgecolor="r", lw=1.2,
      label="tasks' own time / workers")
b.set_ylabel("wall time (s)")
b.set_title(f"{int(one.tasks)} ROM tasks, median of {n_rounds} rounds", fontsize=9)
b.legend(fontsize=7)
save(fig, d, "studies_times")

# The wall time of a 1,000-subject x 100-perturbation x 4-method ROM study, from the measured mean ROM task
# (its Joint's build included: each perturbation is a new COR, so new maps), on this machine's 2 cores at the
# measured two-worker efficiency, and on 64 nodes of 32 cores at the same efficiency.
tasks_large = 1000 * 100 * 4
mean_task = one.mean_task_s
one_machine_days = tasks_large * mean_task / (2 * efficiency) / 86400
cluster_cores = 64 * 32
cluster_hours = tasks_large * mean_task / (cluster_cores * efficiency) / 3600

write_macros(d, "macros", {
    "STUDYcohortTasks": str(int(eq.tasks_local)),
    "STUDYspreadMedian": f"{spread.median():.1f}" if len(spread) else "--",
    "STUDYspreadMax": f"{spread.max():.1f}" if len(spread) else "--",
    "STUDYspreadMaxWhere": (f"{rom_rows.loc[spread.idxmax(), 'subject']}, "
                            f"{dict((fig, label) for _, fig, label in figures)[rom_rows.loc[spread.idxmax(), 'figure']].replace(' (deg)', '')}"
                            if len(spread) else f"fewer than {SPREAD_MIN_CENTRES} centres a limit in this run"),
    "STUDYcohortSubjects": str(len(meta["parameters"]["subjects"])),
    "STUDYcohortPerturbations": str(meta["parameters"]["cohort_perturbations"]),
    "STUDYserialPerturbations": str(meta["parameters"].get("cohort_serial_perturbations",
                                                            meta["parameters"]["cohort_perturbations"])),
    "STUDYserialTasks": str(int(eq.tasks_serial)),
    "STUDYcells": f"{int(eq.cells_compared):,}".replace(",", "{,}"),
    "STUDYcellsDiffering": str(int(eq.cells_differing)),
    "STUDYequalVerdict": "equal" if bool(eq.equal) else "not equal",
    "STUDYlocalWorkers": str(int(eq.workers_local)),
    "STUDYromTasks": str(int(one.tasks)),
    "STUDYwallOne": f"{one.wall_s:.0f}",
    "STUDYwallTwo": f"{two.wall_s:.0f}",
    "STUDYratio": f"{ratio:.3f}",
    "STUDYratioQlow": f"{ratio_lo:.3f}", "STUDYratioQhigh": f"{ratio_hi:.3f}",
    "STUDYrounds": str(n_rounds),
    "STUDYratioVerdict": "meets" if ratio <= 0.56 else "misses",
    "STUDYratioControl": f"{control_ratio:.3f}",
    "STUDYratioControlQlow": f"{control_lo:.3f}", "STUDYratioControlQhigh": f"{control_hi:.3f}",
    "STUDYcontrolSlowdown": f"{100 * (control.mean_task_s / one.mean_task_s - 1):.0f}",
    "STUDYefficiency": f"{100 * efficiency:.0f}",
    "STUDYoverheadOne": f"{100 * one.overhead:.1f}",
    "STUDYoverheadTwo": f"{100 * two.overhead:.1f}",
    "STUDYtaskSlowdown": f"{100 * (two.mean_task_s / one.mean_task_s - 1):.0f}",
    "STUDYmeanRomTask": f"{mean_task:.2f}",
    "STUDYlargeTasks": f"{tasks_large:,}".replace(",", "{,}"),
    "STUDYestOneMachineDays": f"{one_machine_days:.1f}",
    "STUDYclusterCores": f"{cluster_cores:,}".replace(",", "{,}"),
    "STUDYestClusterHours": f"{cluster_hours:.2f}",
    "STUDYestClusterMinutes": f"{60 * cluster_hours:.0f}",
    "STUDYdistributedVersion": meta["versions"]["distributed"],
})
