"""Shared helpers of the analysis scripts: read a results folder, save figures, write LaTeX tables.

Every script reads only the CSVs its driver wrote; no number is typed in here."""
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402


def experiment_dir(name):
    """RESULTS/name from argv[1] (default results/)."""
    root = sys.argv[1] if len(sys.argv) > 1 else "results"
    d = os.path.join(root, name)
    if not os.path.isdir(d):
        sys.exit(f"{d}: no such results folder; run the driver first")
    return d


def read_csv(d, file):
    path = os.path.join(d, file)
    if not os.path.exists(path):
        sys.exit(f"{path}: missing; run the driver first")
    return pd.read_csv(path)


# The paper's printed text width (paper/impinge.tex: A4, 2.2 cm margins) and the smallest text a figure may print
# (issue 51). tools/check-report checks the same two numbers against figures.json.
TEXT_WIDTH_IN = (210 - 2 * 22) / 25.4
MIN_FIGURE_FONT_PT = 8
PAPER_SECTIONS = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "paper", "sections")


def printed_width_in(folder, stem, sections=None):
    """The width (inches) at which the paper prints RESULTS/folder/stem: the fraction of the text width given by
    its \\includegraphics[width=F\\textwidth]{folder/stem} in paper/sections/*.tex, times TEXT_WIDTH_IN; None
    when the paper does not include the figure (the smallest of several widths when it is included more than
    once)."""
    import glob
    import re
    sections = sections or PAPER_SECTIONS
    widths = []
    pattern = re.compile(r"\\includegraphics\[width=([\d.]*)\\textwidth\]\{" + re.escape(folder + "/" + stem) +
                         r"(\.pdf|\.png)?\}")
    for tex in sorted(glob.glob(os.path.join(sections, "*.tex"))):
        with open(tex) as f:
            for m in pattern.finditer(f.read()):
                widths.append(float(m.group(1) or 1) * TEXT_WIDTH_IN)
    return min(widths) if widths else None


def _visible_texts(fig):
    import matplotlib.text
    return [t for t in fig.findobj(matplotlib.text.Text) if t.get_visible() and t.get_text().strip()]


def save(fig, d, stem, rect=None):
    """Save as PDF (for the paper) and PNG (for viewing). rect: the part of the figure (left, bottom, right,
    top, 0-1) the axes fill, leaving the rest to a figure legend.

    Text at its printed size (issue 51): when the paper includes the figure (printed_width_in), every text smaller
    than MIN_FIGURE_FONT_PT at that width (font size x printed width / figure width) is enlarged to it before the
    layout is made, so a figure drawn wider than the page still prints legible ticks, labels and legends. Records the
    figure's width (inches) and the smallest font size of its visible text (points) in d/figures.json, which
    tools/check-report reads to check the text's printed size."""
    import json
    fig.canvas.draw()  # creates the tick labels, so that they are scaled too
    printed = printed_width_in(os.path.basename(os.path.normpath(d)), stem)
    if printed:
        floor = MIN_FIGURE_FONT_PT * fig.get_size_inches()[0] / printed
        for t in _visible_texts(fig):
            if t.get_fontsize() < floor:
                t.set_fontsize(floor)
        for ax in fig.axes:
            for name, axis in (("x", ax.xaxis), ("y", ax.yaxis)):
                ticks = axis.get_major_ticks() + axis.get_minor_ticks()
                if any(t.label1.get_fontsize() < floor for t in ticks):
                    ax.tick_params(axis=name, which="both", labelsize=floor)
    fig.tight_layout(rect=rect)
    sizes = [t.get_fontsize() for t in _visible_texts(fig)]
    path = os.path.join(d, "figures.json")
    record = {}
    if os.path.exists(path):
        with open(path) as f:
            record = json.load(f)
    record[stem] = {"width_in": float(fig.get_size_inches()[0]), "min_font_pt": float(min(sizes)) if sizes else None}
    with open(path + ".tmp", "w") as f:
        json.dump(record, f, indent=1, sort_keys=True)
    os.replace(path + ".tmp", path)
    fig.savefig(os.path.join(d, stem + ".pdf"))
    fig.savefig(os.path.join(d, stem + ".png"), dpi=130)
    plt.close(fig)


def median_quartiles(values):
    """(median, lower quartile, upper quartile) of a pandas Series (NaN dropped; three NaNs when empty): the spread of a
    timing or of a ratio taken round by round."""
    v = values.dropna()
    return (v.median(), v.quantile(0.25), v.quantile(0.75)) if len(v) else (float("nan"),) * 3


ONE_RUN = "one run"  # how a table marks a time measured once; its caption says why (issue 82)


def timing_text(median, q25, q75, runs, fmt, sep="-", unit=""):
    """A time cell: 'median (q25-q75)' over its alternated rounds, or 'median (one run)' for a time measured once
    (runs <= 1: its quartiles would repeat the median, "0.531 (0.531-0.531)", as if it had a spread); '--' when
    not measured. fmt formats one number; unit (e.g. " s") follows the median of a single run, the quartiles
    otherwise."""
    import math
    if median is None or not math.isfinite(median) or (runs is not None and runs < 1):
        return "--"
    if runs is not None and runs <= 1 or q25 is None or not math.isfinite(q25):
        return f"{fmt(median)}{unit} ({ONE_RUN})"
    return f"{fmt(median)} ({fmt(q25)}{sep}{fmt(q75)}){unit}"


