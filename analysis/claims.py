"""The claims table: a verdict for every thesis table, figure group with numbers, and quantitative claim of the
thesis' results and conclusion, from this run's CSVs.

Reads RESULTS/NN_name/*.csv of every experiment (what a run left out, for example the real hips when
shared/data is absent, becomes `not_testable` with the reason); writes
  RESULTS/claims.csv          thesis_item, claim, kind, thesis_value, our_value, tolerance, conditions,
                              same_subjects, verdict, reason, section
  RESULTS/claims/table_claims.tex   the table the paper opens with (longtable)
  RESULTS/claims/macros.tex         the verdict counts, for the abstract and the conclusion
Verdicts: holds (the data agree within the tolerance the row states), partly (a part holds, a part does
not), does_not_hold (the data contradict it under the thesis' conditions), not_reproduced (a claim about the
thesis' own subjects that our other subjects do not show), not_testable (this reproduction cannot measure it; the
reason says why). Kinds: measured, arithmetic (a formula or constant recomputed), qualitative (a figure or
procedure reproduced). The thesis' values come from the drivers' CSVs (their thesis_* columns) where the drivers carry
them, else from the thesis text quoted in the claim. thesis_item names thesis tables, figures, equations
and sections one by one ("Table 4", "Fig. 40"), so that tests/check_claims_test.py can check that every
thesis item of experiments/manifest.tsv has a row.

usage: /usr/bin/python3 analysis/claims.py [RESULTS]"""
import csv
import json
import os
import re
import sys

import numpy as np
import pandas as pd

from claims_rules import (FRAME_MS, ROM_EXCLUDED, RULES, THESIS_TICK_MS, binomial_p, chance_verdict, compound_verdict,
                          hypergeometric_sum_p, leading_digit_equal, measured_verdict, p_text, printed_equal)
from common import THESIS_ROM_ZONES, density_uniformity, in_clock_zones, latex_escape, write_macros

ROOT = sys.argv[1] if len(sys.argv) > 1 else "results"
VERDICTS = ("holds", "partly", "does_not_hold", "not_reproduced", "not_testable")
KINDS = ("measured", "arithmetic", "qualitative")
HW_ONE = "one thread of this machine"
COLUMNS = ["thesis_item", "claim", "kind", "thesis_value", "our_value", "tolerance", "conditions", "same_subjects",
           "verdict", "reason", "section", "data", "rule"]
rows = []
# The numbers the abstract and the conclusion state (issue 82, item 4): each is written as a macro \\Concl<Name> in
# claims/macros.tex, from the same data as the row that judges it.
facts = {}


def lo_hi(name, values, digits=2):
    """facts[name + Low/High]: the range of values as the table prints it."""
    v = [x for x in values if np.isfinite(x)]
    facts[name + "Low"], facts[name + "High"] = n(min(v), digits), n(max(v), digits)


def claim(item, text, thesis, ours, verdict, reason, section, *, kind, tolerance, conditions, same_subjects,
          data=None):
    """One row. kind: measured, arithmetic or qualitative; its verdict comes from that kind's one rule
    (claims_rules.py, RULES: the row's `rule` column). tolerance: what agreement means for the row; conditions:
    mode, pose, precision, hardware, subjects. same_subjects: whether our subjects are the thesis' (formulas,
    generated counterparts of its generic models) or others (its patients are not available): data that contradict
    a claim, measured on other subjects, give not_reproduced, not does_not_hold. data: the CSV files (under
    RESULTS) the verdict reads, so that a referee can recompute it (default: the section's folder)."""
    assert verdict in VERDICTS and kind in KINDS, (verdict, kind)
    assert not (kind == "arithmetic" and verdict == "partly"), (item, "the arithmetic rule has no 'partly'")
    if verdict == "does_not_hold" and not same_subjects:
        verdict = "not_reproduced"
    rows.append(dict(zip(COLUMNS, [item, text, kind, thesis, ours, tolerance, conditions,
                                   "yes" if same_subjects else "no", verdict, reason, section,
                                   data or f"{section}/*.csv", RULES[kind]])))


def csv_of(experiment, file):
    """The CSV as a DataFrame, or None where this run did not write it."""
    path = os.path.join(ROOT, experiment, file)
    return pd.read_csv(path) if os.path.exists(path) else None


def n(x, digits=3):
    """A number as the table prints it: up to `digits` significant digits, thousands separated."""
    if x is None or not np.isfinite(x):
        return "--"
    if abs(x) >= 1000:
        return f"{x:,.0f}"
    if abs(x) >= 10 ** digits:
        return f"{x:.0f}"
    return f"{x:.{digits}g}"


def span(values, digits=3, unit=""):
    v = [x for x in values if np.isfinite(x)]
    if not v:
        return "--"
    lo, hi = min(v), max(v)
    text = n(lo, digits) if n(lo, digits) == n(hi, digits) else f"{n(lo, digits)}--{n(hi, digits)}"
    return text + unit


def drawn(pattern):
    """The qualitative rule for a figure: the files of this run matching pattern (under RESULTS), and the verdict
    (holds when the run drew it, else not_testable)."""
    import glob
    files = sorted(glob.glob(os.path.join(ROOT, pattern)))
    return len(files), "holds" if files else "not_testable"


def missing(item, text, thesis, what, section, **how):
    claim(item, text, thesis, "--", "not_testable", f"not measured in this run ({what})", section, **how)


# --- 01: map sizes and memory (Tables 2, 6, 7; Fig. 49) --------------------------------------------------
lut, match = csv_of("01_lut_memory", "lut_memory.csv"), csv_of("01_lut_memory", "helix_match.csv")
S01 = "01_lut_memory"
if lut is not None and match is not None:
    # One row for the one node-count formula and what follows from it (issue 82: four rows restated it): RSID's
    # (180/p+1)(360/p) nodes and USID's k^2, their memory in double, the counts at p = 1 deg (Fig. 49) and the saving.
    dbl = lut[lut.storage == "double"].sort_values("matched_precision_deg", ascending=False)
    nodes_ok = bool((dbl.nodes == dbl.thesis_nodes).all() and (dbl.nodes == dbl.nodes_formula).all())
    mem_ok = [printed_equal(m, str(t)) for m, t in zip(dbl.memory_mib, dbl.thesis_memory_mb)]
    saving = 100 * (1 - match.node_ratio)
    saving_ok = all(leading_digit_equal(x, 20) for x in saving)
    one = match[match.precision_deg == 1].iloc[0]
    lo_hi("UsidSaving", saving, 3)
    eq, hx = dbl[dbl.scheme == "equiangular"], dbl[dbl.scheme == "helix"]
    claim("Table 2; Table 7; Fig. 49; Sec. 4.4; Ch. 6",
          "RSID's LUT has (180/p+1)(360/p) nodes and USID's k^2 (65,160 and 52,441 at p = 1 deg); in double they take "
          "0.497-197.8 MB and 0.40-160.32 MB; USID needs about 20 % fewer sample points and memory",
          "; ".join(n(x, 4) for x in eq.thesis_memory_mb) + " MB; " + "; ".join(str(x) for x in hx.thesis_memory_mb)
          + " MB; 65,160 and 52,441 nodes; about 20 %",
          "; ".join(n(x, 4) for x in eq.memory_mib) + " MiB; " + "; ".join(n(x, 5) for x in hx.memory_mib)
          + f" MiB; {int(one.equiangular_nodes):,} and {int(one.helix_nodes):,} nodes; {span(saving, 3, ' %')}",
          "holds" if nodes_ok and all(mem_ok) and saving_ok else "does_not_hold",
          f"node counts {'equal the formula and the thesis' if nodes_ok else 'differ'}; memory equal at the thesis' "
          f"last digit in {sum(mem_ok)} of {len(mem_ok)} (the thesis' MB are 2^20 bytes; its 40.07 is 40.079 "
          "truncated); the saving is k^2 against (180/p+1)(360/p) at matched equators", S01,
          kind="arithmetic", tolerance="node counts exactly; memory at the thesis' last printed digit; the saving at "
          "its leading digit", conditions="double storage; p = 1-0.05 deg and the matched k", same_subjects=True,
          data="01_lut_memory/lut_memory.csv; 01_lut_memory/helix_match.csv")
    turns_ok = bool((match.turns == match.thesis_turns).all())
    claim("Table 6", "k turns of the helix match the equator's nodes of precision p: k = 229, 458, 2292, 4584",
          ", ".join(str(int(x)) for x in match.thesis_turns), ", ".join(str(int(x)) for x in match.turns),
          "holds" if turns_ok else "does_not_hold",
          f"same k; the helix's equator then has {span(match.helix_equator_nodes, 5)} nodes (the thesis rounds to "
          "360--7,201)", S01,
          kind="arithmetic", tolerance="the same k", conditions="matched precisions 1-0.05 deg", same_subjects=True,
          data="01_lut_memory/helix_match.csv")
else:
    missing("Table 2; Table 7; Fig. 49; Sec. 4.4; Ch. 6", "the node-count formulas and their memory",
            "65,160 and 52,441 nodes at 1 deg", "lut_memory.csv, helix_match.csv", S01,
            kind="arithmetic", tolerance="--", conditions="--", same_subjects=True)
    missing("Table 6", "helix turns matching the equiangular precisions", "k = 229--4584", "helix_match.csv", S01,
            kind="arithmetic", tolerance="--", conditions="--", same_subjects=True)

density = csv_of("01_lut_memory", "density.csv")
if density is not None and len(density):
    # Fig. 47 / sec. 4.2: the helix's points spread uniformly over the sphere. Node density (nodes per steradian) in
    # 1 deg bands of phi against its mean, as a share of the sphere's area; the equiangular grid beside it.
    hx, eq = density[density.scheme == "helix"], density[density.scheme == "equiangular"]
    (hx_share, hx_peak), (eq_share, eq_peak) = density_uniformity(hx), density_uniformity(eq)
    claim("Fig. 47; Sec. 4.2", "the spherical helix's points sample the sphere uniformly (approximately: sec. 4.5)",
          "uniform", f"helix (k = {int(hx.resolution.iloc[0])}): density within 10 % of its mean over "
          f"{100 * hx_share:.3f} % of the sphere, at most {hx_peak:.1f}x the mean (in the band at a pole); "
          f"equiangular ({eq.resolution.iloc[0]:g} deg): {100 * eq_share:.0f} %, up to {eq_peak:,.0f}x",
          "holds" if hx_share >= 0.99 else "partly" if hx_share >= 0.9 else "does_not_hold",
          "node density per 1 deg band of the polar angle", S01,
          kind="measured", tolerance="density within 10 % of its mean over 99 % of the sphere's area",
          conditions="the helix matched to 1 deg (k = 229), nodes counted per 1 deg band", same_subjects=True)
else:
    missing("Fig. 47; Sec. 4.2", "the spherical helix's points sample the sphere uniformly", "uniform", "density.csv",
            S01, kind="measured", tolerance="--", conditions="--", same_subjects=True)

