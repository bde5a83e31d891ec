#pragma once
/// @file joint.hpp
/// A ball-and-socket joint ready for detection: both maps built once, then any number of
/// poses queried (thesis Fig. 27: preprocessing, then simulation).

#include <Eigen/Core>
#include <algorithm>
#include <limits>
#include <memory>
#include <utility>
#include <optional>
#include <vector>

#include "impinge/casters/first_hit_caster.hpp"
#include "impinge/core/range.hpp"
#include "impinge/core/mesh.hpp"
#include "impinge/detection/detection.hpp"
#include "impinge/detection/impingement_levels.hpp"
#include "impinge/detection/surface_distance.hpp"
#include "impinge/maps/layered_map.hpp"
#include "impinge/maps/radial_distance_map.hpp"
#include "impinge/sampling/rasterize.hpp"
#include "impinge/sampling/sampling.hpp"
#include "impinge/schemes/sampling_scheme.hpp"

namespace impinge {

/// Options of a Joint. Each numeric field's valid values are declared once, as the Range beside it
/// (k...Range); validate() checks them, and the session layer's option table takes its rows' ranges from
/// the same declarations (issue 78).
struct JointOptions {
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  /// Sampling scheme of both maps (make_scheme); default equiangular at p = 0.5 deg.
  std::shared_ptr<const SamplingScheme> scheme = make_scheme("equiangular", 0.5);
  DistanceMode mode = DistanceMode::exact;                         ///< rasterisation distance mode
  SamplingMethod sampling = SamplingMethod::automatic;             ///< how maps are filled
  double occlusion_tolerance_mm = 1.0;                             ///< a vertex farther than its own map's surface
                                                                   ///< plus this is hidden (not on the first surface)
  static constexpr Range kOcclusionToleranceRange{0, kInf};        ///< of occlusion_tolerance_mm, mm
  /// Region of interest about the COR, mm: no vertex farther is tested (hidden ones neither).
  double max_radius_mm = kInf;
  static constexpr Range kMaxRadiusRange{0, 1e4, true};  ///< of max_radius_mm, mm, when finite (inf: every vertex)
  ImpingementLevels levels;                                        ///< gap classes
  /// Exact look-ups at depth discontinuities: mark each map's nodes where its
  /// interpolation may be off by more than discontinuity_tolerance_mm (mark_depth_discontinuities)
  /// and resolve every look-up whose stencil holds one by a ray cast of the other mesh
  /// (FirstHitCaster), and every first-surface decision of such a vertex by a ray cast of its own.
  /// Off, or in a build without Embree or CGAL, the maps answer alone (the thesis' algorithm).
  bool exact_at_discontinuities = true;
  double discontinuity_tolerance_mm = 0.05;  ///< see exact_at_discontinuities, mm (> 0)
  static constexpr Range kDiscontinuityToleranceRange{0, 1e3, true};  ///< of discontinuity_tolerance_mm, mm
  /// Store both maps sparse (RadialDistanceMapT::make_sparse) once they are filled and marked: only
  /// the tiles with a surface within sparse_region_mm of the COR (default: any surface, which gives
  /// every gap bit for bit as the dense maps; a finite region answers "no surface" beyond it).
  /// Source: impinge (not in the thesis).
  bool sparse_maps = false;
  double sparse_region_mm = kInf;                          ///< see sparse_maps, mm (> 0)
  static constexpr Range kSparseRegionRange{0, kInf, true};  ///< of sparse_region_mm, mm
  /// Layered maps: with layers = N > 0, each body also gets a LayeredMap of the same scheme
  /// with N crossings per node (filled by ray casts, all cores), and the vertices hidden behind their
  /// own body's nearer surface (not in the first-surface mask) within extra_articular_radius_mm of the
  /// COR are tested against the other body's layered map: the trochanters, the shaft and the neck
  /// against the ilium, ischium and AIIS (extra-articular impingement). First-surface vertices keep the
  /// single-layer look-up (intra-articular results are unchanged, bit for bit). A cluster of hidden
  /// vertices that a closest-point query proves outside the other bone and farther than reach_mm() from
  /// it is left out at that pose (scan_layered_near; its vertices stay beyond reach: their radial gaps
  /// exceed every level threshold). 0: off (the thesis).
  /// Needs a ray caster (Embree or CGAL). Memory per map: nodes * (4 N + 1) bytes.
  int layers = 0;
  static constexpr Range kLayersRange{0, LayeredMap::kMaxLayers};  ///< of layers
  double extra_articular_radius_mm = 150;  ///< hidden vertices farther from the COR are not tested, mm (> 0)
  static constexpr Range kExtraArticularRadiusRange{0, kInf, true};  ///< of extra_articular_radius_mm, mm
  /// With layers > 0: build the layered maps (true), or leave them out (false: a set-up for a few poses, which
  /// filling them, about 0.12 s for lhdl-ct at 0.5 deg, would not repay): the hidden vertices near the other bone
  /// are then tested by exact ray casts over their rays' crossings (scan_layered_near_exact), the value the
  /// maps' look-ups approximate. The ROM searches need the maps (find_rom_limit refuses a joint without them).
  /// Off, the first-hit casters' trees are also built fast rather than well (HierarchyBuild::fast: Morton codes,
  /// some 10 ms less per bone of lhdl-ct; the same hits, slower rays). Source: impinge (issue 52: a set-up chosen
  /// by the work).
  bool layered_maps = true;
  /// The layered maps' largest node spacing, deg: `scheme` at the coarsest resolution reaching it, or
  /// `scheme` itself when that is coarser already (0: `scheme` itself). The hidden vertices lie far
  /// from the COR (the trochanters, ischium and ilium), where a node spacing of 0.5 deg is 0.5 mm at
  /// 60 mm; the look-ups whose stencil straddles an edge or depth jump are exact ray casts anyway.
  /// Filling a layered map by ray casts costs per node: at 0.1 deg about 3 s for both bones of
  /// lhdl-ct, at 0.5 deg about 0.12 s.
  double layered_spacing_deg = 0.5;
  static constexpr Range kLayeredSpacingRange{0, 90};  ///< of layered_spacing_deg, deg
  /// Euclidean distances: with `distances` on, every detect also gives each vertex within
  /// max_radius_mm of the COR, on the first surface or hidden, its signed distance to the other bone's
  /// surface (ScanGaps::distance_mm; surface_distance.hpp), wherever it cannot be proven farther than
  /// distance_reach_mm. Needs Embree or CGAL. Off: the thesis' radial gaps alone.
  bool distances = false;
  /// The reach of the distances, mm (> 0); 0: the largest threshold of `levels` (the cartilage offset,
  /// 4 mm by default). Vertices proven farther get NaN.
  double distance_reach_mm = 0;
  static constexpr Range kDistanceReachRange{0, kInf};  ///< of distance_reach_mm, mm
  /// What the impingement levels classify (ScanSummary::level_vertices, PLY colours, clock sectors): the
  /// radial gap (the thesis) or, with distances on, the Euclidean distance (then distance_reach_mm must be
  /// 0 or at least the largest level threshold). Unset: the radial gap (level_quantity()); the Session resolves
  /// unset to the distance when distances are on (resolved_hip_options), as the option table's help says.
  std::optional<LevelQuantity> levels_on;
  /// Leave the distance hierarchies (JointBody::distance_query) to Joint::crop_distance_queries, for the poses
  /// the caller will ask (one `impinge distance`), instead of building them over the whole meshes: each then
  /// holds only the triangles those poses' searches can reach (5-13 % of a shared hip's at rest), and answers every
  /// other search from a whole-mesh hierarchy built at its first use, so every result is the same either way.
  /// Source: impinge (issue 52: a set-up chosen by the work).
  bool cropped_distance_queries = false;
  /// Whether the bodies need closest-point hierarchies (SignedDistanceQuery): for the distances, and for the
  /// layered scans' pruning of hidden vertices far from the other body (layers > 0).
  bool needs_distance_queries() const { return distances || layers > 0; }
  /// levels_on resolved: as set, else the radial gap.
  LevelQuantity level_quantity() const { return levels_on.value_or(LevelQuantity::radial_gap); }
  /// Check every field against its declared range (and the levels, the scheme, levels_on against distances);
  /// not what the build can do (a ray caster for layers, a closest-point engine for distances: the Joint checks
  /// those). Throws impinge::Error naming the field (e.g. "JointOptions::layers 99 is outside the valid range
  /// [0, 16]").
  void validate() const;
  /// distance_reach_mm resolved (the largest level threshold when 0), mm.
  double reach_mm() const { return distance_reach_mm > 0 ? distance_reach_mm : std::max(levels.thresholds_mm.front(), 1e-3); }
};

/// One body of the joint after preprocessing.
struct JointBody {
  /// A body of `mesh` whose map uses `scheme` (empty until sampled); every other member default.
  JointBody(TriangleMesh mesh_in, std::shared_ptr<const SamplingScheme> scheme)
      : mesh(std::move(mesh_in)), map(std::move(scheme)) {}
  TriangleMesh mesh;               ///< the frame the joint was given (Session: the joint frame), mm
  Vertices relative;               ///< n x 3, vertices minus the COR, mm
  RadialDistanceMap map;           ///< its radial distance map about the COR
  std::vector<std::uint8_t> mask;  ///< 1 for vertices on the first surface within the region
  ScanSet scan_set;                ///< the masked vertices, prepared for the fast scan
  Eigen::VectorXd vertex_area;     ///< n, mm^2
  SamplingReport sampling;         ///< how the map was filled, with counts
  double sampling_ms = 0;          ///< wall time of filling the map, ms
  /// Ray caster of the mesh about the COR when exact_at_discontinuities is on (else null).
  std::shared_ptr<const FirstHitCaster> exact;
  std::int64_t nodes_marked = 0;   ///< map nodes with the depth-discontinuity mark
  double marking_ms = 0;           ///< wall time of marking them and building the ray caster, ms
  /// With JointOptions::layers > 0 (else null / empty): the layered map about the COR, the ray caster
  /// that filled it (also resolves layered look-ups across edges of the bone), and the hidden vertices
  /// tested against the other body's layered map (in boxes of 32, order_in_boxes: compact clusters, so that
  /// scan_layered_near leaves out all but the hidden vertices near the other bone).
  std::shared_ptr<const LayeredMap> layered;
  std::shared_ptr<const FirstHitCaster> caster;
  ScanSet hidden_set;
  LayeredSamplingReport layered_sampling;
  /// With JointOptions::distances (else null / empty): the closest-point hierarchy of the mesh (the other
  /// body's distance scan queries it), and this body's vertices grouped for its own distance scan.
  std::shared_ptr<const SignedDistanceQuery> distance_query;  ///< also with layers > 0 (the layered scan's pruning)
  DistanceScanSet distance_set;  ///< empty (no clusters) when distances are off
  /// With layers > 0: hidden_set in runs of 32 (cluster_scan_set), so that the layered scan leaves out
  /// the clusters proven beyond the reach of the other bone (scan_layered_near against the other body's
  /// distance_query, which layers > 0 builds too).
  ScanClusters hidden_clusters;
};

/// Result of both scans at one pose.
struct PoseResult {
  ScanGaps ball_gaps, socket_gaps;
  ScanSummary ball, socket;
  double ball_detection_ms = 0, socket_detection_ms = 0;  ///< both include the layered scans when on
  double ball_distance_ms = 0, socket_distance_ms = 0;    ///< the distance scans (JointOptions::distances)
  std::vector<float> compact_gaps;         ///< scratch of detect (the ball's compact scans), kept to reuse its storage
  std::vector<float> compact_gaps_socket;  ///< and the socket's (the two scans may run on two threads)
};

/// What a sequence of Joint::detect calls learns for the next (a motion's frames, one thread's): each
/// distance scan's DistanceScanMemory. Changes no result, only the cost; tied to the surfaces it is about.
struct DetectionMemory {
  DistanceScanMemory ball, socket;  ///< the ball's scan (against the socket's surface), the socket's
};

/// Ball (femur) and socket (pelvis) about a fixed COR.
class Joint {
 public:
  /// Rasterise both meshes (one frame, mm) about `cor` (mm) and compute the first-
  /// surface masks. Throws impinge::Error on invalid options or a non-finite COR.
  Joint(TriangleMesh ball, TriangleMesh socket, const Eigen::Vector3d& cor, const JointOptions& options);

