#pragma once
/// @file joint_centre.hpp
/// Where the femur's centre of rotation sits at each pose: the four ways of moving the femur that
/// Puls et al. 2010 (Comput Aided Surg 15:75-82, "The Equidistant Method - a novel hip joint
/// simulation algorithm for detection of femoroacetabular impingement") compared against navigated
/// motions of bone models and cadavers, the equidistant method being the most accurate; it is the
/// method of the Bern tools (Tannast et al. 2007, J Orthop Res 25:122).
///
/// A pose is the femur's rotation R about its head centre c_h (the joint frame's origin: the COR)
/// and a translation t: a femur point p (joint frame, unposed) is posed at R p + t. The methods
/// give t as follows (c_a: the acetabular sphere's centre in the joint frame, find_acetabulum):
/// - femoral_head: t = 0. Rotation about the femoral head centre (the thesis' method).
/// - acetabular: t = (I - R) c_a. Rotation about the acetabular centre: the femur keeps its scan
///   position at neutral and turns about c_a.
/// - combined: t = c_a. The head centre is placed on the acetabular centre and the femur turns
///   about that common centre (the head seated concentrically, as both centres combined).
/// - equidistant: t minimises the variance of the joint space over the acetabulum's lunate surface
///   at every pose: the head is translated so that the joint space between the head and the
///   acetabulum stays as even as possible. The joint space at a lunate vertex q is its radial gap to
///   the femur's surface (the ball map's look-up, thesis Algorithm 2), counted where that surface is
///   the head's joint surface (within the head sphere's reach r_h + t_h, ArticularZones; not where
///   the ray from the head centre through q leaves through the head-neck junction or the fovea's
///   rim); t is found by Gauss-Newton from the head centre's scan position (LunateSphere::scan_head_centre;
///   the exact Jacobian for a spherical head), to within EquidistantOptions::tolerance_mm, each step constrained so that the joint
///   space stays open (>= 0 mm, up to the tolerance) at every point sampled and at every guard point facing
///   the head's joint surface (the lunate triangles' points at most 0.5 mm apart, guard_points) (those found closed at a converged t join the constraints and the iteration goes
///   on): the head is never pressed into the socket to even the joint space out (an MRI socket whose sphere is
///   barely larger than the head's, tlem2-mri's, had it pressed 1-2.5 mm in and its abduction ended at 8 deg).
///   Only a closure by the head's joint surface is guarded (the femur's surface facing the guard point within
///   the head sphere's reach), and at the guard points anything closes at neutral (guard_at_neutral: a head
///   bulging past its sphere, a segmentation overlap): a neck or cam meeting the rim is an impingement, the ROM's
///   to find. Guarding it too levered the femur out of the socket past the first contact (lhdl-ct: 6 mm at 70 deg
///   of extension, 23-60 mm beyond 75 deg, where the bones parted again and extension ended at 138 deg instead of
///   49; mc22's flexion reached 113 deg with the femur 3.4 mm out, 88 deg now, 1.6 mm).
///
/// Puls et al. define the methods in words (the hip centre fixed in the head, fixed in the
/// acetabulum, both, or recomputed per pose to keep the joint space equidistant); the formulas
/// above are this framework's reading of them. Their methods also differ after a collision is
/// detected (whether the femur may translate out of the socket); here every method stops at the
/// first impingement.

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "impinge/detection/joint.hpp"
#include "impinge/core/enum_names.hpp"

namespace impinge {


/// Puls et al. 2010's four methods (see the file comment).
enum class JointCentreMethod { femoral_head, acetabular, combined, equidistant };
/// The names of the joint-centre methods (the option table's choices of --joint-centre; CSV and JSON outputs).
inline constexpr EnumNames<JointCentreMethod, 4> kJointCentreMethodNames{
    {{JointCentreMethod::femoral_head, "femoral-head"},
     {JointCentreMethod::acetabular, "acetabular"},
     {JointCentreMethod::combined, "combined"},
     {JointCentreMethod::equidistant, "equidistant"}}};

/// Parse "femoral-head", "acetabular", "combined" or "equidistant" (underscores accepted for
/// hyphens). Throws impinge::Error naming `context` otherwise.
JointCentreMethod parse_joint_centre(const std::string& text, const std::string& context);
/// "femoral-head", "acetabular", "combined", "equidistant" (the CLI and CSV spelling).
const char* to_string(JointCentreMethod method);

/// Options of the equidistant method.
struct EquidistantOptions {
  /// Sets the lunate sample's lattice (lunate_sample: 8 max_vertices nodes over the sphere, the lunate
  /// surface covering some of them); more: slower, no better.
  int max_vertices = 256;
  int max_iterations = 6;      ///< Gauss-Newton steps, at most
  /// Bin the lunate directions with x negated (lunate_sample): a left hip in the joint frame, whose x is
  /// medio-lateral, so that a mirrored hip is sampled at the mirrored points (HipJoint sets it by side).
  bool mirror_x = false;
  double tolerance_mm = 0.02;  ///< stop when a step moves t by less than this, mm (the maps' own error: 0.05 mm at 0.1 deg)
};

/// The acetabulum's lunate surface as the joint-centre methods see it, joint frame (relative to the COR), mm.
struct LunateSphere {
  Eigen::Vector3d centre = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());  ///< c_a
  double radius_mm = 0;          ///< the acetabular sphere's radius (find_acetabulum)
  double band_mm = 1.5;          ///< the lunate surface lies within this of the sphere (kLunateBandMm)
  /// Where the head centre sat in the scan (the femur's translation that puts it back there), mm: the
  /// equidistant iteration starts there (the joint space open, as the bones were imaged); NaN: from `centre`.
  Eigen::Vector3d scan_head_centre = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
};

