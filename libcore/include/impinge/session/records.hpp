#pragma once
/// @file records.hpp
/// What a run reports, built once for every front end: JSON records (the CLI's summary.json, the
/// Python module's dicts, the experiments' rows) and CSV tables. Positions and axes are in the
/// input frame (mm), angles in degrees; a quantity that does not exist (no surface, no limit) is
/// JSON null, never a made-up number.

#include <Eigen/Core>
#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "impinge/anatomy/clock_face.hpp"
#include "impinge/clinical/clock_summary.hpp"
#include "impinge/detection/joint.hpp"
#include "impinge/session/session.hpp"

namespace impinge {

/// A table of records: column names and rows (JSON arrays of the same length; numbers, strings,
/// booleans, or null for NaN).
struct Table {
  std::vector<std::string> columns;
  std::vector<nlohmann::json> rows;
  /// Append a row. Throws impinge::Error when its length differs from the columns'.
  void add(nlohmann::json row);
  /// Column `name` of every row. Throws impinge::Error naming an unknown column.
  std::vector<nlohmann::json> column(const std::string& name) const;
};

/// A finite number as JSON, NaN and infinities as null.
nlohmann::json number_or_null(double x);

/// Write `table` as CSV (RFC 4180: header, then one line per row; numbers to 9 significant
/// digits, null as "nan", booleans as 1/0, text quoted when it holds a comma, quote or line break).
/// Throws impinge::Error naming the file on an I/O error.
void write_csv(const std::string& path, const Table& table);
/// Write `j` as indented JSON. Throws impinge::Error naming the file on an I/O error.
void write_json(const std::string& path, const nlohmann::json& j);

/// One scan's summary (ScanSummary: counts, least gaps, penetration, areas per level) with its
/// body's map and sampling figures, its detection time (ms) and, when `clock` is given, where on
/// its clock face it lies (closest hour and the area per clock sector and level, mm^2).
nlohmann::json scan_record(const JointBody& body, const ScanSummary& summary, double detection_ms,
                           const ImpingementLevels& levels, const ClockSummary* clock);

/// An anatomical frame: definition, origin, axes (ISB: x anterior, y superior, z right), landmarks
/// with their source ("found" on the mesh, "given", or "fitted": a sphere's centre) and, for a given one, the file it
/// was given in (`landmarks_file`, when not empty), and its quality (mm) under `quality_name` (null with a
/// `quality_name`_reason beside it when not finite); in the input frame by `to_input` (3 x 3, working -> input).
nlohmann::json frame_record(const AnatomicalFrame& frame, const Eigen::Matrix3d& to_input, const char* quality_name,
                           const std::string& landmarks_file = "");

/// The acetabulum: sphere, rim, opening, radiographic inclination and anteversion
/// (radiographic_orientation), clock axes and coverage; in the input frame by `to_input`.
nlohmann::json acetabulum_record(const Acetabulum& acetabulum, const AnatomicalFrame& pelvis, Side side,
                                 const Eigen::Matrix3d& to_input);

/// What each bone's mesh held and what was done on reading (mesh_hygiene.hpp), for summary.json's "meshes":
/// {"femur": {...}, "pelvis": {...}, "rule": ...}: parts read and kept, fragments removed (area mm^2, size mm,
/// distance mm, centre in the input frame, mm), double-wall faces removed, corners welded, boundary edges, holes
/// (boundary loops), non-manifold edges, and `vertices_removed` (indices into the file, ascending: the per-vertex
/// outputs hold the file's other vertices in order).
nlohmann::json meshes_record(const MeshHygiene& femur, const MeshHygiene& pelvis);

/// What every command reports about its set-up (summary.json's common part): inputs, side and
/// input frame, COR and how it was found, scheme and resolution, map settings, neutral, warnings,
/// the scan-pose overlap, and with anatomical neutral the frames, the scan pose and the acetabulum.
nlohmann::json setup_record(const Session& session);

/// The three centres are named apart: the femoral head centre (Session::head_centre_input, "COR" of --cor), the
/// maps' centre (Session::map_centre_input: the rays' origin) and this pivot: the point (input frame, mm, the pelvis
/// fixed) the femur turns about under the joint-centre method (Puls et al. 2010; joint_centre.hpp): the head centre
/// for femoral-head, the acetabular centre for acetabular and combined (the head seated on it); nullopt for
/// equidistant, whose centre moves with each pose, and when the acetabular centre is unknown (scan neutral).
std::optional<Eigen::Vector3d> pivot_input(const Session& session);

/// The pelvic frame the clinical angles are measured in: "isb" (Wu et al. 2002: ASIS and PSIS), "app" (the
/// anterior pelvic plane of clinical ROM tools: ASIS and pubic tubercles) or "scan" (scan neutral: the input
/// files' axes). rom_limits.csv and summary.json state it.
std::string pelvic_frame_name(const Session& session);

/// Where one scan comes closest to the other bone.
struct ClosestPoint {
  std::int64_t vertex = -1;  ///< the tested vertex with the least gap; -1 when none was tested
  Eigen::Vector3d p_joint = Eigen::Vector3d::Constant(std::nan(""));  ///< it, posed, joint frame, mm
  ContactClass contact_class = ContactClass::none;  ///< HipJoint::contact_class (rim radius + 10 mm)
};
/// The closest point of the femur's scan (`ball`, femur at `pose`, joint frame) or of the pelvis'
/// (`gaps` from the same pose). Never throws.
ClosestPoint closest_point(const Session& session, bool ball, const ScanGaps& gaps, const FemurPose& pose);

/// Both scans at one pose: pose_deg, and ball / socket scan_record()s with clocks (anatomical
/// neutral) and the class of each scan's closest vertex (closest_contact_class).
/// `femur`: the femur's pose at `pose` (HipJoint::femur_pose); its translation is reported as
/// joint_translation_mm (input frame) beside the method (joint_centre).
nlohmann::json pose_record(const Session& session, const PoseAngles& pose, const FemurPose& femur,
                           const PoseResult& result);

}  // namespace impinge