# --- 02: sampling time (Tables 3, 8) ------------------------------------------------------------------------
st = csv_of("02_sampling_time", "sampling_time.csv")
S02 = "02_sampling_time"
ST_DATA = "02_sampling_time/sampling_time.csv"
if st is not None and (st.subject == "generated-3k").any():
    # The paper's Table 7 (table3_8.tex) shows the 3k model's pelvis (the socket model): the rows read the same body.
    g = st[(st.subject == "generated-3k") & (st.precision_deg > 0) & (st.body == "pelvis")]
    piv = g.pivot_table(index="precision_deg", columns="method", values="time_ms").sort_index(ascending=False)
    th = g.pivot_table(index="precision_deg", columns="method", values="thesis_ms").sort_index(ascending=False)
    COND3K = f"generated 3k model's pelvis (the socket model, as Table 7 prints it), {HW_ONE} against the thesis' " \
             "2.6 GHz Opteron 252"
    if {"pairwise", "rsid_linear"} <= set(piv.columns):
        ratio = (piv.pairwise / piv.rsid_linear).dropna()
        tratio = (th.pairwise / th.rsid_linear).dropna()
        lo_hi("SamplingOverPairwise", ratio, 2)
        claim("Table 3", "RSID's O(n) rasterisation samples a 3k-triangle model orders of magnitude faster than "
              "pairwise O(n^2) ray testing", f"{span(tratio, 2)}x faster", f"{span(ratio, 2)}x faster",
              measured_verdict((ratio > 100).all(), (ratio > 1).all()),
              "pairwise times extrapolated from a timed subset of nodes (sampling_time.csv: extrapolated); a ratio "
              "on one machine, so the hardware cancels", S02,
              kind="measured", tolerance="over 100x (two orders of magnitude) at every precision",
              conditions="linear mode; " + COND3K, same_subjects=True, data=ST_DATA)
        # Table 3's RSID times, read at what the thesis' clock could resolve (issue 82): its 15 and 16 ms at 1 and
        # 0.5 deg are one tick of 15.625 ms, so only the growth between the two finest precisions carries
        # information; the thesis' ratio there, a tick either side, against ours (a ratio: the hardware cancels).
        fine = sorted(th.index)[:2]
        if len(fine) == 2 and all(np.isfinite(th.rsid_linear.get(p, np.nan)) for p in fine):
            t_fine, t_coarse = th.rsid_linear[fine[0]], th.rsid_linear[fine[1]]
            lo = (t_fine - THESIS_TICK_MS) / (t_coarse + THESIS_TICK_MS)
            hi = (t_fine + THESIS_TICK_MS) / (t_coarse - THESIS_TICK_MS)
            ours_growth = piv.rsid_linear[fine[0]] / piv.rsid_linear[fine[1]]
            ticks = [x / THESIS_TICK_MS for x in th.rsid_linear]
            claim("Table 3", f"RSID samples a 3k-triangle model in {'; '.join(n(x) for x in th.rsid_linear)} ms at "
                  f"p = {', '.join(f'{p:g}' for p in th.index)} deg: read at the thesis' clock (15.625 ms ticks), "
                  f"one tick at the two coarsest precisions and a {t_fine / t_coarse:.1f}x growth from {fine[1]:g} "
                  f"to {fine[0]:g} deg",
                  f"{'; '.join(n(x) for x in th.rsid_linear)} ms ({'; '.join(f'{x:.1f}' for x in ticks)} ticks); "
                  f"growth {t_fine / t_coarse:.2f}x ({lo:.1f}-{hi:.1f}x within a tick)",
                  f"{'; '.join(n(x) for x in piv.rsid_linear)} ms; growth {ours_growth:.2f}x",
                  measured_verdict(lo <= ours_growth <= hi, ours_growth > 1),
                  "the absolute times are not comparable (other hardware, and the thesis' times at 1 and 0.5 deg are "
                  "one clock tick, 'under about 31 ms'); the growth between the finest precisions is a ratio on one "
                  "machine", S02, kind="measured",
                  tolerance="our growth within the thesis' growth with a tick either side of its times",
                  conditions="linear mode; " + COND3K, same_subjects=True, data=ST_DATA)
    if {"usid_accelerated", "rsid_linear"} <= set(piv.columns):
        ur = (piv.usid_accelerated / piv.rsid_linear).dropna()
        tu = (th.usid_accelerated / th.rsid_linear).dropna()
        # Where the thesis' RSID time spans more than two ticks (0.1 and 0.05 deg), its ratio is a measurement.
        resolved = [p for p in tu.index if th.rsid_linear[p] > 2 * THESIS_TICK_MS and p in ur.index]
        within = all(0.5 <= ur[p] / tu[p] <= 2 for p in resolved)
        direction = bool((ur > 1).all() and ur.iloc[-1] > ur.iloc[0])
        lo_hi("UsidSamplingOurs", ur, 2)
        lo_hi("UsidSamplingThesis", tu, 2)
        claim("Table 8", "USID's (accelerated) sampling costs more than RSID's, more so at finer precision",
              f"{span(tu, 2)}x RSID's ({', '.join(f'{n(tu[p], 2)}x at {p:g} deg' for p in resolved)})",
              f"{span(ur, 2)}x RSID's ({', '.join(f'{n(ur[p], 2)}x at {p:g} deg' for p in resolved)})",
              measured_verdict(within, direction),
              "the direction holds (above 1x, growing with precision); the size does not: the thesis resampled through "
              "the trigonometric helix, we rasterise once and resample by bilinear look-up (sec. 4.2.2)"
              if direction and not within else "resampling an equiangular map at the helix nodes (sec. 4.2.2)", S02,
              kind="measured", tolerance="above 1x at every precision, larger at the finest than at the coarsest, and "
              "within a factor of 2 of the thesis' ratio where its RSID time spans more than two clock ticks",
              conditions="linear RSID, accelerated USID at the matched k; " + COND3K, same_subjects=True, data=ST_DATA)
else:
    missing("Table 3", "sampling time of RSID against pairwise testing", "15--187 ms", "generated-3k rows", S02,
            kind="measured", tolerance="--", conditions="--", same_subjects=True)
    missing("Table 8", "USID's sampling time", "31--11,172 ms", "generated-3k rows", S02,
            kind="measured", tolerance="--", conditions="--", same_subjects=True)
if st is not None:
    # Sec. 3.6.3: "our tests can easily reach 7201x3601 (precision of 0.05 deg) in real-time": the sampling of a map
    # at 0.05 deg against one frame at 60 Hz, in the thesis' linear mode and in impinge's default (exact, culled).
    finest = st[np.isclose(st.precision_deg, 0.05)]
    lin, cul = finest[finest.method == "rsid_linear"], finest[finest.method == "rsid_exact_culled"]
    if len(lin):
        gen, gen_cul = lin[lin.subject == "generated-3k"], cul[cul.subject == "generated-3k"]
        thesis_finest = gen.thesis_ms.dropna()
        verdict = ("holds" if (gen.time_ms <= FRAME_MS).all() else
                   "partly" if len(gen_cul) and (gen_cul.time_ms <= FRAME_MS).all() else "does_not_hold")
        claim("Sec. 3.6.3", "the sampling reaches 7201x3601 nodes (0.05 deg) in real time", "real time",
              f"linear (the thesis' algorithm): {span(gen.time_ms)} ms on the 3k model, "
              f"{span(lin[lin.generated == 0].time_ms)} ms on the real bones; exact culled (impinge's default): "
              f"{span(gen_cul.time_ms)} ms on the 3k model, {span(cul[cul.generated == 0].time_ms)} ms on the real bones",
              verdict, f"one map at 0.05 deg against a frame at 60 Hz ({FRAME_MS:.1f} ms); the thesis' own Table 3 "
              f"gives {span(thesis_finest)} ms for it; impinge's default within a frame: partly", S02,
              kind="measured", tolerance=f"the thesis' algorithm within one frame at 60 Hz ({FRAME_MS:.1f} ms)",
              conditions=f"0.05 deg, the generated 3k model (the thesis' conditions) and every real bone, {HW_ONE}",
              same_subjects=True, data=ST_DATA)
    # Sec. 3.6.3: "our method samples all the triangles ... without missing a single triangle". Each node keeps one
    # triangle's value, so where a bone has more triangles than covered nodes, at least (triangles - covered nodes)
    # of its triangles give no sample point (a pigeonhole bound from the counts; every triangle is rasterised).
    lin = st[(st.method == "rsid_linear") & (st.precision_deg > 0)]
    if len(lin):
        missed = (lin.triangles - lin.nodes_covered).clip(lower=0)
        hit = lin[missed > 0]
        raster_all = bool((lin.triangles_rasterised == lin.triangles).all())
        n_bones = len(lin[["subject", "body"]].drop_duplicates())
        per_p = "; ".join(f"at {p:g} deg {len(g)} of {n_bones} bones"
                          for p, g in hit.groupby("precision_deg", sort=False)) or f"at no precision any of {n_bones} bones"
        claim("Sec. 3.6.3", "the rasteriser samples every triangle, without missing a single one (where Maciel et "
              "al.'s one triangle per direction misses many)", "every triangle",
              f"every triangle rasterised: {'yes' if raster_all else 'no'}; but {per_p} have more triangles than "
              "covered nodes, so at least "
              f"{span(missed[missed > 0], 3)} of their triangles ({span(100 * missed[missed > 0] / hit.triangles, 2, ' %')}) "
              "give no sample point",
              "holds" if raster_all and len(hit) == 0 else "does_not_hold",
              "a node keeps one triangle's distance, so a map of fewer covered nodes than triangles must drop "
              "triangles, as Maciel et al.'s does; at finer precisions (more nodes than triangles) the bound says "
              "nothing", S02, kind="arithmetic",
              tolerance="no bone with more triangles than covered nodes (a count: pigeonhole)",
              conditions="RSID linear mode; every body of every hip and the generated 3k model; 1-0.05 deg",
              same_subjects=True, data=ST_DATA)
# The sampling's cost (thesis sec. 3.2: O(n) in the triangles; each node is written too): RSID's linear-mode times
# over every body and precision against a + b triangles + c nodes, fitted in relative terms.
if st is not None:
    r = st[(st.method == "rsid_linear") & (st.precision_deg > 0)]
    if len(r) >= 4:
        A = np.c_[np.ones(len(r)), r.triangles, r.nodes]
        y = r.time_ms.to_numpy()
        coef = np.linalg.lstsq(A / y[:, None], np.ones(len(y)), rcond=None)[0]
        rel = np.abs(A @ coef - y) / y
        claim("Sec. 3.2", "the sampling is O(n) in the triangles (and, with the LUT, linear in its nodes)", "O(n)",
              f"time = {coef[0]:.2g} ms + {1e6 * coef[1]:.3g} ns per triangle + {1e6 * coef[2]:.3g} ns per node over "
              f"{len(r)} bodies and precisions: median relative residual {100 * np.median(rel):.0f} %, largest "
              f"{100 * rel.max():.0f} %", "holds" if np.median(rel) <= 0.15 and rel.max() <= 0.5 else "partly",
              "a linear model in triangles and nodes, fitted to relative error; what is left is caching (a map that "
              "fits in the cache, poles with many nodes per triangle)", S02, kind="measured",
              tolerance="median relative residual at most 15 %, largest at most 50 %",
              conditions=f"RSID linear mode, every body of every hip and the generated 3k model, 1-0.05 deg, {HW_ONE}",
              same_subjects=True)

