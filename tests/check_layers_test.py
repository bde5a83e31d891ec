"""tools/check-layers: passes on the tree, and fails on a copy with a planted wrong-way include
(a lower layer including a higher one, public or private), a flat include, or a file outside the layers."""
import pathlib
import shutil
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
TOOL = ROOT / "tools" / "check-layers"


def run(root):
    return subprocess.run([sys.executable, str(TOOL), "--root", str(root)], capture_output=True, text=True)


def copy_libcore(tmp_path):
    shutil.copytree(ROOT / "libcore", tmp_path / "libcore")
    return tmp_path


def test_the_tree_passes():
    r = run(ROOT)
    assert r.returncode == 0, r.stdout + r.stderr


def test_a_core_header_including_clinical_fails(tmp_path):
    root = copy_libcore(tmp_path)
    h = root / "libcore/include/impinge/core/error.hpp"
    h.write_text('#include "impinge/clinical/rom.hpp"\n' + h.read_text())
    r = run(root)
    assert r.returncode == 1
    assert "core/error.hpp:1: layer 'core' includes 'impinge/clinical/rom.hpp' of the higher layer 'clinical'" in r.stdout


def test_a_private_header_of_a_higher_layer_fails(tmp_path):
    root = copy_libcore(tmp_path)
    src = root / "libcore/src/schemes/equiangular_grid.cpp"
    src.write_text(src.read_text() + '\n#include "sampling/raster_tables.hpp"\n')
    r = run(root)
    assert r.returncode == 1 and "higher layer 'sampling'" in r.stdout


def test_a_flat_include_and_a_file_outside_the_layers_fail(tmp_path):
    root = copy_libcore(tmp_path)
    (root / "libcore/src/stray.cpp").write_text('#include "impinge/error.hpp"\n')
    src = root / "libcore/src/maps/map_io.cpp"
    src.write_text('#include "impinge/error.hpp"\n' + src.read_text())
    r = run(root)
    assert r.returncode == 1
    assert "libcore/src/stray.cpp: not in a layer folder" in r.stdout
    assert "includes flat 'impinge/error.hpp'" in r.stdout


def test_a_downward_include_passes(tmp_path):
    root = copy_libcore(tmp_path)
    src = root / "libcore/src/clinical/rom.cpp"
    src.write_text('#include "impinge/core/error.hpp"\n#include "core/simd_clones.hpp"\n' + src.read_text())
    assert run(root).returncode == 0
