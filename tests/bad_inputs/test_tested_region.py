"""Issue 80, cases 5/7: --max-radius and --sparse bound where contacts are tested (vertices within max-radius of the
COR; maps holding only the tiles with a surface within sparse of it). `--max-radius 10` tested no vertex and reported
every motion free; `--sparse 15`, below the femoral head, moved a ROM limit. A value below either bone's nearest
vertex is now a one-line error naming the option, the value, each bone's nearest vertex (mm from the COR, checked
here against the meshes) and the least value; one that reaches the joint surfaces but not the acetabular rim (found
at anatomical neutral) is a warning naming the rim; values beyond it change nothing here."""
import json
import os
import re

import numpy as np
import pytest

from conftest import DATA, one_line_error, run

LHDL = os.path.join(DATA, "lhdl-ct", "subject.json")


@pytest.fixture(scope="module")
def nearest(generated):
    """Each bone's nearest vertex to the generated hip's true COR (mm), from its mesh files."""
    impinge = pytest.importorskip("impinge")
    d = os.path.dirname(generated)
    cor = np.array(json.load(open(generated))["true_cor_mm"])
    return {bone: float(np.linalg.norm(impinge.load_mesh(os.path.join(d, f))[0] - cor, axis=1).min())
            for bone, f in (("femur", "femur_r.ply"), ("pelvis", "pelvis.ply"))}


def stated(line, pattern):
    return float(re.search(pattern, line).group(1))


@pytest.mark.parametrize("option, value, verb", [("--max-radius", 10, "reaches no vertex of"),
                                                 ("--sparse", 15, "keeps no surface of")])
def test_a_value_below_both_bones_is_an_error_naming_them(generated, nearest, tmp_path, option, value, verb):
    line = one_line_error(run(["distance", "--subject", generated, option, value, "--out", tmp_path / "o"]),
                          f"{option} {value} mm {verb} the femur", "nor of the pelvis", "no contact can be found")
    # The nearest vertices as stated (0.1 mm, rounded up), against the meshes (the COR found by the fit: 0.1 mm).
    assert stated(line, r"nearest vertex is ([\d.]+) mm") == pytest.approx(nearest["femur"], abs=0.2)
    assert stated(line, r"nor of the pelvis \(([\d.]+) mm\)") == pytest.approx(nearest["pelvis"], abs=0.2)
    assert stated(line, r"give at least ([\d.]+) mm") == pytest.approx(max(nearest.values()), abs=0.2)
    assert not (tmp_path / "o").exists()


def test_a_value_between_the_bones_names_the_one_it_misses(generated, nearest, tmp_path):
    between = round((nearest["femur"] + nearest["pelvis"]) / 2, 1)
    assert nearest["femur"] < between < nearest["pelvis"]
    line = one_line_error(run(["distance", "--subject", generated, "--max-radius", between, "--out", tmp_path / "o"]),
                          f"--max-radius {between:g} mm reaches no vertex of the pelvis")
    assert "femur" not in line


def test_values_reaching_both_bones_run(generated, nearest, tmp_path):
    beyond = round(max(nearest.values()) + 6, 1)
    for args in (["--max-radius", beyond], ["--sparse", beyond], ["--max-radius", 0], ["--sparse", "inf"]):
        r = run(["distance", "--subject", generated, *args, "--out", tmp_path / "o"])
        assert r.returncode == 0 and "warning: --" not in r.stderr, (args, r.stderr)


def test_python_says_the_same(generated):
    impinge = pytest.importorskip("impinge")
    with pytest.raises(impinge.Error, match=r"--max-radius 10 mm reaches no vertex of the femur"):
        impinge.Joint(subject=str(generated), resolution=2.0, max_radius_mm=10)
    with pytest.raises(impinge.Error, match=r"--sparse 15 mm keeps no surface of the femur"):
        impinge.Joint(subject=str(generated), resolution=2.0, sparse_region_mm=15)


@pytest.mark.skipif(not os.path.exists(LHDL), reason="shared data absent")
def test_a_value_inside_the_rim_warns_and_one_below_the_head_is_refused_on_a_real_hip(tmp_path):
    clean = run(["distance", "--subject", LHDL, "--pose", "60,10,20", "--out", tmp_path / "clean"])
    assert clean.returncode == 0, clean.stderr
    rim = json.load(open(tmp_path / "clean" / "summary.json"))["frames"]["acetabulum"]["rim_radius_mm"]
    inside = round(rim - 2, 1)
    for option in ("--max-radius", "--sparse"):
        r = run(["distance", "--subject", LHDL, "--pose", "60,10,20", option, inside, "--out", tmp_path / "o"])
        warnings = [x for x in r.stderr.splitlines() if x.startswith(f"impinge: warning: {option} ")]
        assert r.returncode == 0 and len(warnings) == 1, r.stderr
        assert f"{option} {inside:g} mm ends inside the acetabular rim (" in warnings[0], warnings[0]
        assert stated(warnings[0], r"rim \(([\d.]+) mm from the centre\)") == pytest.approx(rim, abs=0.1)
        # Below the head (the issue's --sparse 15): refused, as on the generated hip.
        one_line_error(run(["rom", "--subject", LHDL, "--preset", "thesis", option, 15, "--out", tmp_path / "r"]),
                       f"{option} 15 mm", "no contact can be found")
