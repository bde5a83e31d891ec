"""Landmarks checked against the bones (issue 48, item 2). Invariants: swapped ASIS, a landmark 1e6 mm away, and
a misspelled key of subject.json are one-line errors naming the landmark or key (they gave a scan pose of 177 deg
flexion, a least gap of -118 mm, or were dropped without a word); the landmarks impinge finds pass the same
checks (the clean subject runs)."""
import json
import os

import pytest

from conftest import DATA, one_line_error, run

SUBJECT = os.path.join(DATA, "lhdl-ct", "subject.json")
pytestmark = pytest.mark.skipif(not os.path.exists(SUBJECT), reason="shared data absent")


@pytest.fixture(scope="module")
def found(tmp_path_factory):
    """The pelvic landmarks impinge finds on lhdl-ct (input frame), from a clean run."""
    out = tmp_path_factory.mktemp("clean") / "o"
    r = run(["distance", "--subject", SUBJECT, "--precision", "2", "--out", out])
    assert r.returncode == 0, r.stderr
    lm = json.load(open(out / "summary.json"))["frames"]["pelvis"]["landmarks"]
    return {k: v["position_mm"] for k, v in lm.items()}


def subject_with(tmp_path, **changes):
    s = json.load(open(SUBJECT))
    base = os.path.dirname(SUBJECT)
    s["femur"], s["pelvis"] = os.path.join(base, s["femur"]), os.path.join(base, s["pelvis"])
    s.update(changes)
    p = tmp_path / "subject.json"
    p.write_text(json.dumps(s))
    return p


def test_swapped_asis_are_named(tmp_path, found):
    p = subject_with(tmp_path, landmarks={"asis_right": found["asis_left"], "asis_left": found["asis_right"]})
    r = run(["distance", "--subject", p, "--precision", "2", "--out", tmp_path / "o"])
    one_line_error(r, "asis_right (given) and asis_left (given) are swapped")


def test_a_landmark_far_away_is_named(tmp_path, found):
    p = subject_with(tmp_path, landmarks={"asis_right": [1e6, 0, 0]})
    r = run(["distance", "--subject", p, "--precision", "2", "--out", tmp_path / "o"])
    one_line_error(r, "landmark asis_right (given) lies", "mm from the hip centre")


@pytest.mark.parametrize("key,fragment", [("landmark", "unknown key 'landmark'"), ("sied", "unknown key 'sied'")])
def test_a_misspelled_key_is_named(tmp_path, key, fragment):
    p = subject_with(tmp_path, **{key: {}})
    r = run(["distance", "--subject", p, "--precision", "2", "--out", tmp_path / "o"])
    one_line_error(r, fragment)


def test_a_misspelled_landmark_is_named(tmp_path, found):
    p = subject_with(tmp_path, landmarks={"asis_rigth": found["asis_right"]})
    r = run(["distance", "--subject", p, "--precision", "2", "--out", tmp_path / "o"])
    one_line_error(r, "unknown name 'asis_rigth'")


def test_a_misspelled_landmark_keyword_in_python_is_named():
    impinge = pytest.importorskip("impinge")
    with pytest.raises(impinge.Error, match="landmarks: unknown name 'asis_rigth'"):
        impinge.Joint(subject=SUBJECT, landmarks={"asis_rigth": [0, 0, 0]})


@pytest.mark.parametrize("args,fragments", [
    (["--side", "left"], ["side left: the femoral head lies", "to the right of the pelvis' centre", "--side"]),
    (["--frame", "RAS"], ["side right: the femoral head lies", "read as RAS", "(--frame) is wrong"]),
    (["--cor", "1e300,0,0", "--allow-any-cor"], ["outside the femur's bounding box"]),
])
def test_a_wrong_side_frame_or_centre_is_named(tmp_path, args, fragments):
    base = os.path.dirname(SUBJECT)
    r = run(["distance", "--ball", os.path.join(base, "femur_r.ply"), "--socket", os.path.join(base, "pelvis.ply"),
             "--precision", "2", "--out", tmp_path / "o"] + (["--frame", "LPS"] if "--frame" not in args else [])
            + args)
    one_line_error(r, *fragments)


def test_the_same_mesh_twice_is_named(tmp_path):
    femur = os.path.join(os.path.dirname(SUBJECT), "femur_r.ply")
    r = run(["distance", "--ball", femur, "--socket", femur, "--frame", "LPS", "--out", tmp_path / "o"])
    one_line_error(r, "ball and socket are the same file")
