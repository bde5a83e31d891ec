"""`impinge plan --labrum` (issue 81 item 4: "the plan can target either" limit): the plan targets the labral limits,
cutting the femur so that it clears the pelvis and the labrum at every target pose; the labrum is never cut.

Oracles, independent of the plan's own distances: a separate `impinge rom --labrum` on the written
femur_resected.ply and the untouched pelvis (the exact first-contact search, not the plan's per-vertex contacts); the
resected volume by numpy's divergence theorem on the input and written meshes; the labrum's vertices as `impinge rom
--labrum` writes them before and after (labrum.ply).

Invariants: a target beyond the labral limit but within the bony limit needs no cut without --labrum (the femur
written unmoved) and a femoral cut with it (volume > 0), after which the labral limit reaches the target (within the
check's 0.1 deg) and the bony limit is not lowered; the labrum is the same before, in the plan and after (1e-4 mm:
float coordinates); only the femur is written; plan.json says the labral limit was targeted; where the labrum blocks
the way to a motion's start (tlem2-mri) the plan frees it, the clearance kept by the exact distance. Bad input
(--labrum with --resect pelvis): tests/bad_inputs/test_plan_inputs.py."""
import csv
import json
import os

import numpy as np
import pytest

import impinge
from test_impinge import DATA
from test_plan import read_ply_properties, run, volume


def rom_rows(folder):
    with open(os.path.join(folder, "rom_limits.csv")) as f:
        return {r["motion"]: r for r in csv.DictReader(f)}


def num(x):
    return float("nan") if x in ("", "nan") else float(x)


def vertices(path):
    props, F = read_ply_properties(path)
    return np.column_stack([props["x"], props["y"], props["z"]]), F


def check_labral_plan(tmp_path, subject, motion, common, femur_mesh):
    """The invariants of the module docstring for `motion` on `subject`; returns the figures."""
    r = run(["rom", "--subject", subject, "--out", tmp_path / "before", "--no-map", "--labrum"] + common)
    assert r.returncode == 0, r.stderr
    before = rom_rows(tmp_path / "before")[motion]
    bony, labral = num(before["limit_deg"]), num(before["labral_limit_deg"])
    assert before["labral_contact_class"] == "labral" and labral < bony - 6, before
    target = round(labral + 0.4 * (bony - labral), 1)  # beyond the labral limit, well within the bony one
    t_arg = f"{motion}={target}"
    # Without --labrum: the bony limit is beyond the target, no cut.
    r = run(["plan", "--subject", subject, "--out", tmp_path / "bony", "--target", t_arg] + common)
    assert r.returncode == 0, r.stderr + r.stdout
    V, F = impinge.load_mesh(femur_mesh)
    Vb, _ = vertices(tmp_path / "bony" / "femur_resected.ply")
    assert np.abs(Vb - V).max() < 1e-3 and "labrum" not in json.load(open(tmp_path / "bony" / "plan.json"))
    assert not (tmp_path / "bony" / "labrum.ply").exists()
    # With --labrum: a femoral cut, only the femur written, the labral limit targeted.
    r = run(["plan", "--subject", subject, "--out", tmp_path / "lab", "--target", t_arg, "--labrum"] + common)
    assert r.returncode == 0, r.stderr + r.stdout
    assert "labral (targeted)" in r.stdout
    plan = json.load(open(tmp_path / "lab" / "plan.json"))
    t = plan["targets"][0]
    assert t["limit_targeted"] == "labral" and t["met"] and plan["labrum"]["targeted"] == "labral limits", t
    assert not (tmp_path / "lab" / "pelvis_resected.ply").exists()
    Vr, Fr = vertices(tmp_path / "lab" / "femur_resected.ply")
    assert np.array_equal(Fr, F)
    removed = volume(V, F) - volume(Vr, F)
    assert removed > 1 and abs(removed - plan["femur_resection"]["volume_mm3"]) <= 1e-3 * removed + 0.05
    assert np.linalg.norm(Vr - V, axis=1).max() <= plan["safety_depth"]["value_mm"] + 1e-3
    # The check, independently: `impinge rom --labrum` on the written femur and the untouched pelvis.
    r = run(["rom", "--subject", subject, "--ball", tmp_path / "lab" / "femur_resected.ply", "--out",
             tmp_path / "after", "--no-map", "--labrum"] + common)
    assert r.returncode == 0, r.stderr
    after = rom_rows(tmp_path / "after")[motion]
    assert num(after["labral_limit_deg"]) >= target - 0.1, (after, target)
    assert num(after["limit_deg"]) >= bony - 0.1, (after, bony)  # bone was only removed
    # The labrum never moves: rom's before, the plan's and rom's after on the resected femur.
    L0, LF = vertices(tmp_path / "before" / "labrum.ply")
    for other in (tmp_path / "lab" / "labrum.ply", tmp_path / "after" / "labrum.ply"):
        L, Lf = vertices(other)
        assert np.array_equal(Lf, LF) and np.abs(L - L0).max() < 1e-4, other
    # A plan without the labrum in the same folder leaves no labrum.ply of the earlier run behind.
    r = run(["plan", "--subject", subject, "--out", tmp_path / "lab", "--target", t_arg] + common)
    assert r.returncode == 0, r.stderr + r.stdout
    assert not (tmp_path / "lab" / "labrum.ply").exists()
    return {"bony": bony, "labral": labral, "target": target, "removed": removed,
            "labral_after": num(after["labral_limit_deg"]), "bony_after": num(after["limit_deg"])}


