#include "impinge/session/records.hpp"

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "impinge/core/atomic_file.hpp"
#include "impinge/core/error.hpp"
#include "impinge/clinical/rom.hpp"
#include "impinge/casters/signed_distance.hpp"
#include "impinge/core/spherical_frame.hpp"
#include "impinge/sampling/sampling.hpp"
#include "impinge/schemes/sampling_scheme.hpp"

namespace impinge {

void Table::add(nlohmann::json row) {
  require(row.is_array() && row.size() == columns.size(),
          "table row of " + std::to_string(row.size()) + " cells for " + std::to_string(columns.size()) + " columns");
  rows.push_back(std::move(row));
}

std::vector<nlohmann::json> Table::column(const std::string& name) const {
  std::size_t c = 0;
  while (c < columns.size() && columns[c] != name) ++c;
  require(c < columns.size(), "table: no column '" + name + "'");
  std::vector<nlohmann::json> out;
  out.reserve(rows.size());
  for (const auto& r : rows) out.push_back(r[c]);
  return out;
}

nlohmann::json number_or_null(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }

namespace {

nlohmann::json vec(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

std::string csv_cell(const nlohmann::json& c) {
  if (c.is_null()) return "nan";
  if (c.is_boolean()) return c.get<bool>() ? "1" : "0";
  if (c.is_number_integer() || c.is_number_unsigned()) return c.dump();
  if (c.is_number_float()) {
    std::ostringstream o;
    o.precision(9);
    o << c.get<double>();
    return o.str();
  }
  const std::string s = c.is_string() ? c.get<std::string>() : c.dump();
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string q = "\"";
  for (char ch : s) q += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return q + "\"";
}

}  // namespace

void write_csv(const std::string& path, const Table& t) {
  std::ostringstream os;
  for (std::size_t k = 0; k < t.columns.size(); ++k) os << (k ? "," : "") << t.columns[k];
  os << '\n';
  for (const auto& r : t.rows) {
    for (std::size_t k = 0; k < r.size(); ++k) os << (k ? "," : "") << csv_cell(r[k]);
    os << '\n';
  }
  write_file_atomically(path, os.str());
}

void write_json(const std::string& path, const nlohmann::json& j) {
  write_file_atomically(path, j.dump(2) + "\n");
}

nlohmann::json scan_record(const JointBody& body, const ScanSummary& s, double detection_ms,
                           const ImpingementLevels& levels, const ClockSummary* clock) {
  nlohmann::json j;
  if (clock != nullptr) {
    j["closest_clock_h"] = number_or_null(clock->closest_hour);
    nlohmann::json sectors = nlohmann::json::array();
    for (int k = 0; k < 12; ++k) {
      nlohmann::json row = nlohmann::json::array();
      for (int l = 0; l < levels.count(); ++l)
        row.push_back(clock->sector_level_area_mm2[static_cast<std::size_t>(k * levels.count() + l)]);
      sectors.push_back(row);
    }
    j["clock_sector_level_area_mm2"] = sectors;
    j["clock_sector_note"] = "row k: hours (k, k+1]; column l: impingement level l; vertex area in mm^2";
  }
  j["vertices"] = s.vertices;
  j["vertices_tested"] = s.vertices_tested;
  j["vertices_no_surface"] = s.vertices_no_surface;
  j["vertices_beyond_reach"] = s.vertices_beyond_reach;
  j["vertices_refined"] = s.vertices_refined;
  j["vertices_tested_layered"] = s.vertices_tested_layered;
  j["min_gap_layered_mm"] = number_or_null(s.min_gap_layered_mm);
  j["min_gap_mm"] = number_or_null(s.min_gap_mm);
  if (!body.distance_set.cluster_begin.empty()) {  // distances on (JointOptions::distances; the query alone
                                                   // is built for the layered scan too)
    j["min_distance_mm"] = number_or_null(s.min_distance_mm);
    j["vertices_distance"] = s.vertices_distance;
    j["vertices_inside"] = s.vertices_inside;
    j["area_inside_mm2"] = s.area_inside_mm2;
    j["distance_signs_by_winding_number"] = s.distance_winding;
    j["distance_signs_undecided"] = s.distance_undecided;
  }
  j["vertices_penetrating"] = s.vertices_penetrating;
  j["area_penetrating_mm2"] = s.area_penetrating_mm2;
  nlohmann::json lv = nlohmann::json::array();
  for (int k = 0; k < levels.count(); ++k)
    lv.push_back({{"level", k},
                  {"name", levels.name(k)},
                  {"vertices", s.level_vertices[static_cast<std::size_t>(k)]},
                  {"area_mm2", s.level_area_mm2[static_cast<std::size_t>(k)]}});
  j["levels"] = lv;
  j["map_nodes"] = body.map.num_nodes();
  j["map_nodes_covered"] = body.sampling.nodes_covered;
  j["sampling_method"] = to_string(body.sampling.method);
  if (body.sampling.resample_precision_deg > 0) j["resample_precision_deg"] = body.sampling.resample_precision_deg;
  j["map_bytes"] = body.map.bytes();
  j["map_sparse"] = body.map.sparse();
  j["map_tiles_stored"] = body.map.tiles_stored();
  j["map_tiles_total"] = body.map.tiles_total();
  if (body.layered) {
    j["layers"] = body.layered->layers();
    j["layered_map_bytes"] = body.layered->bytes();
    j["layered_nodes_covered"] = body.layered_sampling.nodes_covered;
    j["layered_nodes_truncated"] = body.layered_sampling.nodes_truncated;
    j["layered_nodes_not_alternating"] = body.layered_sampling.nodes_not_alternating;
    j["layered_max_crossings"] = body.layered_sampling.max_crossings;
    j["layered_sampling_ms"] = body.layered_sampling.sampling_ms;
    j["hidden_vertices"] = body.hidden_set.size();
  }
  j["triangles"] = body.mesh.F.rows();
  j["degenerate_triangles_skipped"] = body.mesh.degenerate_faces_skipped;
  j["triangles_edge_on"] = body.sampling.raster.triangles_edge_on;
  j["pole_triangles"] = body.sampling.raster.pole_triangles;
  j["seam_triangles"] = body.sampling.raster.seam_triangles;
  j["sampling_ms"] = body.sampling_ms;
  j["detection_ms"] = detection_ms;
  return j;
}

nlohmann::json frame_record(const AnatomicalFrame& f, const Eigen::Matrix3d& to_input, const char* quality_name,
                            const std::string& landmarks_file) {
  nlohmann::json j;
  j["definition"] = f.definition;
  j["origin_mm"] = vec(to_input * f.origin);
  j["x_axis"] = vec(to_input * f.axes.col(0));
  j["y_axis"] = vec(to_input * f.axes.col(1));
  j["z_axis"] = vec(to_input * f.axes.col(2));
  nlohmann::json lm = nlohmann::json::object();
  for (const auto& [name, p] : f.landmarks) {
    const std::string source = f.landmark_source.count(name) ? f.landmark_source.at(name) : "found";
    lm[name] = {{"position_mm", vec(to_input * p)}, {"source", source}};
    if (source == "given" && !landmarks_file.empty()) lm[name]["file"] = landmarks_file;
  }
  j["landmarks"] = lm;
  j[quality_name] = number_or_null(f.quality_mm);
  if (!std::isfinite(f.quality_mm))
    j[std::string(quality_name) + "_reason"] =
        f.landmarks.empty()                          ? "no landmarks: the scan axes stand for the frame"
        : std::string(quality_name) == "head_fit_rms_mm" ? "the head centre was given (a COR or landmark hip_centre), "
                                                           "not fitted: no fit residual"
                                                         : "not computed for this frame";
  return j;
}

nlohmann::json acetabulum_record(const Acetabulum& A, const AnatomicalFrame& pelvis, Side side,
                                 const Eigen::Matrix3d& to_input) {
  const AcetabularOrientation o = radiographic_orientation(A, pelvis, side);
  return {{"sphere_centre_mm", vec(to_input * A.sphere.centre)},
          {"sphere_radius_mm", A.sphere.radius},
          {"sphere_fit_rms_mm", A.sphere.rms_residual},
          {"lunate_area_mm2", A.lunate_area_mm2},
          {"lunate_triangles", A.lunate_triangles},
          {"joint_space_mode_mm", A.joint_space_mode_mm},
          {"rim_centre_mm", vec(to_input * A.rim_centre)},
          {"rim_radius_mm", A.rim_radius_mm},
          {"rim_plane_rms_mm", A.rim_plane_rms_mm},
          {"opening", vec(to_input * A.opening)},
          {"radiographic_inclination_deg", o.inclination_deg},
          {"radiographic_anteversion_deg", o.anteversion_deg},
          {"clock_twelve", vec(to_input * A.clock.twelve)},
          {"clock_three", vec(to_input * A.clock.three)},
          {"notch_coverage_deg", A.notch_coverage_deg},
          {"median_coverage_deg", A.median_coverage_deg},
          {"convention", "12 superior, 3 anterior on both sides, 6 at the acetabular notch (Blankenbaker et al. 2007); "
                         "inclination and anteversion radiographic (Murray 1993) in the pelvic frame"}};
}

std::string pelvic_frame_name(const Session& s) {
  if (s.hip().neutral() != Neutral::anatomical) return "scan";
  return to_string(s.hip_options().frames.pelvis);
}

std::optional<Eigen::Vector3d> pivot_input(const Session& s) {
  switch (s.hip().joint_centre().method()) {
    case JointCentreMethod::femoral_head:
      return s.head_centre_input();
    case JointCentreMethod::acetabular:
    case JointCentreMethod::combined:
      if (const auto a = s.acetabular_centre_input()) return Eigen::Vector3d(*a);
      return std::nullopt;
    case JointCentreMethod::equidistant:
      return std::nullopt;
  }
  return std::nullopt;
}

namespace {

// summary.json's centres (input frame, mm): the femoral head centre, the acetabular centre (when found), the maps'
// centre, how the COR was found, the head radius (mm), the joint-centre method and its pivot (null for
// equidistant), and with the equidistant joint centre the guard points closed at neutral.
void add_centres(nlohmann::json& j, const Session& s) {
  const HipJoint& hip = s.hip();
  // Three centres, each with its own name: the femoral head centre (the COR the femur rotates about: given or
  // fitted), the acetabular centre, and the maps' centre (the rays' origin: the head centre, or the acetabular
  // centre when a fitted head was seated before sampling).
  j["head_centre_mm"] = vec(s.head_centre_input());
  if (const auto a = s.acetabular_centre_input()) j["acetabular_centre_mm"] = vec(*a);
  j["map_centre_mm"] = vec(s.map_centre_input());
  j["cor_method"] = s.cor_method();
  j["head_radius_mm"] = number_or_null(s.head().radius);
  j["joint_centre"] = to_string(hip.joint_centre().method());
  // The pivot (input frame, the pelvis fixed): the point the femur turns about under the joint-centre method, the
  // head centre (femoral-head) or the acetabular centre (acetabular; combined, the head seated on it); null for
  // equidistant, whose centre moves with each pose (a pose's joint_translation_mm).
  j["pivot_mm"] = nullptr;
  if (const auto pivot = pivot_input(s)) j["pivot_mm"] = vec(*pivot);
  // The guard points of the lunate surface (JointCentre's guard_points, 0.5 mm apart) the equidistant placement keeps
  // open at every pose because something of the femur closed them at neutral (a head past its sphere, a segmentation overlap): 0 on a clean hip.
  if (hip.joint_centre().method() == JointCentreMethod::equidistant)
    j["equidistant_guarded_at_neutral"] = hip.joint_centre().guarded_at_neutral();
}

// summary.json's maps and distances: the head fit's rms (mm) and points, the scheme, its resolution and largest
// node spacing (deg), the sampling, distance mode, levels (mm), tolerances (mm), layers and query strategy, the
// distance hierarchies, whether distances are on, what the levels classify, the reach (mm) and the nodes marked.
void add_map_settings(nlohmann::json& j, const Session& s) {
  const JointOptions& opt = s.joint_options();
  j["sphere_fit_rms_mm"] = number_or_null(s.head().rms_residual);
  j["sphere_fit_points"] = s.head().points_used;
  j["scheme"] = opt.scheme->name();
  j[opt.scheme->resolution_name()] = opt.scheme->resolution();
  j["max_node_spacing_deg"] = opt.scheme->max_node_spacing() * kRadToDeg;
  j["sampling_method"] = to_string(s.joint().ball().sampling.method);
  j["mode"] = to_string(opt.mode);
  j["levels_thresholds_mm"] = opt.levels.thresholds_mm;
  j["occlusion_tolerance_mm"] = opt.occlusion_tolerance_mm;
  j["exact_at_discontinuities"] = opt.exact_at_discontinuities && s.joint().ball().exact != nullptr;
  j["discontinuity_tolerance_mm"] = opt.discontinuity_tolerance_mm;
  j["layers"] = opt.layers;
  // What was built for the work (SessionOptions::query_strategy): the layered maps, or exact casts for the hidden vertices.
  j["query_strategy"] = opt.layers > 0 && !opt.layered_maps ? "direct" : "maps";
  // The distance hierarchies: over the whole meshes, or cropped to the session's poses (SessionOptions::only_poses),
  // with the searches a whole-mesh hierarchy answered (built at the first of them).
  auto hierarchy = [](const JointBody& b) {
    const SignedDistanceQuery& q = *b.distance_query;
    return nlohmann::json{{"cropped", q.cropped()}, {"triangles", q.triangles()}, {"of", b.mesh.F.rows()},
                          {"whole_mesh_searches", q.cropped_fallbacks()}};
  };
  if (s.joint().ball().distance_query && s.joint().socket().distance_query)
    j["distance_hierarchies"] = {{"femur", hierarchy(s.joint().ball())}, {"pelvis", hierarchy(s.joint().socket())}};
  j["distances"] = opt.distances;
  j["levels_on"] = to_string(opt.level_quantity());
  if (opt.distances) j["distance_reach_mm"] = opt.reach_mm();
  j["nodes_marked"] = {{"femur", s.joint().ball().nodes_marked}, {"pelvis", s.joint().socket().nodes_marked}};
}

// summary.json's frames (the hip's `frames`; input frame, mm): the pelvic and femoral frames (the femur's quality
// the head fit's rms), the scan pose (deg), the frames' time (ms), the acetabulum and the seat.
nlohmann::json frames_record(const Session& s, const HipFrames& frames) {
  const Eigen::Matrix3d to_input = s.to_input();
  const HipJoint& hip = s.hip();
  nlohmann::json f;
  AnatomicalFrame femur = frames.femur;
  femur.quality_mm = s.head().rms_residual;
  // The head centre is the COR: given (the option or subject.json's hip_centre) or fitted (CorResult::method).
  // A COR given as an option is named so (a given landmark's file is subject.json's).
  const std::string& cor = s.cor_method();
  femur.landmark_source["head_centre"] = cor.rfind("given (subject.json", 0) == 0 ? "given"
                                         : cor.rfind("given", 0) == 0             ? "given: the cor option"
                                                                                  : "fitted";
  const std::string& file = s.hip_options().frames.landmarks_file;
  f["pelvis"] = frame_record(frames.pelvis, to_input, "app_out_of_plane_mm", file);
  f["femur"] = frame_record(femur, to_input, "head_fit_rms_mm", file);
  f["scan_pose_deg"] = {{"flexion", frames.scan_pose.flexion_deg},
                        {"adduction", frames.scan_pose.adduction_deg},
                        {"internal_rotation", frames.scan_pose.internal_rotation_deg}};
  f["frames_ms"] = hip.frames_ms();
  f["acetabulum"] = acetabulum_record(*hip.acetabulum(), frames.pelvis, s.side(), to_input);
  // Combined and equidistant joint centres: the head seated on the acetabular centre (then the COR).
  f["seat_mm"] = vec(to_input * hip.seat_mm());
  f["axes_note"] = "axes and positions in the input files' frame; x anterior, y superior, z right (ISB)";
  return f;
}

}  // namespace

nlohmann::json meshes_record(const MeshHygiene& femur, const MeshHygiene& pelvis) {
  auto bone = [](const MeshHygiene& h) {
    nlohmann::json fragments = nlohmann::json::array();
    for (const MeshFragment& f : h.dropped)
      fragments.push_back({{"triangles", f.triangles}, {"area_mm2", f.area_mm2}, {"extent_mm", f.extent_mm},
                           {"distance_mm", number_or_null(f.distance_mm)}, {"centre_mm", vec(f.centre)}});
    return nlohmann::json{{"parts", h.components},
                          {"parts_kept", h.components_kept},
                          {"fragments_removed", fragments},
                          {"double_wall_faces_removed", h.duplicate_faces_removed},
                          {"corners_welded", h.corners_welded},
                          {"boundary_edges", h.boundary_edges},
                          {"holes", h.boundary_loops},
                          {"nonmanifold_edges", h.nonmanifold_edges},
                          {"vertices_removed", h.removed_vertices}};
  };
  return {{"femur", bone(femur)},
          {"pelvis", bone(pelvis)},
          {"rule", "the bone is the largest connected part and every part within " + std::to_string(static_cast<int>(kBoneGapMm)) +
                       " mm of it; smaller parts farther away (under " + std::to_string(static_cast<int>(100 * kFragmentAreaFraction)) +
                       " % of its area) are fragments, removed; repeated faces removed; holes counted, and a distance "
                       "whose sign the mesh cannot decide is flagged (docs: mesh hygiene)"}};
}

nlohmann::json setup_record(const Session& s) {
  const HipJoint& hip = s.hip();
  nlohmann::json j;
  j["impinge_version"] = IMPINGE_VERSION;
  j["femur_file"] = s.ball_source();
  j["pelvis_file"] = s.socket_source();
  j["side"] = s.side() == Side::right ? "right" : "left";
  j["input_frame"] = s.input_frame() == FrameConvention::LPS ? "LPS" : "RAS";
  add_centres(j, s);
  add_map_settings(j, s);
  j["neutral"] = hip.neutral() == Neutral::anatomical ? "anatomical" : "scan";
  j["pelvic_frame"] = pelvic_frame_name(s);
  j["warnings"] = s.warnings();
  j["meshes"] = meshes_record(s.femur_hygiene(), s.pelvis_hygiene());
  j["scan_pose_min_gap_mm"] = number_or_null(s.scan_pose_min_gap_mm());
  j["overlap_at_scan_pose"] = s.scan_pose_min_gap_mm() < 0;
  j["pose_convention"] =
      "ISB joint coordinate system (Wu et al. 2002): flexion about the pelvic Z axis, adduction about the floating "
      "axis, internal rotation about the femoral y axis; flexion, adduction and internal rotation positive; left "
      "hips mirrored";
  // Which frame each kind of value is in (issue 81): the pose angles above, every point and axis here.
  j["coordinates_note"] =
      "points (*_mm: centres, contacts, translations) and axes in the input files' frame (input_frame), mm; pose and "
      "limit angles in the pelvic frame named by pelvic_frame (pose_convention); the head centre fitted or given as "
      "cor_method says";
  if (const auto& frames = hip.frames()) j["frames"] = frames_record(s, *frames);
  return j;
}

ClosestPoint closest_point(const Session& s, bool ball, const ScanGaps& gaps, const FemurPose& pose) {
  ClosestPoint c;
  float best = std::numeric_limits<float>::infinity();
  for (std::size_t i = 0; i < gaps.gap_mm.size(); ++i)
    if (gaps.gap_mm[i] < best) best = gaps.gap_mm[i], c.vertex = static_cast<std::int64_t>(i);
  if (c.vertex < 0) return c;
  const JointBody& body = ball ? s.joint().ball() : s.joint().socket();
  const Eigen::Vector3d v = body.relative.row(static_cast<Eigen::Index>(c.vertex)).transpose();
  c.p_joint = ball ? Eigen::Vector3d(pose.R * v + pose.t) : v;
  c.contact_class = s.hip().contact_class(ball, c.vertex, pose, kIntraArticularMarginMm);
  return c;
}

nlohmann::json pose_record(const Session& s, const PoseAngles& pose, const FemurPose& femur, const PoseResult& res) {
  nlohmann::json j;
  j["pose_deg"] = {pose.flexion_deg, pose.adduction_deg, pose.internal_rotation_deg};
  j["joint_centre"] = to_string(s.hip().joint_centre().method());
  j["joint_translation_mm"] = vec(s.to_input(s.hip().femur_translation(femur.t)));
  j["pose_names"] = {"flexion", "adduction", "internal_rotation"};
  ClockSummary ball_clock, socket_clock;
  s.hip().clocks(res, ball_clock, socket_clock);
  const bool clocks = s.hip().socket_clock().has_value();
  const ImpingementLevels& levels = s.joint_options().levels;
  j["femur"] = scan_record(s.joint().ball(), res.ball, res.ball_detection_ms, levels, clocks ? &ball_clock : nullptr);
  j["pelvis"] =
      scan_record(s.joint().socket(), res.socket, res.socket_detection_ms, levels, clocks ? &socket_clock : nullptr);
  if (s.joint_options().distances) {
    j["femur"]["distance_ms"] = res.ball_distance_ms;
    j["pelvis"]["distance_ms"] = res.socket_distance_ms;
  }
  // Where each scan comes closest, classed (articular, intra- or extra-articular impingement).
  for (const bool ball : {true, false})
    j[ball ? "femur" : "pelvis"]["closest_contact_class"] =
        to_string(closest_point(s, ball, ball ? res.ball_gaps : res.socket_gaps, femur).contact_class);
  return j;
}

}  // namespace impinge
