"""Python's Joint against the CLI through the one set-up they share (the session layer).

Invariants (the options themselves: test_options.py): a subject given in LPS gives the CLI's gaps bit for bit, whether Python reads subject.json or gets
the LPS arrays with frame='LPS'; results given in the input frame (COR, frames, rotations) are the
CLI's; bad options raise impinge.Error naming the option."""
import json
import os
import subprocess
import tempfile

import numpy as np
import pytest

import impinge
from test_impinge import CLI, DATA, read_gaps, read_ply_vertices

def test_an_unknown_or_bad_option_names_itself():
    with pytest.raises(impinge.Error, match="unknown option 'layer'.*layers"):
        impinge.Joint(subject="x.json", layer=2)
    with pytest.raises(impinge.Error, match="head_region: expected 4 numbers"):
        impinge.Joint(subject="x.json", head_region=[1, 2, 3])
    with pytest.raises(impinge.Error, match="maps_only: expected True or False"):
        impinge.Joint(subject="x.json", maps_only="yes")


def lps_subject(folder):
    """A subject of the shared data given in LPS, or a generated hip converted to LPS."""
    src = os.path.join(DATA, "lhdl-ct", "subject.json")
    if os.path.exists(src):
        with open(src) as f:
            assert json.load(f)["frame"] == "LPS"
        return src, {}
    subprocess.run([CLI, "generate", "--triangles", "3000", "--cam", "2", "--out", folder + "/g"], check=True,
                   capture_output=True)
    lps = np.diag([-1.0, -1.0, 1.0])
    for name in ("femur_r", "pelvis"):
        V, F = impinge.load_mesh(f"{folder}/g/{name}.ply")
        write_ply(f"{folder}/g/{name}_lps.ply", V @ lps, F)
    with open(folder + "/g/subject.json") as f:
        s = json.load(f)
    cor = (np.array(s["true_cor_mm"]) @ lps).tolist()
    s.update(frame="LPS", femur="femur_r_lps.ply", pelvis="pelvis_lps.ply")
    with open(folder + "/g/lps.json", "w") as f:
        json.dump(s, f)
    return folder + "/g/lps.json", {"cor": cor}


def write_ply(path, V, F):
    with open(path, "w") as f:
        f.write(f"ply\nformat ascii 1.0\nelement vertex {len(V)}\nproperty double x\nproperty double y\n"
                f"property double z\nelement face {len(F)}\nproperty list uchar int vertex_indices\nend_header\n")
        for v in V:
            f.write(f"{v[0]!r} {v[1]!r} {v[2]!r}\n")
        for t in F:
            f.write(f"3 {t[0]} {t[1]} {t[2]}\n")


