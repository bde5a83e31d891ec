"""impinge morphology's inputs (issue 49): what it cannot measure is an error naming the file and the step, and says
what to give instead; a part bone measured in scan neutral says what it left out."""
import json
import os

from conftest import CLI, one_line_error, run  # noqa: F401


def generated(tmp_path):
    out = tmp_path / "gen"
    r = run(["generate", "--triangles", "3000", "--out", out])
    assert r.returncode == 0, r.stderr
    return out


def test_a_pelvis_that_is_no_whole_bone_is_an_error_naming_it_and_the_remedies(tmp_path):
    g = generated(tmp_path)
    r = run(["morphology", "--ball", g / "femur_r.ply", "--socket", g / "pelvis.ply", "--out", tmp_path / "m"])
    one_line_error(r, "pelvis.ply", "automatic pelvic landmarks", "landmarks in subject.json")
    assert not (tmp_path / "m" / "morphology.json").exists()


def test_scan_neutral_measures_a_part_bone_and_notes_what_it_left_out(tmp_path):
    g = generated(tmp_path)
    r = run(["morphology", "--ball", g / "femur_r.ply", "--socket", g / "pelvis.ply", "--neutral", "scan",
             "--out", tmp_path / "m"])
    assert r.returncode == 0, r.stderr
    m = json.load(open(tmp_path / "m" / "morphology.json"))
    assert m["femur"]["version_posterior_condylar_deg"]["value"] is None
    assert any("no femoral landmarks" in n for n in m["notes"])
    assert os.path.exists(tmp_path / "m" / "femur_sphericity.ply")


def test_a_side_that_contradicts_the_subject_is_an_error(tmp_path):
    g = generated(tmp_path)
    r = run(["morphology", "--subject", g / "subject.json", "--side", "left", "--out", tmp_path / "m"])
    one_line_error(r, "side 'left' contradicts", "subject.json")
