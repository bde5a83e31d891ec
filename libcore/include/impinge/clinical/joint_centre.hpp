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
///   rim); t is found by Gauss-Newton from the combined method's t (the exact Jacobian for a
///   spherical head), to within EquidistantOptions::tolerance_mm.
///
/// Puls et al. define the methods in words (the hip centre fixed in the head, fixed in the
/// acetabulum, both, or recomputed per pose to keep the joint space equidistant); the formulas
/// above are this framework's reading of them. Their methods also differ after a collision is
/// detected (whether the femur may translate out of the socket); here every method stops at the
/// first impingement.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "impinge/detection/joint.hpp"

namespace impinge {


/// Puls et al. 2010's four methods (see the file comment).
enum class JointCentreMethod { femoral_head, acetabular, combined, equidistant };

/// Parse "femoral-head", "acetabular", "combined" or "equidistant" (underscores accepted for
/// hyphens). Throws impinge::Error naming `context` otherwise.
JointCentreMethod parse_joint_centre(const std::string& text, const std::string& context);
/// "femoral-head", "acetabular", "combined", "equidistant" (the CLI and CSV spelling).
const char* to_string(JointCentreMethod method);

/// Options of the equidistant method.
struct EquidistantOptions {
  /// Sets the lunate sample's lattice (lunate_sample: 8 max_vertices cells over the sphere, the lunate
  /// surface covering some of them); more: slower, no better.
  int max_vertices = 256;
  int max_iterations = 6;      ///< Gauss-Newton steps, at most
  /// Bin the lunate directions with x negated (lunate_sample): a left hip in the joint frame, whose x is
  /// medio-lateral, so that a mirrored hip is sampled at the mirrored points (HipJoint sets it by side).
  bool mirror_x = false;
  double tolerance_mm = 5e-3;  ///< stop when a step moves t by less than this, mm
};

/// The lunate vertices the equidistant method measures the joint space at, chosen by position so that the
/// choice depends on the surface, not on how its file numbers, duplicates or splits the vertices: their
/// directions from the acetabular centre `c_a` (joint frame, mm) binned on a Fibonacci lattice of
/// 8 max_vertices nodes (4.5 deg apart for 256: coarser than any bone mesh's vertices), and
/// in each cell the vertex whose direction is nearest the cell's node (ties, such as duplicated vertices,
/// by position); in cell order. `P`: the pelvis vertices (n x 3, joint frame, mm); `lunate`: n flags.
/// Renumbered or duplicated vertices give the same sample; split triangles add vertices that may be nearer a
/// cell's node. (Sampling each cell at the surface's exact hit in its node direction instead, tessellation-free,
/// made the equidistant translations of the MRI hips swing by millimetres: the node directions reach past the
/// lunate surface's border.) `mirror_x`: bin with x negated (EquidistantOptions::mirror_x).
ScanSet lunate_sample(PointsRef P, const std::vector<std::uint8_t>& lunate, const Eigen::Vector3d& c_a,
                      int max_vertices, bool mirror_x = false);

/// The translation of the femur at each pose by one method.
class JointCentre {
 public:
  /// femoral_head needs nothing else. acetabular and combined need `acetabular_centre_mm` (joint
  /// frame, mm); equidistant also needs `lunate` (one flag per socket vertex of `joint`: the lunate
  /// surface, ArticularZones::pelvis) with at least 16 flagged vertices, and the head sphere's reach
  /// (mm: r_h + t_h, ArticularZones::head_sphere_reach_mm). Throws impinge::Error when what the
  /// method needs is missing or not finite.
  JointCentre(JointCentreMethod method, const Joint& joint, const Eigen::Vector3d& acetabular_centre_mm,
              const std::vector<std::uint8_t>& lunate, double head_sphere_reach_mm,
              const EquidistantOptions& options = {});
  /// The femoral head method (t = 0 at every pose).
  JointCentre() = default;

  JointCentreMethod method() const { return method_; }

  /// t (mm, joint frame) at the femur rotation R (3 x 3, joint frame) of `joint` (the one given to
  /// the constructor: its ball map measures the joint space); a function of R alone (the equidistant
  /// iteration always starts from the combined method's t). Thread-safe. Throws impinge::Error when
  /// fewer than 16 lunate vertices face the head's joint surface or the iteration diverges.
  Eigen::Vector3d translation(const Joint& joint, const Eigen::Matrix3d& R) const;

  /// The joint space's standard deviation (mm) over the lunate vertices used, at pose (R, t): what
  /// the equidistant method minimises (NaN without them).
  double joint_space_sd_mm(const Joint& joint, const Eigen::Matrix3d& R, const Eigen::Vector3d& t) const;

  /// Lunate vertices the equidistant method uses (0 for the other methods).
  std::int64_t vertices_used() const { return lunate_.size(); }

 private:
  // Joint-space gaps of the lunate subset at (R, t) into `out` (one per vertex; NaN where none, or
  // where the femur's surface there lies beyond the head sphere's reach).
  void gaps(const Joint& joint, const Eigen::Matrix3d& R, const Eigen::Vector3d& t, float* out) const;
  JointCentreMethod method_ = JointCentreMethod::femoral_head;
  Eigen::Vector3d c_a_ = Eigen::Vector3d::Zero();
  double reach_mm_ = 0;
  ScanSet lunate_;  // the lunate subset, joint frame (relative to the COR)
  EquidistantOptions options_;
};

}  // namespace impinge
