"""`impinge rom --labrum` (issue 81): the acetabular labrum end to end on a generated hip, and its options' bad values
as one line naming the option, the value and the valid range. Invariants: without --labrum nothing labral is written;
the labral limit is the first of the bony limit and the labrum's contact, so it never exceeds the bony one; a taller
labrum is met no later; a labrum of 0.2 mm lowers no limit by more than 1.5 deg (the bony limits come back);
labrum.ply is a closed ring of 3 vertices and 6 triangles per rim point."""
import csv
import json
import math

import pytest

from conftest import one_line_error, run


@pytest.fixture(scope="module")
def hip(tmp_path_factory):
    """A generated hip whose cup covers 80 deg from its pole (the labrum clear of the neck at neutral)."""
    d = tmp_path_factory.mktemp("labrum")
    r = run(["generate", "--triangles", "12000", "--coverage", "80", "--out", d / "g"])
    assert r.returncode == 0, r.stderr
    return d / "g" / "subject.json"


def rom(hip, out, *extra):
    r = run(["rom", "--subject", hip, "--out", out, "--precision", 1, "--no-map"] + [str(x) for x in extra])
    assert r.returncode == 0, r.stderr
    rows = list(csv.DictReader(open(out / "rom_limits.csv")))
    return rows, json.load(open(out / "summary.json"))


def num(x):
    return float("nan") if x in ("", "nan") else float(x)


def test_labral_limits_beside_the_bony_ones(hip, tmp_path):
    bony, s0 = rom(hip, tmp_path / "bony")
    assert "labral_limit_deg" not in bony[0] and "labrum" not in s0 and not (tmp_path / "bony" / "labrum.ply").exists()
    by_height = {}
    for h in (0.2, 3, 7):
        rows, s = rom(hip, tmp_path / f"h{h}", "--labrum", "--labrum-height", h)
        assert s["labrum"]["height_mm"] == h and s["labrum"]["excluded_vertices"] == 0, s["labrum"]
        for b, r in zip(bony, rows):
            assert r["limit_deg"] == b["limit_deg"], "the bony columns change with --labrum"
            if r["status"] == "limited":
                assert num(r["labral_limit_deg"]) <= num(r["limit_deg"]), r
        by_height[h] = {r["motion"]: r for r in rows}
    for m, r in by_height[0.2].items():
        if r["status"] == "limited" and r["labral_status"] == "limited":
            assert num(r["labral_lowering_deg"]) <= 1.5, (m, r)
    lowered = 0
    for m in by_height[3]:
        lo, mid, hi = (num(by_height[h][m]["labrum_contact_deg"]) for h in (0.2, 3, 7))
        if not math.isnan(hi):
            assert hi <= mid + 0.2 and mid <= lo + 0.2, (m, lo, mid, hi)
            lowered += by_height[7][m]["labral_contact_class"] == "labral"
    assert lowered >= 4, by_height[7]
    # labrum.ply: a ring of 3 vertices and 6 triangles per rim point.
    head = open(tmp_path / "h7" / "labrum.ply", "rb").read(400).decode("latin-1")
    nv = int(head.split("element vertex ")[1].split()[0])
    nf = int(head.split("element face ")[1].split()[0])
    assert nv % 3 == 0 and nf == 2 * nv and nv >= 3 * 36, (nv, nf)


@pytest.mark.parametrize("args,fragments", [
    (["--labrum-width", "0"], ["--labrum-width", "0 mm", "(0, 15] mm"]),
    (["--labrum-width", "-2"], ["--labrum-width", "-2 mm", "(0, 15] mm"]),
    (["--labrum-height", "0"], ["--labrum-height", "0 mm", "(0, 15] mm"]),
    (["--labrum-height", "100"], ["--labrum-height", "100 mm", "(0, 15] mm"]),
    (["--labrum-height", "nan"], ["--labrum-height", "nan"]),
])
def test_bad_labrum_options_are_one_line_errors_naming_them(hip, tmp_path, args, fragments):
    r = run(["rom", "--subject", hip, "--out", tmp_path / "r", "--precision", 2, "--labrum"] + args)
    one_line_error(r, *fragments)
    assert not (tmp_path / "r" / "rom_limits.csv").exists()
