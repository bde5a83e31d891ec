"""Type stubs of the impinge module (pybind11): impingement detection in ball-and-socket joints.

Units: mm and degrees. Vertices: float (n, 3); faces: integer (m, 3), 0-based."""
from typing import Any, Dict, Optional, Sequence, Tuple

import numpy as np
import numpy.typing as npt

__version__: str

class Error(ValueError):
    """Bad input or an impossible request; the message names the file or array and the element."""

def load_mesh(path: str) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.int32]]:
    """Load a triangle mesh (PLY, STL, OBJ, OFF) -> (V (n, 3) mm, F (m, 3))."""

def fit_sphere(points: npt.ArrayLike) -> Dict[str, Any]:
    """Geometric least-squares sphere -> dict(centre, radius, rms_residual, points_used)."""

def locate_femoral_head(V: npt.ArrayLike, F: npt.ArrayLike) -> SphereFit:
    """Femoral head sphere of a whole femur in any orientation."""

def generated_hip(triangles: int = 3000, cam_mm: float = 0.0, coverage_deg: float = 100.0) -> Dict[str, Any]:
    """A generated hip -> dict(ball=(V, F), socket=(V, F), cor, head_radius_mm); use neutral='scan'."""

class SphereFit:
    centre: npt.NDArray[np.float64]
    radius: float
    rms_residual: float
    points_used: int

class Map:
    """A radial distance map (read-only)."""
    values: npt.NDArray[np.float32]
    scheme: str
    resolution: float
    num_nodes: int
    nodes_covered: int
    bytes: int
    sparse: bool
    def node_directions(self) -> npt.NDArray[np.float64]: ...

class Joint:
    """Femur (ball) and pelvis (socket) with both maps built once."""
    def __init__(self, ball: Tuple[npt.ArrayLike, npt.ArrayLike], socket: Tuple[npt.ArrayLike, npt.ArrayLike],
                 cor: Optional[Sequence[float]] = None, side: str = "right", neutral: str = "anatomical",
                 scheme: str = "equiangular", resolution: float = 0.0, mode: str = "exact", sampling: str = "auto",
                 occlusion_tolerance_mm: float = 1.0, max_radius_mm: float = 0.0,
                 levels: Optional[Sequence[float]] = None, reseat: bool = False, pelvis_frame: str = "isb",
                 femur_frame: str = "epicondyles", maps: Optional[Tuple[str, str]] = None,
                 sparse: float = 0.0) -> None: ...
    def save_maps(self, ball_path: str, socket_path: str) -> None:
        """Save both maps for Joint(..., maps=(ball_path, socket_path))."""
    def detect(self, R: Optional[npt.ArrayLike] = None, t: Optional[Sequence[float]] = None) -> Dict[str, Any]:
        """Both scans, femur rotated by R about the COR and translated by t -> dict(ball_gap_mm,
        socket_gap_mm (float32, NaN untested), ball_status, socket_status (uint8), summary)."""
    def detect_pose(self, flexion: float = 0.0, adduction: float = 0.0,
                    internal_rotation: float = 0.0) -> Dict[str, Any]:
        """Both scans at clinical angles (degrees, ISB)."""
    def motion(self, angles: npt.ArrayLike) -> Dict[str, npt.NDArray[np.float64]]:
        """Both scans at every row of angles (k, 3) -> per-frame min gaps and penetrating areas."""
    def rom_limits(self, threshold_mm: float = 0.0, step_deg: float = 2.0,
                   max_deg: float = 150.0) -> Dict[str, Any]:
        """ROM limits from neutral for the standard motions -> dict motion -> dict(limit_deg, limited_by, ...)."""
    def rom_map(self, flexion: Sequence[float], adduction: Sequence[float],
                threshold_mm: float = 0.0) -> npt.NDArray[np.float64]:
        """Largest internal rotation before contact, (len(flexion), len(adduction)) degrees."""
    def femur_rotation(self, flexion: float = 0.0, adduction: float = 0.0,
                       internal_rotation: float = 0.0) -> npt.NDArray[np.float64]: ...
    cor: npt.NDArray[np.float64]
    ball_map: Map
    socket_map: Map
    frames: Optional[Dict[str, Any]]
