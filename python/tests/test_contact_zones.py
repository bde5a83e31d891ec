"""The neck and a cam are never the joint surface (issue 81, item 1). On every shared hip, a 3 mm cam grafted at the
antero-superior head-neck junction (1:30 o'clock, 62 deg from the neck axis, as test_plan.py's): in every motion
whose first contact of every vertex (`--contacts all`) the cam brings earlier by more than 1 deg, the default
search (impingement only) stops there too, and names the contact's femoral zone as not the head. Wherever the
default and `--contacts all` differ, rom_limits.csv says the contact set aside: its angle is `--contacts all`'s
limit, with its zones. Oracle: the separate `--contacts all` runs with and without the cam (the cam's effect), not
the default run's own numbers; and the default runs with and without the cam: the cam lowers at least one limit,
at a contact not on the head."""
import csv
import os

import numpy as np
import pytest

import impinge
from test_impinge import DATA
from test_morphology import write_ply
from test_plan import run

HIPS = ("lhdl-ct", "mc22", "mc22-left", "tlem2-mri")


def rows(folder):
    with open(os.path.join(folder, "rom_limits.csv")) as f:
        return {r["motion"]: r for r in csv.DictReader(f)}


def number(text):
    return float(text) if text not in ("", "nan", None) else float("nan")


def graft_cam(subject, path):
    """The subject's femur with a 3 mm bump at its antero-superior head-neck junction, written to `path`."""
    meshes = impinge.subject_meshes(subject)
    m = impinge.Joint(subject=subject, precision=0.5).morphology()["femur"]
    V, F = impinge.load_mesh(meshes["femur"])
    c, r = np.asarray(m["head_centre_mm"]["value"]), m["head_radius_mm"]["value"]
    a = np.asarray(m["neck_axis"]["value"])
    s = np.asarray(m["frame"]["x_axis"]) + np.asarray(m["frame"]["y_axis"])  # anterior + superior
    u = s - s.dot(a) * a
    u /= np.linalg.norm(u)
    d = np.cos(np.radians(62)) * (-a) + np.sin(np.radians(62)) * u
    p = V - c
    dist = np.linalg.norm(p, axis=1)
    g = np.degrees(np.arccos(np.clip(p @ d / dist, -1, 1))) / 12
    bump = np.where((dist > r - 6) & (dist < r + 12), 3.0 * np.exp(-g * g), 0.0)
    write_ply(path, V + p / dist[:, None] * bump[:, None], F)


@pytest.mark.parametrize("hip", HIPS)
def test_the_cam_is_found_wherever_every_contact_finds_it(hip, tmp_path):
    subject = os.path.join(DATA, hip, "subject.json")
    if not os.path.exists(subject):
        pytest.skip("shared data absent")
    graft_cam(subject, tmp_path / "femur_cam.ply")
    common = ["--subject", subject, "--precision", 0.5, "--no-map"]
    cam = ["--ball", tmp_path / "femur_cam.ply"]
    for name, extra in (("free_all", ["--contacts", "all"]), ("cam_all", cam + ["--contacts", "all"]),
                        ("cam", cam), ("free", [])):
        r = run(["rom", "--out", tmp_path / name] + common + extra)
        assert r.returncode == 0, r.stderr
    free_all, cam_all, default = rows(tmp_path / "free_all"), rows(tmp_path / "cam_all"), rows(tmp_path / "cam")
    free = rows(tmp_path / "free")
    # The cam lowers at least one limit, at a contact not on the head (on an MRI hip every contact search stops
    # first where the head meets the lunate surface, so this is where the cam shows there).
    lowered = [m for m, row in default.items()
               if number(row["limit_deg"]) < number(free[m]["limit_deg"]) - 1 or
               (number(row["limit_deg"]) == number(row["limit_deg"]) and free[m]["status"] == "free")]
    # Measured: on mc22-left the cam lowers no limit by more than 1 deg (its in-flexion limits are set by the neck
    # below the cam, 78-80 deg, the others by the ischium or the rim over the head).
    assert lowered or hip == "mc22-left", (hip, {m: (free[m]["limit_deg"], r["limit_deg"]) for m, r in default.items()})
    for m in lowered:
        assert default[m]["femoral_zone"] != "head", (hip, m, default[m]["femoral_zone"])
    found = 0
    for motion, row in default.items():
        a, a0, lim = number(cam_all[motion]["limit_deg"]), number(free_all[motion]["limit_deg"]), number(row["limit_deg"])
        if a == a and (a0 != a0 or a < a0 - 1):  # the cam brings the first contact earlier: the cam's contact
            found += 1
            assert lim <= a + 0.2, (hip, motion, lim, a)
            assert row["femoral_zone"] != "head", (hip, motion, row["femoral_zone"])
        if a == a and not lim <= a + 1e-9:  # the default passes a contact of every vertex: it says which
            assert abs(number(row["set_aside_contact_deg"]) - a) <= 1e-6, (hip, motion, row)
            assert row["set_aside_contact_class"] and row["set_aside_femoral_zone"], (hip, motion, row)
        else:
            assert np.isnan(number(row["set_aside_contact_deg"])), (hip, motion, row)
