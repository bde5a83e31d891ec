"""Type stubs of the impinge module (pybind11): impingement detection in ball-and-socket joints.

Units: mm and degrees. Vertices: float (n, 3); faces: integer (m, 3), 0-based."""
import os
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

class Error(ValueError):
    """Bad input or an impossible request; the message names the file or array and the element."""

VTK_SUFFIXES: Tuple[str, ...]

def load_mesh(path: Union[str, os.PathLike], scale: float = 1.0) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.int32]]:
    """Load a triangle mesh (PLY, STL, OBJ, OFF; VTK .vtp/.vtk through VTK's readers) -> (V (n, 3) mm, F (m, 3)).
    scale multiplies the coordinates (1000 for OpenSim's metre files)."""

def read_vtk_mesh(path: Union[str, os.PathLike]) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.int32]]:
    """A VTK file's surface (.vtp XML PolyData, .vtk legacy), triangulated by VTK -> (V (n, 3), F (m, 3))."""

def is_vtk_file(path: Any) -> bool:
    """True when path ends in .vtp or .vtk."""

def set_threads(n: int) -> None:
    """OpenMP threads of the calling thread's later calls (ROM searches and maps, sampling)."""

def get_threads() -> int:
    """OpenMP threads the calling thread's next parallel call would use."""

def build_info() -> Dict[str, str]:
    """The build's provenance -> dict(version, compiler, kernels): what every experiment's meta.json records."""

def machine_info() -> Dict[str, str]:
    """What this machine exposes -> dict(cpu_model, cpu_family, cpu_model_number, cpu_stepping, cpu_mhz, l2_cache,
    l3_cache, logical_cpus, sockets, physical_cores, smt ("yes" when a core runs two logical CPUs), thread_siblings,
    memory_gib, hypervisor, os_kernel); 'unknown' where it does not say."""

def load_motion(path: str, side: str = "right") -> Dict[str, Any]:
    """A motion file as impinge motion reads it (CSV or OpenSim .mot/.sto) -> dict(time_s (k,) s,
    angles (k, 3) degrees: flexion, adduction, internal rotation; format 'csv' or 'opensim')."""

def fit_sphere(points: npt.ArrayLike) -> Dict[str, Any]:
    """Geometric least-squares sphere -> dict(centre, radius, rms_residual, points_used)."""

def locate_femoral_head(V: npt.ArrayLike, F: npt.ArrayLike,
                        pelvis: Optional[Tuple[npt.ArrayLike, npt.ArrayLike]] = None) -> SphereFit:
    """Femoral head sphere of a femur in any orientation; with its pelvis (same frame), the end that
    sits in the acetabulum, as the CLI finds it."""


def level_colours(count: int) -> Dict[str, Any]:
    """The impingement levels' colours (0-255) as the PLY files give them, for `count` levels -> dict(femur=[(r, g,
    b) per level], pelvis=[...], untested=(r, g, b))."""
def options() -> List[Dict[str, Any]]:
    """The option table (the session layer's): one dict per option with name (the CLI's), key (Python's and the
    study files'), type, unit, choices, min, max (the field's declared range), min_exclusive, required, default
    (the clinical preset's), thesis_default, help and uses (CLI commands, joint, rom_limits, rom_map, study)."""

def check_options(use: str, **options: Any) -> Dict[str, Any]:
    """Check keywords as the call of `use` (a use of options(): joint, rom_limits, rom_map, joint_plan, study, ...)
    checks them, building nothing (for joint and study: the maps' scheme at its resolution too; for joint_plan: the
    targets, the target motion, a target at all) -> every row of that use as the call would take it. Raises
    impinge.Error naming the key, the value and what is valid."""

def femoral_head_centre(ball: Optional[Union[str, os.PathLike, Tuple[npt.ArrayLike, npt.ArrayLike]]] = None,
                        socket: Optional[Union[str, os.PathLike, Tuple[npt.ArrayLike, npt.ArrayLike]]] = None,
                        **options: Any) -> Dict[str, Any]:
    """The femoral head centre as Joint(...) finds it from the same keywords, without building maps ->
    dict(centre (3,) mm in the input frame, radius mm (NaN when given), method)."""

