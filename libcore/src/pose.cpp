#include "impinge/pose.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <sstream>
#include <vector>

#include "impinge/error.hpp"
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
  std::vector<double> v;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      std::size_t used = 0;
      v.push_back(std::stod(item, &used));
      require(used == item.size(), "");
    } catch (const std::exception&) {
      throw Error("pose '" + text + "': '" + item + "' is not a number (expected FLEX,ABD,ROT in degrees)");
    }
  }
  require(v.size() == 3, "pose '" + text + "': expected three angles FLEX,ABD,ROT in degrees");
  PoseAngles p{v[0], v[1], v[2]};
  pose_rotation(p, Side::right);  // validates finiteness
  return p;
}

}  // namespace impinge