# --- 03: detection time (Tables 4, 9) -----------------------------------------------------------------------
det, det_runs = csv_of("03_detection_time", "detection.csv"), csv_of("03_detection_time", "detection_runs.csv")
S03 = "03_detection_time"
DET_DATA = "03_detection_time/detection.csv; 03_detection_time/detection_runs.csv"
PUSHED = "pushed_3mm"
if det is not None:
    def t(subject, method, resolution=None, pose="rest"):
        """The median time (ms) of one method on one subject and pose (NaN when not run)."""
        g = det[(det.subject == subject) & (det.method == method) & (det.pose == pose)]
        if resolution is not None:
            g = g[np.isclose(g.resolution, resolution)]
        return float(g.time_ms.min()) if len(g) else np.nan

    def faster_rounds(subject, pose, fast, slow):
        """(rounds where `fast` beat `slow`, paired rounds): fast and slow are (method, resolution or None); the
        rounds alternate the methods, so round i of each is a pair (detection_runs.csv)."""
        if det_runs is None:
            return 0, 0
        def times(method, res):
            g = det_runs[(det_runs.subject == subject) & (det_runs.pose == pose) & (det_runs.method == method)]
            if res is not None:
                g = g[np.isclose(g.resolution, res)]
            return g.set_index("round").time_ms
        a, b = times(*fast), times(*slow)
        common = a.index.intersection(b.index)
        return int((a[common] < b[common]).sum()), len(common)

    def all_rounds(pairs):
        return all(k == m and m >= 5 for k, m in pairs)

    RSID = ("rsid", 0.1)
    small = [s for s in ("generated-300", "generated-1k", "generated-3k") if (det.subject == s).any()]
    real = [s for s in det.subject.unique() if not str(s).startswith("generated")]
    wins = [faster_rounds(s, PUSHED, RSID, (m, None)) for s in small for m in ("fcl_first_contact", "fcl_collide")]
    rs = [t(s, "rsid", 0.1, PUSHED) for s in small]
    first = [t(s, "fcl_first_contact", pose=PUSHED) for s in small]
    every = [t(s, "fcl_collide", pose=PUSHED) for s in small]
    claim("Table 4", "RSID's detection is faster than RAPID (an OBB tree) on 300- to 3k-triangle models",
          "0.06--0.48 ms against 1.41--1.43 ms",
          f"RSID {span(rs)} ms against FCL {span(first)} ms (first contact), {span(every)} ms (every contact); RSID "
          f"faster in {sum(k for k, _ in wins)} of {sum(m for _, m in wins)} paired rounds",
          measured_verdict(all_rounds(wins), sum(k for k, _ in wins) > sum(m for _, m in wins) / 2),
          "FCL's OBBRSS collision query stands in for RAPID (same authors' OBB tree), in RAPID's first-contact mode "
          "and with every contact", S03, kind="measured",
          tolerance="RSID faster in every paired round on every model, against FCL in both modes (sign test)",
          conditions=f"3 mm pushed pose (the bones in contact), 0.1 deg, exact mode, {HW_ONE} against the thesis' "
          "2.6 GHz Opteron 252; FCL's OBB tree for RAPID", same_subjects=True, data=DET_DATA)
    # The 12k row (issue 82): the thesis' RAPID answered whether the bones collide, which its first-contact mode
    # does; read at the pushed pose, where there is a contact to find (at rest there is none).
    r12, f12first, f12 = (t("generated-12k", m, r, PUSHED) for m, r in (RSID, ("fcl_first_contact", None),
                                                                          ("fcl_collide", None)))
    k12, m12 = faster_rounds("generated-12k", PUSHED, ("fcl_first_contact", None), RSID)
    fr_all = [t(s, "fcl_collide", pose=p) / t(s, "rsid", 0.1, p) for s in real for p in ("rest", PUSHED)]
    fr_first = [t(s, "fcl_first_contact", pose=p) / t(s, "rsid", 0.1, p) for s in real for p in ("rest", PUSHED)]
    real_wins = [faster_rounds(s, p, RSID, (m, None)) for s in real for p in ("rest", PUSHED)
                 for m in ("fcl_first_contact", "fcl_collide")]
    tri = det[det.subject.isin(real)].femur_triangles
    lo_hi("FclAll", fr_all, 2)
    lo_hi("FclFirst", fr_first, 2)
    # At the pushed pose alone, where the bones touch (issue 82, item 3: section 13 cites them beside the peers).
    lo_hi("FclAllPushed", [t(s, "fcl_collide", pose=PUSHED) / t(s, "rsid", 0.1, PUSHED) for s in real], 2)
    lo_hi("FclFirstPushed", [t(s, "fcl_first_contact", pose=PUSHED) / t(s, "rsid", 0.1, PUSHED) for s in real], 2)
    facts.update(FclFirstTwelveKMs=n(f12first), RsidTwelveKMs=n(r12), FclTwelveKRounds=str(k12),
                 TwelveKRounds=str(m12), RealRoundsRsid=str(sum(k for k, _ in real_wins)),
                 RealRounds=str(sum(m for _, m in real_wins)))
    claim("Table 4; Sec. 3.6.1", "at 12k triangles RAPID is faster than RSID (1.5 against 5.7 ms): BVHs win on "
          "high-resolution models", "RAPID 1.5 ms (Table 4; 1.45 ms in Table 9), RSID 5.7 ms",
          f"generated 12k, pushed: FCL {n(f12first)} ms at first contact (faster in {k12} of {m12} paired rounds), "
          f"{n(f12)} ms with every contact; RSID {n(r12)} ms. Real hips ({span(tri / 1000, 2)}k femur triangles, both "
          f"poses): FCL {span(fr_all, 2)}x RSID with every contact, {span(fr_first, 2)}x at first contact; RSID "
          f"faster in {sum(k for k, _ in real_wins)} of {sum(m for _, m in real_wins)} paired rounds",
          compound_verdict([k12 == m12 and m12 >= 5, all(k == 0 for k, _ in real_wins)]),
          "at 12k triangles the OBB tree's first-contact query beats the map as the thesis found (every contact: "
          "the map wins); on the real hips, with more triangles, the map wins in both modes and both poses, so BVHs "
          "do not win on high-resolution models", S03, kind="measured",
          tolerance="the faster method in every paired round (sign test), at 12k and on the real hips",
          conditions=f"3 mm pushed pose (rest beside it on the real hips), 0.1 deg, exact mode, {HW_ONE}; FCL at first "
          "contact (RAPID_FIRST_CONTACT's counterpart) and with every contact", same_subjects=True, data=DET_DATA)
    # Sec. 3.6.1: "BVH has constant complexity regardless the number of triangles" (RAPID 1.41-1.45 ms, 300-12k).
    ladder = [s for s in ("generated-300", "generated-1k", "generated-3k", "generated-12k") if (det.subject == s).any()]
    if len(ladder) >= 2:
        growth = {(m, p): t(ladder[-1], m, pose=p) / t(ladder[0], m, pose=p)
                  for m in ("fcl_collide", "fcl_first_contact") for p in ("rest", PUSHED)}
        tri_growth = float(det[det.subject == ladder[-1]].femur_triangles.iloc[0] /
                           det[det.subject == ladder[0]].femur_triangles.iloc[0])
        contact = [v for (m, p), v in growth.items() if p == PUSHED]
        apart = [v for (m, p), v in growth.items() if p == "rest"]
        claim("Sec. 3.6.1", "a BVH's cost is constant in the triangle count (RAPID: 1.41--1.45 ms from 300 to 12k "
              "triangles)", "constant: 1.03x over 40x the triangles",
              f"over {tri_growth:.0f}x the triangles FCL's time grows {span(contact, 2)}x with the bones in contact "
              f"(every contact: {n(t(ladder[0], 'fcl_collide', pose=PUSHED))} -> "
              f"{n(t(ladder[-1], 'fcl_collide', pose=PUSHED))} ms) and {span(apart, 2)}x apart",
              compound_verdict([all(v <= 1.5 for v in apart), all(v <= 1.5 for v in contact)]),
              "constant when the bones are apart (the trees' roots separate at once); in contact the query follows "
              "the overlapping nodes, whose number grows with the triangles", S03, kind="measured",
              tolerance="the 12k model's time within 1.5x of the 300-triangle model's",
              conditions=f"generated 300-12k models, rest and 3 mm pushed poses, FCL in both modes, {HW_ONE}",
              same_subjects=True, data=DET_DATA)
    pw = [t(s, "pairwise") / t(s, "rsid", 0.1) for s in small]
    lo_hi("DetectionOverPairwise", pw, 2)
    facts["DetectionTwelveKMs"] = n(t("generated-12k", "rsid", 0.1))
    claim("Table 4", "pairwise O(n^2) triangle testing is orders of magnitude slower (30.7--2,831 ms)",
          "512--5,900x RSID", f"{span(pw, 2)}x RSID", measured_verdict(all(x > 10 for x in pw), all(x > 1 for x in pw)),
          "every triangle pair tested, one thread; a ratio on one machine", S03,
          kind="measured", tolerance="over 10x on every model", conditions=f"rest pose, every triangle pair, {HW_ONE}",
          same_subjects=True, data=DET_DATA)
    ur = [t(s, "usid", 2292) / t(s, "rsid", 0.1) for s in small + ["generated-12k"]]
    claim("Table 9", "USID's detection is slower than RSID's (1.17--3.75x) but still O(n) and real-time",
          "1.17--3.75x RSID (0.07/0.06 to 1.8/0.48 ms)", f"{span(ur, 2)}x RSID",
          measured_verdict(all(1.17 <= x <= 3.75 for x in ur), all(x > 1 for x in ur)),
          "helix stencils cost a few more operations than the equiangular grid's", S03,
          kind="measured", tolerance="above 1x on every model, within the thesis' 1.17--3.75x",
          conditions=f"rest pose; USID k = 2292 against RSID 0.1 deg (matched), {HW_ONE}", same_subjects=True,
          data=DET_DATA)
    worst12 = max(t("generated-12k", m, r, p) for m, r in (RSID, ("usid", 2292)) for p in ("rest", PUSHED))
    claim("Sec. 3.4; Ch. 6", "detection runs in real time, at the millisecond level, on a 12k-triangle real model",
          "5.7 ms (RSID), 12 ms (USID)", f"{n(t('generated-12k', 'rsid', 0.1))} ms (RSID), "
          f"{n(t('generated-12k', 'usid', 2292))} ms (USID) at rest; at most {n(worst12)} ms over both poses",
          measured_verdict(worst12 <= FRAME_MS, True), "both scans of a pose, one thread", S03,
          kind="measured", tolerance=f"within one frame at 60 Hz ({FRAME_MS:.1f} ms)",
          conditions=f"generated 12k model, rest and 3 mm pushed poses, both scans, {HW_ONE}", same_subjects=True,
          data=DET_DATA)

# --- 04: sampling error (Table 5, Eq. 7-8) ------------------------------------------------------------------
t5, cov = csv_of("04_sampling_error", "table5.csv"), csv_of("04_sampling_error", "covering.csv")
S04 = "04_sampling_error"
if t5 is not None:
    ok7 = [printed_equal(x, str(y)) for x, y in zip(t5.eq7_mm, t5.thesis_eq7_mm)]
    ok8 = [printed_equal(x, str(y)) for x, y in zip(t5.eq8_percent, t5.thesis_eq8_percent)]
    claim("Table 5; Eq. 7; Eq. 8", "the largest sampling error sqrt(2) pi r / n: 0.272, 0.136, 0.027, 0.014 mm "
          "(1.23, 0.62, 0.12, 0.06 %) for a 22 mm head", "; ".join(n(x) for x in t5.thesis_eq7_mm) + " mm",
          "; ".join(f"{x:.4f}" for x in t5.eq7_mm) + " mm; " + "; ".join(f"{x:.3f}" for x in t5.eq8_percent) + " %",
          "holds" if all(ok7) and all(ok8) else "does_not_hold",
          f"the arithmetic, re-computed: equal at the thesis' last digit in {sum(ok7)} of {len(ok7)} (mm) and "
          f"{sum(ok8)} of {len(ok8)} (%)", S04,
          kind="arithmetic", tolerance="the thesis' last printed digit", conditions="r = 22 mm", same_subjects=True,
          data="04_sampling_error/table5.csv")
if cov is not None:
    c = cov[cov.scheme == "equiangular"].copy()
    c["ratio"] = c.max_nearest_mm / c.eq7_mm
    sph = c[c["shape"].str.contains("sphere") | c["shape"].str.startswith("head_")]
    con = c[c["shape"] == "conchoid"]
    claim("Eq. 7; Sec. 3.5.1", "Eq. 7 bounds the distance from a surface point to its nearest sample point",
          "the bound (sphere)", f"measured / Eq. 7: {span(sph.ratio, 3)} on spheres and real heads; "
          f"{span(con.ratio, 3)} on the conchoid", "holds" if (sph.ratio <= 1.0).all() else "partly",
          "dense test points against the sample points of each precision; the conchoid is not a sphere, and at its "
          "equator (local radius above r) the bound is exceeded", S04,
      kind="measured", tolerance="measured / Eq. 7 at most 1 on spheres and heads", conditions="dense test points; every precision; spheres, real heads, the conchoid", same_subjects=True)

# The thesis' accuracy claims in its own (linear) mode, beside our exact mode (issue 51, item 2): the radial error of
# the map's look-ups on the real heads against exact ray casts, over random directions (radial_error.csv).
rad = csv_of("04_sampling_error", "radial_error.csv")
if rad is not None:
    heads = rad[(rad.scheme == "equiangular") & rad["shape"].str.startswith("head_")]
    fine = heads[heads.precision_deg <= 0.1 + 1e-9]
    lin, ex = fine[fine["mode"] == "linear"], fine[fine["mode"] == "exact"]
    def falls_with_precision(g):
        """Whether the largest error falls by at least a quarter from the coarser to the finer precision on every
        head, as Eq. 7 (halving) does."""
        by = g.pivot_table(index="shape", columns="precision_deg", values="max_mm")
        return bool(len(by.columns) >= 2 and (by[by.columns.min()] <= 0.75 * by[by.columns.max()]).all())

    if len(lin) and len(ex):
        # Table 5 bounds the largest error (Eq. 7 is a maximum), so the row judges the maximum over the directions
        # (issue 82), in the thesis' linear mode, with exact mode beside it.
        lin_ok, ex_ok = (lin.max_mm <= lin.eq7_mm), (ex.max_mm <= ex.eq7_mm)
        lo_hi("LinearHeadMax", lin.max_mm, 2)
        lo_hi("LinearHeadPNinetyFive", lin.p95_mm, 2)
        claim("Sec. 3.5.1", "precisions of 0.1 deg and finer are acceptable: the sampling error falls to Table 5's "
              "0.027 and 0.014 mm", "at most 0.027; 0.014 mm",
              f"largest error: linear mode {span(lin.max_mm, 2, ' mm')} ({span(lin.max_mm / lin.eq7_mm, 2)}x Eq. 7, "
              f"within it on {int(lin_ok.sum())} of {len(lin)} heads and precisions); exact mode "
              f"{span(ex.max_mm, 2, ' mm')} (within on {int(ex_ok.sum())} of {len(ex)}); p95 "
              f"{span(lin.p95_mm, 2, ' mm')} linear, {span(ex.p95_mm, 2, ' mm')} exact",
              measured_verdict(bool(lin_ok.all()), falls_with_precision(lin)),
              "Eq. 7 bounds the largest error on a sphere; on real heads the largest error lies at creases and depth "
              "steps of the mesh, in both modes; in linear mode the interpolation across each triangle in (theta, "
              "phi) keeps even the 95th percentile above the bound, and a finer precision does not reduce it", S04,
              kind="measured", tolerance="the largest error within Eq. 7 at 0.1 and 0.05 deg on every head (direction: "
              "it falls by a quarter or more from 0.1 to 0.05 deg, as Eq. 7 halves)",
              conditions="the thesis' linear mode (exact mode beside); the real heads; 0.1 and 0.05 deg; 100,000 random "
              "directions against exact ray casts", same_subjects=True, data="04_sampling_error/radial_error.csv")
        claim("Sec. 3.4; Ch. 6", "the rasterised sampling is more accurate than pair-wise ray sampling",
              "more accurate",
              f"rasterised (linear) p95 {span(lin.p95_mm, 2, ' mm')} against {span(ex.p95_mm, 2, ' mm')} for exact "
              "node values (pair-wise ray casting gives them: our exact mode equals it node for node, section 02)",
              "holds" if (lin.p95_mm.max() <= ex.p95_mm.max()) else "does_not_hold",
              "a ray cast per node is exact at the node; the thesis' rasteriser interpolates in (theta, phi) and is only "
              "as accurate where the triangle is small against the node spacing", S04,
              kind="measured", tolerance="the rasterised map's error at most the ray-cast map's",
              conditions="the thesis' linear mode against exact node values; the real heads; 0.1 and 0.05 deg",
              same_subjects=True)

