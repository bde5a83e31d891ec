"""Check a ParaView collection written by `impinge motion` with VTK's own reader (python3-vtk9).

usage: check_pvd.py GAPS.pvd N_POINTS N_TRIANGLES MIN1,MIN2,... [DMIN1,DMIN2,...]
Every file listed in the .pvd must load with vtkXMLPolyDataReader, hold N_POINTS points and
N_TRIANGLES triangles, arrays gap_mm, level and body, and gap_mm's minimum (ignoring NaN) must
equal the frame's expected minimum gap within 1e-4 mm; with DMIN (nan: none measured), an array distance_mm
whose minimum equals it. Prints "K frames ok" and exits 0.
"""
import math
import os
import sys
import xml.etree.ElementTree as ET

import vtk
from vtk.util.numpy_support import vtk_to_numpy
import numpy as np


def main():
    pvd, n_points, n_tris, mins = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
    expected = [float(x) for x in mins.split(",") if x]
    dmins = [float(x) for x in sys.argv[5].split(",") if x] if len(sys.argv) > 5 else None
    sets = ET.parse(pvd).getroot().find("Collection").findall("DataSet")
    if len(sets) != len(expected):
        sys.exit(f"{pvd}: {len(sets)} data sets, expected {len(expected)}")
    for k, ds in enumerate(sets):
        path = os.path.join(os.path.dirname(pvd), ds.get("file"))
        reader = vtk.vtkXMLPolyDataReader()
        reader.SetFileName(path)
        reader.Update()
        out = reader.GetOutput()
        if out.GetNumberOfPoints() != n_points or out.GetNumberOfPolys() != n_tris:
            sys.exit(f"{path}: {out.GetNumberOfPoints()} points, {out.GetNumberOfPolys()} triangles")
        pd = out.GetPointData()
        for name in ("gap_mm", "level", "body"):
            if pd.GetArray(name) is None:
                sys.exit(f"{path}: no point array {name}")
        gap = vtk_to_numpy(pd.GetArray("gap_mm"))
        if not math.isclose(float(np.nanmin(gap)), expected[k], abs_tol=1e-4):
            sys.exit(f"{path}: min gap {np.nanmin(gap)} != {expected[k]}")
        if dmins is not None:
            if pd.GetArray("distance_mm") is None:
                sys.exit(f"{path}: no point array distance_mm")
            dist = vtk_to_numpy(pd.GetArray("distance_mm"))
            got = float(np.nanmin(dist)) if np.any(np.isfinite(dist)) else math.nan
            if not (math.isnan(got) and math.isnan(dmins[k])) and not math.isclose(got, dmins[k], abs_tol=1e-4):
                sys.exit(f"{path}: min distance {got} != {dmins[k]}")
    print(f"{len(sets)} frames ok")


if __name__ == "__main__":
    main()
