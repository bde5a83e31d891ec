#pragma once
/// @file hip_joint.hpp
/// A hip ready for clinical poses: the anatomical frames found from the bones, and the Joint
/// (both radial distance maps) built in the pelvic frame, so that a pose is three clinical angles
/// and the results do not depend on how the subject lay in the scanner.

#include <Eigen/Core>
#include <array>
#include <memory>
#include <optional>

#include "impinge/anatomy/articular_zones.hpp"
#include "impinge/anatomy/clock_face.hpp"
#include "impinge/anatomy/hip_frames.hpp"
#include "impinge/anatomy/labrum.hpp"
#include "impinge/anatomy/pose.hpp"
#include "impinge/clinical/clock_summary.hpp"
#include "impinge/clinical/joint_centre.hpp"
#include "impinge/detection/joint.hpp"

namespace impinge {

/// The femur's pose in the joint frame: a femur point p (joint frame, unposed, mm) is posed at
/// R p + t.
struct FemurPose {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  ///< 3 x 3 rotation
  Eigen::Vector3d t = Eigen::Vector3d::Zero();      ///< translation, mm (the joint-centre method's)
};

/// Options of a HipJoint.
struct HipJointOptions {
  JointOptions joint;                     ///< maps, mode, levels
  /// What zero angles mean. Unset: anatomical (Session: the subject's "neutral", else anatomical).
  std::optional<Neutral> neutral;
  HipFrameOptions frames;                 ///< which pelvic and femoral frames (anatomical neutral only)
  /// How the femur moves at each pose (joint_centre.hpp; Puls et al. 2010). Unset: equidistant with
  /// anatomical neutral, femoral_head (the thesis' method) with scan neutral, which allows no other
  /// (the others need the acetabulum).
  std::optional<JointCentreMethod> joint_centre;
  EquidistantOptions equidistant;  ///< the equidistant method's iteration
  /// Map files (save_map) to use instead of sampling: {ball, socket}; empty = sample. They must
  /// have been saved from a HipJoint of the same meshes and options (save_maps): their stored COR
  /// (working frame) must equal this joint's within 1e-6 mm and their scheme joint.scheme's.
  std::string ball_map_file, socket_map_file;
  /// Accept a centre of rotation outside the femur (ball) mesh, for research; otherwise that is an
  /// error (the gaps would be measured along rays that leave the head: silently wrong numbers).
  bool allow_cor_outside_ball = false;
  /// The femoral head sphere (working frame, mm) when the COR is not its centre (a given COR): the
  /// articular zones, the acetabulum, the clock faces and the seat of the combined and equidistant
  /// methods use it, so that they do not move with the COR. Unset: the COR's sphere (`head`).
  std::optional<SphereFitResult> head_sphere;
  /// Tolerances of the articular zones (anatomical neutral only; articular_zones.hpp).
  ArticularZoneOptions articular;
  /// Combined and equidistant methods: seat the femur before sampling, so that the maps' centre (cor())
  /// is the acetabular centre with the femoral head on it (true: the COR was fitted), or keep the maps
  /// about the given head centre `head.centre` and move the femur by the seat at every pose instead
  /// (false: a COR the user gave, about which the radial gaps at the scan pose are then measured).
  bool seat_before_sampling = true;
  /// The frame errors give positions in: working frame -> it (3 x 3; Session: the input frame), and its name.
  Eigen::Matrix3d to_report = Eigen::Matrix3d::Identity();
  std::string report_frame_name;
};

/// Femur (ball) and pelvis (socket) of one hip about the centre of rotation, posed by clinical
/// angles. The joint frame, in which the maps are built and detect() works, has its origin at the
/// COR and axes:
/// - anatomical neutral: the pelvic frame's, arranged as the thesis' scan frame (x = pelvic Z
///   right, y = pelvic X anterior, z = pelvic Y superior; the maps' pole superior), so the maps
///   and gaps are the same for any placement of the subject in the scanner;
/// - scan neutral: the working frame's (the maps as the thesis built them).
class HipJoint {
 public:
  /// Build the frames (anatomical neutral: find_hip_frames with "hip_centre" = head.centre; the
  /// acetabulum and both clock faces) and both maps. With the combined and equidistant joint
  /// centres and options.seat_before_sampling the femur is first seated (seat_mm()) and the maps' centre
  /// (cor()) is the acetabular centre; otherwise it is `head.centre`. `femur`, `pelvis`: whole bones in the
  /// working frame (RAS, mm); `head`: the femoral head sphere (mm, working frame; its centre is
  /// the COR; a NaN radius is estimated as the median distance of the femur's vertices within
  /// 35 mm of the centre); `given`: landmarks that replace found ones (mm, working frame).
  /// Throws impinge::Error naming the mesh and step that failed (with anatomical neutral, a failure to find the
  /// head or the anatomy ends in how to do without it: scan neutral, or the landmarks given), and naming
  /// the COR when it lies outside the femur mesh (its map leaves more than 1e-4 of the directions
  /// without surface) unless options.allow_cor_outside_ball. A head radius outside 5-60 mm (metres
  /// instead of mm?) adds a warning (warnings()).
  HipJoint(TriangleMesh femur, TriangleMesh pelvis, Side side, const SphereFitResult& head, const Landmarks& given,
           const HipJointOptions& options);