  /// The same with both maps given (for example loaded with load_map) instead of sampled: no
  /// rasterisation. The maps must be about `cor` in the meshes' frame and of options.scheme's
  /// scheme and resolution. Throws impinge::Error when a map's scheme, resolution or node count
  /// differs from options.scheme.
  Joint(TriangleMesh ball, TriangleMesh socket, const Eigen::Vector3d& cor, const JointOptions& options,
        RadialDistanceMap ball_map, RadialDistanceMap socket_map);

  /// Both scans (ball vertices against the socket map, socket vertices against the ball map)
  /// with the ball rotated by R (3 x 3) about the COR and then translated by t (mm, socket
  /// frame; zero for a pure ball-and-socket motion, nonzero to push the head into the cup).
  /// Thesis Algorithm 2 applied twice, through scan_gaps_compact; with layers, the hidden vertices of
  /// each body against the other's layered map too (scan_layered; status tested_layered); with
  /// distances, the Euclidean distance scans after them (scan_distances, ScanGaps::distance_mm).
  PoseResult detect(const Eigen::Matrix3d& R, const Eigen::Vector3d& t = Eigen::Vector3d::Zero()) const;

  /// The same into `out`, reusing its vectors: after the first pose, no allocation per pose
  /// (for motions and ROM searches over many poses).
  void detect(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, PoseResult& out) const;