def test_a_subject_in_lps_gives_the_cli_gaps():
    d = tempfile.mkdtemp(prefix="impinge_session_")
    subject, extra = lps_subject(d)
    cli_extra = [f"--cor={','.join(map(repr, extra['cor']))}"] if "cor" in extra else []
    subprocess.run([CLI, "distance", "--subject", subject, "--precision", "1", "--pose=30,5,10", "--out", d + "/cli"]
                   + cli_extra, check=True, capture_output=True)
    cli_ball, cli_socket = read_gaps(d + "/cli/femur_gaps.ply"), read_gaps(d + "/cli/pelvis_gaps.ply")
    with open(d + "/cli/summary.json") as f:
        summary = json.load(f)
    assert summary["input_frame"] == "LPS"

    # Python reading the same subject.json (set up as the CLI's distance sets up its one pose: query strategy direct).
    j = impinge.Joint(subject=subject, precision=1, query_strategy="direct", **extra)
    r = j.detect_pose(30, 5, 10)
    np.testing.assert_array_equal(r["femur_gap_mm"], cli_ball)
    np.testing.assert_array_equal(r["pelvis_gap_mm"], cli_socket)
    np.testing.assert_allclose(j.cor, summary["head_centre_mm"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(j.map_centre, summary["map_centre_mm"], rtol=0, atol=1e-9)
    assert j.setup["input_frame"] == "LPS"
    assert j.setup["head_centre_mm"] == pytest.approx(summary["head_centre_mm"], abs=1e-9)

    # Python given the LPS arrays and frame='LPS': the same joint, the same gaps.
    with open(subject) as f:
        s = json.load(f)
    base = os.path.dirname(subject)
    ball, socket = (impinge.load_mesh(os.path.join(base, s[k])) for k in ("femur", "pelvis"))
    j2 = impinge.Joint(ball, socket, frame="LPS", side=s["side"], neutral=s.get("neutral"), precision=1, query_strategy="direct",
                       **extra)
    np.testing.assert_array_equal(j2.detect_pose(30, 5, 10)["femur_gap_mm"], cli_ball)
    np.testing.assert_array_equal(j2.detect_pose(30, 5, 10)["pelvis_gap_mm"], cli_socket)

    # Rotations are in the input frame: the pose's rotation about the COR, applied to the LPS
    # vertices, gives the same gaps, and moves the femur as the CLI's posed PLY shows it.
    R, t = j.femur_pose(30, 5, 10)
    np.testing.assert_array_equal(j.detect(R, t)["femur_gap_mm"], cli_ball)
    posed = (ball[0] - j.cor) @ R.T + j.cor + t
    rec = read_ply_vertices(d + "/cli/femur_gaps.ply")
    xyz = np.stack([rec["x"], rec["y"], rec["z"]], axis=1)
    np.testing.assert_allclose(posed, xyz, atol=1e-3)

    # Frames, when anatomical, are the CLI's (input frame).
    if summary.get("frames"):
        np.testing.assert_allclose(j.frames["pelvis"]["origin_mm"], summary["frames"]["pelvis"]["origin_mm"], atol=1e-9)
        np.testing.assert_allclose(j.frames["pelvis"]["x_axis"], summary["frames"]["pelvis"]["x_axis"], atol=1e-12)


def test_side_or_frame_contradicting_the_subject_is_an_error():
    d = tempfile.mkdtemp(prefix="impinge_session_")
    subprocess.run([CLI, "generate", "--triangles", "1000", "--out", d + "/g"], check=True, capture_output=True)
    with pytest.raises(impinge.Error, match="side 'left' contradicts"):
        impinge.Joint(subject=d + "/g/subject.json", side="left")
    with pytest.raises(impinge.Error, match="frame 'LPS' contradicts"):
        impinge.Joint(subject=d + "/g/subject.json", frame="LPS")
    out = subprocess.run([CLI, "distance", "--subject", d + "/g/subject.json", "--frame", "LPS", "--out", d + "/o"],
                         capture_output=True, text=True)
    assert out.returncode == 2 and "frame 'LPS' contradicts" in out.stderr


@pytest.mark.skipif(not os.path.exists(os.path.join(DATA, "mc22-left", "subject.json")), reason="shared data absent")
def test_the_head_is_found_beside_its_pelvis_as_the_cli_finds_it():
    """mc22's real left femur: with its pelvis, the head within 2 mm of its hand-checked centre (LPS,
    tests/anatomy/femur_frame_test.cpp) and the CLI's centre; a pelvis far away is an error."""
    V, F = impinge.load_mesh(os.path.join(DATA, "mc22-left", "femur_l.ply"))
    P, G = impinge.load_mesh(os.path.join(DATA, "mc22-left", "pelvis.ply"))
    head = impinge.locate_femoral_head(V, F, pelvis=(P, G))
    assert np.linalg.norm(head.centre - np.array([88.08, -6.13, -12.91])) < 2.0
    j = impinge.Joint(subject=os.path.join(DATA, "mc22-left", "subject.json"), precision=2)
    np.testing.assert_allclose(j.setup["head_centre_mm"], head.centre, atol=1e-9)
    with pytest.raises(impinge.Error, match="cannot tell which end of the femur is proximal"):
        impinge.locate_femoral_head(V, F, pelvis=(P + 300.0, G))