/// The points of the lunate surface at which the equidistant method measures the joint space, chosen by the
/// surface alone, so that they do not depend on how its file numbers, duplicates or splits the vertices: the
/// nodes of a Fibonacci lattice of 8 max_vertices directions about c_a (4.5 deg apart for 256; x negated
/// with `mirror_x`, EquidistantOptions::mirror_x), each taken to the sphere (c_a, r_a), and there the
/// socket's surface in that direction from the COR (`socket_map`'s look-up: the first surface, interpolated
/// between exact node values, so the same for any tessellation of one surface). A node is kept when the
/// surface point lies within band_mm of the sphere (not the fossa, not past the rim's edge, where the bone
/// turns away from the sphere) and its look-up has no depth discontinuity in its stencil. The rim plane is
/// not used: it is found from vertices (the farthest per azimuth, find_acetabulum) and moves when a file
/// splits its triangles. In lattice order; `index` holds the lattice node, `vertices` the lattice size.
/// (Until 2026-11 the sample was the lunate vertex nearest each node, which moved when a file split its
/// triangles: 0.44 deg on lhdl-ct's limits, 0.02 mm of the equidistant translation.) Never throws.
ScanSet lunate_sample(const RadialDistanceMap& socket_map, const LunateSphere& lunate, int max_vertices,
                      bool mirror_x = false);

/// The coarsest node spacing (deg) of the socket map at which lunate_sample finds its 16 points on every shared hip
/// (at 3 deg mc22 gives 3 points, at 4 deg tlem2-mri 3; at 10 deg lhdl-ct none).
inline constexpr double kLunateSpacingDeg = 2.0;

/// The error for a lunate sample of `points` (fewer than 16) points in `socket`'s map: with the map's nodes farther
/// apart than kLunateSpacingDeg, that the resolution is too coarse for the lunate surface, naming the scheme, its
/// resolution, the options that set it (--precision, --spacing) and a value that works; else that the equidistant
/// joint centre needs the acetabulum's joint surface. Names `socket`'s mesh. Source: impinge.
std::string too_few_lunate_points(const JointBody& socket, std::size_t points);

/// The guard's points are at most this far apart on each lunate triangle (guard_points), mm.
inline constexpr double kGuardSpacingMm = 0.5;
/// A lunate triangle is cut at most this many times along an edge (guard_points).
inline constexpr int kGuardMaxCuts = 64;

/// The points of the lunate surface where the equidistant method keeps the joint space open: every triangle of
/// F (m x 3) whose three corners are flagged (`flags`: one per row of P, n x 3, mm) cut into k x k congruent
/// triangles, k the least power of two (at most kGuardMaxCuts) that makes their edges at most kGuardSpacingMm
/// long, and the corners of those (the triangle's own corners among them). A triangle split in four at its edges'
/// midpoints is cut into the same triangles, so the points are the same for either tessellation of one surface
/// (where a triangle's edges are all shorter than kGuardSpacingMm it is its corners alone, and a split adds its
/// edges' midpoints, which a 0.5 mm chord of a 25 mm socket brings 0.0013 mm nearer the head: below the
/// iteration's 0.02 mm tolerance)
/// (the mesh's vertices alone were not: an edge's midpoint lies on the chord, nearer the head than the corners,
/// and splitting mc22's or tlem2-mri's pelvis moved limits 0.1-0.28 deg). `index`: the face of each point
/// (points on a shared edge repeat); `vertices`: n. Never throws (the flags' length is the caller's to check).
/// Source: impinge (issue 81).
ScanSet guard_points(const Vertices& P, const Faces& F, const std::vector<std::uint8_t>& flags);

