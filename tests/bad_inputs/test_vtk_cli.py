"""VTK meshes wherever the CLI reads a mesh (issue 47, item 4). Invariants: a femur and pelvis written as VTK XML
PolyData give the PLY files' gaps bit for bit, given with --ball/--socket or named by a subject.json; a file VTK
cannot read is a one-line error naming it."""
import importlib.util
import json
import os

import pytest

from conftest import one_line_error, run
from test_geometry_only import read_ply

vtk = pytest.importorskip("vtkmodules.vtkIOXML")


def vtk_meshes():
    """python/impinge/vtk_meshes.py from the source tree, loaded on its own: it needs no compiled extension, so this
    CLI test also runs where the Python module is not built (./test --sanitize builds none)."""
    path = os.path.join(os.path.dirname(__file__), "..", "..", "python", "impinge", "vtk_meshes.py")
    spec = importlib.util.spec_from_file_location("vtk_meshes_standalone", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def write_vtp(path, V, F):
    poly = vtk_meshes().polydata(V, F)
    w = vtk.vtkXMLPolyDataWriter()
    w.SetFileName(str(path))
    w.SetInputData(poly)
    assert w.Write() == 1


def gaps(path):
    return open(path, "rb").read().split(b"end_header\n", 1)[1]


def test_vtk_meshes_give_the_ply_gaps(generated, tmp_path):
    d = os.path.dirname(generated)
    for name in ("femur_r", "pelvis"):
        write_vtp(tmp_path / f"{name}.vtp", *read_ply(os.path.join(d, f"{name}.ply")))
    common = ["--precision", "2", "--pose", "20,5,10", "--neutral", "scan"]
    r = run(["distance", "--subject", generated, "--out", tmp_path / "ply"] + common)
    assert r.returncode == 0, r.stderr
    r = run(["distance", "--ball", tmp_path / "femur_r.vtp", "--socket", tmp_path / "pelvis.vtp",
             "--cor", ",".join(map(str, json.load(open(generated))["true_cor_mm"])), "--allow-any-cor",
             "--out", tmp_path / "vtp"] + common)
    assert r.returncode == 0, r.stderr
    s = json.load(open(generated))
    s.update(femur=str(tmp_path / "femur_r.vtp"), pelvis=str(tmp_path / "pelvis.vtp"))
    (tmp_path / "subject.json").write_text(json.dumps(s))
    r = run(["distance", "--subject", tmp_path / "subject.json", "--out", tmp_path / "subject"] + common)
    assert r.returncode == 0, r.stderr
    for scan in ("femur_gaps.ply", "pelvis_gaps.ply"):
        assert gaps(tmp_path / "subject" / scan) == gaps(tmp_path / "ply" / scan)


def test_a_broken_vtk_file_is_one_line(generated, tmp_path):
    (tmp_path / "bad.vtp").write_text("<VTKFile type='PolyData'><broken")
    r = run(["distance", "--ball", tmp_path / "bad.vtp", "--socket", os.path.join(os.path.dirname(generated),
             "pelvis.ply"), "--out", tmp_path / "o"])
    one_line_error(r, "bad.vtp")
