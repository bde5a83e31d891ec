#include "impinge/clinical/hip_joint.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

#include "impinge/core/error.hpp"
#include "impinge/core/timing.hpp"
#include "impinge/maps/map_io.hpp"

namespace impinge {

namespace {
double median_radius(const Vertices& V, const Eigen::Vector3d& c) {
  std::vector<double> d;
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    const double r = (V.row(i).transpose() - c).norm();
    if (r < 35) d.push_back(r);
  }
  if (d.size() < 10) return std::nan("");  // no head around the COR
  std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2), d.end());
  return d[d.size() / 2];
}
}  // namespace

HipJoint::HipJoint(TriangleMesh femur, TriangleMesh pelvis, Side side, const SphereFitResult& head,
                   const Landmarks& given, const HipJointOptions& options)
    : side_(side), neutral_(options.neutral), cor_(head.centre) {
  require(cor_.allFinite(), "hip joint: centre of rotation is not finite");
  require(!options.reseat || neutral_ == Neutral::anatomical,
          "hip joint: re-seating the head needs anatomical neutral (the acetabulum's frame)");
  head_radius_ = std::isfinite(head.radius) ? head.radius : median_radius(femur.V, cor_);
  require(std::isfinite(head_radius_) || neutral_ == Neutral::scan,
          femur.source + ": fewer than 10 femur vertices within 35 mm of the centre of rotation: no femoral head "
                         "there for the acetabulum and clock faces");
  if (!std::isfinite(head_radius_))
    warnings_.push_back(femur.source + ": no femoral head within 35 mm of the centre of rotation");
  else if (!(head_radius_ >= 5 && head_radius_ <= 60))
    warnings_.push_back(femur.source + ": the femoral head radius is " + std::to_string(head_radius_) +
                        " mm, outside 5-60 mm: are the meshes in millimetres?");
  const Eigen::Matrix3d S = scan_axes();
  if (neutral_ == Neutral::anatomical) {
    const auto t0 = std::chrono::steady_clock::now();
    Landmarks g = given;
    g["hip_centre"] = cor_;
    frames_ = find_hip_frames(femur, pelvis, side, g, options.frames);
    acetabulum_ = find_acetabulum(pelvis, cor_, head_radius_, frames_->pelvis);
    SphereFitResult head_sphere = head;
    head_sphere.centre = cor_;
    head_sphere.radius = head_radius_;
    articular_ = find_articular_zones(femur, head_sphere, pelvis, *acetabulum_, options.articular);
    const ClockFace femoral = femoral_clock_face(femur, cor_, head_radius_, frames_->femur);
    if (options.reseat) {
      // The femur, its frame and clock move with the head onto the acetabular centre.
      // Translation only: the pelvic landmarks stay, the femoral ones move with the femur, both frames
      // keep their axes and take the new COR as origin.
      reseat_ = acetabulum_->sphere.centre - cor_;
      femur.V.rowwise() += reseat_.transpose();
      cor_ = acetabulum_->sphere.centre;
      FemurLandmarks& fl = frames_->femur_landmarks;
      for (Eigen::Vector3d* p : {&fl.head_centre, &fl.epicondyle_lateral, &fl.epicondyle_medial,
                                 &fl.posterior_condyle_lateral, &fl.posterior_condyle_medial})
        *p += reseat_;
      frames_->head.centre = cor_;
      const double quality = frames_->femur.quality_mm;
      frames_->pelvis = pelvis_frame(frames_->pelvis_landmarks, cor_, options.frames.pelvis);
      frames_->femur = femur_frame(fl, side, options.frames.femur);
      frames_->femur.quality_mm = quality;
    }
    frames_ms_ = ms_since(t0);
    // Joint frame: pelvic axes arranged as the scan frame, p_joint = S P^T (p - cor).
    joint_to_working_ = frames_->pelvis.axes * S.transpose();
    femur_axes_joint_ = joint_to_working_.transpose() * frames_->femur.axes;
    const Eigen::Matrix3d A = joint_to_working_.transpose();
    socket_clock_ = acetabulum_->clock.transformed(A, -A * cor_);
    ball_clock_ = femoral.transformed(A, A * (reseat_ - cor_));
  } else {
    femur_axes_joint_ = S;  // scan neutral: both frames are the scan axes
  }
  const Eigen::Matrix3d to_joint = joint_to_working_.transpose();
  for (TriangleMesh* m : {&femur, &pelvis}) m->V = ((m->V.rowwise() - cor_.transpose()) * to_joint.transpose()).eval();
  if (options.ball_map_file.empty() != options.socket_map_file.empty())
    throw Error("hip joint: give both map files (ball and socket) or neither");
  if (options.ball_map_file.empty()) {
    joint_.emplace(std::move(femur), std::move(pelvis), Eigen::Vector3d::Zero(), options.joint);
  } else {
    auto load = [&](const std::string& path) {
      Eigen::Vector3d c;
      RadialDistanceMap m = load_map<float>(path, &c);
      require((c - cor_).norm() <= 1e-6, path + ": saved about the COR (" + std::to_string(c.x()) + ", " +
                                             std::to_string(c.y()) + ", " + std::to_string(c.z()) +
                                             ") mm, this joint's is (" + std::to_string(cor_.x()) + ", " +
                                             std::to_string(cor_.y()) + ", " + std::to_string(cor_.z()) +
                                             "): another subject or COR");
      return m;
    };
    joint_.emplace(std::move(femur), std::move(pelvis), Eigen::Vector3d::Zero(), options.joint,
                   load(options.ball_map_file), load(options.socket_map_file));
  }
  // The COR must lie inside the femur: then every ray from it meets the femur's surface.
  const RadialDistanceMap& bm = joint_->ball().map;
  // (Counted when the map was filled: a sparse map with a finite region reads "no surface" beyond it.)
  const double uncovered = 1.0 - double(joint_->ball().sampling.nodes_covered) / double(bm.num_nodes());
  if (uncovered > 1e-4 && !options.allow_cor_outside_ball)
    throw Error(joint_->ball().mesh.source + ": the centre of rotation (" + std::to_string(cor_.x()) + ", " +
                std::to_string(cor_.y()) + ", " + std::to_string(cor_.z()) + ") mm is outside the femur mesh (" +
                std::to_string(100 * uncovered) + " % of the directions from it meet no femur surface): a COR "
                "in the wrong frame or units? allow_cor_outside_ball (CLI: --allow-any-cor) accepts it");
}