# USID (thesis sec. 1.3, 4.2.2): the helix LUT is filled in O(n) of its nodes (from an equiangular map) and "the sampling
# precision is preserved" while the memory falls: the accelerated sampling's time against triangles and nodes, and
# the helix map's error at the matched k against Eq. 7 and the equiangular map's.
if st is not None and rad is not None:
    u = st[(st.method == "usid_accelerated") & (st.precision_deg > 0)]
    hx = rad[(rad.scheme == "helix") & rad["shape"].str.startswith("head_") & (rad["mode"] == "exact")]
    eqa = rad[(rad.scheme == "equiangular") & rad["shape"].str.startswith("head_") & (rad["mode"] == "exact")]
    if len(u) >= 4 and len(hx):
        A = np.c_[np.ones(len(u)), u.triangles, u.nodes]
        y = u.time_ms.to_numpy()
        coef = np.linalg.lstsq(A / y[:, None], np.ones(len(y)), rcond=None)[0]
        rel = np.abs(A @ coef - y) / y
        linear = bool(np.median(rel) <= 0.15 and rel.max() <= 0.5)
        pair = hx.merge(eqa, on=["shape", "precision_deg"], suffixes=("", "_eq"))
        kept = bool((hx.p95_mm <= hx.eq7_mm).all())
        claim("Sec. 1.3; Sec. 4.2.2", "USID fills its LUT in O(n) and preserves the sampling precision while "
              "reducing the memory", "O(n); precision preserved",
              f"time = {coef[0]:.2g} ms + {1e6 * coef[1]:.3g} ns per triangle + {1e6 * coef[2]:.3g} ns per node over "
              f"{len(u)} bodies and precisions (median relative residual {100 * np.median(rel):.0f} %, largest "
              f"{100 * rel.max():.0f} %); helix p95 error within Eq. 7 on {int((hx.p95_mm <= hx.eq7_mm).sum())} of "
              f"{len(hx)} heads and k, {span(pair.p95_mm / pair.p95_mm_eq, 2)}x the equiangular map's",
              compound_verdict([linear, kept]),
              "the helix map is resampled from an equiangular one, so it interpolates twice: its error is a few times "
              "the equiangular map's, still inside the precision's Eq. 7 bound", S04, kind="measured",
              tolerance="the linear fit of the Sec. 3.2 row (median residual at most 15 %, largest 50 %); the p95 "
              "error within Eq. 7 at the matched k on every head",
              conditions=f"accelerated USID at the matched k, every body and the 3k model, {HW_ONE}; exact mode, the "
              "real heads, 100,000 directions", same_subjects=True,
              data="02_sampling_time/sampling_time.csv; 04_sampling_error/radial_error.csv")

# The thesis' headline accuracy ("we achieved the accuracy": the gap within Table 5's sampling error) in its own
# configuration: equiangular maps at 0.1 deg, linear mode, the maps alone (no exact refinement), against the exact
# gap of every vertex (experiment 10, rest and pushed poses) and, in exact mode, at ROM-extreme poses (experiment 11).
er, disc = csv_of("10_error_vs_runtime", "error_runtime.csv"), csv_of("11_extreme_cases", "discontinuities.csv")
if er is not None and len(er):
    e = er[(er.scheme == "equiangular") & np.isclose(er.precision_deg, 0.1) & (er.storage == "dense")]
    lin, ex = e[e["mode"] == "linear"], e[e["mode"] == "exact"]
    gen, realr = lin[lin.generated == 1], lin[lin.generated == 0]
    bound = float(t5[np.isclose(t5.precision_deg, 0.1)].thesis_eq7_mm.iloc[0]) if t5 is not None else 0.027
    worst = realr.groupby("subject").max_abs_mm.max()
    facts.update(HeadlineBound=n(bound), HeadlineGenMax=n(gen.max_abs_mm.max(), 2))
    d_text = ""
    if disc is not None and len(disc):
        dm = disc[(disc.method == "maps") & (disc.generated == 0)]
        lo_hi("MapsAlone", dm[dm.subject != "mc22"].max_abs_mm, 2)
        d_text = (f"; the maps alone in exact mode at {int(dm.poses.max())} ROM-extreme poses: largest error "
                  f"{span(dm[dm.subject != 'mc22'].max_abs_mm, 2, ' mm')} ({span(dm.max_abs_mm, 3, ' mm')} with mc22), "
                  "at depth steps where a ray passes from one surface to another")
    claim("Abstract; Table 5", "the detection is accurate: the gap it reports lies within the sampling error of Table "
          "5 (0.027 mm at 0.1 deg)", "at most 0.027 mm",
          f"thesis' configuration (linear, 0.1 deg, maps alone): largest |gap error| {span(gen.max_abs_mm, 2, ' mm')} on "
          f"the generated 3k model (p95 {span(gen.p95_abs_mm, 2, ' mm')}); on the real hips "
          + "; ".join(f"{s_} {n(v, 3)} mm" for s_, v in worst.items())
          + f" (p95 {span(realr.p95_abs_mm, 2, ' mm')}){d_text}",
          measured_verdict(bool((gen.max_abs_mm <= bound).all()), bool((gen.p95_abs_mm <= bound).all())),
          "in linear mode the interpolation across each triangle in (theta, phi) exceeds Table 5's bound even on the "
          "smooth generated hip; on real hips a ray that passes a depth step (the head's rim, a crease) reads the "
          "wrong surface by millimetres to centimetres; impinge's exact refinement removes both (sections 10 and 11)",
          "10_error_vs_runtime", kind="measured",
          tolerance="the largest |gap error| on the generated 3k model (the thesis' counterpart) within 0.027 mm; "
          "direction: its 95th percentile within it",
          conditions="equiangular, 0.1 deg, linear mode, maps alone, rest and 3 mm pushed poses, every vertex "
          "against the exact gap (experiment 10); exact mode at ROM-extreme poses beside (experiment 11)",
          same_subjects=True, data="10_error_vs_runtime/error_runtime.csv; 11_extreme_cases/discontinuities.csv")

# --- 05: slices (Sec. 3.5.2, Fig. 46) -----------------------------------------------------------------------
ny, stair = csv_of("05_slice_sampling", "nyquist.csv"), csv_of("05_slice_sampling", "staircase.csv")
S05 = "05_slice_sampling"
if ny is not None:
    r = ny[ny.thesis_min_dphi_deg.notna()]
    if len(r):
        r = r.iloc[0]
        claim("Sec. 3.5.2; Fig. 46", "for 1.25 mm CT slices on a 44 mm head the smallest slice angle is about 3 deg; "
              "by Shannon, a precision of 1.5 deg or finer", f"{n(r.thesis_min_dphi_deg)} deg; {n(r.thesis_precision_deg)} deg",
              f"{n(r.min_dphi_deg)} deg; {n(r.nyquist_precision_deg)} deg",
              "holds" if (leading_digit_equal(r.min_dphi_deg, r.thesis_min_dphi_deg)
                          and r.thesis_precision_deg <= r.nyquist_precision_deg) else "does_not_hold",
              "arccos of the slice heights, 17 slices a side; 'about 3 deg' at its leading digit, and 1.5 deg is finer "
              "than the Nyquist precision, as the thesis' 'or finer' states", S05,
              kind="arithmetic", tolerance="the angle at its leading digit ('about'); the thesis' precision at most "
              "half the angle (its stated bound)", conditions="1.25 mm slices, 44 mm head", same_subjects=True,
              data="05_slice_sampling/nyquist.csv")
if stair is not None:
    fine = stair.sort_values("precision_deg")
    rms = fine.gap_vs_smooth_rms_mm
    claim("Sec. 3.5.2", "precisions finer than the Nyquist precision gain nothing on sliced data",
          "1.5 deg suffices", f"gap RMS against the smooth head {span(rms, 4)} mm from {n(fine.precision_deg.max())} to "
          f"{n(fine.precision_deg.min())} deg", "holds" if (rms.max() - rms.min()) < 0.01 else "partly",
          "a staircase (voxel) head sampled at every precision: the error is the staircase's, not the map's", S05,
      kind="measured", tolerance="RMS range under 0.01 mm", conditions="a staircase (voxel) head, every precision", same_subjects=True)

# --- 06: conchoid (Sec. 5.1, Table 10, Fig. 53, 58-59) -------------------------------------------------------
ln, t10, ang = (csv_of("06_conchoid_sampling", f) for f in ("length.csv", "table10.csv", "angles.csv"))
seg = csv_of("06_conchoid_sampling", "segments.csv")
S06 = "06_conchoid_sampling"
if ln is not None:
    exact = float(ln.length_over_b.iloc[0])
    closed = ln[ln.variant.str.contains("closed form")]
    ours = float(closed.length_over_b.iloc[0]) if len(closed) else exact
    claim("Sec. 5.1; Eq. 14", "the conchoid's quarter curve (a = 1.15 b) is 3.03 b long", "3.03 b",
          f"{ours:.4f} b by the thesis' closed form (a = 1.15 b, 2.3 b^2); {exact:.4f} b by quadrature of Eq. 14",
          "holds" if printed_equal(ours, "3.03") else "does_not_hold",
          f"the thesis' own closed form recomputed equals its 3.03 at the last digit; the exact length (GSL QAGS with "
          f"Menschik's a and b) is {100 * (exact / ours - 1):.1f} % longer", S06,
          kind="arithmetic", tolerance="the thesis' last printed digit", conditions="Menschik's a = 1.15 b",
          same_subjects=True, data="06_conchoid_sampling/length.csv")
if t10 is not None:
    d = float((abs(t10.eq16_deg - t10.thesis_adjusted_deg)).max())
    claim("Table 10", "Eq. 16 moves the 30 deg rays to 27, 56 and 90 deg",
          ", ".join(n(x) for x in t10.thesis_adjusted_deg) + " deg", ", ".join(f"{x:.1f}" for x in t10.eq16_deg) + " deg",
          "holds" if d < 0.5 else "does_not_hold", f"within {d:.2f} deg (the thesis rounds to whole degrees)", S06,
      kind="arithmetic", tolerance="0.5 deg", conditions="Eq. 16 with the thesis' constants", same_subjects=True)
if ang is not None:
    lo = float(ang.eq16_adjustment_deg.min())
    at = float(ang.original_deg[ang.eq16_adjustment_deg.idxmin()])
    claim("Fig. 58; Fig. 59; Ch. 6", "at p = 0.1 deg the largest adjustment is -4 deg, for the rays in the middle",
          "-4 deg", f"{lo:.2f} deg at {at:.0f} deg", "holds" if round(lo) == -4 else "does_not_hold",
          "Eq. 16 over 901 rays; the exact arc length gives nearly the same", S06,
      kind="arithmetic", tolerance="rounds to -4 deg", conditions="p = 0.1 deg, 901 rays", same_subjects=True)