  /// Rotation (3 x 3, joint frame) of the femur about the COR at `angles` (degrees, ISB signs).
  Eigen::Matrix3d femur_rotation(const PoseAngles& angles) const;
  /// The same with `angles` measured in the pelvic frame `frame` (anatomical neutral): zero angles put the
  /// femoral frame parallel to that frame's axes, and flexion turns about its Z. With the other frame than
  /// pelvis_frame_kind() it is the motion performed about that frame's axes, on the same joint (maps, zones,
  /// clocks); R = A^T P_frame Rjcs F^T (pose.hpp's femur_rotation with that frame's axes P_frame). Both
  /// frames share Z (through both ASIS), so the other frame's angles are the session frame's with the
  /// flexion offset by the angle between their X axes. Throws impinge::Error with scan neutral, or when that
  /// frame could not be built from the landmarks (other_pelvis_frame_note()). Source: impinge.
  Eigen::Matrix3d femur_rotation(const PoseAngles& angles, PelvisFrameKind frame) const;
  /// The pelvic frame the angles are measured in (HipJointOptions::frames.pelvis); empty with scan neutral.
  std::optional<PelvisFrameKind> pelvis_frame_kind() const { return pelvis_kind_; }
  /// Whether femur_rotation(angles, frame) can pose in `frame` (anatomical neutral, its landmarks usable).
  bool has_pelvis_frame(PelvisFrameKind frame) const {
    return pelvic_axes_joint_[static_cast<std::size_t>(frame)].has_value();
  }
  /// Why the other pelvic frame is not available (scan neutral, or the landmarks' error), else empty.
  const std::string& other_pelvis_frame_note() const { return other_frame_note_; }

  /// The femur's translation (mm, joint frame) at rotation R by the joint-centre method: a femur
  /// point p (joint frame, unposed) is posed at R p + t (JointCentre::translation; a function of R
  /// alone). Throws impinge::Error as that does.
  Eigen::Vector3d joint_translation(const Eigen::Matrix3d& R) const {
    return centre_.translation(centre_joint_ ? *centre_joint_ : *joint_, R);
  }
  /// femur_rotation(angles) with its joint_translation.
  FemurPose femur_pose(const PoseAngles& angles) const {
    const Eigen::Matrix3d R = femur_rotation(angles);
    return {R, joint_translation(R)};
  }
  /// The femur's translation at joint-frame translation t (a pose's, mm) from where the scan put it,
  /// after its rotation about its own head centre: working-frame axes, mm. With the combined and
  /// equidistant methods it includes seat_mm(). Posed femur point (working frame): c_h + A R A^T
  /// (p - c_h) + this, with c_h the fitted head centre and A = joint_to_working().
  Eigen::Vector3d femur_translation(const Eigen::Vector3d& t) const { return seat_ + joint_to_working_ * t; }
  /// The femur's pose at the scan pose (joint frame: R = I, t = -seat).
  FemurPose scan_pose() const { return {Eigen::Matrix3d::Identity(), -(joint_to_working_.transpose() * seat_)}; }
  /// Combined and equidistant methods: the translation (working frame, mm) that seats the femoral
  /// head centre on the acetabular sphere's centre, which is then the COR (cor()); zero otherwise.
  const Eigen::Vector3d& seat_mm() const { return seat_; }
  /// The method in use and its state.
  const JointCentre& joint_centre() const { return centre_; }

  /// Both scans at `angles` (Joint::detect with femur_rotation(angles) and its joint_translation);
  /// into `out`, reusing its storage.
  void detect(const PoseAngles& angles, PoseResult& out) const;
  PoseResult detect(const PoseAngles& angles) const;

