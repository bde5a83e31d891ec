#include "impinge/core/spherical_frame.hpp"

#include <algorithm>
#include <cmath>

namespace impinge {

SphericalCoordinates to_spherical(const Eigen::Vector3d& p) {
  SphericalCoordinates s;
  s.d = p.norm();
  if (s.d == 0) return s;
  s.phi = std::acos(std::clamp(p.z() / s.d, -1.0, 1.0));
  double t = std::atan2(p.y(), p.x());
  if (t < 0) t += 2 * kPi;
  if (t >= 2 * kPi) t -= 2 * kPi;
  s.theta = t;
  return s;
}

Eigen::Vector3d direction(double phi, double theta) {
  const double s = std::sin(phi);
  return {s * std::cos(theta), s * std::sin(theta), std::cos(phi)};
}

}  // namespace impinge