def generated_hip(*, triangles: int = 3000, cam_mm: float = 0.0, coverage_deg: float = 100.0) -> Dict[str, Any]:
    """A generated hip -> dict(femur=(V, F), pelvis=(V, F), cor, head_radius_mm); use neutral='scan'."""

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
    """A hip set up as `impinge distance` sets it up (the session layer): both maps built once, then
    any number of poses. Every option of `impinge distance` is a keyword, named as the CLI's with
    underscores (lengths with _mm); None means the default. Positions, rotations and frames given
    or returned are in the input frame (`frame`)."""
    def __init__(self, ball: Optional[Union[str, Tuple[npt.ArrayLike, npt.ArrayLike]]] = None,
                 socket: Optional[Union[str, Tuple[npt.ArrayLike, npt.ArrayLike]]] = None, *,
                 preset: str = 'clinical', subject: Optional[Union[str, os.PathLike]] = None,
                 side: Optional[str] = None, frame: Optional[str] = None, strict: bool = False,
                 landmarks: Optional[Dict[str, Sequence[float]]] = None,
                 cor: Optional[Union[str, Sequence[float]]] = None, allow_any_cor: bool = False,
                 head_region: Optional[Sequence[float]] = None, scheme: str = 'equiangular', resolution: float = 0.0,
                 precision: float = 0.0, turns: float = 0.0, spacing_deg: float = 0.0, sampling: str = 'auto',
                 mode: str = 'exact', levels: Optional[Sequence[float]] = None, occlusion_tolerance_mm: float = 1.0,
                 max_radius_mm: float = 0.0, sparse_region_mm: float = 0.0, discontinuity_tolerance_mm: float = 0.05,
                 layers: int = 4, query_strategy: str = 'auto', layered_spacing_deg: float = 0.5,
                 extra_articular_radius_mm: float = 150.0, distances: bool = True, levels_on: Optional[str] = None,
                 distance_reach_mm: float = 0.0, max_memory_gb: float = 0.0, maps_only: bool = False,
                 maps: Optional[Tuple[str, str]] = None, neutral: Optional[str] = None, pelvis_frame: str = 'isb',
                 joint_centre: Optional[str] = None, femur_frame: str = 'epicondyles') -> None:
        """Every keyword is a row of impinge.options() (the session layer's option table, shared with the CLI
        and study files), its default the clinical preset's; preset='thesis' starts from the thesis' set-up.
        ball, socket: mesh files or (V (n, 3) float mm, F (m, 3) int); or subject: a subject.json
        (meshes, side, frame, landmarks, neutral). side: 'right'/'left'; frame: 'LPS'/'RAS' (the
        meshes' frame; default the subject's, else RAS). cor: 'auto' (the femoral head fitted) or
        (x, y, z) mm, the femoral head centre about which the radial gaps at the scan pose are measured; head_region: (x, y, z, r) mm, fit the head there; allow_any_cor: accept a COR (or landmark hip_centre)
        outside the head. scheme and one of resolution/precision/turns/spacing_deg (0: the scheme's
        0.5 deg default); sampling; mode 'exact'/'linear'; levels: thresholds mm, decreasing;
        sparse_region_mm: mm kept around the COR (inf: any surface; 0: dense); layers: N crossings per node for
        hidden vertices (extra-articular), within extra_articular_radius_mm, at layered_spacing_deg (0: the maps' own); query_strategy: 'maps', 'direct' (no
        layered maps: the hidden vertices by exact ray casts, for a few poses; no ROM searches) or 'auto' (maps); distances: the signed
        Euclidean distance to the other bone beside each gap (results' femur_distance_mm, pelvis_distance_mm),
        for every vertex within distance_reach_mm of it (0: the largest level threshold); levels_on: what the
        levels classify, 'distance' or 'radial' (the thesis' gap; default: distance, radial with distances off); maps_only: no exact
        look-ups at depth discontinuities; maps: (ball_path, socket_path) from save_maps().
        neutral: 'anatomical' (ISB frames) or 'scan' (default: the subject's, else anatomical);
        pelvis_frame 'isb'/'app'; femur_frame 'epicondyles'/'posterior-condyles'; joint_centre: how the
        femur moves at each pose (Puls et al. 2010): 'femoral-head', 'acetabular', 'combined' or
        'equidistant' (default: equidistant with anatomical neutral, femoral-head with scan neutral).
        Raises Error naming the option, array or file."""
    def save_maps(self, ball_path: str, socket_path: str) -> None:
        """Save both maps for Joint(..., maps=(ball_path, socket_path))."""
    def detect(self, R: Optional[npt.ArrayLike] = None, t: Optional[Sequence[float]] = None) -> Dict[str, Any]:
        """Both scans, femur rotated by R about its head centre (`cor`) and translated by t -> dict(femur_gap_mm,
        pelvis_gap_mm (float32, NaN untested), femur_distance_mm, pelvis_distance_mm (float32, the signed
        Euclidean distance to the other bone, NaN beyond the reach; with distances on), femur_status,
        pelvis_status (uint8), femur_level, pelvis_level (uint8, the impingement level; 255 untested), summary: each
        scan's record as summary.json gives it)."""
    def detect_pose(self, flexion: float = 0.0, adduction: float = 0.0,
                    internal_rotation: float = 0.0) -> Dict[str, Any]:
        """Both scans at clinical angles (degrees, ISB), the femur placed by the joint-centre method; the
        dict of detect() with joint_translation_mm (3,): the femur's translation from its scan position
        after its rotation about its head centre (input frame, mm)."""
    def motion(self, angles: npt.ArrayLike) -> Dict[str, npt.NDArray[np.float64]]:
        """Both scans at every row of angles (k, 3) -> the columns of the CLI's frames.csv, (k,) each. Frames
        are scanned in blocks on impinge.get_threads() threads; rows come back in order."""
    def rom_limits(self, *, threshold_mm: float = 0.0, contact_depth_mm: float = 0.0, metric: str = 'distance',
                   contacts: str = 'impingement', step_deg: float = 2.0, tolerance_deg: float = 0.1,
                   max_deg: float = 150.0, labrum: bool = False, labrum_width_mm: float = 5.3,
                   labrum_height_mm: float = 7.0) -> Dict[str, Any]:
        """ROM limits from neutral for the standard motions -> dict motion -> the CLI's rom_limits.csv row
        (limit_deg, first_contact_deg, limited_by, contact_class, ...). The keywords and defaults are `impinge
        rom`'s (the option table). contacts: 'impingement' (the joint surfaces meeting is left out), 'articular'
        (only that: the joint space closing) or 'all'. contact_depth_mm: how far past the threshold a contact must
        reach to end a search (default 0: the first touch, exact between vertices; > 0 for noisy meshes, when
        first_contact_deg still gives the first touch). metric: 'distance' (needs the Joint's distances) or
        'radial'."""
    def plan(self, *, threshold_mm: float = 0.0, contact_depth_mm: float = 0.0, metric: str = 'distance',
             contacts: str = 'impingement', step_deg: float = 2.0, tolerance_deg: float = 0.1, max_deg: float = 150.0,
             labrum: bool = False, labrum_width_mm: float = 5.3, labrum_height_mm: float = 7.0,
             target: Optional[str] = None, target_motion: Optional[Union[str, os.PathLike]] = None,
             resect: str = 'femur', clearance_mm: float = 0.3, max_depth_fraction: float = 0.3,
             max_depth_mm: float = 0.0, burr_radius_mm: float = 2.5, plan_step_deg: float = 0.5,
             allow_partial: bool = False) -> Dict[str, Any]:
        """Resection plan (`impinge plan`'s plan.json as a dict): the least bone to remove so that the targets
        ('MOTION=DEG,...' and/or 'normal'; target_motion: a motion file) run free of impingement, shaped for a
        spherical burr (burr_radius_mm), within the safety depth (max_depth_fraction of the neck's least diameter,
        or max_depth_mm), never the head inside the labrum line or the lunate surface; checked on the resected
        bones in their own placement (the ROM search and the clearance at every target pose). Adds femur_resected
        (V, F: input frame, mm) and femur_resection_mm (per vertex, mm), and the pelvis' with resect 'pelvis' or
        'both'. Raises impinge.Error when a target is missed unless
        allow_partial."""
    def rom_map(self, *, threshold_mm: float = 0.0, contact_depth_mm: float = 0.0, metric: str = 'distance',
                flexion: Sequence[float] = [0.0, 5.0, 10.0, 15.0, 20.0, 25.0, 30.0, 35.0, 40.0, 45.0, 50.0, 55.0,
                                            60.0, 65.0, 70.0, 75.0, 80.0, 85.0, 90.0, 95.0, 100.0, 105.0, 110.0,
                                            115.0, 120.0],
                adduction: Sequence[float] = [-20.0, -15.0, -10.0, -5.0, 0.0, 5.0, 10.0, 15.0, 20.0, 25.0, 30.0, 35.0,
                                              40.0]) -> npt.NDArray[np.float64]:
        """Largest internal rotation before contact, (len(flexion), len(adduction)) degrees: `impinge rom`'s
        ROM map (the same search)."""
    def morphology(self) -> Dict[str, Any]: ...
    def femur_rotation(self, flexion: float = 0.0, adduction: float = 0.0,
                       internal_rotation: float = 0.0) -> npt.NDArray[np.float64]: ...
    def femur_pose(self, flexion: float = 0.0, adduction: float = 0.0,
                   internal_rotation: float = 0.0) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """(R, t) at the clinical angles with the joint-centre method's translation: posed vertices =
        (V - cor) R^T + cor + t (input frame); detect(R, t) scans that pose."""
    cor: npt.NDArray[np.float64]
    """The femoral head centre (input frame, mm): the `cor` given, else fitted; the femur's rotations are
    about it (then translated by the joint-centre method: see pivot)."""
    map_centre: npt.NDArray[np.float64]
    """The maps' centre (the rays' origin): the head centre, or the acetabular centre where a fitted head
    was seated before sampling."""
    acetabular_centre: Optional[npt.NDArray[np.float64]]
    """The acetabular centre (anatomical neutral), input frame, mm."""
    pivot: Optional[npt.NDArray[np.float64]]
    """The point the femur turns about under the joint-centre method (input frame, mm, the pelvis fixed): the
    head centre (femoral-head) or the acetabular centre (acetabular, combined); None for equidistant."""
    meshes: Dict[str, Tuple[npt.NDArray[np.float64], npt.NDArray[np.int32]]]
    """Both bones as given (input frame, scan pose): dict(femur=(V, F), pelvis=(V, F))."""
    femur_map: Map
    pelvis_map: Map
    frames: Optional[Dict[str, Any]]
    """summary.json's "frames" record (anatomical neutral; None with scan neutral), input frame."""
    setup: Dict[str, Any]
    """The set-up as the CLI's summary.json reports it."""
    warnings: List[str]