def test_a_plan_with_the_labrum_cuts_the_femur_to_the_labral_target_on_a_generated_hip(tmp_path):
    """A generated hip whose cup covers 80 deg (the labrum clear of the neck at neutral): abduction's labrum contact
    comes about 15 deg before the bone."""
    r = run(["generate", "--triangles", "12000", "--coverage", "80", "--out", tmp_path / "g"])
    assert r.returncode == 0, r.stderr
    check_labral_plan(tmp_path, tmp_path / "g" / "subject.json", "abduction", ["--precision", 1],
                      str(tmp_path / "g" / "femur_r.ply"))


@pytest.mark.skipif(not os.path.isdir(os.path.join(DATA, "lhdl-ct")), reason="shared data absent")
def test_a_plan_with_the_labrum_cuts_the_femur_to_the_labral_target_on_a_real_hip(tmp_path):
    """lhdl-ct: internal rotation at 90 deg flexion, labral limit 17.4 deg, bony 40.8 deg."""
    subject = os.path.join(DATA, "lhdl-ct", "subject.json")
    check_labral_plan(tmp_path, subject, "internal_rotation_90_flexion", ["--precision", 0.5],
                      impinge.subject_meshes(subject)["femur"])


@pytest.mark.skipif(not os.path.isdir(os.path.join(DATA, "tlem2-mri")), reason="shared data absent")
def test_a_motion_the_labrum_blocks_on_its_way_is_freed_with_the_clearance_kept_exactly(tmp_path):
    """tlem2-mri: the labrum meets the femur on the way to 90 deg flexion, so internal rotation there is not reachable
    (bony limit 23.8 deg). A plan for 5 deg frees the way and the motion, keeping the clearance by the exact distance
    (the labrum's margin between its vertices: the per-vertex plan alone left 0.295 mm of the 0.3), as a separate
    `impinge rom --labrum` on the written femur confirms."""
    subject = os.path.join(DATA, "tlem2-mri", "subject.json")
    r = run(["rom", "--subject", subject, "--out", tmp_path / "before", "--no-map", "--labrum"])
    assert r.returncode == 0, r.stderr
    assert rom_rows(tmp_path / "before")["internal_rotation_90_flexion"]["labral_status"] == "not_reachable"
    r = run(["plan", "--subject", subject, "--out", tmp_path / "lab", "--target", "internal_rotation_90_flexion=5",
             "--labrum"])
    assert r.returncode == 0, r.stderr + r.stdout
    t = json.load(open(tmp_path / "lab" / "plan.json"))["targets"][0]
    assert t["met"] and t["clearance"]["least_labrum_mm"] >= 0.3 - 1e-4, t
    r = run(["rom", "--subject", subject, "--ball", tmp_path / "lab" / "femur_resected.ply", "--out",
             tmp_path / "after", "--no-map", "--labrum"])
    assert r.returncode == 0, r.stderr
    after = rom_rows(tmp_path / "after")["internal_rotation_90_flexion"]
    assert after["labral_status"] == "limited" and num(after["labral_limit_deg"]) >= 5 - 0.1, after


def test_joint_plan_takes_the_labrum_and_refuses_it_with_a_pelvis_only_trim(tmp_path):
    r = run(["generate", "--triangles", "6000", "--coverage", "80", "--out", tmp_path / "g"])
    assert r.returncode == 0, r.stderr
    j = impinge.Joint(subject=str(tmp_path / "g" / "subject.json"), precision=1)
    p = j.plan(target="abduction=40", labrum=True, labrum_height_mm=6)
    assert p["labrum"]["height_mm"] == 6 and p["targets"][0]["limit_targeted"] == "labral" and p["all_targets_met"]
    assert p["femur_resection"]["volume_mm3"] > 0
    message = "--labrum with --resect pelvis: a contact with the labrum can be cleared only on the femur"
    with pytest.raises(impinge.Error, match=message):
        j.plan(target="abduction=40", labrum=True, resect="pelvis")
    with pytest.raises(impinge.Error, match=message):
        impinge.check_options("joint_plan", target="abduction=40", labrum=True, resect="pelvis")