if seg is not None:
    full = seg[seg.ray_to_deg - seg.ray_from_deg > 0.999]  # whole 1-deg segments (the last one is cut short)

    def longer(origin):
        g = full[full.origin == origin]
        return 100 * (g.length_mm.max() / g.length_mm.min() - 1), g.loc[g.length_mm.idxmax()]

    ours, at = longer("conchoid_origin")
    claim("Fig. 53", "with the origin at the conchoid's origin, equal-angle rays cut segments up to 30 % longer at "
          "the bottom than at the top", "30 %", f"{ours:.0f} %, longest at phi = {at.phi_from_deg:.0f} deg",
          "holds" if abs(ours - 30) <= 5 and at.phi_from_deg < 45 else "does_not_hold",
          "curve length between rays 1 deg apart with Menschik's a and b: (a + b) / sqrt(a^2 + b^2) at the ends; the "
          "thesis' figure understates it" if abs(ours - 30) > 5 else "curve length between rays 1 deg apart", S06,
      kind="arithmetic", tolerance="the longest segments where the thesis has them, and 30 +- 5 %", conditions="Menschik's a and b; rays 1 deg apart", same_subjects=True)
    (c1, at1), (c2, at2) = longer("object_centroid"), longer("object_extent_middle")
    middle = all(10 < x.phi_from_deg < 80 for x in (at1, at2))
    inside = min(c1, c2) <= 20 <= max(c1, c2)
    claim("Fig. 53", "with the origin at the object's centre, the segments in the middle are up to 20 % longer than "
          "at the bottom", "20 %, in the middle", f"{c1:.0f} % (area centroid) or {c2:.0f} % (middle of the extent), "
          f"longest at phi = {at1.phi_from_deg:.0f} (area centroid) or {at2.phi_from_deg:.0f} deg (middle of the extent)",
          "holds" if inside and middle else "does_not_hold", "the thesis does not define the centre; 20 % lies between our two readings of it, but the "
          "longest segments are at the rim end, not in the middle", S06,
      kind="arithmetic", tolerance="the longest segments in the middle, and 20 % between our two readings of the centre", conditions="Menschik's a and b; rays 1 deg apart", same_subjects=True)
else:
    missing("Fig. 53", "equal-angle segments up to 20 % (object centre) or 30 % (conchoid origin) longer",
            "20 %; 30 %", "segments.csv", S06,
      kind="arithmetic", tolerance="--", conditions="--", same_subjects=True)

# Fig. 57: Table 10's rays on the conchoid, original and adjusted by Eq. 16; the figure holds when this run drew it
# and the adjusted rays cut the hip curve into more nearly equal segments than the original ones (Eq. 12's length
# between the rays, Menschik's a and b as the experiment's meta.json gives them).
if t10 is not None:
    meta06 = json.load(open(os.path.join(ROOT, S06, "meta.json")))["parameters"]
    a_, b_ = meta06["a_mm"], meta06["b_mm"]

    def cut(angles):
        out = []
        for p0, p1 in zip(angles[:-1], angles[1:]):
            p = np.linspace(np.radians(p0), np.radians(p1), 2001)
            f = np.sqrt(a_ ** 2 + b_ ** 2 + 2 * a_ * b_ * np.cos(p))
            out.append(float(np.sum((f[1:] + f[:-1]) / 2 * np.diff(p))))
        return np.array(out)
    so, sa = cut(list(t10.original_deg)), cut(list(t10.eq16_deg))
    k57, v57 = drawn(f"{S06}/fig57.pdf")
    claim("Fig. 57", "sampling rays: original (dashed) and adjusted (solid)", "the adjusted rays",
          f"segments {', '.join(f'{x:.1f}' for x in so)} mm (original) and {', '.join(f'{x:.1f}' for x in sa)} mm "
          f"(Eq. 16) ({k57} figure)", v57 if np.ptp(sa) < np.ptp(so) else "does_not_hold",
          "Table 10's rays drawn on r = a + b cos(phi); the adjusted rays' segments more nearly equal", S06,
          kind="qualitative", tolerance="the figure drawn from the same quantity; the adjusted segments' spread below "
          "the original's", conditions="Table 10 (30 deg, 4 rays), Menschik's a and b", same_subjects=True,
          data=f"{S06}/table10.csv; {S06}/meta.json; {S06}/fig57.pdf")
else:
    missing("Fig. 57", "sampling rays: original and adjusted", "the adjusted rays", "table10.csv", S06,
            kind="qualitative", tolerance="--", conditions="--", same_subjects=True)

# --- 07: helix traveled distance (Eq. 10) -------------------------------------------------------------------
ie, selfc = csv_of("07_helix_arc_length", "index_errors.csv"), csv_of("07_helix_arc_length", "self_consistent.csv")
S07 = "07_helix_arc_length"
if ie is not None:
    # One row for Eq. 10 (issue 82: it had two): the thesis' helix has nodes at equal arc length, so the locator is
    # judged against the exact arc length's nodes; the self-consistent reading (nodes placed by Eq. 10 too) beside it.
    big = ie.sort_values("turns").iloc[-1]
    sc_text = ""
    if selfc is not None and len(selfc):
        fine = selfc[selfc.turns >= 229]
        sc_text = (f"; read self-consistently (nodes placed by Eq. 10 too) the location is exact and the node spacing "
                   f"within 10 % of the exact helix's over {100 * fine.share_within_10pct.min():.3f} % of the intervals "
                   f"(k >= 229), at most {selfc.max_spacing_ratio.max():.2f}x at a pole")
    within = big.fraction_differing == 0
    claim("Eq. 10", "Eq. 10's traveled distance locates a direction's neighbouring helix nodes", "locates them",
          f"{100 * big.fraction_differing:.0f} % of stencils differ from the exact arc length's at k = "
          f"{int(big.turns)}, by at most {int(big.max_node_index_difference)} node" + sc_text,
          measured_verdict(bool(within), bool(big.max_node_index_difference <= 1)),
          "Eq. 10 approximates the arc length to within half a step, so a direction near a node's boundary gets the "
          "neighbouring node: the look-up works (within one node), its stencil is not the nearest; with the nodes "
          "placed by Eq. 10 as well the two agree, at the price of an uneven spacing near the poles", S07,
          kind="measured", tolerance="the nearest nodes' stencil (direction: within one node)",
          conditions=f"k = {int(ie.turns.min())}-{int(ie.turns.max())}, {int(big.directions):,} directions; nodes at equal exact arc length (self-consistent reading beside)",
          same_subjects=True, data="07_helix_arc_length/index_errors.csv; 07_helix_arc_length/self_consistent.csv")

# Figs. 47-48: the helix drawn from the scheme's own nodes (helix_nodes.csv) and one direction's look-up on the k = 10
# helix (helix_locate.csv): the figure holds when this run drew it from the same quantity and, for Fig. 47, the node
# counts are the thesis' w = k^2; for Fig. 48, when the stencil is two nodes on each turn around P_a and P_b (the
# thesis' three steps) by the exact and the Eq. 10 locator.
hn, hl = csv_of(S07, "helix_nodes.csv"), csv_of(S07, "helix_locate.csv")
if hn is not None and len(hn):
    counts = hn.groupby("turns").size()
    k47, v47 = drawn(f"{S07}/fig47.pdf")
    square = bool(all(int(c) == int(k) ** 2 for k, c in counts.items()))
    claim("Fig. 47", "k-turn spherical helices on the unit sphere: k = 10, 20, 40 with w = 100, 400, 1600 points",
          "w = k^2: 100, 400, 1600", "w = " + ", ".join(f"{int(c):,}" for c in counts) + f" nodes of the helix scheme "
          f"at k = " + ", ".join(str(int(k)) for k in counts.index) + f" on Eq. 9's curve ({k47} figure)",
          v47 if square else "does_not_hold", "the scheme's node_direction for each node, drawn on the sphere", S07,
          kind="qualitative", tolerance="the figure drawn from the same quantity; the counts equal k^2",
          conditions="the helix scheme (exact arc length) at k = 10, 20, 40", same_subjects=True,
          data=f"{S07}/helix_nodes.csv; {S07}/fig47.pdf")
else:
    missing("Fig. 47", "k-turn spherical helices with w = k^2 points", "100, 400, 1600", "helix_nodes.csv", S07,
            kind="qualitative", tolerance="--", conditions="--", same_subjects=True)
if hl is not None and len(hl):
    pts = hl.set_index("point")
    k48, v48 = drawn(f"{S07}/fig48.pdf")

    def brackets(g):
        g = g.sort_values("steps")
        return bool(g.steps.iloc[0] <= pts.loc["P_a", "steps"] <= g.steps.iloc[1]
                    and g.steps.iloc[2] <= pts.loc["P_b", "steps"] <= g.steps.iloc[3])
    ok = {loc: brackets(g) for loc, g in hl[hl.locator != "--"].groupby("locator")}
    claim("Fig. 48", "a direction's four neighbouring helix points: two on the turn above (around P_a) and two on the "
          "turn below (around P_b), found by their traveled distances", "P_0, P_1 around P_a; P_2, P_3 around P_b",
          f"k = 10, v at phi = {pts.loc['v', 'phi_deg']:.0f}, theta = {pts.loc['v', 'theta_deg']:.0f} deg: P_a at "
          f"{pts.loc['P_a', 'steps']:.2f} and P_b at {pts.loc['P_b', 'steps']:.2f} node steps; stencil "
          + "; ".join(f"{loc} " + ", ".join(str(int(x)) for x in g.node) for loc, g in hl[hl.locator != "--"]
                      .groupby("locator")) + f" ({k48} figure)",
          v48 if all(ok.values()) else "does_not_hold",
          "the scheme's stencil for v (interpolate) against the traveled distances of P_a and P_b", S07,
          kind="qualitative", tolerance="the figure drawn from the same quantity; the stencil brackets P_a and P_b",
          conditions="the helix scheme at k = 10, one direction; exact and Eq. 10 locators", same_subjects=True,
          data=f"{S07}/helix_locate.csv; {S07}/fig48.pdf")
else:
    missing("Fig. 48", "a direction's four neighbouring helix points", "P_0-P_3", "helix_locate.csv", S07,
            kind="qualitative", tolerance="--", conditions="--", same_subjects=True)

# --- 08: distance maps (Fig. 31, 40-42, 50) -----------------------------------------------------------------
gs = csv_of("08_distance_maps", "gap_statistics.csv")
S08 = "08_distance_maps"
if gs is not None:
    eqm = gs[(gs.scheme == "equiangular")]
    cov_share = (eqm.map_nodes_covered / eqm.map_nodes).replace([np.inf], np.nan)
    k_maps, v_maps = drawn("08_distance_maps/maps_*.pdf")
    claim("Fig. 31; Fig. 40", "rasterising the triangles fills the LUT with sample points directly on the surface",
          "images", f"maps of {gs.subject.nunique()} hips at {span(eqm.precision_deg)} deg ({k_maps} figures), "
          f"{span(100 * cov_share, 3, ' %')} of nodes covered", v_maps,
          "every covered node's value is the ray's nearest hit (exact mode: checked against ray casts in experiment 10)",
          S08,
      kind="qualitative", tolerance="the figure drawn from the same quantity", conditions="our hips' maps at every "
      "precision", same_subjects=False, data="08_distance_maps/gap_statistics.csv; 08_distance_maps/maps_*.pdf")
    hx = gs[(gs.scheme == "helix") & (gs["mode"] == "exact") & (gs.vs_equiangular_compared > 0)]
    claim("Fig. 50", "USID gives the same impingement result as RSID", "the same colours",
          f"gaps differ by at most {n(hx.vs_equiangular_max_abs_mm.max())} mm (95th percentile "
          f"{n(hx.vs_equiangular_p95_abs_mm.max())} mm)", "holds" if hx.vs_equiangular_p95_abs_mm.max() < 0.1 else "partly",
          "the same vertices looked up in both maps at matched precision (exact mode)", S08,
      kind="measured", tolerance="95th percentile under 0.1 mm", conditions="exact mode, matched precision, the same vertices", same_subjects=True)