  /// Working-frame position (mm) of a joint-frame point p (mm): cor + A^T p.
  Eigen::Vector3d to_working(const Eigen::Vector3d& p) const { return cor_ + joint_to_working_ * p; }
  /// Rotation from joint-frame to working-frame directions (3 x 3, orthonormal).
  const Eigen::Matrix3d& joint_to_working() const { return joint_to_working_; }
  /// Vertices (n x 3, mm, working frame) of the femur posed by R and t (joint frame, mm) or of the pelvis.
  Vertices posed_femur(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) const;
  Vertices pelvis_vertices() const;

  const Joint& joint() const { return *joint_; }
  /// Crop the joint's distance hierarchies to these poses (femur_pose's, scan_pose's):
  /// Joint::crop_distance_queries, for options.joint.cropped_distance_queries. Throws as that does.
  void crop_distance_queries(const std::vector<FemurPose>& poses);
  /// The anatomical frames in the working frame (empty with scan neutral).
  const std::optional<HipFrames>& frames() const { return frames_; }
  /// The acetabulum (working frame; empty with scan neutral).
  const std::optional<Acetabulum>& acetabulum() const { return acetabulum_; }
  /// Clock faces in the joint frame (socket: acetabular; ball: femoral head-neck, on the unposed
  /// femur); empty with scan neutral.
  const std::optional<ClockFace>& socket_clock() const { return socket_clock_; }
  const std::optional<ClockFace>& ball_clock() const { return ball_clock_; }
  /// Where each scan of `res` lies on its clock face (anatomical neutral only; else untouched).
  void clocks(const PoseResult& res, ClockSummary& ball, ClockSummary& socket) const;
  /// The joint surfaces per vertex (the femoral head's, the lunate's), to tell the joint space
  /// closing from impingement (anatomical neutral only: they need the acetabulum; else empty).
  const std::optional<ArticularZones>& articular() const { return articular_; }
  /// The femoral head up to its head-neck junction (ArticularZones::head) in the joint frame, unposed femur
  /// (a femur point x of the posed femur R x + t); empty with scan neutral.
  const std::optional<FemoralHeadZone>& head_zone_joint() const { return head_zone_joint_; }
  /// Where on the femur the point p (joint frame, unposed femur: R^T (q - t) for a posed point q) lies
  /// (femoral_zone; articular_zones.hpp); none with scan neutral.
  FemoralZone femoral_zone(const Eigen::Vector3d& p) const;
  /// Where on the pelvis the point p_joint (joint frame) lies (pelvic_zone; articular_zones.hpp); none with scan
  /// neutral.
  PelvicZone pelvic_zone(const Eigen::Vector3d& p_joint) const;
  /// The class of a contact at vertex `vertex` of the femur (`ball`) or the pelvis with the femur at
  /// `pose`: articular when the vertex is on its joint surface (articular()), or is a pelvis vertex
  /// within ArticularZones::head_sphere_reach_mm of the posed head centre on the head side of the head-neck
  /// junction (it meets the head's joint surface: head_zone_joint()->contains); else intra-articular
  /// impingement within the acetabular rim radius (head radius + 5 mm
  /// without an acetabulum) plus `intra_margin_mm` of the COR, else extra-articular.
  ContactClass contact_class(bool ball, std::int64_t vertex, const FemurPose& pose, double intra_margin_mm) const;
  /// The class of a contact at the point p_joint (joint frame, mm; e.g. an exact contact between vertices) with the
  /// femur at `pose`: articular when the point carried onto the unposed femur (R^T (p - t)) lies in the head up to
  /// its head-neck junction (head_zone_joint()->contains), labral on a labral hip, else as contact_class by the
  /// point's distance from the COR. Source: impinge (issue 81).
  ContactClass contact_class_at(const Eigen::Vector3d& p_joint, const FemurPose& pose, double intra_margin_mm) const;
  /// The same hip with the acetabular labrum (make_labrum, `width_mm` x `height_mm`) as its socket in place of the
  /// pelvis: a Joint of the femur against the labrum alone, with maps of the same scheme and options, in the same
  /// joint frame about the same COR; the frames, clocks, articular zones of the femur and the joint-centre method
  /// are this hip's (its translations come from this hip's Joint, so that the femur moves exactly as here). Its
  /// searches (find_rom_limit) find the femur's first contact with the labrum; a contact off the head's joint
  /// surface is ContactClass::labral. The rim: acetabulum(), or with scan neutral find_acetabulum about the head
  /// sphere with the joint frame's axes (only the clock's orientation, unused here, depends on them). With
  /// `splits` > 0 each of the labrum's triangles is split in four at its edges' midpoints (shared between
  /// neighbours) that many times: the same surface, with 4^splits times the triangles and vertices dense enough
  /// for a per-vertex test (the plan's contacts: the free margin, a sharp edge with a vertex per rim point, 2-3 mm
  /// apart, is otherwise seen only at those). Throws impinge::Error as make_labrum, find_acetabulum and Joint do,
  /// and naming the splits outside 0..kMaxLabrumSplits. Source: impinge (issue 81).
  std::shared_ptr<const HipJoint> with_labrum(double width_mm, double height_mm, int splits = 0) const;
  /// The most splits with_labrum takes (4^5 = 1024 times the labrum's 432 triangles).
  static constexpr int kMaxLabrumSplits = 5;
  /// Whether this is a labral hip (with_labrum): its socket is the labrum.
  bool labral() const { return labral_; }
  /// The acetabulum the labrum is built on, joint frame (with_labrum's rim). Throws as find_acetabulum.
  Acetabulum acetabulum_joint() const;
  /// Save both maps (map_io.hpp) with the working-frame COR, for options.ball_map_file and
  /// socket_map_file of a later HipJoint. Throws impinge::Error on I/O errors.
  void save_maps(const std::string& ball_path, const std::string& socket_path) const;
  /// Warnings about the input (e.g. an implausible head radius: wrong units?), one line each.
  const std::vector<std::string>& warnings() const { return warnings_; }
  /// The femoral head centre (HipJointOptions::head_sphere, else the COR) in the joint frame, on the
  /// unposed femur (mm; zero when the head is seated or is the COR).
  const Eigen::Vector3d& head_centre_joint() const { return head_centre_joint_; }
  /// Head radius used for the acetabulum and clocks (mm).
  double head_radius_mm() const { return head_radius_; }
  const Eigen::Vector3d& cor() const { return cor_; }
  Side side() const { return side_; }
  Neutral neutral() const { return neutral_; }
  double frames_ms() const { return frames_ms_; }

