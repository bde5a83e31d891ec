#include "impinge/session/morphology_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <initializer_list>
#include <map>
#include <utility>

#include "impinge/anatomy/pelvis_frame.hpp"
#include "impinge/core/error.hpp"
#include "impinge/io/mesh_io.hpp"
#include "impinge/session/records.hpp"

namespace impinge {

namespace {
// How locate_femoral_head fits the head beside the pelvis (CorResult::method's words).
constexpr const char* kAutomaticHeadFit = "automatic sphere fit (long axis, RANSAC + geometric; the end in the acetabulum)";

// The head sphere in run.frames was fitted (by `method`), not given, though find_hip_frames took it as the given
// hip_centre: the frames say so (source "fitted") and carry the fit's residual; and the file given landmarks came from.
void mark_fitted_head(MorphologyRun& run, const std::string& method, const LoadedInput& in) {
  run.head_method = method;
  run.frames.femur.quality_mm = run.frames.head.rms_residual;
  if (!run.frames.femur_landmarks.source.empty()) {
    run.frames.head_source = "fitted";
    run.frames.femur_landmarks.source["head_centre"] = run.frames.femur.landmark_source["head_centre"] = "fitted";
  }
  run.landmarks_file = in.landmarks.empty() ? "" : in.landmarks_file;
}

/// The head sphere the femur shows (a given COR moves neither the head nor what is measured about it) and both frames
/// (find_hip_frames; scan neutral: the input frame's axes) of the loaded input `in` into `run`.
void find_head_and_frames(const SessionOptions& options, const LoadedInput& in, MorphologyRun& run) {
  const CorResult cor = find_centre_of_rotation(in, options.cor);
  check_side_and_frame(in, cor, options.input);
  SphereFitResult head = cor.head;
  if (!std::isfinite(head.radius)) head = cor.fitted_head ? *cor.fitted_head : located_head(in);
  HipJointOptions hip_options = resolved_hip_options(options, in.neutral);
  hip_options.frames.landmarks_file = in.landmarks_file;
  if (hip_options.neutral.value_or(Neutral::anatomical) == Neutral::anatomical) {
    Landmarks given = in.landmarks;
    given["hip_centre"] = head.centre;
    run.frames = find_hip_frames(in.femur, in.pelvis, in.side, given, hip_options.frames);
  } else {
    // Scan neutral (a generated hip, a proximal femur in a cup): the input frame's axes stand for both frames,
    // and there are no landmarks (no version, neck-shaft angle or anterior pelvic plane).
    for (AnatomicalFrame* f : {&run.frames.pelvis, &run.frames.femur}) {
      f->origin = head.centre;
      f->axes = scan_axes();
      f->definition = "scan neutral: the input frame's axes (X anterior, Y superior, Z right)";
    }
  }
  run.frames.head = head;
  mark_fitted_head(run, std::isfinite(cor.head.radius) ? cor.method : kAutomaticHeadFit, in);
}
}  // namespace

MorphologyRun run_morphology(const SessionOptions& options, const MorphologyRun* reference) {
  const auto t0 = std::chrono::steady_clock::now();
  LoadedInput in = load_input(options.input);
  MorphologyRun run;
  if (reference) {  // the head sphere and frames before the resection, and where they came from
    run.frames = reference->frames;
    run.head_method = reference->head_method;
    run.landmarks_file = reference->landmarks_file;
  } else {
    find_head_and_frames(options, in, run);
  }
  const SphereFitResult& head = run.frames.head;
  run.acetabulum = find_acetabulum(in.pelvis, head.centre, head.radius, run.frames.pelvis);
  run.morphology = measure_morphology(in.femur, in.pelvis, in.side, run.frames, run.acetabulum,
                                      reference ? &reference->morphology.head_neck_clock : nullptr);
  run.side = in.side;
  run.to_input = in.to_working.transpose();
  run.input_frame = in.frame;
  run.femur_source = in.femur_source;
  run.pelvis_source = in.pelvis_source;
  run.subject = in.name;
  run.warnings = in.warnings;
  run.meshes = meshes_record(in.femur_hygiene, in.pelvis_hygiene);
  run.femur = std::move(in.femur);
  run.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return run;
}

namespace {
// A point or axis; NaN entries (a measure not taken) as null.
nlohmann::json vec(const Eigen::Vector3d& v) {
  return {number_or_null(v.x()), number_or_null(v.y()), number_or_null(v.z())};
}
// One measure: value, unit, definition, source (the method's reference), the frame its angles, points or axes are in
// (`frame`), and where the value came from (`obtained`: fitted, measured on the mesh, from landmarks found or given).
nlohmann::json measure(nlohmann::json value, const char* unit, const char* definition, const char* source,
                       const std::string& frame, const std::string& obtained) {
  return {{"value", std::move(value)}, {"unit", unit},   {"definition", definition},
          {"source", source},          {"frame", frame}, {"obtained", obtained}};
}
nlohmann::json per_hour(const std::array<double, 12>& v) {
  nlohmann::json j = nlohmann::json::object();
  for (int h = 1; h <= 12; ++h) j[std::to_string(h)] = number_or_null(v[static_cast<std::size_t>(h - 1)]);
  return j;
}

// The frame names of morphology.json's measures.
constexpr const char* kNoFrame = "none: a length, share or count, the same in every frame";
constexpr const char* kBetweenAxes = "none: the angle between two axes in 3D, the same in every frame";
std::string input_frame(const MorphologyRun& run) {
  return std::string("input: the input files' frame (") + (run.input_frame == FrameConvention::LPS ? "LPS" : "RAS") +
         "), mm";
}
// The pelvic frame `kind` as the record names it (the scan axes without landmarks).
std::string pelvic_frame_label(const MorphologyRun& run, PelvisFrameKind kind) {
  if (run.frames.pelvis_landmarks.source.empty()) return "scan: the input frame's axes (no pelvic landmarks)";
  return kind == PelvisFrameKind::anterior_pelvic_plane
             ? "app: the anterior pelvic plane (both ASIS and the pubic tubercles), acetabulum.anterior_pelvic_plane_frame"
             : "isb: the ISB pelvic frame (Wu et al. 2002), acetabulum.isb_pelvic_frame";
}
// Where the landmarks `names` of `source` (per name "found" or "given") came from.
std::string landmark_origin(const std::map<std::string, std::string>& source, std::initializer_list<const char*> names,
                            const std::string& file) {
  if (source.empty()) return "no landmarks (scan neutral)";
  std::string found, given;
  for (const char* name : names) {
    const auto s = source.find(name);
    std::string& list = s != source.end() && s->second == "given" ? given : found;
    list += (list.empty() ? "" : ", ") + std::string(name);
  }
  const std::string in_file = file.empty() ? "given" : "given in " + file;
  if (given.empty()) return "landmarks found on the mesh (" + found + ")";
  if (found.empty()) return "landmarks " + in_file + " (" + given + ")";
  return "landmarks found on the mesh (" + found + ") and " + in_file + " (" + given + ")";
}

// morphology.json's femur head: the sphere (centre, input frame, and radius, mm; its fit) and sphericity (mm).
void femur_head_measures(const MorphologyRun& run, nlohmann::json& f) {
  const Morphology& m = run.morphology;
  const std::string fitted = "fitted: " + run.head_method;
  const std::string about = "measured on the mesh about the fitted sphere";
  f["head_centre_mm"] = measure(vec(run.to_input * m.head_centre_mm), "mm",
                                "centre of the sphere fitted to the femoral head", "geometric sphere fit, thesis sec. 3.4",
                                input_frame(run), fitted);
  f["head_radius_mm"] =
      measure(number_or_null(m.head_radius_mm), "mm", "radius of that sphere", "thesis sec. 3.4", kNoFrame, fitted);
  f["head_fit_rms_mm"] = measure(number_or_null(m.head_fit_rms_mm), "mm", "weighted rms distance of the head's surface from it (fit_sphere_to_surface: biweight x facing x area)",
                                 "thesis sec. 3.4", kNoFrame, fitted);
  f["sphericity_rms_mm"] =
      measure(number_or_null(m.sphericity_rms_mm), "mm",
              "rms of |distance from the head centre - radius| over the head's cap (over 100 deg from the neck axis)",
              "impinge", kNoFrame, about);
  f["sphericity_max_mm"] =
      measure(number_or_null(m.sphericity_max_mm), "mm", "largest of the same", "impinge", kNoFrame, about);
}

// morphology.json's femoral versions (deg): against the posterior condylar and transepicondylar axes, across the
// mechanical axis and across the shaft axis, each with its method, reference axis and projection plane.
void femur_version_measures(const MorphologyRun& run, nlohmann::json& f) {
  const Morphology& m = run.morphology;
  const auto& src = run.frames.femur_landmarks.source;
  const std::string pc = landmark_origin(src, {"posterior_condyle_lateral", "posterior_condyle_medial"},
                                         run.landmarks_file),
                    te = landmark_origin(src, {"epicondyle_lateral", "epicondyle_medial"}, run.landmarks_file);
  const char* mech = "the mechanical axis (the epicondyles' midpoint to the fitted head centre)";
  const char* shaft = "the shaft axis (femur.shaft_axis, measured on the mesh)";
  const auto version = [&](double value, const char* definition, const char* source, const char* method,
                           const char* axis, const std::string& on, const std::string& from) {
    nlohmann::json j = measure(number_or_null(value), "deg", definition, source,
                               "femoral: the plane normal to " + on + ", + anterior",
                               "neck axis measured on the mesh; condylar axis from " + from + "; projected across " + on);
    j["method"] = method;
    j["reference_axis"] = axis;
    j["projection_plane"] = "normal to " + on;
    return j;
  };
  const char* pcd = "the line through the posterior condyle landmarks (their tangent across the long axis)";
  const char* ted = "the line through the epicondyle landmarks";
  f["version_posterior_condylar_deg"] = version(
      m.version_posterior_condylar_deg,
      "neck axis against the posterior condylar axis, both projected on the plane normal to the femur's mechanical "
      "axis (knee centre to head centre); + anteversion",
      "impinge (3D, the ISB femoral frame's y: Wu et al. 2002); the posterior condylar reference of Murphy et al. "
      "1987, J Bone Joint Surg Am 69:1169",
      "mechanical-axis (3D)", pcd, mech, pc + "; the mechanical axis from " + te);
  f["version_transepicondylar_deg"] =
      version(m.version_transepicondylar_deg, "the same against the transepicondylar axis",
              "impinge (3D, the ISB femoral frame's y: Wu et al. 2002)", "mechanical-axis (3D)", ted, mech, te);
  f["version_posterior_condylar_shaft_deg"] = version(
      m.version_posterior_condylar_shaft_deg,
      "neck axis against the posterior condylar axis, both projected on the plane normal to the femoral shaft (the "
      "axial CT slice); + anteversion (normal 10-20)",
      "Reikeras et al. 1983, Acta Orthop Scand 54:18 (neck axis, axial CT); Murphy et al. 1987, J Bone Joint Surg Am "
      "69:1169 (posterior condylar tangent)",
      "CT axial (shaft-perpendicular)", pcd, shaft, pc);
  f["version_transepicondylar_shaft_deg"] =
      version(m.version_transepicondylar_shaft_deg, "the same against the transepicondylar axis",
              "Reikeras et al. 1983, Acta Orthop Scand 54:18 (axial CT), against the transepicondylar axis",
              "CT axial (shaft-perpendicular)", ted, shaft, te);
}

// morphology.json's femur: the head (femur_head_measures), neck and shaft axes (unit vectors, input frame),
// neck-shaft angle and versions (deg), alpha angles per head-neck clock hour (deg), head-neck offset (mm) and ratio,
// and the femoral frame.
nlohmann::json femur_measures(const MorphologyRun& run) {
  const Morphology& m = run.morphology;
  const Eigen::Matrix3d& T = run.to_input;
  const std::string on_mesh = "measured on the mesh", clock = "the head-neck clock: 12 superior, 3 anterior";
  nlohmann::json f;
  femur_head_measures(run, f);
  f["neck_axis"] =
      measure(vec(T * m.neck_axis), "unit vector",
              "through the head centre and the centre of the neck's narrowest cross-section (normal to the axis), "
              "towards the head",
              "Reikeras et al. 1983, Acta Orthop Scand 54:18 (femoral_neck_axis)", input_frame(run),
              on_mesh + " (sections of the neck about the fitted head centre)");
  f["shaft_axis"] =
      measure(vec(T * m.shaft_axis), "unit vector",
              "principal axis of the diaphysis' surface (35-65 % of the head-to-knee length), proximal", "impinge",
              input_frame(run), on_mesh);
  f["neck_shaft_angle_deg"] =
      measure(number_or_null(m.neck_shaft_angle_deg), "deg",
              "between the neck axis and the shaft axis pointing distal (normal 125-135)", "impinge (3D)",
              kBetweenAxes, on_mesh);
  femur_version_measures(run, f);
  f["alpha_deg_by_hour"] = measure(
      per_hour(m.alpha_deg), "deg",
      "in the plane through the neck axis at each hour of the head-neck clock (12 superior, 3 anterior), the angle "
      "between the neck axis and where the surface first lies past the head radius + max(0.5 mm, 2 x the fit's "
      "rms), coming from the head (normal under 50-55; a cam above)",
      "Noetzli et al. 2002, J Bone Joint Surg Br 84:556, measured radially", clock, on_mesh + " (exact rays)");
  f["alpha_max_deg"] = measure(number_or_null(m.alpha_max_deg), "deg", "largest alpha angle over the hours",
                               "Noetzli et al. 2002", clock, on_mesh);
  f["alpha_max_hour"] =
      measure(number_or_null(m.alpha_max_hour), "h", "the hour of the largest alpha angle", "", clock, on_mesh);
  f["head_neck_offset_mm"] =
      measure(number_or_null(m.head_neck_offset_mm), "mm",
              "at 3 o'clock (anterior): the head radius less the least distance of the neck surface from the neck axis",
              "Eijer et al. 2001, Hip Int 11:37", kNoFrame, on_mesh + " (exact rays)");
  f["head_neck_offset_ratio"] = measure(number_or_null(m.head_neck_offset_ratio), "",
                                        "offset / head diameter (normal over 0.15-0.17; a cam under)",
                                        "Eijer et al. 2001", kNoFrame, on_mesh);
  f["frame"] = frame_record(run.frames.femur, T, "head_fit_rms_mm", run.landmarks_file);
  return f;
}

// morphology.json's acetabulum: the lunate surface's sphere (centre, input frame, and radius, mm; its fit and area).
void acetabular_sphere_measures(const MorphologyRun& run, nlohmann::json& a) {
  const Morphology& m = run.morphology;
  const char* fitted = "fitted: the sphere of the lunate surface (find_acetabulum)";
  a["centre_mm"] = measure(vec(run.to_input * m.acetabular_centre_mm), "mm",
                           "centre of the sphere fitted to the whole lunate surface", "impinge (find_acetabulum)",
                           input_frame(run), fitted);
  a["radius_mm"] = measure(number_or_null(m.acetabular_radius_mm), "mm", "its radius", "impinge", kNoFrame, fitted);
  a["fit_rms_mm"] = measure(number_or_null(m.acetabular_fit_rms_mm), "mm",
                            "weighted rms of the lunate surface about it (fit_sphere_to_surface: biweight x facing x area)", "impinge", kNoFrame, fitted);
  a["lunate_area_mm2"] = measure(number_or_null(m.lunate_area_mm2), "mm^2", "area the sphere is fitted on",
                                 "impinge (find_acetabulum)", kNoFrame, "measured on the mesh");
}

// morphology.json's acetabulum: the sphere (acetabular_sphere_measures), radiographic inclination and anteversion
// (deg, APP and ISB frames), centre-edge angles (deg), head coverage (share, and deg per acetabular clock hour), the
// rim (input frame, mm), the pelvic frame of the session (`pelvic_frame`) and the APP and ISB frames themselves.
nlohmann::json acetabulum_measures(const MorphologyRun& run) {
  const Morphology& m = run.morphology;
  const Eigen::Matrix3d& T = run.to_input;
  const std::string app = pelvic_frame_label(run, PelvisFrameKind::anterior_pelvic_plane),
                    isb = pelvic_frame_label(run, PelvisFrameKind::isb);
  const std::string pelvic = landmark_origin(run.frames.pelvis_landmarks.source,
                                             {"asis_left", "asis_right", "psis_left", "psis_right",
                                              "pubic_tubercle_left", "pubic_tubercle_right"},
                                             run.landmarks_file);
  const std::string rim = "measured on the mesh (the rim plane's normal); the frame from " + pelvic;
  const std::string rays = "measured on the mesh (exact rays from the fitted head centre); the frame from " + pelvic;
  nlohmann::json a;
  acetabular_sphere_measures(run, a);
  a["radiographic_inclination_deg"] =
      measure(number_or_null(m.orientation_app.inclination_deg), "deg",
              "radiographic inclination of the rim plane's normal in the anterior pelvic plane (normal 40-50)",
              "Murray 1993, J Bone Joint Surg Br 75:228", app, rim);
  a["radiographic_anteversion_deg"] =
      measure(number_or_null(m.orientation_app.anteversion_deg), "deg",
              "radiographic anteversion of the same (normal 10-25; retroversion under 0)", "Murray 1993", app, rim);
  a["radiographic_inclination_isb_deg"] = measure(number_or_null(m.orientation_isb.inclination_deg), "deg",
                                                  "the same in the ISB pelvic frame", "Murray 1993; Wu et al. 2002",
                                                  isb, rim);
  a["radiographic_anteversion_isb_deg"] = measure(number_or_null(m.orientation_isb.anteversion_deg), "deg",
                                                  "the same in the ISB pelvic frame", "Murray 1993; Wu et al. 2002",
                                                  isb, rim);
  a["lateral_centre_edge_deg"] =
      measure(number_or_null(m.lateral_centre_edge_deg), "deg",
              "in the coronal plane (anterior pelvic plane frame) through the head centre, from the superior axis to "
              "the edge of the acetabular roof (where rays from the head centre, swept laterally, first meet no "
              "bone within the head radius + 10 mm; the median over planes -4 to 4 mm), + lateral (normal 25-39; "
              "dysplasia under 20)",
              "Wiberg 1939", app, rays);
  a["anterior_centre_edge_deg"] =
      measure(number_or_null(m.anterior_centre_edge_deg), "deg",
              "the same in the sagittal plane, + anterior (normal over 20-25)", "Lequesne and de Seze 1961", app, rays);
  a["head_coverage"] = measure(number_or_null(m.head_coverage), "share",
                               "share of the head sphere's surface inside the rim, seen from the head centre "
                               "(0.5: a hemisphere)",
                               "impinge", kNoFrame, "measured on the mesh (the rim about the fitted head centre)");
  a["coverage_deg_by_hour"] =
      measure(per_hour(m.coverage_deg), "deg",
              "the rim's angle from the acetabular pole per acetabular clock hour (12 superior, 3 anterior, 6 at the "
              "notch)",
              "Blankenbaker et al. 2007 (clock)", "the acetabular clock: 12 superior, 3 anterior, 6 at the notch",
              "measured on the mesh (the rim)");
  nlohmann::json points = nlohmann::json::array();
  for (const Eigen::Vector3d& p : run.acetabulum.rim) points.push_back(vec(T * p));
  a["rim_mm"] = measure(points, "mm",
                        "the acetabular rim: per 5 deg of azimuth about the cup's axis, the cup's point "
                        "farthest from its pole",
                        "impinge (find_acetabulum)", input_frame(run), "measured on the mesh");
  a["pelvic_frame"] = frame_record(run.frames.pelvis, T, "app_out_of_plane_mm", run.landmarks_file);
  a["pelvic_frame"]["role"] =
      "the session's pelvic frame (--pelvis-frame), kept for reference: each angle above names its own frame "
      "(frame: app or isb)";
  // Both pelvic frames from the same landmarks (measure_morphology built them already: they do not throw here).
  for (const auto& [key, kind] : {std::pair{"anterior_pelvic_plane_frame", PelvisFrameKind::anterior_pelvic_plane},
                                  std::pair{"isb_pelvic_frame", PelvisFrameKind::isb}}) {
    const AnatomicalFrame f = run.frames.pelvis_landmarks.source.empty()
                                  ? run.frames.pelvis
                                  : pelvis_frame(run.frames.pelvis_landmarks, run.frames.head.centre, kind);
    a[key] = frame_record(f, T, "app_out_of_plane_mm", run.landmarks_file);
  }
  return a;
}
}  // namespace

nlohmann::json morphology_record(const MorphologyRun& run) {
  const Morphology& m = run.morphology;
  nlohmann::json j;
  j["femur_file"] = run.femur_source;
  j["pelvis_file"] = run.pelvis_source;
  j["side"] = run.side == Side::right ? "right" : "left";
  j["input_frame"] = run.input_frame == FrameConvention::LPS ? "LPS" : "RAS";
  j["axes_note"] =
      "points and axes in the input files' frame, mm; angles in degrees; left hips measured mirrored, "
      "so that both sides read alike";
  j["femur"] = femur_measures(run);
  j["acetabulum"] = acetabulum_measures(run);
  j["notes"] = m.notes;
  j["warnings"] = run.warnings;
  j["meshes"] = run.meshes;
  j["ms"] = run.ms;
  return j;
}

void write_morphology_ply(const std::string& path, const MorphologyRun& run) {
  const auto n = run.femur.V.rows();
  Vertices V = run.femur.V * run.to_input.transpose();
  Eigen::VectorXf dev(n);
  Eigen::Matrix<unsigned char, Eigen::Dynamic, 1> level(n);
  Eigen::Matrix<unsigned char, Eigen::Dynamic, 3, Eigen::RowMajor> rgb(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double d = run.morphology.head_deviation_mm[static_cast<std::size_t>(i)];
    dev[i] = static_cast<float>(d);
    level[i] = 255;
    if (!std::isfinite(d)) {
      rgb.row(i) << 160, 160, 160;
      continue;
    }
    const double s = std::clamp(std::abs(d) / 2.0, 0.0, 1.0);
    const auto fade = static_cast<unsigned char>(std::lround(255 * (1 - s)));
    if (d > 0)
      rgb.row(i) << 255, fade, fade;
    else
      rgb.row(i) << fade, fade, 255;
  }
  write_gap_ply(path, V, run.femur.F, dev, level, rgb);
}

}  // namespace impinge
