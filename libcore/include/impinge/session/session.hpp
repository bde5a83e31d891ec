#pragma once
/// @file session.hpp
/// One set-up for every front end. The CLI, the Python module, the experiments and the benchmarks
/// hand the same inputs and options to a Session and get the same HipJoint: the meshes read and
/// brought from their input frame (LPS or RAS) into the working frame (RAS), the centre of rotation
/// found by one policy and checked, the scheme and resolution chosen, the frames and both maps built.
/// What a run reports (records.hpp) and the loops over poses (runs.hpp) build on it.
///
/// Frames: the *input frame* is the meshes' own (LPS or RAS, subject.json's "frame"); the *working
/// frame* is RAS, mm; the *joint frame* is HipJoint's (origin at the COR). Everything a user gives
/// (COR, head region, landmarks, rotations) and everything reported is in the input frame.

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "impinge/anatomy/anatomical_frame.hpp"
#include "impinge/anatomy/pose.hpp"
#include "impinge/anatomy/sphere_fit.hpp"
#include "impinge/clinical/hip_joint.hpp"
#include "impinge/core/range.hpp"
#include "impinge/core/mesh.hpp"
#include "impinge/core/mesh_hygiene.hpp"
#include "impinge/io/subject.hpp"

namespace impinge {

/// Where the bones come from: a subject.json, mesh files, or meshes in memory (any mix: meshes
/// and files given here replace the subject's).
struct SessionInput {
  std::string subject;                                 ///< subject.json: meshes, side, frame, landmarks, neutral
  std::string ball, socket;                            ///< femur and pelvis mesh files (PLY, STL, OBJ, OFF; mm)
  std::optional<TriangleMesh> ball_mesh, socket_mesh;  ///< femur and pelvis in memory (input frame, mm)
  std::string side;   ///< "right" | "left"; empty: the subject's, else right. Contradicting the subject: an error
  std::string frame;  ///< "LPS" | "RAS"; empty: the subject's, else RAS. Contradicting the subject: an error
  Landmarks landmarks;  ///< given landmarks (input frame, mm; names as subject.json's), over the subject's
  /// Refuse a mesh that needs a repair beyond the winding (a fragment apart from the bone, a double wall:
  /// mesh_hygiene.hpp) instead of making it and saying so.
  bool strict = false;
};

/// How the centre of rotation (COR) is found. In order: `head_region` (a sphere fit to the femur's
/// vertices there), `given`, the subject's "hip_centre" landmark, else automatic: the femoral head
/// found on the femur (whole or proximal, either side, in any orientation) and fitted: a sphere at
/// each end of the long axis (RANSAC and geometric fit; thesis sec. 3.4), the head the one that sits
/// in the acetabulum (locate_femoral_head with the pelvis).
struct CorOptions {
  std::optional<Eigen::Vector3d> given;        ///< X, Y, Z: mm, input frame
  std::optional<Eigen::Vector4d> head_region;  ///< X, Y, Z, R: fit the head to femur vertices within R mm of X, Y, Z
  /// Accept a given COR outside the femoral head (research). Otherwise a given COR (or the subject's
  /// landmark hip_centre) farther from the fitted head centre than the head radius is an error naming
  /// both (check_cor_in_head), and HipJoint refuses a COR outside the femur mesh.
  bool allow_any = false;
};

/// Parse the CLI's COR text: "auto" (empty optional) or "X,Y,Z" (mm). Throws impinge::Error
/// naming `context` on anything else.
std::optional<Eigen::Vector3d> parse_cor(const std::string& text, const std::string& context);
/// Parse "X,Y,Z,R" (mm) for CorOptions::head_region. Throws impinge::Error naming `context`.
Eigen::Vector4d parse_head_region(const std::string& text, const std::string& context);

/// The maps' sampling scheme and resolution as a front end asks for them (session-only: the Session
/// resolves it, scheme_of, into HipJointOptions::joint.scheme). At most one of resolution, precision, turns and
/// spacing; none: the scheme's default (0.5 deg node spacing equivalent).
struct GridRequest {
  static constexpr const char* kDefaultScheme = "equiangular";
  std::string scheme = kDefaultScheme;  ///< a registered scheme (scheme_names())
  double resolution = 0;               ///< the scheme's own unit; 0: not given
  static constexpr Range kResolutionRange{0, 2147483647};
  double precision = 0;                ///< alias for equiangular grids: p, degrees; 0: not given
  static constexpr Range kPrecisionRange{0, 90};  ///< the equiangular grid's own: p in (0, 90] dividing 180
  double turns = 0;                    ///< alias for the helix: k turns; 0: not given
  static constexpr Range kTurnsRange{0, 2147483647};
  double spacing = 0;                  ///< largest node spacing wanted, degrees: the coarsest resolution reaching it
  static constexpr Range kSpacingRange{0, 90};
  /// Whether anything but the defaults was asked for (a resolution, or a scheme other than equiangular).
  bool given() const {
    return resolution > 0 || precision > 0 || turns > 0 || spacing > 0 || scheme != kDefaultScheme;
  }
};

/// About how many bytes the two maps of `scheme` take (float node values, their marks and bound pyramids:
/// 5 bytes a node, doubled for the two bones; the layered maps, at most 0.5 deg by default, come on top).
double map_memory_bytes(const SamplingScheme& scheme);

/// Below this many poses SessionOptions::query_strategy "auto" takes "direct" (no layered maps), from this many "maps": on
/// lhdl-ct (0.5 deg, defaults, 2 cores) the layered maps cost some 80 ms more to set up and save some 0.2 ms per
/// pose, so they pay back from about 400 poses (impinge motion, 10 / 100 / 1,000 frames: direct 0.32 / 0.45 / 1.66 s,
/// maps 0.33 / 0.51 / 1.56 s, medians of 5 alternated runs; issue 52).
inline constexpr std::size_t kDirectQueryMaxPoses = 400;

/// The query strategy a run of `poses` poses takes: `strategy` itself when it is "maps" or "direct"; for "auto", "direct"
/// below kDirectQueryMaxPoses poses, else "maps". Throws impinge::Error for any other value.
std::string query_strategy_for_poses(const std::string& strategy, std::size_t poses);

/// Everything a Session needs: the inputs, how the COR is found, the library's own options of the hip
/// (`hip`: HipJointOptions, its JointOptions `hip.joint` and their declared ranges; the one place each
/// library option and its default live), and what only a session decides (the grid request, the set-up, the
/// memory limit, the poses to come). Default-constructed: the library's defaults (the thesis' single-layer
/// maps, no distances); the front ends start from RunOptions::clinical() (option_table.hpp), whose table
/// binds each option's name, unit, help and default to one field here.
///
/// The Session resolves these fields of `hip` itself (Session::hip_options() gives what it built with):
/// joint.scheme (from `grid`; SessionOptions() leaves it null; a scheme set here is used as it is, and giving
/// `grid` as well is an error), joint.layered_maps (from `query_strategy`; a value given is replaced),
/// joint.cropped_distance_queries (from `only_poses`; replaced), joint.levels_on when unset (the distance with
/// distances on, else the radial gap), neutral when unset (the subject's "neutral", else anatomical), and,
/// replacing any value given, allow_cor_outside_ball (cor.allow_any), head_sphere, seat_before_sampling, to_report
/// and report_frame_name (from the input and the COR). SessionOptions is not an aggregate (its constructor
/// leaves the scheme to `grid`): set its fields by name.
struct SessionOptions {
  SessionOptions() { hip.joint.scheme.reset(); }
  SessionInput input;
  CorOptions cor;
  HipJointOptions hip;  ///< the library's options: maps, detection, levels, neutral, frames, joint centre, map files
  GridRequest grid;     ///< the maps' scheme and resolution as asked (resolved into hip.joint.scheme)
  /// What to build for the work: "maps" (both maps and, with layers, the layered maps), "direct" (no layered
  /// maps: the hidden vertices by exact ray casts, JointOptions::layered_maps off; for a few poses; no ROM
  /// searches), "auto" (the front end's choice by the number of poses, query_strategy_for_poses: `impinge distance` and
  /// motions of fewer than kDirectQueryMaxPoses frames take direct; ROM searches, plans and longer motions maps).
  std::string query_strategy = "auto";
  /// The most memory the maps may take, GB; 0: three quarters of this machine's memory. A resolution whose
  /// maps would need more is refused before anything is allocated (map_memory_bytes).
  double max_memory_gb = 0;
  static constexpr Range kMaxMemoryRange{0, 1e6};  ///< of max_memory_gb, GB
  /// The poses the session will be asked for, when the front end knows them (`impinge distance`'s --pose; not
  /// an option of its own). With query_strategy "direct" and distances or layers on, the distance hierarchies are
  /// cropped to them and the scan pose (JointOptions::cropped_distance_queries): the same results, less set-up.
  /// Empty: built over the whole meshes.
  std::vector<PoseAngles> only_poses;
};

/// The meshes of a SessionInput in the working frame (RAS, mm), with what the input said.
struct LoadedInput {
  TriangleMesh femur, pelvis;  ///< working frame
  std::string femur_source, pelvis_source;  ///< file paths, or "ball (in memory)" / "socket (in memory)"
  Side side = Side::right;
  FrameConvention frame = FrameConvention::RAS;
  Eigen::Matrix3d to_working = Eigen::Matrix3d::Identity();  ///< input frame -> working frame (3 x 3)
  Landmarks landmarks;     ///< working frame, mm
  std::string neutral;     ///< the subject's "neutral" (empty when none)
  std::string name;        ///< the subject's folder name (empty without a subject)
  /// The file the given landmarks come from (the subject.json), named in their errors; empty when there are none or
  /// some were given in SessionInput::landmarks.
  std::string landmarks_file;
  /// What was repaired on reading (triangles wound against their neighbours, flipped; fragments, double walls:
  /// mesh_hygiene.hpp), one line each.
  std::vector<std::string> warnings;
  MeshHygiene femur_hygiene, pelvis_hygiene;  ///< what each bone's mesh held and what was done (clean_bone_mesh)
};

/// The femoral head found on the femur of `in`: the end of its long axis that sits in the acetabulum when the
/// pelvis is there, else the end with the better sphere (locate_femoral_head). Throws impinge::Error as that does.
SphereFitResult located_head(const LoadedInput& in);

/// The side of `input` without reading its meshes (subject.json's, or `side`, else right), to
/// read a motion file for it before the joint is built. Throws impinge::Error as load_input.
Side input_side(const SessionInput& input);

/// Read and convert the input (no COR, no maps). Throws impinge::Error naming the file or option:
/// a missing mesh, an unreadable file, a side or frame that contradicts subject.json.
LoadedInput load_input(const SessionInput& input);

/// The COR and how it was found.
struct CorResult {
  SphereFitResult head;  ///< centre: the COR (working frame, mm); radius and rms NaN when given
  std::string method;    ///< e.g. "automatic sphere fit (long axis, RANSAC + geometric)"
  /// The femoral head the bone shows, when it was fitted to check a given COR (working frame, mm).
  std::optional<SphereFitResult> fitted_head;
};

/// Check a centre of rotation given as `what` ("cor", or "<subject.json>: landmark hip_centre") at `cor` (working
/// frame, mm) against the femoral head the bone of `in` shows (located_head): it must lie within the head's radius of
/// its centre. Returns that head. Throws impinge::Error naming `what`, both points (input frame, mm), the distance
/// and the radius, and that allow-any-cor accepts it; or as located_head. Source: impinge.
SphereFitResult check_cor_in_head(const std::string& what, const Eigen::Vector3d& cor, const LoadedInput& in);

/// The COR of `in` by the policy of CorOptions (see there). Throws impinge::Error naming the
/// option: a given COR or landmark hip_centre outside the head without allow_any (check_cor_in_head), both a
/// given COR and a head region, a head region with too few vertices, or no femoral head found.
CorResult find_centre_of_rotation(const LoadedInput& in, const CorOptions& cor);

/// Check the side and the input frame against the bones (side_check.cpp). On a whole pelvis (over 200 mm wide) the
/// femoral head (`cor`'s centre, working frame) lies 60-100 mm to its own side of the pelvis' centroid (the shared
/// hips: 82-94 mm); a head on the other side means the side or the frame (LPS read as RAS mirrors left and right) is
/// wrong. On a hemipelvis (narrower) the acetabulum opens laterally (acetabular_opening_direction) and the femoral
/// neck leaves the head laterally (head_to_neck_direction), about the head sphere (`cor`'s when fitted, else its
/// fitted_head; neither: no check): both at least 0.3 towards the other side is a wrong side or frame (the shared
/// hips cut to their hemipelvis: 0.72-0.84 towards their own); the acetabulum opening anteriorly then blames the
/// side, posteriorly the frame (a frame read wrongly turns anterior to posterior as well). Throws impinge::Error
/// naming the subject (`given`'s), the side given, what the bones say and the option (`given`'s side or frame, or the
/// subject's) that is wrong.
void check_side_and_frame(const LoadedInput& in, const CorResult& cor, const SessionInput& given);

/// The scheme a GridRequest asks for. Throws impinge::Error on two resolutions, a resolution outside its
/// range, or an unknown scheme.
std::shared_ptr<const SamplingScheme> scheme_of(const GridRequest& grid);

/// The HipJointOptions a Session builds with (before the input and the COR are known): `options.hip` with its
/// scheme resolved (options.grid, or the scheme given in options.hip.joint.scheme), the layered maps by
/// options.query_strategy, and the neutral, when unset, `subject_neutral` ("anatomical" | "scan"; empty: left unset, which
/// HipJoint reads as anatomical);
/// validated (JointOptions::validate). Throws impinge::Error naming the option.
HipJointOptions resolved_hip_options(const SessionOptions& options, const std::string& subject_neutral = "");

/// A hip set up from inputs and options: the same for the CLI, Python, experiments and benchmarks.
/// Immutable once built; detect() and the runs are const and may be called from several threads.
class Session {
 public:
  /// Load, find the COR, build the frames and maps (HipJoint), and scan the scan pose once (a
  /// segmentation overlap there becomes a warning). Throws impinge::Error naming the file, option
  /// or step that failed; with anatomical neutral a failure to find the anatomy says how to use scan neutral
  /// instead (HipJoint).
  explicit Session(const SessionOptions& options);

