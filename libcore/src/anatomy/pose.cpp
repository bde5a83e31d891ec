#include "impinge/anatomy/pose.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "impinge/core/error.hpp"
#include "impinge/core/parse.hpp"
#include "impinge/core/spherical_frame.hpp"

namespace impinge {

namespace {
double mirror(Side side) { return side == Side::right ? 1.0 : -1.0; }
}  // namespace

Eigen::Matrix3d jcs_rotation(const PoseAngles& a, Side side) {
  require(std::isfinite(a.flexion_deg) && std::isfinite(a.adduction_deg) && std::isfinite(a.internal_rotation_deg),
          "pose: angles must be finite");
  const double m = mirror(side);
  const Eigen::AngleAxisd rz(a.flexion_deg * kDegToRad, Eigen::Vector3d::UnitZ());
  const Eigen::AngleAxisd rx(m * a.adduction_deg * kDegToRad, Eigen::Vector3d::UnitX());
  const Eigen::AngleAxisd ry(m * a.internal_rotation_deg * kDegToRad, Eigen::Vector3d::UnitY());
  return (rz * rx * ry).toRotationMatrix();
}

PoseAngles jcs_angles(const Eigen::Matrix3d& R, Side side) {
  // R = Rz(a) Rx(b) Ry(c): R(2,1) = sin b; R(0,1) = -sin a cos b; R(1,1) = cos a cos b;
  // R(2,0) = -cos b sin c; R(2,2) = cos b cos c.
  const double m = mirror(side);
  const double b = std::asin(std::clamp(R(2, 1), -1.0, 1.0));
  double a, c;
  if (std::cos(b) > 1e-12) {
    a = std::atan2(-R(0, 1), R(1, 1));
    c = std::atan2(-R(2, 0), R(2, 2));
  } else {
    a = std::atan2(R(1, 0), R(0, 0));
    c = 0;
  }
  return PoseAngles{a * kRadToDeg, m * b * kRadToDeg, m * c * kRadToDeg};
}

Eigen::Matrix3d femur_rotation(const AnatomicalFrame& pelvis, const AnatomicalFrame& femur, const PoseAngles& angles,
                               Side side) {
  return pelvis.axes * jcs_rotation(angles, side) * femur.axes.transpose();
}

Eigen::Matrix3d scan_axes() {
  Eigen::Matrix3d B;
  B.col(0) = Eigen::Vector3d::UnitY();
  B.col(1) = Eigen::Vector3d::UnitZ();
  B.col(2) = Eigen::Vector3d::UnitX();
  return B;
}

Eigen::Matrix3d pose_rotation(const PoseAngles& angles, Side side) {
  const Eigen::Matrix3d B = scan_axes();
  return B * jcs_rotation(angles, side) * B.transpose();
}

PoseAngles parse_pose(const std::string& text) {
  const std::vector<double> v = parse_number_list(text, "pose (FLEX,ADD,IR in degrees)", 3);
  return PoseAngles{v[0], v[1], v[2]};
}

Neutral parse_neutral(const std::string& text, const std::string& context) {
  return parse_enum(kNeutralNames, text, context);
}

}  // namespace impinge