def density_uniformity(g, within=0.1):
    """Thesis Fig. 47's uniformity of a scheme's nodes, from experiment 01's density.csv rows of one scheme (nodes and
    band_sr per band of the polar angle): the share of the sphere's area whose node density lies within `within` of
    the mean (0-1), and the largest density over the mean."""
    mean = g.nodes.sum() / g.band_sr.sum()
    close = (g.nodes_per_sr / mean - 1).abs() <= within
    return g.band_sr[close].sum() / g.band_sr.sum(), g.nodes_per_sr.max() / mean


def latex_escape(s):
    """Escape a table cell (cells are plain text, except a cell that is one math span such as "$\\infty$";
    headers are LaTeX and are not escaped)."""
    t = str(s)
    if len(t) > 1 and t.startswith("$") and t.endswith("$") and "$" not in t[1:-1]:
        return t
    return (str(s).replace("\\", r"\textbackslash{}").replace("_", r"\_").replace("%", r"\%")
            .replace("&", r"\&").replace("^", r"\textasciicircum{}").replace("#", r"\#"))


def stacked_cell(text):
    """A cell "median (q1-q3)" as two lines, the quartiles under the median (a LaTeX cell, already escaped): a table
    of many timings then fits the page at a readable size (issue 82) instead of being shrunk."""
    import re
    m = re.fullmatch(r"(.+?) (\(.+\).*)", text)
    if not m:
        return text
    return r"\begin{tabular}[t]{@{}r@{}}" + m.group(1) + r"\\ " + m.group(2) + r"\end{tabular}"


def write_table(d, stem, header, rows, align=None, caption=None, label=None, stack=False):
    """A booktabs tabular in d/stem.tex. header: list of str; rows: list of lists of str. With a caption, a
    longtable instead (caption and label inside, the header repeated on every page), for a table too long
    for one page: input it outside a table float. stack: every cell "median (q1-q3)" prints its quartiles
    under its median (stacked_cell), for a table too wide for the page otherwise."""
    align = align or "l" + "r" * (len(header) - 1)
    head = " & ".join(header) + r" \\"
    if caption is None:
        lines = [r"\begin{tabular}{" + align + "}", r"\toprule", head, r"\midrule"]
    else:
        lines = [r"\begin{longtable}{" + align + "}",
                 r"\caption{" + caption + "}" + (r"\label{" + label + "}" if label else "") + r" \\",
                 r"\toprule", head, r"\midrule", r"\endfirsthead", r"\toprule", head, r"\midrule", r"\endhead",
                 r"\bottomrule", r"\endfoot"]
    cell = (lambda c: stacked_cell(latex_escape(c))) if stack else latex_escape
    lines += [" & ".join(cell(c) for c in r) + r" \\" for r in rows]
    lines += [r"\bottomrule", r"\end{tabular}"] if caption is None else [r"\end{longtable}"]
    with open(os.path.join(d, stem + ".tex"), "w") as f:
        f.write("\n".join(lines) + "\n")


def precision_axis(ax, values):
    """A log x axis of map precisions (deg): ticks at the precisions a run used, printed plainly (no
    exponent form, no crowded minor labels)."""
    import matplotlib.ticker as ticker
    v = sorted(set(float(x) for x in values))
    ax.xaxis.set_major_locator(ticker.FixedLocator(v))
    ax.xaxis.set_minor_locator(ticker.NullLocator())
    ax.xaxis.set_major_formatter(ticker.FixedFormatter([f"{x:g}" for x in v]))


def resolution_text(x):
    """A scheme's resolution as a table prints it: whole numbers (turns, nodes, cells) with thousands
    separators, never in exponent form; fractional ones (degrees) to 6 significant digits."""
    return f"{int(round(x)):,}" if abs(x - round(x)) < 1e-9 else f"{x:.6g}"


def write_macros(d, stem, values):
    """LaTeX macros \\name{value} for numbers quoted in the paper text."""
    with open(os.path.join(d, stem + ".tex"), "w") as f:
        for k, v in values.items():
            f.write("\\newcommand{\\%s}{%s}\n" % (k, v))


def session_figures(experiment):
    """Figures measured in benchmark sessions outside the reference run, for the prose of one
    experiment's section: {key: value as typed in benchmarks/sessions.csv} (the CSV records unit, date,
    commit and command of each)."""
    path = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "benchmarks", "sessions.csv")
    out = {}
    with open(path) as f:
        rows = list(__import__("csv").DictReader(f))
    for r in rows:
        if r["experiment"] == experiment:
            out[r["key"]] = r["value"]
    return out



# The thesis' ROM observation (sec. 5.2, Tables 12-13): red zones at 1-2 o'clock for patient A, at 1-3 and 7
# o'clock for patient B (acetabular clock face: 12 superior, 3 anterior, 6 at the notch).
THESIS_ROM_ZONES = {"A": [(1, 2)], "B": [(1, 3), (7, 7)]}


def in_clock_zones(hour, zones, slack=0.5):
    """Whether a clock hour (0-12) lies within `slack` hours of one of the zones [(from, to), ...]."""
    return any((hour - (a - slack)) % 12 <= (b - a) + 2 * slack for a, b in zones)