  const HipJoint& hip() const { return *hip_; }
  /// The HipJoint, shared (Python keeps map views alive with it).
  const std::shared_ptr<const HipJoint>& shared_hip() const { return hip_; }
  const Joint& joint() const { return hip_->joint(); }
  const SessionOptions& options() const { return options_; }
  const HipJointOptions& hip_options() const { return hip_options_; }
  const JointOptions& joint_options() const { return hip_options_.joint; }

  Side side() const { return side_; }
  FrameConvention input_frame() const { return frame_; }
  /// Input frame -> working frame (3 x 3, orthonormal); to_input() is its transpose.
  const Eigen::Matrix3d& to_working() const { return to_working_; }
  Eigen::Matrix3d to_input() const { return to_working_.transpose(); }
  const std::string& ball_source() const { return ball_source_; }
  const std::string& socket_source() const { return socket_source_; }
  const std::string& subject_name() const { return subject_name_; }
  /// The head sphere the COR came from (working frame; radius NaN when the COR was given).
  const SphereFitResult& head() const { return cor_.head; }
  const std::string& cor_method() const { return cor_.method; }
  /// Least gap of both scans at the scan pose (after any re-seating), mm; < 0: the bones overlap.
  double scan_pose_min_gap_mm() const { return scan_pose_min_gap_mm_; }
  /// Both scans at `pose` (joint frame; Joint::detect). With SessionOptions::only_poses set, the set-up's own scan
  /// of the scan pose is kept, and a `pose` equal to the scan pose (R and t bit for bit) returns a copy of it
  /// instead of scanning again: the same result, since detect is a function of the pose. Throws as Joint::detect.
  PoseResult detect(const FemurPose& pose) const;
  /// HipJoint's warnings and the session's (overlap at the scan pose), one line each.
  const std::vector<std::string>& warnings() const { return warnings_; }
  /// What the femur's and the pelvis' meshes held and what was done on reading (mesh_hygiene.hpp).
  const MeshHygiene& femur_hygiene() const { return femur_hygiene_; }
  const MeshHygiene& pelvis_hygiene() const { return pelvis_hygiene_; }

