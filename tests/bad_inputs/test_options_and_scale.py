"""Inputs that make no sense, refused with one line naming the cause (issue 48, item 2), each within 30 s.
Invariants: every numeric option is checked against its range before anything is read; a resolution whose maps
would not fit in memory, a spacing finer than any map holds, a naive ray cast of minutes, meshes in metres,
contacts that scan neutral cannot tell apart, a femur translated off its head and decreasing levels are each a
one-line error (exit 2) that names the option or file, the value and what is valid."""
import numpy as np
import pytest

from conftest import one_line_error, run, DATA
import os


@pytest.mark.parametrize("args,fragments", [
    (["--spacing", "1e-4"], ["node spacing", "finer than the finest searched, 0.01 deg"]),
    (["--scheme", "conchoid", "--spacing", "0.004"], ["conchoid", "0.01 deg"]),
    (["--precision", "0.01", "--max-memory", "2"], ["need about 6.5 GB", "--max-memory 2 GB"]),
    (["--max-radius", "-1"], ["--max-radius: -1 mm is outside the valid range [0, 10000] mm"]),
    (["--layers", "2.5"], ["--layers: 2.5 is not a whole number"]),
    (["--levels", "4,5"], ["threshold 2 (5 mm) is not below threshold 1 (4 mm)"]),
    (["--distances", "maybe"], ["--distances: 'maybe' is not on or off"]),
    (["--joint-centre", "middle"], ["--joint-centre: 'middle' is not one of femoral-head"]),
])
def test_a_bad_option_is_one_line_naming_it(generated, tmp_path, args, fragments):
    r = run(["distance", "--subject", generated, "--out", tmp_path / "o"] + args)
    one_line_error(r, *fragments)
    assert not (tmp_path / "o").exists()  # refused before anything was written


def test_generate_refuses_nan_and_a_mesh_beyond_memory(tmp_path):
    one_line_error(run(["generate", "--cam", "nan", "--out", tmp_path / "g"]), "--cam: 'nan' is not a finite number")
    one_line_error(run(["generate", "--triangles", "2000000000", "--out", tmp_path / "g"]),
                   "--triangles: 2000000000 is outside the valid range [50, 20000000]")


def test_contacts_articular_needs_anatomical_neutral(generated, tmp_path):
    r = run(["rom", "--subject", generated, "--precision", "2", "--contacts", "articular", "--out", tmp_path / "o"])
    one_line_error(r, "contacts articular: needs anatomical neutral")


@pytest.mark.skipif(not os.path.exists(os.path.join(DATA, "lhdl-ct")), reason="shared data absent")
def test_a_naive_ray_cast_of_minutes_is_refused(tmp_path):
    r = run(["distance", "--subject", os.path.join(DATA, "lhdl-ct", "subject.json"), "--sampling", "ray-cast",
             "--out", tmp_path / "o"])
    one_line_error(r, "sampling ray-cast", "use ray-cast-bvh")


def test_meshes_in_metres_and_a_femur_far_away(generated):
    impinge = pytest.importorskip("impinge")
    d = os.path.dirname(generated)
    (V, F), (P, G) = impinge.load_mesh(os.path.join(d, "femur_r.ply")), impinge.load_mesh(os.path.join(d, "pelvis.ply"))
    with pytest.raises(impinge.Error, match=r"spans 0.10\d* .* metres \(scale by 1000\) or inches"):
        impinge.Joint((V / 1000, F), (P / 1000, G), neutral="scan")
    j = impinge.Joint((V, F), (P, G), neutral="scan", resolution=2.0)
    # The head radius: the polyhedron's fitted surface, within 0.1 mm of the 22 mm sphere through its vertices.
    with pytest.raises(impinge.Error, match=r"t: the femur translated by 100000 mm.*at most the head radius, "
                                            r"(21\.9\d*|22(\.0\d*)?) mm"):
        j.detect(None, (1e5, 0, 0))
    assert np.isfinite(j.detect(None, (1, 0, 0))["summary"]["femur"]["min_gap_mm"])


@pytest.mark.parametrize("args", [["distance", "--bogus"], ["distance", "--subject"], ["rom", "--precision"],
                                  ["view", "--port", "1", "--port", "2"], ["nonsense"], []])
def test_usage_errors_exit_2_as_every_other_error(args):
    """A command-line usage error (unknown option or command, a missing value) exits 2, as every error of impinge does;
    --help and --version exit 0 (CLI11's own codes are 100 and up)."""
    r = run(args)
    assert r.returncode == 2 and r.stderr.strip(), (args, r.returncode, r.stderr)


@pytest.mark.parametrize("args", [["--help"], ["--version"], ["distance", "--help"], ["view", "--help"]])
def test_help_and_version_exit_0(args):
    r = run(args)
    assert r.returncode == 0 and r.stdout.strip(), (args, r.returncode, r.stderr)


def test_a_search_tolerance_beyond_the_step_names_both(generated, tmp_path):
    r = run(["rom", "--subject", generated, "--precision", "2", "--no-map", "--step", "2", "--search-tolerance", "5",
             "--out", tmp_path / "o"])
    one_line_error(r, "--search-tolerance 5 deg is more than --step 2 deg")
