#pragma once
/// @file rom.hpp
/// Range-of-motion limits (thesis sec. 5.2): from neutral along a motion, the first
/// angle at which the bones meet (minimum gap <= threshold), found by steps and bisection, with
/// where they meet; and the ROM map of clinical planning tools (Tannast et al. 2007,
/// Kubiak-Langer et al. 2007): the largest internal rotation over flexion x adduction.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "impinge/anatomy/pose.hpp"
#include "impinge/clinical/hip_joint.hpp"
#include "impinge/core/enum_names.hpp"
#include "impinge/core/range.hpp"

namespace impinge {

/// Which vertices a ROM search counts.
enum class RomVertices {
  all,            ///< every tested vertex (the ROM limit)
  first_surface,  ///< the single-layer scans only (intra-articular; the thesis' maps)
  hidden,         ///< the hidden vertices against the layered maps only (the first extra-articular contact)
};

/// Which contacts end a ROM search (the articular zones of HipJoint::articular(); with scan neutral
/// there are none and every option counts every vertex).
enum class RomContacts {
  impingement,  ///< impingement only: the femoral head up to its head-neck junction against the acetabulum (the
                ///< joint space closing) is not counted; the neck or a cam against the lunate surface is (the limit)
  articular,    ///< the head against the acetabulum only: where the joint space closes, reported apart
  all,          ///< every vertex: where the bones first meet (the thesis' criterion)
};
/// The names of RomContacts (the option table's choices of --contacts).
inline constexpr EnumNames<RomContacts, 3> kRomContactsNames{
    {{RomContacts::impingement, "impingement"}, {RomContacts::articular, "articular"}, {RomContacts::all, "all"}}};

/// Parse "impingement", "articular" or "all". Throws impinge::Error naming `context` otherwise.
RomContacts parse_rom_contacts(const std::string& text, const std::string& context);
/// "impingement", "articular" or "all" (the CLI's spelling).
const char* to_string(RomContacts contacts);

/// What a ROM search compares with the threshold.
enum class RomMetric {
  radial,    ///< the thesis' radial gap (Algorithm 2): along the ray from the COR; fast (cluster bounds)
  distance,  ///< the signed Euclidean distance to the other bone's surface (ScanGaps::distance_mm): what a
             ///< cartilage offset or clearance means; every pose is a full Joint::detect with distances
};
/// The names of RomMetric (the option table's choices of --metric).
inline constexpr EnumNames<RomMetric, 2> kRomMetricNames{
    {{RomMetric::distance, "distance"}, {RomMetric::radial, "radial"}}};
/// "radial" or "distance".
const char* to_string(RomMetric metric);
/// Parse "radial" or "distance". Throws impinge::Error naming `context` otherwise.
RomMetric parse_rom_metric(const std::string& text, const std::string& context);

/// Contacts within the acetabular rim radius plus this (mm) of the COR are intra-articular, farther
/// ones extra-articular (RomOptions' default; the motion and distance summaries use it too).
inline constexpr double kIntraArticularMarginMm = 10;

/// Options of a ROM search.
struct RomOptions {
  double threshold_mm = 0;       ///< contact when the minimum gap <= this less contact_depth_mm (0: bone contact;
                                 ///< a cartilage offset > 0)
  static constexpr Range kThresholdRange{-100, 100};  ///< of threshold_mm, mm
  /// A contact must reach this far past the threshold to end a search, mm. 0 (the default): the limit is
  /// where the bones first touch (the least exact surface-to-surface distance reaches the threshold;
  /// published simulated ROM is at first bony contact). > 0 is for noisy meshes: a graze shallower than the
  /// data's own error (an MRI surface's roughness about its fitted sphere, 0.4-0.8 mm rms) does not stop a
  /// motion, whose femur the joint's play lets slide past it (measured before issue 81: tlem2-mri's flexion
  /// 118 -> 27 deg at 0 mm against 0.1 mm); such a limit is a depth of overlap, found by the per-vertex
  /// test, and RomLimit::first_contact_deg still gives the first touch.
  double contact_depth_mm = 0;
  static constexpr Range kContactDepthRange{0, 100};  ///< of contact_depth_mm, mm
  /// What is compared with the threshold: the radial gap, or the Euclidean distance (which needs the
  /// joint's JointOptions::distances on, with a reach of at least max(threshold_mm, 0), and counts every
  /// vertex: RomVertices::all). The two agree on whether the bones overlap; above 0 they differ, the
  /// distance reaching a threshold earlier (the radial gap bounds it from above), and a penetration's
  /// depth by the distance is the true one where the ray runs inside the other bone. At or
  /// below a cut (threshold less contact depth) of 0 the radial scan screens the distance's: only the
  /// vertices whose radial gap is within the cut plus 0.5 mm get a distance (a vertex inside the other
  /// bone has a radial gap at most its distance, up to the maps' interpolation error); above 0 every pose
  /// is a whole distance scan (Joint::detect), about 10x slower. The CLI's and Python's default is the
  /// distance; the library's and the thesis experiments' the radial gap.
  RomMetric metric = RomMetric::radial;
  double step_deg = 2;           ///< coarse step along the motion, deg
  static constexpr Range kStepRange{0.01, 90};  ///< of step_deg, deg
  double max_deg = 150;          ///< search no farther than this from neutral, deg
  static constexpr Range kMaxRange{0.1, 360};   ///< of max_deg, deg
  double tolerance_deg = 0.1;    ///< bisection until the bracket is this narrow, deg
  static constexpr Range kToleranceRange{1e-4, 90};  ///< of tolerance_deg, deg (and at most step_deg)
  bool use_bounds = true;        ///< skip vertex clusters whose bound cannot reach the threshold (same results,
                                 ///< fewer look-ups; equiangular maps)
  RomVertices vertices = RomVertices::all;  ///< which vertices are counted (hidden ones need JointOptions::layers)
  RomContacts contacts = RomContacts::impingement;  ///< which contacts end a search; applied by
                                                    ///< rom_baseline, through the vertices it leaves out
  /// Contacts within the acetabular rim radius plus this (mm) of the COR are intra-articular,
  /// farther ones extra-articular.
  double intra_articular_margin_mm = kIntraArticularMarginMm;
  /// Contacts found exactly between vertices (issue 81): where the cut (threshold less contact depth) is
  /// >= 0 and, with the radial metric, 0 (where the bones meet, the two metrics agree), and every vertex
  /// is counted (RomVertices::all), whether the bones meet at a pose is the exact least distance between
  /// the meshes (MeshContact: vertex against face and edge against edge, every triangle of either bone)
  /// at or below the cut, not a vertex's gap; so a limit does not depend on where the vertices lie. A
  /// pair of triangles is classed by where it comes nearest, not by its corners: it is articular when the
  /// femur's closest point lies on the head up to its head-neck junction (RomBaseline::meets_head), so that
  /// a triangle across the junction counts on its neck side (RomContacts), and the femur's triangles within
  /// the threshold at the baseline are left out (RomBaseline::contact). false: the per-vertex test
  /// throughout (the thesis' Algorithm 2; for comparisons). Not an option of the CLI or Python: their ROM
  /// limits are always exact (the envelope is not: rom_envelope).
  bool exact_contact = true;
};

/// A standard motion: angles(theta) for theta >= 0 from its start (degrees), angles(0) = start.
struct StandardMotion {
  std::string name;
  std::function<PoseAngles(double)> angles;
  /// Where the motion starts (deg). Not neutral (90 deg flexion, say): the start must be reached first, along
  /// the straight path from neutral (each angle in proportion), or the motion is RomLimitStatus::not_reachable.
  PoseAngles start{};
};

/// The standard motions of clinical ROM tests: flexion, extension, abduction, adduction,
/// internal_rotation, external_rotation (from neutral), internal_rotation_90_flexion,
/// external_rotation_90_flexion (from 90 deg flexion) and fadir (internal rotation at 90 deg
/// flexion and 10 deg adduction).
std::vector<StandardMotion> standard_motions();

/// What a ROM limit is.
enum class RomLimitStatus {
  limited,           ///< the bones meet at limit_deg
  free,              ///< they do not meet within RomOptions::max_deg (limit NaN)
  contact_at_start,  ///< they meet already at the motion's start (limit 0)
  not_reachable,     ///< the motion's start cannot be reached from neutral: the bones meet on the way (limit NaN)
};
/// "limited", "free", "contact_at_start", "not_reachable" (the CSV and JSON spelling).
const char* to_string(RomLimitStatus status);

/// Where a ROM limit's contact lies: intra-articular (within the rim radius plus
/// RomOptions::intra_articular_margin_mm of the COR) or extra-articular (farther); none without a limit.
enum class ImpingementSite { none, intra_articular, extra_articular };
/// "", "intra_articular", "extra_articular" (the CSV and JSON spelling).
const char* to_string(ImpingementSite site);

/// Where and how a motion is limited.
struct RomLimit {
  double limit_deg = std::numeric_limits<double>::quiet_NaN();  ///< first contact angle (upper end of the final
                                                                 ///< bracket), NaN when none within max_deg
  /// Where the bones first touch along the motion (contact depth 0: the least exact distance reaches
  /// the threshold), deg: limit_deg when RomOptions::contact_depth_mm is 0, else a search of its own at
  /// depth 0; 0 with contact at the start, NaN when free within max_deg or not reachable.
  double first_contact_deg = std::numeric_limits<double>::quiet_NaN();
  /// The least counted gap (RomOptions::metric: radial gap or distance) at the limit, mm; with exact
  /// contacts (RomOptions::exact_contact) the exact least distance between the counted triangles, 0 where
  /// they cross.
  double min_gap_at_limit_mm = std::numeric_limits<double>::quiet_NaN();
  /// The same at the start, mm; with the distance metric, NaN when every vertex is beyond the reach.
  double min_gap_at_start_mm = std::numeric_limits<double>::quiet_NaN();
  bool monotone = true;            ///< the bones are still in contact one step beyond the limit (false: a transient
                                   ///< touch; the gap curve crosses the threshold again)
  bool limited_by_ball = false;    ///< the least gap was a femur vertex (else a pelvis vertex)
  bool limited_by_hidden_vertex = false;  ///< that vertex is hidden behind its own body's nearer surface and was
                                          ///< tested by the other body's layered map (JointOptions::layers)
  ContactClass contact_class = ContactClass::none;  ///< the limit's contact (HipJoint::contact_class); none
                                                    ///< without a limit
  ImpingementSite limited_by = ImpingementSite::none;  ///< intra- or extra-articular (none without a limit): extra when
                                   ///< the contact lies farther than the rim radius plus
                                   ///< RomOptions::intra_articular_margin_mm from the COR (a hidden vertex
                                   ///< near the joint, such as the far side of the rim, is intra-articular)
  Eigen::Vector3d contact_mm = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
                                   ///< the contact vertex at the limit, working frame (pelvis fixed), mm; with
                                   ///< exact contacts the point where the bones first touch (the closest point,
                                   ///< at the bracket's lower end, on the counted triangle: the femur's when it
                                   ///< counts), and limited_by_ball and the class name that triangle's counted
                                   ///< corner nearest it
  /// The femur's translation at the limit by the joint-centre method (HipJoint::femur_translation:
  /// from its scan position, after its rotation about its head centre), working-frame axes, mm; NaN
  /// without a limit.
  Eigen::Vector3d joint_translation_mm = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  /// Where on each bone the limit's contact lies (HipJoint::femoral_zone of the contact carried onto the
  /// femur, HipJoint::pelvic_zone of it on the pelvis; articular_zones.hpp); none without a limit or with scan
  /// neutral (issue 81, item 1).
  FemoralZone femoral_zone = FemoralZone::none;
  PelvicZone pelvic_zone = PelvicZone::none;
  double socket_clock_h = std::numeric_limits<double>::quiet_NaN();  ///< contact on the acetabular clock
  double femur_clock_h = std::numeric_limits<double>::quiet_NaN();   ///< contact on the femoral head-neck clock
  std::int64_t excluded_vertices = 0;  ///< vertices within the threshold at the baseline pose (pre-existing
                                       ///< overlap, e.g. of the segmentation): not counted
  bool contact_at_start = false;       ///< the counted gap is already within the threshold at theta = 0 (limit 0)
  RomLimitStatus status = RomLimitStatus::free;  ///< what the limit is (find_rom_limits sets not_reachable)
  /// Why the limit is not a number (not_reachable: where the way to the start is blocked), else empty.
  std::string note;
  int evaluations = 0;                 ///< poses evaluated
  std::int64_t vertices_looked_up = 0;  ///< map look-ups made over the search
  std::int64_t vertices_skipped = 0;    ///< first-surface vertices skipped by the cluster bounds
};

class MeshContact;      ///< detection/mesh_contact.hpp
struct RomSearchBounds;  ///< opaque: a joint's bound pyramids and vertex clusters for ROM searches

/// The vertices not counted in ROM searches: those within the threshold at a baseline pose
/// (anatomical neutral for clinical motions), so that a segmentation's overlap is reported and not
/// taken for a limit.
struct RomBaseline {
  std::vector<std::uint8_t> skip_ball, skip_socket;  ///< 1 = not counted (per vertex of each body)
  std::int64_t excluded_vertices = 0;
  std::int64_t articular_vertices = 0;  ///< not counted for RomOptions::contacts (on, or off, the joint surfaces)
  RomContacts contacts = RomContacts::all;  ///< the options' (with head_zone)
  /// How the pelvis' contacts are classed at each pose (HipJoint::contact_class): the head up to its head-neck
  /// junction, joint frame (HipJoint::head_zone_joint()); empty: not applied (scan neutral, or RomContacts::all).
  std::optional<FemoralHeadZone> head_zone;
  /// Whether a pelvis point at y (joint frame, carried onto the unposed femur: R^T (p - t)) meets the head's
  /// joint surface: within head_zone->reach_mm of the head centre and on the head side of the head-neck
  /// junction (issue 81: the neck below the junction is never the joint). False when not classed.
  bool meets_head(const Eigen::Vector3d& y) const { return head_zone && head_zone->contains(y); }
  double min_gap_mm = std::numeric_limits<double>::quiet_NaN();  ///< least gap of all vertices at the baseline
  /// The joint space at the baseline: the least gap (the metric's) of the lunate surface's vertices to the femur,
  /// mm; NaN without articular zones (scan neutral) or when every lunate vertex is beyond the distance's reach.
  /// Negative: the joint-centre method presses the head into the socket.
  double joint_space_min_mm = std::numeric_limits<double>::quiet_NaN();
  /// The bounds of the cluster search (RomOptions::use_bounds), built once by rom_baseline (about
  /// 10 ms for 0.1 deg maps) and shared by every search given this baseline with the same joint and
  /// threshold; a search with another threshold builds its own.
  std::shared_ptr<const RomSearchBounds> bounds;
  /// The meshes of the exact contact test (RomOptions::exact_contact; null when it cannot apply at depth 0:
  /// a negative threshold, the radial metric above 0, or not every vertex counted): which femur triangles
  /// count, wholly or pair by pair at their closest points (by head_zone and contacts, not by the per-vertex
  /// articular flags), less those within the threshold at the baseline pose.
  std::shared_ptr<const MeshContact> contact;
};

/// The baseline at the femur rotation R (joint frame), e.g. hip.femur_rotation({}) for neutral,
/// with the search bounds for options.threshold_mm when options.use_bounds.
RomBaseline rom_baseline(const HipJoint& hip, const Eigen::Matrix3d& R, const RomOptions& options = {});

/// Search one motion of `hip`: evaluate both scans at theta = 0, step_deg, 2 step_deg, ... up to
/// max_deg, the femur rotated by the motion and translated by the hip's joint-centre method
/// (HipJoint::joint_translation), until the minimum gap over the counted vertices (those not in
/// `baseline`; pelvis vertices meeting the head's joint surface are classed at each pose) is <=
/// threshold - contact_depth_mm, then bisect the last step to tolerance_deg. The gaps are those of
/// Joint::detect (exact ray casts at the maps' depth discontinuities included). Only the minimum is computed: the
/// counted first-surface vertices are taken in clusters (32 vertices, in groups of 128: boxes of median
/// splits in space, order_in_boxes) with a cone of directions and a radius range, and a cluster is
/// skipped when a bound of the other map over its cone (a pyramid of minima or maxima over the
/// equiangular map) shows that none of its gaps can reach the threshold; the hidden vertices likewise
/// (16, 128 and 1,024 vertices) against the other bone's radial shells and, for a leaf, its Euclidean
/// distance. A bound over the cone widened by 12.1 deg is reused at later poses whose rotation relative
/// to it is within that angle, and once that fails in a search, one widened by 4.1 deg; femur vertices
/// nearer the COR than the socket map's least node less the threshold are left out of the scans that
/// ask only whether the bones meet. The others are looked up exactly, so the result is the full
/// scan's. Throws impinge::Error on invalid options.
RomLimit find_rom_limit(const HipJoint& hip, const std::function<PoseAngles(double)>& motion,
                        const RomOptions& options, const RomBaseline& baseline);

/// The same for any path of femur rotations (joint frame) `rotation(theta)`, e.g. a rotation
/// about a fixed axis for analytic tests.
RomLimit find_rom_limit(const HipJoint& hip, const std::function<Eigen::Matrix3d(double)>& rotation,
                        const RomOptions& options, const RomBaseline& baseline);

/// Every motion of `motions`, on all cores (OpenMP), sharing one set of bounds. A motion whose start is not
/// neutral is searched only when its start is reached first: the straight path from neutral to the start
/// (searched as a motion of its own, its largest angle as the parameter) must be free of contact, else the
/// motion is RomLimitStatus::not_reachable with limit NaN and a note naming the angle at which the bones met
/// on the way (a hip whose flexion stops at 83 deg has no internal rotation at 90 deg flexion, not a 0 deg one).
std::vector<RomLimit> find_rom_limits(const HipJoint& hip, const std::vector<StandardMotion>& motions,
                                      const RomOptions& options, const RomBaseline& baseline);

/// How clinical angles pose the femur: its rotation (3 x 3, joint frame) at `angles` (deg), e.g.
/// HipJoint::femur_rotation with a pelvic frame.
using PoseRotation = std::function<Eigen::Matrix3d(const PoseAngles&)>;

/// The same with the motions' angles turned into femur rotations by `rotation` (e.g. the angles measured in
/// the other pelvic frame: [&](const PoseAngles& a) { return hip.femur_rotation(a, PelvisFrameKind::
/// anterior_pelvic_plane); }, with a baseline at that frame's neutral). The overload above passes
/// HipJoint::femur_rotation.
std::vector<RomLimit> find_rom_limits(const HipJoint& hip, const std::vector<StandardMotion>& motions,
                                      const RomOptions& options, const RomBaseline& baseline,
                                      const PoseRotation& rotation);

/// One cell of a ROM map: the largest internal rotation at (flexion, adduction).
/// The outcome of one ROM map cell's search.
enum class RomMapStatus {
  limited,          ///< contact at max_internal_rotation_deg
  free,             ///< no contact up to max_deg
  contact_at_zero,  ///< in contact already without rotation
};
/// "limited", "free", "contact_at_zero" (the CSV spelling).
const char* to_string(RomMapStatus status);

struct RomMapCell {
  double flexion_deg = 0, adduction_deg = 0;
  double max_internal_rotation_deg = std::numeric_limits<double>::quiet_NaN();  ///< NaN: see status
  RomMapStatus status = RomMapStatus::free;
  std::int64_t vertices_looked_up = 0, vertices_skipped = 0;  ///< over its search
  int evaluations = 0;                                        ///< poses evaluated by its search
};

/// The ROM map: for every flexion x adduction of the grids (degrees), the largest internal
/// rotation before contact (find_rom_limit along internal rotation from zero, `baseline` as for
/// the standard motions). Cells are independent and run on all cores (OpenMP).
std::vector<RomMapCell> rom_map(const HipJoint& hip, const std::vector<double>& flexion_deg,
                                const std::vector<double>& adduction_deg, const RomOptions& options,
                                const RomBaseline& baseline);

/// The grid of a ROM envelope (degrees, ISB clinical angles) and how it is refined.
struct RomEnvelopeOptions {
  double flexion_min_deg = -30, flexion_max_deg = 130;
  double adduction_min_deg = -50, adduction_max_deg = 40;
  double internal_rotation_min_deg = -60, internal_rotation_max_deg = 60;
  double step_deg = 1;    ///< grid step on every axis, deg (each range a whole number of steps)
  int coarse_steps = 4;   ///< the first lattice every this many steps (1: every pose evaluated)
  static constexpr Range kCoarseStepsRange{1, 64};  ///< of coarse_steps
};

/// Every pose of a grid as valid (the bones apart: the least counted gap > the threshold) or not.
struct RomEnvelope {
  std::vector<double> flexion_deg, adduction_deg, internal_rotation_deg;  ///< the grid's axes
  std::vector<std::uint8_t> valid;   ///< 1 valid, 0 in contact; index (i * na + j) * nr + k for flexion i,
                                     ///< adduction j, internal rotation k (na, nr: axis sizes)
  std::int64_t poses = 0;            ///< grid poses
  std::int64_t poses_evaluated = 0;  ///< poses scanned (the rest filled from the corners of their cell)
  std::int64_t vertices_looked_up = 0, vertices_skipped = 0;
  bool at(std::size_t i, std::size_t j, std::size_t k) const {
    return valid[(i * adduction_deg.size() + j) * internal_rotation_deg.size() + k] != 0;
  }
};

/// The ROM envelope: every pose of the flexion x adduction x internal rotation grid as valid
/// or in contact, by adaptive refinement: the poses of a coarse lattice (every coarse_steps steps) are
/// scanned; a cell whose eight corners agree is filled with their answer; a cell whose corners disagree
/// is split in two along each axis and the new corners scanned, down to single steps. Only poses near
/// the envelope's boundary are scanned. Assumption (the price of the refinement): a region of contact
/// (or of freedom) smaller than a cell and touching none of its corners is missed; coarse_steps = 1
/// scans every pose. Each scan stops at the first contact (RomOptions, `baseline` as for
/// find_rom_limit), by the per-vertex test: RomOptions::exact_contact does not apply here. A grid pose is
/// valid or not; the exact test (vertex-face and edge-edge, issue 81) moves where the bones meet by a
/// fraction of a degree, well within the grid's step, and cost some 350 times as much per envelope (the
/// tests' generated cam hip: 156 s against 0.44 s), so the envelope's boundary is the per-vertex one while
/// the ROM limits are exact. All cores (OpenMP). Throws impinge::Error on an empty or uneven grid. Source:
/// impinge (not in the thesis); the refinement of Kawasaki et al. 2007 in spirit.
RomEnvelope rom_envelope(const HipJoint& hip, const RomEnvelopeOptions& envelope, const RomOptions& options,
                         const RomBaseline& baseline);

}  // namespace impinge
