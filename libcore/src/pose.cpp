#include "impinge/pose.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "impinge/error.hpp"
#include "impinge/parse.hpp"
#include "impinge/spherical_frame.hpp"

namespace impinge {

Eigen::Matrix3d pose_rotation(const PoseAngles& a, Side side) {
  require(std::isfinite(a.flexion_deg) && std::isfinite(a.abduction_deg) && std::isfinite(a.rotation_deg),
          "pose: angles must be finite");
  const double m = side == Side::right ? 1.0 : -1.0;
  const Eigen::AngleAxisd rx(a.flexion_deg * kDegToRad, Eigen::Vector3d::UnitX());
  const Eigen::AngleAxisd ry(-m * a.abduction_deg * kDegToRad, Eigen::Vector3d::UnitY());
  const Eigen::AngleAxisd rz(m * a.rotation_deg * kDegToRad, Eigen::Vector3d::UnitZ());
  return (rx * ry * rz).toRotationMatrix();
}

PoseAngles parse_pose(const std::string& text) {
  const std::vector<double> v = parse_number_list(text, "pose (FLEX,ABD,ROT in degrees)", 3);
  return PoseAngles{v[0], v[1], v[2]};
}

}  // namespace impinge