/// The translation of the femur at each pose by one method.
class JointCentre {
 public:
  /// femoral_head needs nothing else. acetabular and combined need the acetabular centre (`lunate.centre`,
  /// joint frame, mm); equidistant also needs the rest of `lunate` (lunate_sample must find at least 16
  /// points on it in `joint`'s socket map), the head sphere's reach (mm: r_h + t_h,
  /// ArticularZones::head_sphere_reach_mm) and `guard`: one flag per socket vertex of `joint`, 1 on the
  /// lunate surface (ArticularZones::pelvis): the joint space must stay open at its triangles' guard_points (empty: the
  /// sample's points only). Throws impinge::Error when what the method needs is missing, not finite or not positive (too few lunate
  /// points: too_few_lunate_points), or `guard` has another size.
  JointCentre(JointCentreMethod method, const Joint& joint, const LunateSphere& lunate,
              const std::vector<std::uint8_t>& guard, double head_sphere_reach_mm, const EquidistantOptions& options = {});
  /// The femoral head method (t = 0 at every pose).
  JointCentre() = default;

  JointCentreMethod method() const { return method_; }

  /// t (mm, joint frame) at the femur rotation R (3 x 3, joint frame) of `joint` (the one given to
  /// the constructor: its ball map measures the joint space); a function of R alone (the equidistant
  /// iteration always starts from the head centre's scan position). Thread-safe. Throws impinge::Error when
  /// fewer than 16 lunate vertices face the head's joint surface or the iteration diverges.
  Eigen::Vector3d translation(const Joint& joint, const Eigen::Matrix3d& R) const;

  /// Equidistant: the guard points that whatever of the femur closes at the neutral rotation R0 (3 x 3, joint
  /// frame) stay guarded at every pose, however far the closing surface lies from the head sphere (a head that
  /// bulges past its sphere, or a segmentation overlap: mc22's head was pressed 0.59 mm into its socket at neutral
  /// without it). Elsewhere only a closure by the head's joint surface is guarded. Call once, before the first
  /// translation (HipJoint does, with the anatomical neutral). No-op for the other methods.
  void guard_at_neutral(const Joint& joint, const Eigen::Matrix3d& R0);

  /// Equidistant: the guard points (guard_points) guarded at every pose by guard_at_neutral (0 before it).
  std::int64_t guarded_at_neutral() const;

  /// The joint space's standard deviation (mm) over the lunate vertices used, at pose (R, t): what
  /// the equidistant method minimises (NaN without them).
  double joint_space_sd_mm(const Joint& joint, const Eigen::Matrix3d& R, const Eigen::Vector3d& t) const;

  /// Lunate points the equidistant method samples (0 for the other methods).
  std::int64_t vertices_used() const { return lunate_.size(); }

 private:
  // Joint-space gaps of the lunate subset at (R, t) into `out` (one per vertex; NaN where none, or
  // where the femur's surface there lies beyond the head sphere's reach).
  void gaps(const Joint& joint, const Eigen::Matrix3d& R, const Eigen::Vector3d& t, float* out) const;
  // Points of the lunate surface (joint frame, mm) whose joint space must stay open, and their gaps at t (mm).
  struct OpenPoints {
    std::vector<double> x, y, z, g;
    void clear() { x.clear(), y.clear(), z.clear(), g.clear(); }
    void add(double px, double py, double pz, double gap) { x.push_back(px), y.push_back(py), z.push_back(pz), g.push_back(gap); }
  };
  // One Gauss-Newton step d (mm) of the equidistant least squares (normal equations H, b at the head
  // centre t), constrained so that the joint space stays open at every point of `open`: g_k - w_k . d >= 0.
  // `active`: the constraints that bound at the last step (indices into `open`), in and out.
  static Eigen::Vector3d constrained_step(const Eigen::Matrix4d& H, const Eigen::Vector4d& b, const Eigen::Vector3d& t,
                                          const OpenPoints& open, std::vector<std::size_t>& active);
  JointCentreMethod method_ = JointCentreMethod::femoral_head;
  Eigen::Vector3d c_a_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d start_ = Eigen::Vector3d::Zero();  // where the equidistant iteration starts
  double reach_mm_ = 0;
  ScanSet lunate_;  // the lunate sample, joint frame (relative to the COR)
  ScanSet guard_;   // the guard points: where the lunate surface's joint space must stay open (guard_points)
  std::vector<std::uint8_t> neutral_closed_;  // per guard_ point: closed at neutral (guard_at_neutral), guarded always
  // translation's iteration; guard_all: every closure guarded (not only the head's); closed_out (guard_.size(), or
  // null): set to 1 at every guard vertex watched
  Eigen::Vector3d solve(const Joint& joint, const Eigen::Matrix3d& R, bool guard_all,
                        std::vector<std::uint8_t>* closed_out) const;
  EquidistantOptions options_;
};

}  // namespace impinge
