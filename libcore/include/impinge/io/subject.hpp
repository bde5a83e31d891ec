#pragma once
/// @file subject.hpp
/// A subject: femur and pelvis meshes, side and frame convention, from subject.json.

#include <Eigen/Core>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "impinge/anatomy/anatomical_frame.hpp"
#include "impinge/anatomy/pose.hpp"
#include "impinge/core/mesh.hpp"

namespace impinge {

/// Frame convention of a scan. LPS: +x left, +y posterior, +z superior (DICOM);
/// RAS: +x right, +y anterior, +z superior. impinge's working frame is RAS (the ISB bone frames, anatomy/anatomical_frame.hpp, are another thing).
enum class FrameConvention { LPS, RAS };

/// Parsed subject.json: {"side": "right"|"left", "frame": "LPS"|"RAS", "units": "mm",
/// "femur": file, "pelvis": file, "landmarks": {name: [x, y, z], ...}} (file names relative to
/// the json's folder; landmarks optional, mm, in the files' frame). Landmark names: asis_right,
/// asis_left, psis_right, psis_left, pubic_tubercle_right, pubic_tubercle_left, hip_centre,
/// epicondyle_lateral, epicondyle_medial, posterior_condyle_lateral, posterior_condyle_medial.
/// Optional "neutral": "anatomical" or "scan" (see Neutral).
struct SubjectInfo {
  std::string name;  ///< folder name
  Side side = Side::right;
  FrameConvention frame = FrameConvention::RAS;
  std::string femur_path;  ///< absolute or relative-to-cwd path
  std::string pelvis_path;
  Landmarks landmarks;  ///< given landmarks, mm, in the files' frame (`frame`)
  std::string neutral;  ///< optional "neutral": "anatomical" | "scan": the zero pose when the user gives none
                        ///< (generated models, which have no whole bones, say "scan"); empty when absent
  /// A model of `impinge generate` (a proximal femur and a cup; "generated": true), with its exact centre of
  /// rotation ("true_cor_mm", the files' frame, mm) and head radius ("head_radius_mm", mm).
  bool generated = false;
  std::optional<Eigen::Vector3d> true_cor_mm;
  double head_radius_mm = std::numeric_limits<double>::quiet_NaN();
};

/// The keys a subject.json may hold, the one list: load_subject refuses any other (a misspelled key would
/// otherwise be dropped without a word; keys starting with '_' are notes) and save_subject writes only these.
const std::vector<std::string>& subject_keys();

/// Read `json_path`. Throws impinge::Error naming the file and the key on a missing or bad
/// key, unknown side/frame, units other than mm, an unknown landmark name or a landmark that is
/// not three finite numbers, or unreadable JSON.
SubjectInfo load_subject(const std::string& json_path);

/// Write `s` as `json_path` (atomically: a temporary file renamed into place): side, frame, units "mm", femur and
/// pelvis (relative to the json's folder when they lie in it), neutral when set, landmarks when any, and the
/// generated model's keys when `s.generated`; load_subject reads it back as `s` (but `name`). Throws
/// impinge::Error naming the file when it cannot be written, or a key this writer would write that
/// subject_keys() lacks (a test of the writer against the reader).
void save_subject(const std::string& json_path, const SubjectInfo& s);

/// Linear map (3 x 3) from `frame` coordinates (the input frame) to the working frame (RAS). Orthogonal and
/// its own inverse for LPS (diag(-1, -1, 1)).
Eigen::Matrix3d to_working_frame(FrameConvention frame);

/// Apply a 3 x 3 linear map to every vertex in place (V <- V * M^T).
void transform_vertices(Vertices& V, const Eigen::Matrix3d& M);

/// Parse "LPS" / "RAS"; "right" / "left". Throw impinge::Error naming `context` otherwise.
FrameConvention parse_frame(const std::string& s, const std::string& context);
Side parse_side(const std::string& s, const std::string& context);

}  // namespace impinge
