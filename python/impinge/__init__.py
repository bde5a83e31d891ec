"""impinge: impingement detection in ball-and-socket joints (the hip) by spherical radial distance maps.

Units: mm and degrees. Vertices: float (n, 3); faces: integer (m, 3), 0-based. Gaps: positive apart,
negative penetrating, NaN where a vertex was not tested.

The package is the C++ extension `impinge._impinge` (every function and type, re-exported here) and, in
Python: meshes from VTK files (`.vtp`, `.vtk`: OpenSim's bone geometry) through VTK's own readers, in
`load_mesh` and wherever `Joint` takes a mesh file; and `impinge.study`, studies of many subjects, motions
and perturbations on Dask (`/usr/bin/python3 -m impinge.study run STUDY.toml --out DIR`)."""
import os as _os

from . import _impinge
from ._impinge import *  # noqa: F401,F403 (the extension's functions and types)
from ._impinge import Error, __version__  # noqa: F401
from . import _json_file
from . import vtk_meshes as _vtk_meshes

VTK_SUFFIXES = (".vtp", ".vtk")


def is_vtk_file(path):
    """True when `path` (str or os.PathLike) names a VTK file by its suffix (.vtp XML PolyData, .vtk legacy)."""
    return isinstance(path, (str, _os.PathLike)) and _os.fspath(path).lower().endswith(VTK_SUFFIXES)


def read_vtk_mesh(path):
    try:
        return _vtk_meshes.read_vtk_mesh(path)
    except _vtk_meshes.VtkMeshError as e:
        raise Error(str(e)) from None


read_vtk_mesh.__doc__ = _vtk_meshes.read_vtk_mesh.__doc__


def load_mesh(path, scale=1.0):
    """(V (n, 3) float64 mm, F (m, 3) int32) of a mesh file: STL, PLY, OBJ and the other formats of assimp
    (the extension's loader), or VTK's `.vtp` and `.vtk` (read_vtk_mesh). scale: multiplies every coordinate
    (1000 for OpenSim's metre files). Raises Error naming the file and the element at fault."""
    if is_vtk_file(path):
        V, F = read_vtk_mesh(path)
    else:
        V, F = _impinge.load_mesh(_os.fspath(path))
    if scale != 1.0:
        if not (scale > 0 and scale < float("inf")):
            raise Error(f"load_mesh: scale must be a finite number > 0 (got {scale})")
        V = V * float(scale)
    return V, F


def subject_meshes(subject):
    """{"femur": path, "pelvis": path}: the mesh files a subject.json names, as absolute paths (they are relative
    to its folder); {} when it cannot be read (the extension then reports what is wrong with it)."""
    path = _os.fspath(subject)
    try:
        info = _json_file.load(path)
    except (OSError, ValueError):
        return {}
    folder = _os.path.dirname(_os.path.abspath(path))
    out = {}
    for key in ("femur", "pelvis"):
        if isinstance(info, dict) and isinstance(info.get(key), str):
            out[key] = _os.path.join(folder, info[key])
    return out


def _with_vtk_meshes(ball, socket, options):
    """ball and socket with VTK files (given, or named by options' subject) read here as (V, F) arrays."""
    if is_vtk_file(ball):
        ball = read_vtk_mesh(ball)
    if is_vtk_file(socket):
        socket = read_vtk_mesh(socket)
    subject = options.get("subject")
    if subject is not None and (ball is None or socket is None):
        meshes = subject_meshes(subject)
        if ball is None and is_vtk_file(meshes.get("femur")):
            ball = read_vtk_mesh(meshes["femur"])
        if socket is None and is_vtk_file(meshes.get("pelvis")):
            socket = read_vtk_mesh(meshes["pelvis"])
    return ball, socket


def femoral_head_centre(ball=None, socket=None, **options):
    ball, socket = _with_vtk_meshes(ball, socket, options)
    return _impinge.femoral_head_centre(ball, socket, **options)


femoral_head_centre.__doc__ = _impinge.femoral_head_centre.__doc__


class Joint(_impinge.Joint):
    # The extension's Joint, with VTK files wherever it takes a mesh file: `ball=`, `socket=`, or the femur
    # and pelvis a subject.json names. VTK files are read here (read_vtk_mesh) and handed over as arrays.
    __doc__ = _impinge.Joint.__doc__

    def __init__(self, ball=None, socket=None, **options):
        ball, socket = _with_vtk_meshes(ball, socket, options)
        super().__init__(ball, socket, **options)

    __init__.__doc__ = _impinge.Joint.__init__.__doc__
