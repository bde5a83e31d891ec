// HipJoint's labrum (issue 81): the hip with the acetabular labrum as its socket (hip_joint.hpp, labrum.hpp).
#include <algorithm>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include "impinge/clinical/hip_joint.hpp"
#include "impinge/core/error.hpp"

namespace impinge {

Acetabulum HipJoint::acetabulum_joint() const {
  require(!labral_, "hip joint: the acetabulum of a labral hip's socket (the labrum) is its bony hip's");
  if (acetabulum_) {  // found with the frames (working frame): into the joint frame
    const Eigen::Matrix3d A = joint_to_working_.transpose();
    Acetabulum a = *acetabulum_;
    a.sphere.centre = A * (a.sphere.centre - cor_);
    a.rim_centre = A * (a.rim_centre - cor_);
    a.opening = A * a.opening;
    for (Eigen::Vector3d& p : a.rim) p = A * (p - cor_);
    a.clock = a.clock.transformed(A, -A * cor_);
    return a;
  }
  // Scan neutral: found now about the head sphere, with the joint frame's axes for superior and anterior (which
  // orient only its clock face).
  require(std::isfinite(head_radius_), joint_->ball().mesh.source +
                                           ": no femoral head radius: the labrum needs the acetabulum about the head");
  AnatomicalFrame axes;
  axes.definition = "joint frame axes (scan neutral)";
  return find_acetabulum(joint_->socket().mesh, head_centre_joint_, head_radius_, axes);
}

std::shared_ptr<const HipJoint> HipJoint::with_labrum(double width_mm, double height_mm, int splits) const {
  require(splits >= 0 && splits <= kMaxLabrumSplits, "labrum: " + std::to_string(splits) +
                                                         " splits of its triangles; valid: 0.." +
                                                         std::to_string(kMaxLabrumSplits));
  TriangleMesh labrum = make_labrum(acetabulum_joint(), width_mm, height_mm, joint_->socket().mesh.source);
  for (int k = 0; k < splits; ++k) labrum = split_in_four(labrum);
  const auto n = static_cast<std::size_t>(labrum.V.rows());
  auto out = std::make_shared<HipJoint>(*this);  // shares this Joint until its own replaces it below
  out->centre_joint_ = joint_;                    // the femur moves as in this hip
  out->labral_ = true;
  out->joint_ = std::make_shared<Joint>(joint_->ball().mesh, std::move(labrum), Eigen::Vector3d::Zero(),
                                        joint_->options());
  if (out->articular_) {  // the femur's joint surface stays; the labrum holds no lunate surface
    out->articular_->pelvis.assign(n, 0);
    out->articular_->pelvis_vertices = 0;
  }
  if (socket_clock_) out->socket_hours_ = clock_hours(out->joint_->socket().relative, *socket_clock_);
  return out;
}

}  // namespace impinge
