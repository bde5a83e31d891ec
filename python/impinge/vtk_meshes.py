"""VTK meshes (.vtp XML PolyData, .vtk legacy) read by VTK's own readers, without impinge's extension, so that
the CLI can use it too: `python3 vtk_meshes.py IN.vtp OUT.ply` writes the surface as a binary PLY (vertices in
the file's order) for `impinge` commands given a VTK file; impinge.read_vtk_mesh is `read_vtk_mesh` here."""
import os as _os
import sys as _sys


class VtkMeshError(ValueError):
    """A VTK file that cannot be read; the message names the file."""


Error = VtkMeshError  # the name the functions below raise; impinge/__init__.py re-raises as impinge.Error


def _read_vtk_polydata(path):
    """The surface of a VTK file as vtkPolyData, triangulated. Raises Error naming the file."""
    from vtkmodules.vtkCommonCore import vtkFileOutputWindow, vtkLogger, vtkOutputWindow
    from vtkmodules.vtkFiltersCore import vtkTriangleFilter
    from vtkmodules.vtkFiltersGeometry import vtkGeometryFilter
    from vtkmodules.vtkIOLegacy import vtkGenericDataObjectReader
    from vtkmodules.vtkIOXML import vtkXMLPolyDataReader

    if not _os.path.isfile(path):
        raise Error(f"{path}: no such file")
    import tempfile

    # VTK reports a bad file on its output window, not by raising: send that to a file we read back.
    window = vtkFileOutputWindow()
    with tempfile.NamedTemporaryFile(suffix=".log", delete=True) as t:
        window.SetFileName(t.name)
        previous = vtkOutputWindow.GetInstance()
        vtkOutputWindow.SetInstance(window)
        verbosity = vtkLogger.GetCurrentVerbosityCutoff()
        vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_OFF)
        try:
            if path.lower().endswith(".vtp"):
                reader = vtkXMLPolyDataReader()
            else:
                reader = vtkGenericDataObjectReader()
            reader.SetFileName(path)
            reader.Update()
            data = reader.GetOutputDataObject(0)
            surface = vtkGeometryFilter()  # unstructured grids and polydata alike to polygons
            surface.SetInputData(data)
            triangles = vtkTriangleFilter()  # quads and polygons to triangles (VTK's own, not ours)
            triangles.SetInputConnection(surface.GetOutputPort())
            triangles.PassVertsOff()
            triangles.PassLinesOff()
            triangles.Update()
            out = triangles.GetOutput()
        finally:
            vtkOutputWindow.SetInstance(previous)
            vtkLogger.SetStderrVerbosity(verbosity)
        log = open(t.name, errors="replace").read()
        complaints = [line.split("): ", 1)[-1].strip() for line in log.splitlines()
                      if "Error" in line and not line.startswith("ERROR: In")] if "ERROR" in log else []
    if complaints or data is None:
        raise Error(f"{path}: VTK cannot read it" + (f" ({complaints[0]})" if complaints else ""))
    return out


def read_vtk_mesh(path):
    """(V, F) of a VTK file's surface: V (n, 3) float64 in the file's units, F (m, 3) int32, 0-based; polygons
    triangulated by VTK's vtkTriangleFilter, points kept as the file has them (unused points too).
    `.vtp`: VTK's XML PolyData (OpenSim's bone geometry; OpenSim's files are in metres: scale them to mm);
    `.vtk`: the legacy format (PolyData or an unstructured grid, whose surface is taken).
    Raises Error naming the file: missing, unreadable, no triangles, or a point that is not finite."""
    import numpy as np
    from vtkmodules.util.numpy_support import vtk_to_numpy

    path = _os.fspath(path)
    poly = _read_vtk_polydata(path)
    if poly.GetNumberOfPoints() == 0 or poly.GetNumberOfPolys() == 0:
        raise Error(f"{path}: no triangles (VTK read {poly.GetNumberOfPoints()} points, "
                    f"{poly.GetNumberOfPolys()} polygons)")
    V = np.ascontiguousarray(vtk_to_numpy(poly.GetPoints().GetData()), dtype=np.float64)
    bad = np.flatnonzero(~np.isfinite(V).all(axis=1))
    if bad.size:
        raise Error(f"{path}: point {int(bad[0])} is not three finite numbers")
    polys = poly.GetPolys()
    if hasattr(polys, "GetConnectivityArray"):  # VTK >= 9: offsets and connectivity
        offsets = vtk_to_numpy(polys.GetOffsetsArray())
        conn = vtk_to_numpy(polys.GetConnectivityArray())
        if not np.all(np.diff(offsets) == 3):
            raise Error(f"{path}: a polygon VTK did not triangulate")
        F = conn.reshape(-1, 3)
    else:  # pragma: no cover (VTK 8's legacy cell array: n, i, j, k per cell)
        F = vtk_to_numpy(polys.GetData()).reshape(-1, 4)[:, 1:]
    return V, np.ascontiguousarray(F, dtype=np.int32)




def polydata(V, F):
    """V (n, 3, mm) and F (m, 3, vertex indices) as vtkPolyData (double points, triangles), for VTK's writers: the
    inverse of read_vtk_mesh."""
    import numpy as np
    from vtkmodules.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray
    from vtkmodules.vtkCommonCore import vtkPoints
    from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData

    poly = vtkPolyData()
    pts = vtkPoints()
    pts.SetData(numpy_to_vtk(np.ascontiguousarray(V, dtype=np.float64), deep=True))
    poly.SetPoints(pts)
    cells = vtkCellArray()
    conn = np.hstack([np.full((len(F), 1), 3), F]).astype(np.int64).ravel()
    cells.SetCells(len(F), numpy_to_vtkIdTypeArray(conn, deep=True))
    poly.SetPolys(cells)
    return poly


def write_ply(path, V, F):
    """V (n, 3) and F (m, 3) as a binary little-endian PLY (double vertices, int faces)."""
    import numpy as np

    with open(path, "wb") as f:
        f.write(f"ply\nformat binary_little_endian 1.0\nelement vertex {len(V)}\nproperty double x\n"
                f"property double y\nproperty double z\nelement face {len(F)}\n"
                "property list uchar int vertex_indices\nend_header\n".encode())
        f.write(np.ascontiguousarray(V, dtype="<f8").tobytes())
        rec = np.zeros(len(F), dtype=[("n", "u1"), ("i", "<i4", (3,))])
        rec["n"], rec["i"] = 3, F
        f.write(rec.tobytes())


if __name__ == "__main__":  # the CLI's converter: one line on stderr and exit 2 on a bad file
    if len(_sys.argv) != 3:
        _sys.exit("usage: vtk_meshes.py IN.vtp|IN.vtk OUT.ply")
    try:
        write_ply(_sys.argv[2], *read_vtk_mesh(_sys.argv[1]))
    except VtkMeshError as e:
        print(e, file=_sys.stderr)
        _sys.exit(2)
    except ImportError as e:
        print(f"{_sys.argv[1]}: reading VTK files needs VTK's Python bindings and numpy (apt-get install python3-vtk9 "
              f"python3-numpy): {e}", file=_sys.stderr)
        _sys.exit(2)
