"""The verdict rules of the claims table (analysis/claims.py), written once (issue 82, item 1).

Every row of claims.csv names its kind, and its verdict comes from the one rule of that kind below, applied to the
data the row names (its `data` column) under the conditions it names (its `conditions` column):

  measured     a value this run measured against the thesis' value or statement, with the tolerance the row
               states. holds: every value inside the tolerance; partly: the direction agrees everywhere (which
               method is faster, the sign of a change) but a value lies outside the tolerance, or one part of a
               compound claim holds and another does not; does_not_hold: the direction is contradicted. A claim
               that one method is faster than another is judged round by round: the faster in every one of the
               paired, alternated rounds (5 rounds: a one-sided sign test, p = 1/32 = 0.031).
  arithmetic   the thesis' formula or constant recomputed. holds: our value, rounded or truncated as the thesis
               prints it (its last printed digit; an "about" value at its leading digit), equals the thesis', or meets
               the bound the thesis states; does_not_hold otherwise; partly only where a compound claim has a part
               that holds and a part that does not.
  qualitative  a pattern the thesis shows (where red zones lie, which motions come closest). A count k of n units
               (extremities, hips, motions) shows it, against the chance p0 that a unit shows it if the claim were
               false: a one-sided exact binomial test (a sum of hypergeometrics where units are drawn without
               replacement). holds: p < 0.05 and k >= 3/4 n; partly: p < 0.05 and k < 3/4 n (above chance, not
               the thesis' size); does_not_hold: p >= 0.05 (chance level). A figure the thesis draws, with no
               number to compare: holds when this run drew the same quantity (the row names the file), else
               not_testable.
Across kinds: a contradiction found on other subjects than the thesis' (its patients are not available) is
not_reproduced, never does_not_hold; a claim this run cannot measure is not_testable with the reason.
ROM verdicts (the extremities, the limits, the cams) leave mc22 out: its femur and pelvis segmentations overlap
(the bones interpenetrate by 1.6 mm at the scan pose, section 08), so its limits are the overlap's, not a joint's."""
from math import comb

ALPHA = 0.05
MAJORITY = 0.75
# A frame at 60 Hz: what "real time" means in every row that judges it.
FRAME_MS = 1000 / 60
# The thesis' clock: Windows' default timer resolution, 15.625 ms (its times are whole ticks: 15/16, 62, 187 ms).
THESIS_TICK_MS = 15.625
ROM_EXCLUDED = {"mc22": "its segmentations overlap (the bones interpenetrate by 1.6 mm at the scan pose)"}

RULES = {
    "measured": "every value within the row's tolerance: holds; the direction agrees but not the size (or one part "
                "of the claim holds): partly; the direction contradicted: does not hold; faster = in every paired round "
                "(sign test, p = 1/32)",
    "arithmetic": "our value rounded or truncated to the thesis' last printed digit equals the thesis' (or meets its stated bound): holds; "
                  "else does not hold",
    "qualitative": "k of n units show the pattern; one-sided exact test against chance p0: p < 0.05 and k >= 3/4 n "
                   "holds, p < 0.05 and k < 3/4 n partly, p >= 0.05 (chance level) does not hold; a figure: holds "
                   "when drawn from the same quantity",
}


def binomial_p(k, n, p0):
    """One-sided exact binomial p-value P(X >= k), X ~ Bin(n, p0)."""
    return float(sum(comb(n, i) * p0 ** i * (1 - p0) ** (n - i) for i in range(k, n + 1)))


def hypergeometric_sum_p(k, draws):
    """One-sided p-value P(X >= k) of X = the sum of independent hypergeometric overlaps: draws is a list of
    (population N, marked K, drawn m) per unit (for example per hip: 6 motions, the thesis' m motions marked, the m
    smallest drawn)."""
    dist = {0: 1.0}
    for N, K, m in draws:
        one = {j: comb(K, j) * comb(N - K, m - j) / comb(N, m) for j in range(0, min(K, m) + 1)}
        new = {}
        for a, pa in dist.items():
            for b, pb in one.items():
                new[a + b] = new.get(a + b, 0.0) + pa * pb
        dist = new
    return float(sum(p for x, p in dist.items() if x >= k))


def chance_verdict(k, n, p):
    """The qualitative rule: holds / partly / does_not_hold from k of n units and the one-sided p-value."""
    if n == 0:
        return "not_testable"
    if p < ALPHA:
        return "holds" if k >= MAJORITY * n else "partly"
    return "does_not_hold"


def measured_verdict(within, direction):
    """The measured rule: within (every value inside the tolerance) and direction (the direction agrees)."""
    return "holds" if within and direction else "partly" if direction else "does_not_hold"


def compound_verdict(parts):
    """A claim of several parts (booleans): holds if all hold, does_not_hold if none, else partly."""
    parts = list(parts)
    return "holds" if all(parts) else "does_not_hold" if not any(parts) else "partly"


def printed_equal(ours, thesis_text):
    """The arithmetic rule: ours rounded or truncated to the last digit the thesis prints (thesis_text, e.g. "0.497",
    "3.03", "65,160") equals the thesis' value (a relative 1e-9 for floating point)."""
    t = thesis_text.replace(",", "").strip()
    decimals = len(t.split(".")[1]) if "." in t else 0
    value = float(t)
    unit = 10 ** -decimals
    rounded = abs(ours - value) <= 0.5 * unit * (1 + 1e-9) + 1e-12
    truncated = 0 <= (ours - value) * (1 if value >= 0 else -1) < unit * (1 + 1e-9)
    return rounded or truncated


def leading_digit_equal(ours, about):
    """An "about" value: ours rounded at the leading digit of `about` (20 -> tens) equals it."""
    import math
    unit = 10 ** math.floor(math.log10(abs(about)))
    return round(ours / unit) * unit == about


def p_text(p):
    """A p-value as the table prints it."""
    return "p < 0.001" if p < 0.001 else f"p = {p:.3f}" if p < 0.1 else f"p = {p:.2f}"
