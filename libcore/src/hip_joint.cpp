#include "impinge/hip_joint.hpp"

#include <chrono>

#include "impinge/error.hpp"

namespace impinge {

HipJoint::HipJoint(TriangleMesh femur, TriangleMesh pelvis, Side side, const Eigen::Vector3d& cor,
                   const Landmarks& given, const HipJointOptions& options)
    : side_(side), neutral_(options.neutral), cor_(cor) {
  require(cor.allFinite(), "hip joint: centre of rotation is not finite");
  const Eigen::Matrix3d S = scan_axes();
  if (neutral_ == Neutral::anatomical) {
    const auto t0 = std::chrono::steady_clock::now();
    Landmarks g = given;
    g["hip_centre"] = cor;
    frames_ = find_hip_frames(femur, pelvis, side, g, options.frames);
    frames_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    // Joint frame: pelvic axes arranged as the scan frame, p_joint = S P^T (p - cor).
    joint_to_working_ = frames_->pelvis.axes * S.transpose();
    femur_axes_joint_ = joint_to_working_.transpose() * frames_->femur.axes;
  } else {
    femur_axes_joint_ = S;  // scan neutral: both frames are the scan axes
  }
  const Eigen::Matrix3d to_joint = joint_to_working_.transpose();
  for (TriangleMesh* m : {&femur, &pelvis}) m->V = ((m->V.rowwise() - cor.transpose()) * to_joint.transpose()).eval();
  joint_.emplace(std::move(femur), std::move(pelvis), Eigen::Vector3d::Zero(), options.joint);
}

Eigen::Matrix3d HipJoint::femur_rotation(const PoseAngles& angles) const {
  // Pelvic axes in the joint frame are S; R = S Rjcs F_joint^T (femur_rotation of pose.hpp).
  return scan_axes() * jcs_rotation(angles, side_) * femur_axes_joint_.transpose();
}

void HipJoint::detect(const PoseAngles& angles, PoseResult& out) const {
  joint_->detect(femur_rotation(angles), Eigen::Vector3d::Zero(), out);
}

PoseResult HipJoint::detect(const PoseAngles& angles) const {
  PoseResult r;
  detect(angles, r);
  return r;
}

Vertices HipJoint::posed_femur(const Eigen::Matrix3d& R) const {
  const Eigen::Matrix3d A = joint_to_working_ * R;
  return ((joint_->ball().relative * A.transpose()).rowwise() + cor_.transpose()).eval();
}

Vertices HipJoint::pelvis_vertices() const {
  return ((joint_->socket().relative * joint_to_working_.transpose()).rowwise() + cor_.transpose()).eval();
}

}  // namespace impinge