  /// A working-frame point or direction (mm) in the input frame.
  Eigen::Vector3d to_input(const Eigen::Vector3d& working) const { return to_working_.transpose() * working; }
  /// The femoral head centre, the centre of rotation (COR): the one given (CorOptions::given) or fitted;
  /// input frame, mm. The femur rotates about it (joint_motion) and, when given, the radial gaps at the
  /// scan pose are measured about it.
  Eigen::Vector3d head_centre_input() const { return to_input(hip_->cor() - hip_->seat_mm()); }
  /// The maps' centre, where every ray of a radial gap starts (HipJoint::cor()): the head centre, or the
  /// acetabular centre when the combined or equidistant method seated a fitted head before sampling; input
  /// frame, mm.
  Eigen::Vector3d map_centre_input() const { return to_input(hip_->cor()); }
  /// The acetabular centre (the sphere fitted to the acetabulum, find_acetabulum; anatomical neutral
  /// only), input frame, mm.
  std::optional<Eigen::Vector3d> acetabular_centre_input() const {
    if (!hip_->acetabulum()) return std::nullopt;
    return to_input(hip_->acetabulum()->sphere.centre);
  }
  /// Vertices (n x 3, mm, input frame) of the femur at `pose` (joint frame), of the pelvis.
  Vertices femur_input(const FemurPose& pose) const;
  Vertices pelvis_input() const;
  /// A femur motion given in the input frame (the femur as scanned rotated by R_in 3 x 3 about the
  /// femoral head centre h (head_centre_input()), then translated by t_in, mm: posed = h + R_in (p - h) +
  /// t_in) as a joint-frame pose for
  /// Joint::detect (which poses the seated femur: HipJoint::seat_mm()). Rotations checked by the caller.
  std::pair<Eigen::Matrix3d, Eigen::Vector3d> joint_motion(const Eigen::Matrix3d& R_in,
                                                           const Eigen::Vector3d& t_in) const;
  /// The inverse for the translation: the input-frame t_in of joint_motion for a joint-frame pose.
  Eigen::Vector3d input_translation(const FemurPose& pose) const;
  /// A joint-frame rotation of the femur (femur_rotation) in the input frame (3 x 3).
  Eigen::Matrix3d input_rotation(const Eigen::Matrix3d& R_joint) const;
  /// A joint-frame point (mm) as reports give it: in the pelvic frame (AnatomicalFrame::to_local:
  /// its origin and ISB axes) with anatomical neutral, else in the input frame.
  Eigen::Vector3d report_point(const Eigen::Vector3d& joint_point) const;

 private:
  SessionOptions options_;
  HipJointOptions hip_options_;
  Side side_ = Side::right;
  FrameConvention frame_ = FrameConvention::RAS;
  Eigen::Matrix3d to_working_ = Eigen::Matrix3d::Identity();
  std::string ball_source_, socket_source_, subject_name_;
  CorResult cor_;
  std::shared_ptr<const HipJoint> hip_;
  double scan_pose_min_gap_mm_ = 0;
  std::shared_ptr<const PoseResult> scan_result_;  ///< the scan pose's scans, kept when only_poses is set
  std::vector<std::string> warnings_;
  MeshHygiene femur_hygiene_, pelvis_hygiene_;
};

}  // namespace impinge
