"""A mesh whose triangles face in and out at random (issue 48, item 1). Invariant: its distances are the
consistently wound mesh's (the triangles are flipped to agree with their neighbours, and a warning says how many);
before, the femur of a generated hip 1 mm from its cup read as deep inside it."""
import json
import os

import numpy as np

from conftest import run
from test_geometry_only import read_ply, write_ply


def test_randomly_wound_triangles_are_flipped_and_said(generated, tmp_path):
    d = os.path.dirname(generated)
    V, F = read_ply(os.path.join(d, "femur_r.ply"))
    rng = np.random.default_rng(3)
    flip = rng.random(len(F)) < 0.3
    G = F.copy()
    G[flip] = G[flip][:, [0, 2, 1]]
    write_ply(tmp_path / "femur_r.ply", V, G)
    s = json.load(open(generated))
    s["femur"], s["pelvis"] = str(tmp_path / "femur_r.ply"), os.path.join(d, s["pelvis"])
    (tmp_path / "subject.json").write_text(json.dumps(s))
    out = {}
    for name, subject in (("clean", generated), ("wound", tmp_path / "subject.json")):
        r = run(["distance", "--subject", subject, "--precision", "1", "--pose", "20,5,10", "--out", tmp_path / name])
        assert r.returncode == 0, r.stderr
        out[name] = (json.load(open(tmp_path / name / "summary.json")), r.stderr)
    (a, _), (b, err) = out["clean"], out["wound"]
    assert f"{int(flip.sum())} of {len(F)} triangles were wound against their neighbours" in err, err
    for scan in ("femur", "pelvis"):
        assert b[scan]["min_distance_mm"] == a[scan]["min_distance_mm"], (scan, a[scan], b[scan])
        assert b[scan]["min_gap_mm"] == a[scan]["min_gap_mm"]