 private:
  // The constructor's steps, in order: the head sphere (radius, warnings); the frames, acetabulum, zones and
  // clocks (anatomical neutral), seating the femur where the method asks; the maps about the COR; the check
  // that the COR lies in the femur.
  SphereFitResult head_sphere(const TriangleMesh& femur, const SphereFitResult& head, const HipJointOptions& options);
  void build_anatomy(TriangleMesh& femur, const TriangleMesh& pelvis, SphereFitResult& sphere, const Landmarks& given,
                     const HipJointOptions& options, JointCentreMethod method);
  void seat_femur(TriangleMesh& femur, const SphereFitResult& sphere, const HipJointOptions& options);
  void build_joint(TriangleMesh femur, TriangleMesh pelvis, const HipJointOptions& options);
  void check_cor_inside_femur(const HipJointOptions& options);

  Side side_;
  Neutral neutral_;
  Eigen::Vector3d cor_;
  Eigen::Matrix3d joint_to_working_ = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d femur_axes_joint_ = Eigen::Matrix3d::Identity();  // femoral frame axes in the joint frame
  std::optional<PelvisFrameKind> pelvis_kind_;                        // anatomical neutral only
  std::array<std::optional<Eigen::Matrix3d>, 2> pelvic_axes_joint_;   // each pelvic frame's axes, joint frame
  std::string other_frame_note_;                                      // why the other frame is missing
  std::optional<HipFrames> frames_;
  std::optional<Acetabulum> acetabulum_;
  std::optional<ClockFace> socket_clock_, ball_clock_;
  std::vector<double> socket_hours_, ball_hours_;  ///< every vertex's clock hour (clock_hours), once
  std::optional<ArticularZones> articular_;
  std::optional<FemoralHeadZone> head_zone_joint_;
  double head_radius_ = 0;
  std::vector<std::string> warnings_;
  std::shared_ptr<Joint> joint_;
  std::shared_ptr<const Joint> centre_joint_;  ///< a labral hip's: the bony hip's Joint, whose translations it takes
  bool labral_ = false;
  JointCentre centre_;
  Eigen::Vector3d seat_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d head_centre_joint_ = Eigen::Vector3d::Zero();
  double frames_ms_ = 0;
};

}  // namespace impinge