  /// The same, with the distance scans using and updating `memory` (null: none; DetectionMemory): the
  /// same result at less cost when the poses follow each other closely, as a motion's frames do. One
  /// memory per thread.
  void detect(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, PoseResult& out, DetectionMemory* memory) const;

  /// With JointOptions::cropped_distance_queries (required before the first detect that needs a distance
  /// hierarchy, with distances or layers on): build both bodies' distance hierarchies cropped to the balls their
  /// searches at these poses (R: 3 x 3, t: mm, as detect's) can reach: the other body's distance-scan clusters
  /// grown by the reach (which hold its vertices' balls of the reach), and its hidden clusters alike
  /// (SignedDistanceQuery's region constructor). A detect at any other pose gives the same answers, at the cost of
  /// the whole hierarchies, built at their first use. Replaces hierarchies built before. Throws impinge::Error on
  /// a pose that is not finite.
  void crop_distance_queries(const std::vector<std::pair<Eigen::Matrix3d, Eigen::Vector3d>>& poses);

  const JointBody& ball() const { return ball_; }
  const JointBody& socket() const { return socket_; }
  const Eigen::Vector3d& cor() const { return cor_; }
  const JointOptions& options() const { return options_; }
  /// The layered maps' scheme (JointOptions::layered_spacing_deg).
  std::shared_ptr<const SamplingScheme> layered_scheme() const;

 private:
  Joint(const Eigen::Vector3d& cor, const JointOptions& options, std::pair<JointBody, JointBody> bodies);
  /// Both bodies, their parts on two threads, after checking the options (throws impinge::Error).
  static std::pair<JointBody, JointBody> build_bodies(const Eigen::Vector3d& cor, const JointOptions& options,
                                                      TriangleMesh ball, TriangleMesh socket,
                                                      std::optional<RadialDistanceMap> ball_map,
                                                      std::optional<RadialDistanceMap> socket_map);
  static std::shared_ptr<const SamplingScheme> layered_scheme(const JointOptions& options);
  Eigen::Vector3d cor_;
  JointOptions options_;
  JointBody ball_, socket_;
};

}  // namespace impinge