clock = csv_of("08_distance_maps", "red_clock_hours.csv")
clock = clock[(clock.red_vertices > 0) & ~clock.subject.isin(list(ROM_EXCLUDED))] if clock is not None else None
morph = csv_of("15_morphology", "morphology.csv")
if clock is not None and len(clock):
    share, chance = clock.share_in_thesis_hours, float(clock.thesis_hours_share_of_clock.iloc[0])
    cams = ""
    if morph is not None and len(morph):
        m = morph[morph.subject.isin(clock.subject)].set_index("subject").alpha_max_deg
        cams = ("; largest alpha angles " + ", ".join(f"{s_} {v:.1f} deg" for s_, v in m.items()) +
                f" (a cam above the 55 deg threshold on {int((m > 55).sum())} of {len(m)}, section 15)")
    claim("Fig. 42; Fig. 43", "on the CT hip the impinged socket regions (within 2 mm) lie at 12-4 and 8-9 o'clock, "
          "in the anterosuperior quadrant as Kubiak-Langer et al. 2007 report", "12-4 and 8-9 h",
          f"{span(100 * share, 2, ' %')} of our hips' red socket vertices there (those hours are "
          f"{100 * chance:.0f} % of the clock); mostly at " + "; ".join(
              f"{r.subject} {r.main_hours}" for r in clock.itertuples()) + cams,
          measured_verdict(bool((share >= 0.75).all()), bool((share > chance).mean() > 0.5)),
          "clock hour of every socket vertex within 2 mm at the scan pose; the thesis' patient is not available. "
          "lhdl-ct, also a CT hip, has a cam by its alpha angle, and its red zone still lies posterosuperior: the "
          "thesis' location does not carry over to it. mc22 is left out: " + ROM_EXCLUDED["mc22"], S08,
          kind="measured", tolerance="three quarters of the red socket vertices in those hours on every hip "
          "(direction: above the hours' share of the clock on most hips)",
          conditions="scan pose, clock hour of every socket vertex within 2 mm; our hips without mc22, not the "
          "thesis' patient", same_subjects=False,
          data="08_distance_maps/red_clock_hours.csv; 15_morphology/morphology.csv")
else:
    claim("Fig. 42; Fig. 43", "on the CT hip the impinged socket regions lie at 12-4 and 8-9 o'clock (matching "
          "Kubiak-Langer et al. 2007)", "12-4 and 8-9 h", "--", "not_testable",
          "the thesis' patient's mesh is not available; the clock hours of our hips' closest regions are in section "
          "09 (the ROM observation)", S08,
      kind="measured", tolerance="--", conditions="--", same_subjects=False)

# --- 09: ROM observation (Sec. 5.2, Tables 11-13, Fig. 60-63) ------------------------------------------------
obs = csv_of("09_rom_observation", "observation.csv")
S09 = "09_rom_observation"
claim("Table 11", "the six extremities of two FAI patients' recorded ROM (Vicon)", "as measured",
      "applied as clinical angles from anatomical neutral", "not_testable",
      "data of the thesis' patients; we apply them to our hips", S09,
      kind="measured", tolerance="--", conditions="--", same_subjects=False)
sectors = csv_of("09_rom_observation", "observation_sectors.csv")


def red_area_in_zones(patient, reverse=False):
    """The share of patient's extremities' red area (every hip) whose clock sector's middle lies in the thesis' zones
    (half an hour of slack, as for the closest point), on our clock or the horizontally reversed one; None without
    the sectors' data or red area."""
    if sectors is None or not len(sectors):
        return None
    g = sectors[(sectors.patient == patient) & ~sectors.subject.isin(list(ROM_EXCLUDED))]
    mid = (g.sector + 0.5) % 12
    inside = [in_clock_zones((12 - h) % 12 if reverse else h, THESIS_ROM_ZONES[patient]) for h in mid]
    total = g.red_area_mm2.sum()
    return float(g.red_area_mm2[inside].sum() / total) if total > 0 else None


OBS_DATA = "09_rom_observation/observation.csv; 09_rom_observation/observation_sectors.csv"
EXCL = ", ".join(f"{k} ({v})" for k, v in ROM_EXCLUDED.items())
if obs is not None and len(obs):
    obs = obs[~obs.subject.isin(list(ROM_EXCLUDED))]
    for item, patient, zones_text in (("Table 12", "A", "1-2 o'clock"), ("Table 13", "B", "1-3 and 7 o'clock")):
        g = obs[obs.patient == patient]
        hours = [h for h in g.socket_closest_clock_h if np.isfinite(h)]
        hits = sum(in_clock_zones(h, THESIS_ROM_ZONES[patient]) for h in hours)
        # The thesis shows its clock faces "horizontally reversed": read that way, an hour h is 12 - h of ours.
        reversed_hits = sum(in_clock_zones((12 - h) % 12, THESIS_ROM_ZONES[patient]) for h in hours)
        # Chance: the zones' share of the clock, with the half hour of slack either side.
        p0 = sum((b - a) + 1 for a, b in THESIS_ROM_ZONES[patient]) / 12
        p, p_rev = binomial_p(hits, len(hours), p0), binomial_p(reversed_hits, len(hours), p0)
        by_area, by_area_reversed = red_area_in_zones(patient), red_area_in_zones(patient, True)
        area_text = ("" if by_area is None else
                     f"; by area {100 * by_area:.0f} % of the red area lies in the zones "
                     f"({100 * by_area_reversed:.0f} % reversed)")
        claim(f"{item}; Sec. 5.2", f"at patient {patient}'s extremities the red zones (within 2 mm) lie at {zones_text}",
              zones_text, f"{hits} of {len(hours)} extremities over {g.subject.nunique()} hips, {p_text(p)} against "
              f"chance {100 * p0:.0f} % ({reversed_hits} of {len(hours)} on the horizontally reversed clock, "
              f"{p_text(p_rev)}){area_text}",
              chance_verdict(hits, len(hours), p),
              "the socket's closest point within half an hour of the thesis' zones, on our clock (3 o'clock anterior "
              "on both sides); ours are mostly posterosuperior, where our hips' joint space is thinnest", S09,
              kind="qualitative", tolerance=f"one-sided binomial test against the zones' share of the clock ({p0:.2f})",
              conditions=f"the thesis' extremities as clinical angles from anatomical neutral, our hips without {EXCL}",
              same_subjects=False, data=OBS_DATA)
    # Which extremities give the smallest gap (thesis sec. 5.2 under Tables 12 and 13): per hip, the thesis' motions
    # against the same number of motions with the least gap of both scans; chance: a sum of hypergeometrics.
    THESIS_SMALLEST = {"A": ["abduction", "internal_rotation", "flexion"],
                       "B": ["abduction", "adduction", "internal_rotation", "flexion"]}
    for item, patient in (("Table 12", "A"), ("Table 13", "B")):
        want = THESIS_SMALLEST[patient]
        g = obs[obs.patient == patient].assign(least=lambda x: np.fmin(x.ball_min_gap_mm, x.socket_min_gap_mm),
                                               red=lambda x: x.socket_area_0to2_mm2 + x.socket_area_penetrating_mm2)
        found, found_by_area, per_hip, draws = 0, 0, [], []
        for subject, h in g.groupby("subject", sort=False):
            smallest = list(h.sort_values("least").motion.iloc[:len(want)])
            found += sum(m in smallest for m in want)
            reddest = list(h.sort_values("red", ascending=False, kind="stable").motion.iloc[:len(want)])
            found_by_area += sum(m in reddest for m in want)
            per_hip.append(f"{subject}: {', '.join(m.replace('_', ' ') for m in smallest)}")
            draws.append((len(h), len(want), len(want)))
        total = len(want) * g.subject.nunique()
        p, p_area = hypergeometric_sum_p(found, draws), hypergeometric_sum_p(found_by_area, draws)
        claim(f"{item}; Sec. 5.2", f"at patient {patient}'s extremities {', '.join(m.replace('_', ' ') for m in want)} "
              "give the smallest gap between the bones",
              ", ".join(m.replace("_", " ") for m in want),
              f"{found} of {total} among each hip's {len(want)} smallest, {p_text(p)} against chance "
              f"({'; '.join(per_hip)}); by the largest red area instead, {found_by_area} of {total}, {p_text(p_area)}",
              chance_verdict(found, total, p),
              f"the least gap of both scans at each extremity; by chance the thesis' {len(want)} of the six motions "
              f"would put {100 * len(want) / 6:.0f} % of them among the {len(want)} smallest", S09,
              kind="qualitative", tolerance="one-sided test against chance: a sum over the hips of hypergeometric "
              "overlaps (the thesis' motions among as many drawn from six)",
              conditions="the thesis' extremities as clinical angles from anatomical neutral, 0.1 deg, exact mode, our "
              f"hips without {EXCL}", same_subjects=False, data=OBS_DATA)
    # Sec. 5.2's red zones, with a test that could fail (issue 82): every real socket is red at the scan pose already,
    # so the test is whether an extremity brings the bones closer than the scan pose does (least gap of both scans),
    # against a coin (p0 = 1/2: closer or farther by chance).
    if gs is not None:
        scan = gs[(gs.scheme == "equiangular") & (gs["mode"] == "exact") & np.isclose(gs.precision_deg, 0.1)]
        scan_gap = scan.groupby("subject").min_gap_mm.min()
        g = obs[obs.subject.isin(scan_gap.index)]
        least = np.fmin(g.ball_min_gap_mm, g.socket_min_gap_mm)
        closer = int((least < g.subject.map(scan_gap)).sum())
        red = g.socket_area_0to2_mm2 + g.socket_area_penetrating_mm2
        p = binomial_p(closer, len(g), 0.5)
        claim("Sec. 5.2", "the extremities bring the socket within 2 mm of the femur (red zones appear)", "red zones",
              f"the least gap is smaller than at the scan pose at {closer} of {len(g)} extremities, {p_text(p)} against "
              f"a coin; red area at {int((red > 0).sum())} of {len(g)} extremities (and at the scan pose on every "
              "hip, so its presence alone tests nothing)",
              chance_verdict(closer, len(g), p),
              "each hip's least gap at the thesis' extremities against its least gap at the scan pose", S09,
              kind="qualitative", tolerance="one-sided binomial test against 1/2 (closer or farther than the scan pose)",
              conditions=f"the thesis' extremities on our hips without {EXCL}; exact mode, 0.1 deg",
              same_subjects=False, data=OBS_DATA + "; 08_distance_maps/gap_statistics.csv")
else:
    missing("Table 12; Sec. 5.2", "patient A's red zones at 1-2 o'clock", "1-2 h", "observation.csv", S09,
            kind="qualitative", tolerance="--", conditions="--", same_subjects=False)
    missing("Table 13", "patient B's red zones at 1-3 and 7 o'clock", "1-3, 7 h", "observation.csv", S09,
            kind="qualitative", tolerance="--", conditions="--", same_subjects=False)
# Figs. 60-61: the cam is where the hip impinges. Every cam of 2 mm and more: the generated hip's (experiment 16,
# 2-4 mm) and the real femurs with a 3 mm cam added (mc22 left out). A cam impinges when it shortens a limit by more
# than 1 deg and at least half of the bone its plan removes lies on the cam (the contact is on the cam).
gen_cam, added_cam = csv_of("16_resection_planning", "generated.csv"), csv_of("16_resection_planning", "added_cam.csv")
cam = csv_of("09_rom_observation", "cam.csv")
if gen_cam is not None and len(gen_cam):
    units = []
    for mm, g in gen_cam[gen_cam.cam_mm >= 2].groupby("cam_mm"):
        cut = g.limit_free_deg - g.limit_cam_deg
        units.append((f"generated {mm:g} mm", float(cut.max()), float(g.on_cam_share.fillna(0).max()),
                      ", ".join(f"{m.replace('_', ' ')} {a:.1f}->{b:.1f}" for m, a, b in
                                zip(g.motion, g.limit_free_deg, g.limit_cam_deg) if a - b > 1)))
    if added_cam is not None and len(added_cam):
        for subject, g in added_cam[~added_cam.subject.isin(list(ROM_EXCLUDED))].groupby("subject", sort=False):
            cut = (g.limit_free_deg - g.limit_cam_deg).fillna(0)
            units.append((f"{subject} +{g.cam_mm.iloc[0]:g} mm", float(cut.max()),
                          float(g.on_cam_share.fillna(0).max()), ""))
    impinges = [u for u in units if u[1] > 1 and u[2] >= 0.5]
    facts.update(CamsImpinge=str(len(impinges)), Cams=str(len(units)))
    cam2 = ""
    if cam is not None and len(cam):
        with2 = cam[(cam.cam_mm == 2) & np.isfinite(cam.cam_height_at_contact_mm)]
        cam2 = (f"; with the 2 mm cam the contact stands at most {n(with2.cam_height_at_contact_mm.max(), 2)} mm on "
                "it (the neck meets the rim first)")
    claim("Fig. 60; Fig. 61", "the cam region (the femoral head outside its fitted sphere) is where the hip impinges "
          "at the extremities", "red circles on the cam",
          f"{len(impinges)} of {len(units)} cams shorten a limit and are where the plan removes bone: "
          + "; ".join(f"{u[0]}: limit cut {u[1]:.1f} deg, {100 * u[2]:.0f} % of the plan on the cam"
                      + (f" ({u[3]})" if u[3] else "") for u in units) + cam2,
          measured_verdict(len(impinges) == len(units), len(impinges) > 0),
          "cams of 3 mm and more reach the rim and limit the motion there; a 2 mm cam does not reach it (and the "
          f"patients' meshes are not available); mc22 left out: {ROM_EXCLUDED['mc22']}", S09,
          kind="measured", tolerance="every cam shortens a limit by more than 1 deg with at least half of its plan on "
          "the cam (direction: some do)",
          conditions=f"the generated hip with 2, 3 and 4 mm cams; the real femurs with a 3 mm cam added, without {EXCL}",
          same_subjects=False, data="16_resection_planning/generated.csv; 16_resection_planning/added_cam.csv; "
          "09_rom_observation/cam.csv")
