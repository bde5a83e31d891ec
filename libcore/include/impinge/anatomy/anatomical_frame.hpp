#pragma once
/// @file anatomical_frame.hpp
/// An anatomical coordinate system of a bone (ISB convention, Wu et al. 2002, J Biomech
/// 35:543-548): origin and three orthonormal axes, X anterior, Y superior, Z to the right,
/// with the landmarks that defined it.

#include <Eigen/Core>
#include <map>
#include <string>

namespace impinge {

/// Named landmark positions, mm. Keys are snake_case names ("asis_right", "epicondyle_lateral").
using Landmarks = std::map<std::string, Eigen::Vector3d>;

/// An anatomical frame in the working (RAS) frame of the meshes.
struct AnatomicalFrame {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();     ///< mm, working frame
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();   ///< columns X (anterior), Y (superior), Z (right),
                                                        ///< orthonormal, right-handed (X x Y = Z)
  std::string definition;                               ///< e.g. "ISB pelvis (Wu et al. 2002)"
  Landmarks landmarks;                                  ///< mm, working frame: the points that defined the axes
  std::map<std::string, std::string> landmark_source;   ///< per landmark: "found" or "given"
  double quality_mm = 0;                                ///< a residual of the construction (see the builder), mm

  /// Coordinates of the working-frame point p (mm) in this frame (mm): axes^T (p - origin).
  Eigen::Vector3d to_local(const Eigen::Vector3d& p) const { return axes.transpose() * (p - origin); }
};

/// Orthonormal right-handed axes from a primary axis and a second direction:
/// `primary` is kept exactly as axis `primary_index` (0 = X, 1 = Y, 2 = Z), `secondary` is made
/// orthogonal to it (Gram-Schmidt) and becomes axis `secondary_index`; the third completes a
/// right-handed frame. Throws impinge::Error naming `what` when either vector is zero or not
/// finite, or the two are parallel (within 1e-6 rad).
Eigen::Matrix3d orthonormal_axes(const Eigen::Vector3d& primary, int primary_index, const Eigen::Vector3d& secondary,
                                 int secondary_index, const std::string& what);

/// Angle (degrees, [0, 180]) of the rotation taking axes A to axes B (both 3 x 3 rotations):
/// the angle of A^T B. Used to compare frames.
double rotation_angle_deg(const Eigen::Matrix3d& A, const Eigen::Matrix3d& B);

}  // namespace impinge
