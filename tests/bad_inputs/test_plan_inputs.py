"""`impinge plan`'s inputs (issue 50): a bad target, motion file or option (--labrum with --resect pelvis, issue 81)
is one line naming it, before anything is written; a motion file as a target is read as `impinge motion` reads it,
and the plan frees its frames.
Invariant: no plan.json is written when the inputs are refused."""
import json

import pytest

from conftest import one_line_error, run


@pytest.fixture(scope="module")
def cam(tmp_path_factory):
    d = tmp_path_factory.mktemp("cam")
    r = run(["generate", "--triangles", "6000", "--cam", "3", "--out", d / "g"])
    assert r.returncode == 0, r.stderr
    return d / "g" / "subject.json"


@pytest.mark.parametrize("args,fragments", [
    (["--target", "flexon=120"], ["'flexon' is not a standard motion; valid: flexion"]),
    (["--target", "flexion=200"], ["--target flexion=200: the angle must lie in (0, 150] deg"]),
    (["--target", "flexion=abc"], ["--target flexion", "abc"]),
    (["--target", "flexion"], ["'flexion' is not MOTION=DEG or 'normal'"]),
    (["--target", "flexion=100,flexion=60"], ["--target: flexion given twice (flexion=100 and flexion=60)"]),
    ([], ["no target: give --target"]),
    (["--target-motion", "/nonexistent/walk.mot"], ["/nonexistent/walk.mot"]),
    (["--target", "flexion=60", "--clearance", "-1"], ["--clearance: -1 mm is outside the valid range"]),
    (["--target", "flexion=60", "--clearance-mm", "-1"], ["--clearance-mm: -1 mm is outside the valid range"]),
    (["--target", "flexion=60", "--resect", "tibia"], ["--resect: 'tibia' is not one of femur, pelvis, both"]),
    (["--target", "flexion=60", "--max-depth-fraction", "2"], ["--max-depth-fraction: 2 is outside the valid range"]),
    (["--target", "flexion=60", "--burr-radius", "nan"], ["--burr-radius: 'nan' is not a finite number"]),
    (["--target", "flexion=60", "--max-depth", "-2"], ["--max-depth: -2 mm is outside the valid range [0, 100] mm"]),
    (["--target", "flexion=60", "--clearance", "0.3", "--clearance-mm", "0.3"],
     ["give --clearance or --clearance-mm (its former name), not both"]),
    # The labrum is soft tissue, never cut: a labral contact can be cleared only on the femur (issue 81).
    (["--target", "flexion=60", "--labrum", "--resect", "pelvis"],
     ["--labrum with --resect pelvis", "can be cleared only on the femur", "give --resect femur or both"]),
    (["--target", "flexion=60", "--labrum", "--labrum-height", "20"], ["--labrum-height", "20 mm", "(0, 15] mm"]),
])
def test_bad_plan_inputs_are_one_line_errors_naming_them(cam, tmp_path, args, fragments):
    r = run(["plan", "--subject", cam, "--out", tmp_path / "p", "--precision", 2] + args)
    one_line_error(r, *fragments)
    assert not (tmp_path / "p" / "plan.json").exists()


def test_a_former_option_name_works_for_one_release_with_a_deprecation_line(cam, tmp_path):
    """--clearance-mm, --max-depth-mm and --burr-radius-mm (issue 78: CLI names carry no unit) still work, each
    saying once which name replaces it; the plan is the one the new names give."""
    plans = {}
    for names in (("--clearance", "--burr-radius", "--max-depth"), ("--clearance-mm", "--burr-radius-mm",
                                                                      "--max-depth-mm")):
        out = tmp_path / names[0].strip("-")
        r = run(["plan", "--subject", cam, "--out", out, "--precision", 2, "--target", "flexion=60", "--allow-partial",
                 names[0], "0.4", names[1], "2", names[2], "3"])
        assert r.returncode == 0, r.stderr
        warned = [x for x in r.stderr.splitlines() if "deprecated" in x]
        if names[0].endswith("-mm"):
            assert len(warned) == 3 and all(f"{old} is deprecated" in w and f"use {old[:-3]}" in w
                                            for old, w in zip(sorted(names), sorted(warned))), warned
        else:
            assert warned == [], warned
        p = json.load(open(out / "plan.json"))
        plans[names[0]] = (p["options"], p["targets"])
    assert plans["--clearance"] == plans["--clearance-mm"]


def test_a_motion_file_with_a_bad_cell_is_refused_naming_its_line(cam, tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("time_s,flexion_deg,adduction_deg,internal_rotation_deg\n0,0,0,0\n1,abc,0,0\n")
    r = run(["plan", "--subject", cam, "--out", tmp_path / "p", "--precision", 2, "--target-motion", bad])
    one_line_error(r, "bad.csv:3", "flexion_deg", "abc")


def test_a_motion_file_target_is_freed(cam, tmp_path):
    motion = tmp_path / "flex.csv"
    motion.write_text("time_s,flexion_deg,adduction_deg,internal_rotation_deg\n" +
                      "".join(f"{k * 0.1},{k},0,0\n" for k in range(0, 46)))
    r = run(["plan", "--subject", cam, "--out", tmp_path / "p", "--precision", 1, "--target-motion", motion])
    assert r.returncode == 0, r.stderr + r.stdout
    t = json.load(open(tmp_path / "p" / "plan.json"))["targets"][0]
    assert t["frames_in_contact_before"] > 0 and t["frames_in_contact_after"] == 0 and t["met"], t
