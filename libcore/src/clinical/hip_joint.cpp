#include "impinge/clinical/hip_joint.hpp"
#include "impinge/core/concurrent.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

#include "impinge/core/error.hpp"
#include "impinge/core/mesh_hygiene.hpp"
#include "impinge/core/timing.hpp"
#include "impinge/maps/map_io.hpp"

namespace impinge {

namespace {
// What an anatomy error adds: the ways around it.
constexpr const char* kAnatomyHint =
    " [anatomical neutral needs a whole femur and pelvis, or landmarks in subject.json; neutral scan uses the scan "
    "pose instead]";
}  // namespace

HipJoint::HipJoint(TriangleMesh femur, TriangleMesh pelvis, Side side, const SphereFitResult& head,
                   const Landmarks& given, const HipJointOptions& options)
    : side_(side), neutral_(options.neutral.value_or(Neutral::anatomical)), cor_(head.centre) {
  require(cor_.allFinite(), "hip joint: centre of rotation is not finite");
  const JointCentreMethod method = options.joint_centre.value_or(
      neutral_ == Neutral::anatomical ? JointCentreMethod::equidistant : JointCentreMethod::femoral_head);
  require(method == JointCentreMethod::femoral_head || neutral_ == Neutral::anatomical,
          std::string("hip joint: the ") + to_string(method) +
              " joint centre needs anatomical neutral (the acetabulum); scan neutral allows femoral-head only");
  SphereFitResult sphere;
  try {
    sphere = head_sphere(femur, head, options);
    if (neutral_ == Neutral::anatomical) build_anatomy(femur, pelvis, sphere, given, options, method);
  } catch (const Error& e) {
    if (neutral_ != Neutral::anatomical) throw;
    throw Error(std::string(e.what()) + kAnatomyHint);  // the bones' anatomy not found: what would do without it
  }
  if (neutral_ != Neutral::anatomical) {
    femur_axes_joint_ = scan_axes();  // scan neutral: both frames are the scan axes
    other_frame_note_ = "scan neutral: no pelvic frame";
  }
  head_centre_joint_ = joint_to_working_.transpose() * (sphere.centre + seat_ - cor_);
  build_joint(std::move(femur), std::move(pelvis), options);
  // The acetabular centre in the joint frame: the origin once seated.
  if (method != JointCentreMethod::femoral_head) {
    EquidistantOptions equidistant = options.equidistant;
    equidistant.mirror_x = side_ == Side::left;  // the joint frame's x is medio-lateral: mirrored hips alike
    const Eigen::Matrix3d to_joint = joint_to_working_.transpose();
    LunateSphere lunate;
    lunate.centre = to_joint * (acetabulum_->sphere.centre - cor_);
    lunate.radius_mm = acetabulum_->sphere.radius;
    lunate.band_mm = kLunateBandMm;
    lunate.scan_head_centre = -(to_joint * seat_);
    centre_ = JointCentre(method, *joint_, lunate, articular_->pelvis, articular_->head_sphere_reach_mm, equidistant);
    const std::int64_t head_hole = boundary_edges_within(
        joint_->ball().mesh, to_joint * (sphere.centre - cor_), head_radius_ + 2 + seat_.norm());
    if (head_hole > 0)  // a hole in the head: the equidistant seat follows the head surface left (issue 80)
      warnings_.push_back(joint_->ball().mesh.source + ": a hole in the femoral head (" + std::to_string(head_hole) +
                          " boundary edges within its sphere): the " + to_string(method) +
                          " joint centre is fitted to the head surface left, and moves with the hole; "
                          "--joint-centre femoral-head does not use it");
    const std::int64_t rim = boundary_edges_within(joint_->socket().mesh, lunate.centre, lunate.radius_mm + lunate.band_mm);
    if (rim > 0)  // a hole in the lunate surface: the centre is fitted to what is left of it (issue 80)
      warnings_.push_back(joint_->socket().mesh.source + ": a hole in the acetabulum (" + std::to_string(rim) +
                          " boundary edges within its sphere): the " + to_string(method) +
                          " joint centre is fitted to the lunate surface left, and moves with the hole; "
                          "--joint-centre femoral-head does not use it");
    centre_.guard_at_neutral(*joint_, femur_rotation({}));  // no head pressed into the socket at neutral
  }
  if (socket_clock_) {
    ball_hours_ = clock_hours(joint_->ball().relative, *ball_clock_);
    socket_hours_ = clock_hours(joint_->socket().relative, *socket_clock_);
  }
  check_cor_inside_femur(options);
}

SphereFitResult HipJoint::head_sphere(const TriangleMesh& femur, const SphereFitResult& head,
                                      const HipJointOptions& options) {
  // The head sphere of the zones, the acetabulum, the clocks and the seat: the COR's own unless the
  // COR was given (then the fitted head's, so that they do not move with it).
  SphereFitResult sphere = options.head_sphere.value_or(head);
  if (!options.head_sphere) sphere.centre = cor_;
  head_radius_ = std::isfinite(sphere.radius) ? sphere.radius : head_radius_about(femur.V, sphere.centre);
  require(std::isfinite(head_radius_) || neutral_ == Neutral::scan,
          femur.source + ": fewer than 10 femur vertices within 35 mm of the centre of rotation: no femoral head "
                         "there for the acetabulum and clock faces");
  if (!std::isfinite(head_radius_))
    warnings_.push_back(femur.source + ": no femoral head within 35 mm of the centre of rotation");
  else if (!(head_radius_ >= 5 && head_radius_ <= 60))
    warnings_.push_back(femur.source + ": the femoral head radius is " + std::to_string(head_radius_) +
                        " mm, outside 5-60 mm: are the meshes in millimetres?");
  return sphere;
}

void HipJoint::build_anatomy(TriangleMesh& femur, const TriangleMesh& pelvis, SphereFitResult& sphere,
                             const Landmarks& given, const HipJointOptions& options, JointCentreMethod method) {
  const auto t0 = std::chrono::steady_clock::now();
  Landmarks g = given;
  g["hip_centre"] = cor_;
  frames_ = find_hip_frames(femur, pelvis, side_, g, options.frames);
  acetabulum_ = find_acetabulum(pelvis, sphere.centre, head_radius_, frames_->pelvis);
  sphere.radius = head_radius_;
  const ClockFace femoral = femoral_clock_face(femur, sphere.centre, head_radius_, frames_->femur);
  articular_ = find_articular_zones(femur, sphere, femoral, pelvis, *acetabulum_, options.articular);
  if (options.seat_before_sampling &&
      (method == JointCentreMethod::combined || method == JointCentreMethod::equidistant))
    seat_femur(femur, sphere, options);
  frames_ms_ = ms_since(t0);
  // Joint frame: pelvic axes arranged as the scan frame, p_joint = S P^T (p - cor).
  joint_to_working_ = frames_->pelvis.axes * scan_axes().transpose();
  femur_axes_joint_ = joint_to_working_.transpose() * frames_->femur.axes;
  // Both pelvic frames' axes in the joint frame: the session's is the joint frame's arrangement itself; the
  // other is built from the same landmarks (both share Z through the ASIS).
  pelvis_kind_ = options.frames.pelvis;
  pelvic_axes_joint_[static_cast<std::size_t>(*pelvis_kind_)] = scan_axes();
  const PelvisFrameKind other =
      *pelvis_kind_ == PelvisFrameKind::isb ? PelvisFrameKind::anterior_pelvic_plane : PelvisFrameKind::isb;
  try {
    require(!frames_->pelvis_landmarks.source.empty(), "no pelvic landmarks");
    pelvic_axes_joint_[static_cast<std::size_t>(other)] =
        joint_to_working_.transpose() * pelvis_frame(frames_->pelvis_landmarks, cor_, other).axes;
  } catch (const Error& e) {
    other_frame_note_ = std::string("the ") + to_string(other) + " pelvic frame could not be built: " + e.what();
  }
  const Eigen::Matrix3d A = joint_to_working_.transpose();
  socket_clock_ = acetabulum_->clock.transformed(A, -A * cor_);
  ball_clock_ = femoral.transformed(A, A * (seat_ - cor_));
  head_zone_joint_ = articular_->head.transformed(A, A * (seat_ - cor_));
}

void HipJoint::seat_femur(TriangleMesh& femur, const SphereFitResult& sphere, const HipJointOptions& options) {
  // Seated: the femur, its frame and clock move with the head onto the acetabular centre, which becomes the
  // COR (the maps' centre: rays from the seated head centre); the methods' translations are then relative to
  // the seated femur (combined: none; equidistant: the small deviations). Translation only: the pelvic
  // landmarks stay, the femoral ones move with the femur, both frames keep their axes and take the new COR
  // as origin.
  seat_ = acetabulum_->sphere.centre - sphere.centre;
  femur.V.rowwise() += seat_.transpose();
  cor_ = acetabulum_->sphere.centre;
  FemurLandmarks& fl = frames_->femur_landmarks;
  for (Eigen::Vector3d* p : {&fl.head_centre, &fl.epicondyle_lateral, &fl.epicondyle_medial,
                             &fl.posterior_condyle_lateral, &fl.posterior_condyle_medial})
    *p += seat_;
  frames_->head.centre = cor_;
  const double quality = frames_->femur.quality_mm;
  frames_->pelvis = pelvis_frame(frames_->pelvis_landmarks, cor_, options.frames.pelvis);
  frames_->femur = femur_frame(fl, side_, options.frames.femur);
  frames_->femur.quality_mm = quality;
}

void HipJoint::build_joint(TriangleMesh femur, TriangleMesh pelvis, const HipJointOptions& options) {
  const Eigen::Matrix3d to_joint = joint_to_working_.transpose();
  // Into the joint frame, the pelvis on a second thread (the same arithmetic either way).
  auto to_joint_frame = [&](TriangleMesh& m) { m.V = ((m.V.rowwise() - cor_.transpose()) * to_joint.transpose()).eval(); };
  run_both([&] { to_joint_frame(femur); }, [&] { to_joint_frame(pelvis); });
  if (options.ball_map_file.empty() != options.socket_map_file.empty())
    throw Error("hip joint: give both map files (ball and socket) or neither");
  if (options.ball_map_file.empty()) {
    joint_ = std::make_shared<Joint>(std::move(femur), std::move(pelvis), Eigen::Vector3d::Zero(), options.joint);
    return;
  }
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
  joint_ = std::make_shared<Joint>(std::move(femur), std::move(pelvis), Eigen::Vector3d::Zero(), options.joint,
                 load(options.ball_map_file), load(options.socket_map_file));
}

void HipJoint::check_cor_inside_femur(const HipJointOptions& options) {
  // The COR must lie inside the femur: then every ray from it meets the femur's surface.
  const RadialDistanceMap& bm = joint_->ball().map;
  // (Counted when the map was filled: a sparse map with a finite region reads "no surface" beyond it.)
  const double uncovered = 1.0 - double(joint_->ball().sampling.nodes_covered) / double(bm.num_nodes());
  const Eigen::Vector3d reported_cor = options.to_report * cor_;
  if (uncovered <= 1e-4 || options.allow_cor_outside_ball) return;
  // A hole in the femur (a segmentation's gap in the head): the rays through it meet no surface, but the COR is
  // inside by the winding number (1 less the hole's solid angle / 4 pi; outside, under 1/2).
  const double w = std::abs(winding_number(joint_->ball().mesh, Eigen::Vector3d::Zero()));
  if (w >= 0.5) {
    warnings_.push_back(joint_->ball().mesh.source + ": " + std::to_string(100 * uncovered) +
                        " % of the directions from the centre of rotation meet no femur surface (a hole in the "
                        "femur; the COR is inside it by the winding number, " + std::to_string(w) +
                        "): pelvis vertices in those directions have no radial gap");
    return;
  }
  if (uncovered > 1e-4)
    throw Error(joint_->ball().mesh.source + ": the centre of rotation (" + std::to_string(reported_cor.x()) + ", " +
                std::to_string(reported_cor.y()) + ", " + std::to_string(reported_cor.z()) + ") mm" +
                (options.report_frame_name.empty() ? "" : " (" + options.report_frame_name + ")") +
                " is outside the femur mesh (" +
                std::to_string(100 * uncovered) + " % of the directions from it meet no femur surface): a COR "
                "in the wrong frame or units? allow_cor_outside_ball (CLI: --allow-any-cor) accepts it");
}

ContactClass HipJoint::contact_class(bool ball, std::int64_t vertex, const FemurPose& pose,
                                     double intra_margin_mm) const {
  const Vertices& V = ball ? joint_->ball().relative : joint_->socket().relative;
  require(vertex >= 0 && vertex < V.rows(), "contact class: vertex " + std::to_string(vertex) + " out of range");
  const Eigen::Vector3d v = V.row(static_cast<Eigen::Index>(vertex)).transpose();
  const Eigen::Vector3d p_joint = ball ? Eigen::Vector3d(pose.R * v + pose.t) : v;
  if (articular_) {  // the head against the acetabulum, the lunate surface against the neck not (issue 81)
    if (ball && articular_->femur[static_cast<std::size_t>(vertex)]) return ContactClass::articular;
    if (!ball && head_zone_joint_->contains(pose.R.transpose() * (v - pose.t))) return ContactClass::articular;
  }
  if (labral_) return ContactClass::labral;
  const double rim = acetabulum_ ? acetabulum_->rim_radius_mm : head_radius_ + 5;
  return p_joint.norm() <= rim + intra_margin_mm ? ContactClass::intra_articular_impingement
                                                 : ContactClass::extra_articular_impingement;
}

ContactClass HipJoint::contact_class_at(const Eigen::Vector3d& p_joint, const FemurPose& pose,
                                        double intra_margin_mm) const {
  if (articular_ && head_zone_joint_->contains(pose.R.transpose() * (p_joint - pose.t))) return ContactClass::articular;
  if (labral_) return ContactClass::labral;
  const double rim = acetabulum_ ? acetabulum_->rim_radius_mm : head_radius_ + 5;
  return p_joint.norm() <= rim + intra_margin_mm ? ContactClass::intra_articular_impingement
                                                 : ContactClass::extra_articular_impingement;
}

FemoralZone HipJoint::femoral_zone(const Eigen::Vector3d& p) const {
  return head_zone_joint_ ? impinge::femoral_zone(*head_zone_joint_, p) : FemoralZone::none;
}

PelvicZone HipJoint::pelvic_zone(const Eigen::Vector3d& p_joint) const {
  return articular_ && acetabulum_ ? impinge::pelvic_zone(*acetabulum_, *articular_, to_working(p_joint))
                                   : PelvicZone::none;
}

void HipJoint::save_maps(const std::string& ball_path, const std::string& socket_path) const {
  save_map(ball_path, joint_->ball().map, cor_);
  save_map(socket_path, joint_->socket().map, cor_);
}

void HipJoint::clocks(const PoseResult& res, ClockSummary& ball, ClockSummary& socket) const {
  if (!socket_clock_) return;
  const JointOptions& o = joint_->options();
  clock_summary(res.ball_gaps, ball_hours_, joint_->ball().vertex_area, o.levels, ball, o.level_quantity());
  clock_summary(res.socket_gaps, socket_hours_, joint_->socket().vertex_area, o.levels,
                socket, o.level_quantity());
}

Eigen::Matrix3d HipJoint::femur_rotation(const PoseAngles& angles) const {
  // Pelvic axes in the joint frame are S; R = S Rjcs F_joint^T (femur_rotation of pose.hpp).
  return scan_axes() * jcs_rotation(angles, side_) * femur_axes_joint_.transpose();
}

Eigen::Matrix3d HipJoint::femur_rotation(const PoseAngles& angles, PelvisFrameKind frame) const {
  const auto& P = pelvic_axes_joint_[static_cast<std::size_t>(frame)];
  if (!P)
    throw Error(std::string("hip joint: no ") + to_string(frame) + " pelvic frame to pose in (" +
                (other_frame_note_.empty() ? "anatomical neutral needed" : other_frame_note_) + ")");
  return *P * jcs_rotation(angles, side_) * femur_axes_joint_.transpose();
}

void HipJoint::detect(const PoseAngles& angles, PoseResult& out) const {
  const FemurPose p = femur_pose(angles);
  joint_->detect(p.R, p.t, out);
}

void HipJoint::crop_distance_queries(const std::vector<FemurPose>& poses) {
  std::vector<std::pair<Eigen::Matrix3d, Eigen::Vector3d>> joint_poses;
  for (const FemurPose& p : poses) joint_poses.emplace_back(p.R, p.t);
  joint_->crop_distance_queries(joint_poses);
}

PoseResult HipJoint::detect(const PoseAngles& angles) const {
  PoseResult r;
  detect(angles, r);
  return r;
}

Vertices HipJoint::posed_femur(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) const {
  const Eigen::Matrix3d A = joint_to_working_ * R;
  const Eigen::Vector3d shift = cor_ + joint_to_working_ * t;
  return ((joint_->ball().relative * A.transpose()).rowwise() + shift.transpose()).eval();
}

Vertices HipJoint::pelvis_vertices() const {
  return ((joint_->socket().relative * joint_to_working_.transpose()).rowwise() + cor_.transpose()).eval();
}

}  // namespace impinge
