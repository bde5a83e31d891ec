"""18_labrum: how much the acetabular labrum lowers each ROM limit of every shared hip, beside the published median
lowering of simulated internal rotation (issue 81).

Reads RESULTS/18_labrum/{labrum,published}.csv; writes table_labrum.tex, ir90_lowering.pdf/png and macros.tex
(LBhips, LBirNinety<Hip>, LBirNinetyLow/High/Median over the hips reached, LBpublishedMedian/QOne/QThree, LBmedianAll:
the median lowering over every limited motion of every hip). With no hips (no shared data) it writes the macros
as "--" and no figure."""
import matplotlib.pyplot as plt
import numpy as np

from common import experiment_dir, read_csv, save, write_macros, write_table

d = experiment_dir("18_labrum")
lab = read_csv(d, "labrum.csv")
pub = read_csv(d, "published.csv").iloc[0]
hips = sorted(lab.subject.unique())


def f(x, n=1):
    return "--" if x is None or (isinstance(x, float) and np.isnan(x)) else f"{x:.{n}f}"


DIGITS = dict(zip("0123456789", ("Zero", "One", "Two", "Three", "Four", "Five", "Six", "Seven", "Eight", "Nine")))


def macro_name(hip):
    """A hip's name as LaTeX macro letters: mc22-left -> McTwoTwoLeft."""
    words = hip.replace("-", " ").replace("_", " ").split()
    return "".join("".join(DIGITS.get(ch, ch) for ch in w.capitalize()) for w in words)


macros = {"LBhips": str(len(hips)), "LBpublishedMedian": f"{pub.median_deg:g}", "LBpublishedQOne": f"{pub.q1_deg:g}",
          "LBpublishedQThree": f"{pub.q3_deg:g}", "LBpublishedHips": str(int(pub.hips))}
ir90 = lab[lab.motion == "internal_rotation_90_flexion"].set_index("subject")
for h in hips:
    macros["LBirNinety" + macro_name(h)] = f(float(ir90.lowering_deg.get(h, np.nan)))
reached = ir90.lowering_deg.dropna()
macros["LBirNinetyReached"] = str(len(reached))
macros["LBirNinetyLow"] = f(reached.min()) if len(reached) else "--"
macros["LBirNinetyHigh"] = f(reached.max()) if len(reached) else "--"
macros["LBirNinetyMedian"] = f(float(reached.median())) if len(reached) else "--"
both = lab[(lab.bony_status == "limited") & (lab.labral_status == "limited")]
macros["LBmedianAll"] = f(float(both.lowering_deg.median())) if len(both) else "--"
macros["LBlabralFirst"] = str(int((lab.labral_contact_class == "labral").sum()))
macros["LBlimits"] = str(len(lab))
write_macros(d, "macros", macros)

# The table: each motion's bony limit, labral limit and lowering per hip.
rows = []
for m in lab.motion.unique():
    cells = []
    for h in hips:
        r = lab[(lab.subject == h) & (lab.motion == m)].iloc[0]
        cells.append(f"{f(r.bony_limit_deg)} / {f(r.labral_limit_deg)}")
    rows.append([m.replace("_", " ")] + cells)
write_table(d, "table_labrum", ["motion (bony / labral, deg)"] + hips, rows, align="l" + "r" * len(hips))

if hips:
    fig, ax = plt.subplots(figsize=(6.0, 3.2))
    x = np.arange(len(hips))
    vals = [float(ir90.lowering_deg.get(h, np.nan)) for h in hips]
    ax.axhspan(pub.q1_deg, pub.q3_deg, color="0.85", label=f"published IQR ({int(pub.hips)} CT arthrograms)")
    ax.axhline(pub.median_deg, color="0.3", ls="--", label=f"published median {pub.median_deg:g} deg")
    ax.bar(x, [0 if np.isnan(v) else v for v in vals], color="tab:blue", width=0.6, label="this labrum, IR90")
    for xi, v in zip(x, vals):
        if np.isnan(v):
            ax.text(xi, 1, "not\nreached", ha="center", va="bottom", fontsize=8)
    ax.set_xticks(x, hips)
    ax.set_ylabel("lowering of IR at 90 deg flexion (deg)")
    ax.legend(fontsize=8, loc="upper right")
    save(fig, d, "ir90_lowering")