else:
    missing("Fig. 60; Fig. 61", "the cam region is where the hip impinges", "red circles on the cam", "generated.csv",
            S09, kind="measured", tolerance="--", conditions="--", same_subjects=False)
# The single-layer LUT's reach (issue 51, item 2): with layered maps, the limits counting every vertex and where the
# bones meet first (extra_articular.csv); a single-layer map has no place for the vertices behind each bone's first
# surface, so an extra-articular first contact is one it cannot see.
xa = csv_of("09_rom_observation", "extra_articular.csv")
if xa is not None and len(xa):
    xa = xa[~xa.subject.isin(list(ROM_EXCLUDED))]
    every = xa[(xa.counted == "all") & (xa.validated != "no_limit")]
    outside = every[every.limited_by == "extra_articular"]
    facts.update(ExtraLimits=str(len(outside)), AllLimits=str(len(every)))
    claim("Ch. 6", "one layer of distance field suffices: the subjects have one spherical surface affected by the "
          "impingement (multiple layers by distance offsets)", "one layer suffices",
          f"{len(outside)} of {len(every)} limits (counting every vertex, layered maps) end where the bones meet "
          f"outside the joint first, on {outside.subject.nunique()} of {every.subject.nunique()} hips",
          measured_verdict(len(outside) == 0, len(outside) < len(every) / 2),
          "a single-layer map keeps each bone's first surface seen from the centre: the trochanters, the ischium and "
          "the ilium behind it have no place in it, and an offset of the same layer does not add them (the thesis' "
          f"ch. 6 names multiple layers as future work); layered maps add them; mc22 left out: {ROM_EXCLUDED['mc22']}",
          S09, kind="measured", tolerance="no limit ending outside the joint (direction: most limits inside it)",
          conditions="the standard motions and two with external rotation, layered maps of 4 crossings, 0.1 deg, our "
          f"hips without {EXCL}", same_subjects=True, data="09_rom_observation/extra_articular.csv")
k_med, v_med = drawn("09_rom_observation/medial_*.pdf")
claim("Fig. 62; Fig. 63", "the scene: femur rotated about the head centre, socket seen from the medial side",
      "images", f"medial views with the clock face (section 09: {k_med} figures)", v_med, "same set-up, our hips", S09,
      kind="qualitative", tolerance="the figure drawn from the same quantity", conditions="our hips, medial view",
      same_subjects=False, data="09_rom_observation/medial_*.pdf")

# --- 12: sphere fit (Sec. 3.4, Fig. 38-39) -------------------------------------------------------------------
real, syn = csv_of("12_sphere_fit", "real.csv"), csv_of("12_sphere_fit", "synthetic.csv")
S12 = "12_sphere_fit"
if syn is not None:
    g = syn[(syn.method == "geometric") & (syn.noise_mm == 0) & (syn.cam_mm == 0)]
    claim("Sec. 3.4; Fig. 38", "the least-squares sphere fit (Eberly) gives the head's centre as the COR", "the method",
          f"centre error {n(g.centre_error_mm.max())} mm without noise; real heads: RMS "
          f"{span(real[~real.subject.str.startswith('generated')].rms_mm) if real is not None else '--'} mm",
          "holds" if g.centre_error_mm.max() < 0.01 else "does_not_hold",
          "the fit on generated heads of known centre, and on the real heads' automatically found regions", S12,
      kind="measured", tolerance="centre error under 0.01 mm without noise", conditions="generated heads of known centre; real heads' found regions", same_subjects=True)
    k_res, v_res = drawn("12_sphere_fit/residuals_*.pdf")
    claim("Fig. 39", "a colour scale shows the surface's distance from the fitted sphere", "image",
          f"residual maps per hip ({k_res} figures)", v_res, "same quantity, our hips", S12,
          kind="qualitative", tolerance="the figure drawn from the same quantity", conditions="our hips",
          same_subjects=False, data="12_sphere_fit/residuals.csv; 12_sphere_fit/residuals_*.pdf")

# --- 13: the radial gap against closest-point distance (Sec. 3.6.1, Ch. 6) ----------------------------------
peers = csv_of("13_distance_peers", "distance_peers.csv")
ways = csv_of("13_distance_peers", "three_ways.csv")
rvd = csv_of("08_distance_maps", "radial_vs_distance.csv")
if ways is not None and len(ways):
    # Judged against a competent Open3D user (issue 82, item 3): a KD-tree cull to the vertices that can be within
    # reach, then Open3D's exact signed distance of those only, against impinge's detect_pose, paired round by round.
    # The naive way (every vertex: the whole-process table's per-pose rows) and impinge's own vertex set (which a user
    # cannot know beforehand) stand beside it; neither is the fair comparison.
    def per_hip(way, threads):
        g = ways[ways.threads == threads]
        return g.groupby("subject")[f"ratio_{way}_median"].median().tolist()
    one, two = ways[ways.threads == 1], ways[ways.threads == 2]
    lead = int((ways.ratio_culled_min > 1).sum())  # impinge faster in every paired round (the measured rule)
    lo_hi("CompetentOne", per_hip("culled", 1), 2)
    lo_hi("NaiveOne", per_hip("every", 1), 2)
    lo_hi("OwnOne", per_hip("own", 1), 2)
    if len(two):
        lo_hi("CompetentTwo", per_hip("culled", 2), 2)
    else:
        facts["CompetentTwoLow"] = facts["CompetentTwoHigh"] = "--"
    facts.update(CompetentHips=str(ways.subject.nunique()), CompetentLost=str(int(ways.culled_lost.sum())))
    agree = rvd[rvd.pose == "scan"].p95_abs_diff_mm if rvd is not None else pd.Series(dtype=float)
    two_text = (f", {span(per_hip('culled', 2), 2)}x at two threads ({', '.join(dict.fromkeys(two.subject))})"
                if len(two) else "")
    claim("Sec. 3.6.1; Ch. 6", "the map gives the surface-to-surface distance without extra cost, where a "
          "BVH must search its tree for every point", "O(n) against O(n log n)",
          f"per pose, a competent Open3D user (a KD-tree cull to the vertices within reach plus the longest edge, then "
          f"Open3D's exact signed distance of those; {int(ways.culled_lost.sum())} of impinge's vertices lost) takes "
          f"{span(per_hip('culled', 1), 2)}x impinge's time at one thread (per-hip medians of the paired ratios)"
          f"{two_text}; impinge faster in every paired round on {lead} of {len(ways)} hip-pose rows; beside it, "
          f"Open3D on every vertex {span(per_hip('every', 1), 2)}x and on impinge's own vertex set "
          f"{span(per_hip('own', 1), 2)}x; the radial gap against the closest-point distance: p95 |difference| "
          f"{span(agree, 2, ' mm')} per scan at the scan pose",
          measured_verdict(bool((ways.ratio_culled_min > 1).all() and (agree <= 0.1).all()),
                           bool(ways.ratio_culled_median.median() > 1)),
          "judged against a competent user's pipeline, the same answer side by side (issue 82): the naive ratio of "
          "the whole-process table's per-pose rows (section 13) sets Open3D on every vertex against impinge on the vertices within reach, and "
          "Open3D on impinge's own vertex set needs what only impinge's bounds know; the look-up is faster, but the "
          "radial gap is a distance along the ray, not the closest point's: they part where the ray grazes a bone "
          "(section 08)", "13_distance_peers",
          kind="measured", tolerance="faster than a competent Open3D user in every paired round of every hip-pose "
          "row, and the radial gap within 0.1 mm of the closest-point distance (p95); direction: "
          "faster on the median row",
          conditions="per pose, detect_pose against Open3D after a KD-tree cull, 1 and 2 threads, 5 alternated "
          "rounds; every real hip", same_subjects=True,
          data="13_distance_peers/three_ways.csv; 08_distance_maps/radial_vs_distance.csv")
elif peers is not None and len(peers):
    missing("Sec. 3.6.1; Ch. 6", "the map gives the surface-to-surface distance without extra cost",
            "O(n) against O(n log n)", "three_ways.csv (Open3D three ways)", "13_distance_peers", kind="measured",
            tolerance="--", conditions="--", same_subjects=True)
# Ch. 6 / sec. 3.6.2: an order of magnitude less computation and memory than a distance field on a 3D Cartesian grid,
# settled by arithmetic (issue 82): a grid over a cube just enclosing the joint (the 22 mm head's 44 mm and 8 mm of
# socket either side) at the spacing the map resolves on the head at 0.1 deg, against the map's nodes; any fill
# writes each value at least once, so the ratio bounds the computation too.
if lut is not None and t5 is not None:
    cube_mm, head_r = 60.0, float(t5.radius_mm.iloc[0])
    nodes01 = int(lut[(lut.scheme == "equiangular") & np.isclose(lut.matched_precision_deg, 0.1)].nodes.iloc[0])
    spacing_eq7 = float(t5[np.isclose(t5.precision_deg, 0.1)].eq7_mm.iloc[0])
    spacing_node = head_r * np.radians(0.1)
    voxels = {name: (cube_mm / h) ** 3 for name, h in (("Eq. 7", spacing_eq7), ("node", spacing_node))}
    ratio = min(voxels.values()) / nodes01
    claim("Ch. 6; Sec. 3.6.2", "RSID and USID need an order of magnitude less computation and memory than distance "
          "fields on 3D Cartesian grids", "10x less",
          f"a {cube_mm:.0f} mm cube at {spacing_eq7:.3f} mm (Eq. 7 at 0.1 deg) is {voxels['Eq. 7']:.2g} voxels, at the "
          f"node spacing on the head ({spacing_node:.4f} mm) {voxels['node']:.2g}; the map at 0.1 deg has "
          f"{nodes01:,} nodes: {ratio:,.0f}x fewer values (and writes)",
          "holds" if ratio >= 10 else "does_not_hold",
          "the field over the joint at the map's resolution, against the map; a fill writes each value at least "
          "once, so the ratio bounds the computation as well as the memory (an adaptive field, an octree, would "
          "need fewer: the thesis' claim is about uniform grids)", S01,
          kind="arithmetic", tolerance="at least 10x fewer values", conditions=f"a {cube_mm:.0f} mm cube enclosing "
          f"the joint, a {head_r:g} mm head, 0.1 deg", same_subjects=True,
          data="01_lut_memory/lut_memory.csv; 04_sampling_error/table5.csv")
else:
    missing("Ch. 6; Sec. 3.6.2", "an order of magnitude less than Cartesian distance fields", "10x less",
            "lut_memory.csv, table5.csv", S01, kind="arithmetic", tolerance="--", conditions="--", same_subjects=True)

claim("Ch. 6", "the systems extend to deformable models such as cartilage, because updating the sampled data of a "
      "deformed surface is very efficient; self-collision can be found in the same sampling step", "extends", "--",
      "not_testable", "no deformable surface is modelled here (rigid bones); a deformed surface's update is a new "
      "sampling, whose cost per map is in experiment 02 (Table 3's row)", S02,
      kind="qualitative", tolerance="--", conditions="--", same_subjects=True)

# --- 17: Joint3D in the browser (Sec. 3.4, Fig. 36, 41, 42, 44) ---------------------------------------------
# The thesis' Joint3D figures reproduced from impinge view's page: each figure row holds when this run drew the same
# quantity (the file named in data); Fig. 41's also needs every level of the page's legend on the bones it shows.
S17 = "17_viewer"
vw_images, vw_latency, vw_levels = csv_of(S17, "images.csv"), csv_of(S17, "latency.csv"), csv_of(S17, "levels.csv")
if vw_latency is not None and len(vw_latency):
    first = vw_latency.iloc[0]
    claim("Sec. 3.4", "Joint3D lets the user control the hip's motion and watch the impingement detected and the "
          "distances on the joint surfaces", "interactive system",
          f"impinge view: a page where sliders pose the hip and both bones are coloured by the library's detection; "
          f"{n(first.data_path_median_ms)} ms median from a pose to its values ({first.hip}, "
          f"{int(first.triangles):,} triangles)", "holds" if first.data_path_median_ms <= 30 else "partly",
          "the page's values at a pose equal impinge distance's files (tests/viewer); the draw is the browser's",
          S17, kind="measured", tolerance="a pose's values in the page within a frame of a slider's move (30 ms)",
          conditions=f"{first.resolution_deg:g} deg, distances on, 2 cores, headless Chromium", same_subjects=False,
          data=f"{S17}/latency.csv")
