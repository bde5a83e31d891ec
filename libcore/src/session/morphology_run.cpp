#include "impinge/session/morphology_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "impinge/core/error.hpp"
#include "impinge/io/mesh_io.hpp"
#include "impinge/session/records.hpp"

namespace impinge {

namespace {
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
}
}  // namespace

MorphologyRun run_morphology(const SessionOptions& options, const MorphologyRun* reference) {
  const auto t0 = std::chrono::steady_clock::now();
  LoadedInput in = load_input(options.input);
  MorphologyRun run;
  if (reference)
    run.frames = reference->frames;  // the head sphere and frames before the resection
  else
    find_head_and_frames(options, in, run);
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
// One measure: value, unit, definition, source.
nlohmann::json measure(nlohmann::json value, const char* unit, const char* definition, const char* source) {
  return {{"value", std::move(value)}, {"unit", unit}, {"definition", definition}, {"source", source}};
}
nlohmann::json per_hour(const std::array<double, 12>& v) {
  nlohmann::json j = nlohmann::json::object();
  for (int h = 1; h <= 12; ++h) j[std::to_string(h)] = number_or_null(v[static_cast<std::size_t>(h - 1)]);
  return j;
}

// morphology.json's femur: the head sphere (centre, input frame, and radius, mm; its fit), sphericity (mm), neck
// and shaft axes (unit vectors, input frame), neck-shaft angle and version (deg), alpha angles per head-neck
// clock hour (deg), head-neck offset (mm) and ratio, and the femoral frame.
nlohmann::json femur_measures(const MorphologyRun& run) {
  const Morphology& m = run.morphology;
  const Eigen::Matrix3d& T = run.to_input;
  nlohmann::json f;
  f["head_centre_mm"] = measure(vec(T * m.head_centre_mm), "mm", "centre of the sphere fitted to the femoral head",
                                "geometric sphere fit, thesis sec. 3.4");
  f["head_radius_mm"] = measure(number_or_null(m.head_radius_mm), "mm", "radius of that sphere", "thesis sec. 3.4");
  f["head_fit_rms_mm"] =
      measure(number_or_null(m.head_fit_rms_mm), "mm", "rms distance of the fitted vertices from it", "");
  f["sphericity_rms_mm"] =
      measure(number_or_null(m.sphericity_rms_mm), "mm",
              "rms of |distance from the head centre - radius| over the head's cap (over 100 deg from the neck axis)",
              "impinge");
  f["sphericity_max_mm"] = measure(number_or_null(m.sphericity_max_mm), "mm", "largest of the same", "impinge");
  f["neck_axis"] =
      measure(vec(T * m.neck_axis), "unit vector",
              "through the head centre and the centre of the neck's narrowest cross-section (normal to the axis), "
              "towards the head",
              "Reikeras et al. 1983, Acta Orthop Scand 54:18 (femoral_neck_axis)");
  f["shaft_axis"] =
      measure(vec(T * m.shaft_axis), "unit vector",
              "principal axis of the diaphysis' surface (35-65 % of the head-to-knee length), proximal", "impinge");
  f["neck_shaft_angle_deg"] =
      measure(number_or_null(m.neck_shaft_angle_deg), "deg",
              "between the neck axis and the shaft axis pointing distal (normal 125-135)", "impinge (3D)");
  f["version_posterior_condylar_deg"] =
      measure(number_or_null(m.version_posterior_condylar_deg), "deg",
              "neck axis against the posterior condylar axis across the femur's long axis (knee centre to head "
              "centre); + anteversion (normal 10-20)",
              "Murphy et al. 1987, J Bone Joint Surg Am 69:1169");
  f["version_transepicondylar_deg"] =
      measure(number_or_null(m.version_transepicondylar_deg), "deg", "the same against the transepicondylar axis",
              "Reikeras et al. 1983, Acta Orthop Scand 54:18");
  f["alpha_deg_by_hour"] = measure(
      per_hour(m.alpha_deg), "deg",
      "in the plane through the neck axis at each hour of the head-neck clock (12 superior, 3 anterior), the angle "
      "between the neck axis and where the surface first lies past the head radius + max(0.5 mm, 2 x the fit's "
      "rms), coming from the head (normal under 50-55; a cam above)",
      "Noetzli et al. 2002, J Bone Joint Surg Br 84:556, measured radially");
  f["alpha_max_deg"] = measure(number_or_null(m.alpha_max_deg), "deg", "largest alpha angle over the hours", "");
  f["alpha_max_hour"] = measure(number_or_null(m.alpha_max_hour), "h", "the hour of the largest alpha angle", "");
  f["head_neck_offset_mm"] =
      measure(number_or_null(m.head_neck_offset_mm), "mm",
              "at 3 o'clock (anterior): the head radius less the least distance of the neck surface from the neck axis",
              "Eijer et al. 2001, Hip Int 11:37");
  f["head_neck_offset_ratio"] =
      measure(number_or_null(m.head_neck_offset_ratio), "",
              "offset / head diameter (normal over 0.15-0.17; a cam under)", "Eijer et al. 2001");
  f["frame"] = frame_record(run.frames.femur, T, "head_fit_rms_mm");
  return f;
}

// morphology.json's acetabulum: the lunate surface's sphere (centre, input frame, and radius, mm; its fit and
// area), radiographic inclination and anteversion (deg, APP and ISB frames), centre-edge angles (deg), head
// coverage (share, and deg per acetabular clock hour), the rim (input frame, mm) and the pelvic frame.
nlohmann::json acetabulum_measures(const MorphologyRun& run) {
  const Morphology& m = run.morphology;
  const Eigen::Matrix3d& T = run.to_input;
  nlohmann::json a;
  a["centre_mm"] = measure(vec(T * m.acetabular_centre_mm), "mm",
                           "centre of the sphere fitted to the whole lunate surface", "impinge (find_acetabulum)");
  a["radius_mm"] = measure(number_or_null(m.acetabular_radius_mm), "mm", "its radius", "impinge");
  a["fit_rms_mm"] =
      measure(number_or_null(m.acetabular_fit_rms_mm), "mm", "area-weighted rms of the lunate surface about it", "");
  a["lunate_area_mm2"] = measure(number_or_null(m.lunate_area_mm2), "mm^2", "area the sphere is fitted on", "");
  a["radiographic_inclination_deg"] =
      measure(number_or_null(m.orientation_app.inclination_deg), "deg",
              "radiographic inclination of the rim plane's normal in the anterior pelvic plane (normal 40-50)",
              "Murray 1993, J Bone Joint Surg Br 75:228");
  a["radiographic_anteversion_deg"] =
      measure(number_or_null(m.orientation_app.anteversion_deg), "deg",
              "radiographic anteversion of the same (normal 10-25; retroversion under 0)", "Murray 1993");
  a["radiographic_inclination_isb_deg"] = measure(number_or_null(m.orientation_isb.inclination_deg), "deg",
                                                  "the same in the ISB pelvic frame", "Murray 1993; Wu et al. 2002");
  a["radiographic_anteversion_isb_deg"] = measure(number_or_null(m.orientation_isb.anteversion_deg), "deg",
                                                  "the same in the ISB pelvic frame", "Murray 1993; Wu et al. 2002");
  a["lateral_centre_edge_deg"] =
      measure(number_or_null(m.lateral_centre_edge_deg), "deg",
              "in the coronal plane (anterior pelvic plane frame) through the head centre, from the superior axis to "
              "the edge of the acetabular roof (where rays from the head centre, swept laterally, first meet no "
              "bone within the head radius + 10 mm; the median over planes -4 to 4 mm), + lateral (normal 25-39; "
              "dysplasia under 20)",
              "Wiberg 1939");
  a["anterior_centre_edge_deg"] =
      measure(number_or_null(m.anterior_centre_edge_deg), "deg",
              "the same in the sagittal plane, + anterior (normal over 20-25)", "Lequesne and de Seze 1961");
  a["head_coverage"] = measure(number_or_null(m.head_coverage), "share",
                               "share of the head sphere's surface inside the rim, seen from the head centre "
                               "(0.5: a hemisphere)",
                               "impinge");
  a["coverage_deg_by_hour"] = measure(per_hour(m.coverage_deg), "deg",
                                      "the rim's angle from the acetabular pole per acetabular clock hour (12 "
                                      "superior, 3 anterior, 6 at the notch)",
                                      "Blankenbaker et al. 2007 (clock)");
  nlohmann::json rim = nlohmann::json::array();
  for (const Eigen::Vector3d& p : run.acetabulum.rim) rim.push_back(vec(T * p));
  a["rim_mm"] = measure(rim, "mm",
                        "the acetabular rim: per 5 deg of azimuth about the cup's axis, the cup's point "
                        "farthest from its pole",
                        "impinge (find_acetabulum)");
  a["pelvic_frame"] = frame_record(run.frames.pelvis, T, "app_out_of_plane_mm");
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
