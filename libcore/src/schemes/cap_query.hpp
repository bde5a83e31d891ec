#pragma once
// Private to libcore/src/schemes: the argument checks of SamplingScheme::nodes_in_cap, shared by the
// default and the schemes that override it.

#include <Eigen/Core>
#include <string>

#include "impinge/core/error.hpp"

namespace impinge {

/// The unit direction of a cap query. Throws impinge::Error naming `scheme` for a zero or
/// non-finite direction or a negative or NaN radius (radians).
inline Eigen::Vector3d checked_cap_axis(const std::string& scheme, const Eigen::Vector3d& direction, double radius_rad) {
  require(direction.allFinite() && direction.norm() > 0,
          "sampling scheme '" + scheme + "': nodes_in_cap needs a nonzero, finite direction");
  require(radius_rad >= 0,
          "sampling scheme '" + scheme + "': nodes_in_cap radius " + std::to_string(radius_rad) + " rad must be >= 0");
  return direction.normalized();
}

}  // namespace impinge