else:
    missing("Sec. 3.4", "Joint3D: control the motion, watch the impingement", "interactive system", "latency.csv",
            S17, kind="measured", tolerance="--", conditions="--", same_subjects=False)
VW_COND = "impinge view in headless Chromium (SwiftShader); our hips, not the thesis' patient"
if vw_images is not None and len(vw_images):
    def shots(figure):
        return vw_images[vw_images.figure == figure]
    k36, v36 = drawn(f"{S17}/fig36.pdf")
    f36 = shots("Fig. 36")
    claim("Fig. 36", "Joint3D: a right hip joint displayed from anterior view", "the hip from anterior",
          f"the page with {', '.join(sorted(set(f36.hip)))} from anterior, coloured by the levels ({k36} figure)",
          v36, "the page photographed at a pose", S17, kind="qualitative",
          tolerance="the figure drawn from the same quantity", conditions=VW_COND, same_subjects=False,
          data=f"{S17}/images.csv; {S17}/fig36.pdf")
    k42, v42 = drawn(f"{S17}/fig42.pdf")
    f42 = shots("Fig. 42")
    claim("Fig. 42", "the impingement result (the strain distribution) drawn on both models: the joint from anterior, "
          "the socket from the side, the femur", "three views", f"{len(f42)} pictures of {f42.hip.nunique()} hips at "
          f"the scan pose: both bones from anterior and lateral, the acetabulum from medial ({k42} figure)", v42,
          "the page's levels on both bones, photographed in three views; where the impinged regions lie is the "
          "clock-hour row (Fig. 42; Fig. 43)", S17, kind="qualitative",
          tolerance="the figure drawn from the same quantity", conditions=VW_COND, same_subjects=False,
          data=f"{S17}/images.csv; {S17}/fig42.pdf")
    k44, v44 = drawn(f"{S17}/fig44.pdf")
    f44 = shots("Fig. 44")
    claim("Fig. 44", "three visualisation options (filled polygons, lines, blending) in three views (anterior, medial, "
          "oblique)", "3 x 3 views", f"{len(f44)} pictures, {f44.display.nunique()} modes x {f44.view.nunique()} "
          f"views, from the page ({k44} figure)", v44 if len(f44) == 9 else "partly",
          "the page's display modes and view presets, photographed", S17,
          kind="qualitative", tolerance="the figure drawn from the same quantity (3 x 3 pictures)",
          conditions=VW_COND, same_subjects=False, data=f"{S17}/images.csv; {S17}/fig44.pdf")
else:
    for item, text in (("Fig. 36", "a right hip joint from anterior"), ("Fig. 42", "the result on both models"),
                       ("Fig. 44", "filled, lines, blending in three views")):
        missing(item, text, "figure", "images.csv", S17, kind="qualitative", tolerance="--", conditions="--",
                same_subjects=False)
k_lv, _ = drawn("08_distance_maps/levels.pdf")
k41, v41 = drawn(f"{S17}/fig41.pdf")
if vw_levels is not None and len(vw_levels) and k41:
    lv = vw_levels[vw_levels.level != 255]
    shown = {b: int((g.vertices > 0).sum()) for b, g in lv.groupby("bone")}
    every = lv.groupby("bone").size().max()
    r41 = vw_levels.iloc[0]
    FIG41_PAST = json.load(open(os.path.join(ROOT, S17, "meta.json")))["parameters"].get("fig41_past_limit_deg", "--")
    claim("Fig. 41", "five colour levels (none; four levels within the 4 mm cartilage offset, purple at contact) show "
          "the impingement level; the head moved into the socket to show them", "5 levels",
          f"{every} levels ({', '.join(re.sub(r'[0-9]+[.][0-9]+', lambda m: f'{float(m.group()):.3g}', x) for x in dict.fromkeys(lv.sort_values('level').range_mm))} mm) in the page's legend; "
          + ", ".join(f"{k} of {every} on the {b}" for b, k in shown.items())
          + f" of {r41.hip} at {r41.motion.replace('_', ' ')} {r41.flexion_deg:g}, {r41.adduction_deg:g}, "
          f"{r41.internal_rotation_deg:g} deg (past its ROM limit); the levels figure of section 08 beside "
          f"({k41 + k_lv} figures)",
          v41 if all(k == every for k in shown.values()) else "partly",
          "the page's levels (the library's, as every output gives them) photographed with its legend; the "
          "thresholds are parameters (--levels): the page's clinical preset splits 4 mm in thirds, section 08 uses "
          "6, 4, 2 and 0 mm", S17, kind="qualitative",
          tolerance="the figure drawn from the same quantity; every level of the legend on both bones",
          conditions=VW_COND + f"; {FIG41_PAST} deg past the first ROM limit", same_subjects=False,
          data=f"{S17}/levels.csv; {S17}/fig41.pdf; 08_distance_maps/levels.pdf")
else:
    claim("Fig. 41", "five colour levels after a 4 mm cartilage offset show the impingement level", "levels",
          "levels per vertex in every output (summary.json, PLY, VTP); the levels figure of section 08" if k_lv
          else "--", "holds" if k_lv else "not_testable",
          "the thresholds are parameters (--levels); section 08 uses 6, 4, 2 and 0 mm (the viewer's figure: not in "
          "this run)", "08_distance_maps", kind="qualitative", tolerance="the figure drawn from the same quantity",
          conditions="thresholds 6, 4, 2, 0 mm", same_subjects=True,
          data="08_distance_maps/gap_statistics.csv; 08_distance_maps/levels.pdf")

# --- write -------------------------------------------------------------------------------------------------
out = os.path.join(ROOT, "claims.csv")
with open(out, "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=COLUMNS)
    w.writeheader()
    w.writerows(rows)

tex_dir = os.path.join(ROOT, "claims")
os.makedirs(tex_dir, exist_ok=True)


label = {"holds": "holds", "partly": "partly", "does_not_hold": r"\textbf{does not hold}",
         "not_reproduced": "not reproduced on other subjects", "not_testable": "not testable"}
ragged = "".join(r">{\raggedright\arraybackslash}p{%s\textwidth}" % w
                 for w in ("0.08", "0.18", "0.085", "0.1", "0.17", "0.08", "0.215"))
lines = [r"\begin{longtable}{@{}" + ragged + "@{}}",
         r"\caption{The thesis' claims beside this run's data, with verdicts (\texttt{analysis/claims.py}, "
         r"\texttt{claims.csv}).}\label{tab:claims} \\",
         r"\toprule thesis & claim & kind & thesis' value & ours & verdict & why (tolerance; conditions) \\ \midrule "
         r"\endfirsthead",
         r"\toprule thesis & claim & kind & thesis' value & ours & verdict & why (tolerance; conditions) \\ \midrule "
         r"\endhead",
         r"\bottomrule \endfoot"]
for r in rows:
    cells = [latex_escape(r[k]) for k in ("thesis_item", "claim", "kind", "thesis_value", "our_value")]
    how = "; ".join(latex_escape(r[k]) for k in ("tolerance", "conditions") if r[k] != "--")
    why = (latex_escape(r["reason"]) + (f" ({how})" if how else "") + r" (\S\ref{sec:" + r["section"].replace("_", "-")
           + "})")
    lines.append(" & ".join(cells + [label[r["verdict"]], why]) + r" \\")
lines.append(r"\end{longtable}")
with open(os.path.join(tex_dir, "table_claims.tex"), "w") as f:
    f.write("\n".join(lines) + "\n")
# "What holds, in one page" (issue 51, item 5): every claim by verdict, one line each (its thesis item, what it says,
# the kind of evidence), ahead of the full table.
headings = {"holds": "Holds", "partly": "Holds in part", "does_not_hold": "Does not hold (refuted under the thesis' "
            "conditions)", "not_reproduced": "Not reproduced on our subjects (a claim about the thesis' patients or "
            "models; not a refutation)", "not_testable": "Not testable here"}
summary = [r"{\footnotesize"]
for v in VERDICTS:
    group = [r for r in rows if r["verdict"] == v]
    if not group:
        continue
    summary.append(r"\paragraph{%s (%d).}" % (headings[v], len(group)))
    summary.append(r"\begin{itemize}\setlength{\itemsep}{0pt}\setlength{\parskip}{0pt}")
    for r in group:
        summary.append(r"\item \textbf{%s} (%s): %s" % (latex_escape(r["thesis_item"]), r["kind"],
                                                      latex_escape(r["claim"])))
    summary.append(r"\end{itemize}")
summary.append("}")
with open(os.path.join(tex_dir, "summary.tex"), "w") as f:
    f.write("\n".join(summary) + "\n")

counts = {v: sum(r["verdict"] == v for r in rows) for v in VERDICTS}
# Counts per kind of evidence, so that the abstract does not add measured agreement, recomputed arithmetic and
# reproduced figures into one number (issue 51).
by_kind = {(k, v): sum(r["kind"] == k and r["verdict"] == v for r in rows) for k in KINDS for v in VERDICTS}

# The run's provenance for the front matter, from the drivers' meta.json files: the commit (or every commit,
# where the run is mixed), the machine, compiler and cores (the same in every driver), and the dates.
metas = []
for name in sorted(os.listdir(ROOT)):
    path = os.path.join(ROOT, name, "meta.json")
    if os.path.isfile(path):
        with open(path) as f:
            metas.append(json.load(f))
commits = sorted({m.get("git_commit", "") for m in metas})
dates = sorted(m["date"] for m in metas if m.get("date"))


def first(key):
    return next((str(m[key]) for m in metas if m.get(key)), "unknown")


def machine_text():
    """The CPU as the machine exposes it: model, family/model number, the clock the kernel reports, caches, memory
    and whether it is a virtual machine (every meta.json's machine block, provenance.hpp)."""
    m = next((m["machine"] for m in metas if isinstance(m.get("machine"), dict)), None)
    if m is None:
        return "unknown"
    parts = [m.get("cpu_model", "unknown")]
    if m.get("cpu_family", "unknown") != "unknown":
        parts[0] += f" (family {m['cpu_family']}, model {m.get('cpu_model_number', '?')})"
    try:
        parts.append(f"{float(m['cpu_mhz']) / 1000:.1f} GHz")
    except (KeyError, ValueError):
        pass
    if m.get("l3_cache", "unknown") != "unknown":
        parts.append(f"{m['l3_cache'].replace('K', ' KiB')} L3")
    if m.get("memory_gib", "unknown") != "unknown":
        parts.append(f"{m['memory_gib']} GiB")
    if m.get("hypervisor") == "yes":
        parts.append("a virtual machine")
    return ", ".join(parts)


# The ROM observation's p-values (the qualitative rows of section 09), for the conclusion's "chance level".
rom_tests = [[float(x) for x in __import__("re").findall(r"p = ([0-9.]+)", r["our_value"].split("(")[0])]
             for r in rows if r["section"] == S09 and r["kind"] == "qualitative"]
rom_p = [p[0] for p in rom_tests if p]
if rom_p:
    facts["RomPLow"], facts["RomPHigh"] = f"{min(rom_p):.2f}", f"{max(rom_p):.2f}"
    facts["RomRows"] = str(len(rom_p))
write_macros(tex_dir, "macros", {
    **{f"Concl{k}": latex_escape(v) for k, v in facts.items()},
    "ClaimsTotal": str(len(rows)), "ClaimsHolds": str(counts["holds"]), "ClaimsPartly": str(counts["partly"]),
    "ClaimsNot": str(counts["does_not_hold"]), "ClaimsUntestable": str(counts["not_testable"]),
    "ClaimsNotReproduced": str(counts["not_reproduced"]),
    **{f"Claims{k.capitalize()}{v.title().replace('_', '')}": str(by_kind[(k, v)]) for k in KINDS for v in VERDICTS},
    **{f"Claims{k.capitalize()}Total": str(sum(r["kind"] == k for r in rows)) for k in KINDS},
    "RunCommit": latex_escape(", ".join(c[:7] + ("-dirty" if c.endswith("-dirty") else "") for c in commits) or "unknown"),
    "RunCommits": str(len(commits)), "RunCpu": latex_escape(machine_text()), "RunCompiler": latex_escape(first("compiler")),
    "RunCores": latex_escape(first("cores")), "RunDates": latex_escape(dates[0][:10] if dates and dates[0][:10] == dates[-1][:10]
                                                     else f"{dates[0][:10]} to {dates[-1][:10]}" if dates else "unknown"),
})
print(f"claims: {len(rows)} rows ({', '.join(f'{v} {c}' for v, c in counts.items())}) -> {out}")
