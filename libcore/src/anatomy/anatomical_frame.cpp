#include "impinge/anatomy/anatomical_frame.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "impinge/core/error.hpp"

namespace impinge {

Eigen::Matrix3d orthonormal_axes(const Eigen::Vector3d& primary, int primary_index, const Eigen::Vector3d& secondary,
                                 int secondary_index, const std::string& what) {
  require(primary_index >= 0 && primary_index < 3 && secondary_index >= 0 && secondary_index < 3 &&
              primary_index != secondary_index,
          what + ": axis indices must be two different values of 0, 1, 2");
  require(primary.allFinite() && secondary.allFinite(), what + ": an axis is not finite");
  const double np = primary.norm();
  require(np > 0, what + ": the primary axis is zero (coincident landmarks?)");
  const Eigen::Vector3d a = primary / np;
  Eigen::Vector3d b = secondary - secondary.dot(a) * a;
  require(b.norm() > 1e-6 * std::max(1.0, secondary.norm()),
          what + ": the two defining directions are parallel (collinear landmarks?)");
  b.normalize();
  Eigen::Matrix3d M;
  M.col(primary_index) = a;
  M.col(secondary_index) = b;
  const int third = 3 - primary_index - secondary_index;
  // Right-handed: col(k) = col(k+1) x col(k+2) (indices mod 3).
  M.col(third) = M.col((third + 1) % 3).cross(M.col((third + 2) % 3));
  return M;
}

double rotation_angle_deg(const Eigen::Matrix3d& A, const Eigen::Matrix3d& B) {
  const double c = std::clamp(((A.transpose() * B).trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(c) * 180.0 / M_PI;
}

}  // namespace impinge