ContactClass HipJoint::contact_class(bool ball, std::int64_t vertex, const Eigen::Vector3d& p_joint,
                                     double intra_margin_mm) const {
  if (articular_) {
    const std::vector<std::uint8_t>& zone = ball ? articular_->femur : articular_->pelvis;
    if (vertex >= 0 && static_cast<std::size_t>(vertex) < zone.size() && zone[static_cast<std::size_t>(vertex)])
      return ContactClass::articular;
  }
  const double rim = acetabulum_ ? acetabulum_->rim_radius_mm : head_radius_ + 5;
  return p_joint.norm() <= rim + intra_margin_mm ? ContactClass::intra_articular_impingement
                                                 : ContactClass::extra_articular_impingement;
}

void HipJoint::save_maps(const std::string& ball_path, const std::string& socket_path) const {
  save_map(ball_path, joint_->ball().map, cor_);
  save_map(socket_path, joint_->socket().map, cor_);
}

void HipJoint::clocks(const PoseResult& res, ClockSummary& ball, ClockSummary& socket) const {
  if (!socket_clock_) return;
  const JointOptions& o = joint_->options();
  clock_summary(res.ball_gaps, joint_->ball().relative, joint_->ball().vertex_area, *ball_clock_, o.levels, ball);
  clock_summary(res.socket_gaps, joint_->socket().relative, joint_->socket().vertex_area, *socket_clock_, o.levels,
                socket);
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
