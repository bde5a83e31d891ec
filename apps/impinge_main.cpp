// impinge command-line interface.
//   impinge distance --subject S.json | --ball FEMUR --socket PELVIS  [map, frame options] --pose FLEX,ADD,IR --out DIR
//   impinge motion   --subject S.json --motion FILE(.csv|.mot|.sto)   [map, frame options] --out DIR
//   impinge generate --triangles N --out DIR
// Options bind to the structs below; errors exit 2 with a one-line message.

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "impinge/anatomy/clock_face.hpp"
#include "impinge/anatomy/hip_frames.hpp"
#include "impinge/anatomy/pose.hpp"
#include "impinge/anatomy/sphere_fit.hpp"
#include "impinge/clinical/hip_joint.hpp"
#include "impinge/clinical/rom.hpp"
#include "impinge/core/error.hpp"
#include "impinge/core/parse.hpp"
#include "impinge/core/spherical_frame.hpp"
#include "impinge/core/timing.hpp"
#include "impinge/detection/joint.hpp"
#include "impinge/io/generated_models.hpp"
#include "impinge/io/mesh_io.hpp"
#include "impinge/io/motion.hpp"
#include "impinge/io/subject.hpp"
#include "impinge/io/vtk_output.hpp"
#include "impinge/maps/map_image.hpp"
#include "impinge/sampling/sampling.hpp"

using namespace impinge;
namespace fs = std::filesystem;

namespace {


// ---- options -------------------------------------------------------------------------------

struct InputOptions {
  std::string ball, socket, subject, side = "right", frame = "RAS", cor = "auto", head_region;
  bool allow_any_cor = false;
};
struct MapOptions {
  std::string scheme = "equiangular", sampling = "auto", mode = "exact", levels;
  double resolution = 0, precision = 0, turns = 0, spacing = 0, occlusion_tolerance = 1.0, max_radius = 0,
         sparse_region = 0;
  double discontinuity_tolerance = 0.05;  // mm
  bool maps_only = false;                 // no exact look-ups at depth discontinuities
  int layers = 0;                         // layered maps (extra-articular), 0 = off
  double extra_articular_radius = 150;    // mm
};
struct FrameOptions {
  std::string neutral;  // empty: subject.json's "neutral", else anatomical
  bool reseat = false;
  std::string pelvis_frame = "isb", femur_frame = "epicondyles";
};

void add_input_options(CLI::App* app, InputOptions& o) {
  app->add_option("--subject", o.subject,
                  "subject.json giving side, frame (LPS or RAS) and optional landmarks; supplies --ball/--socket");
  app->add_option("--ball", o.ball, "Ball mesh (femur): PLY, STL, OBJ or OFF, mm");
  app->add_option("--socket", o.socket, "Socket mesh (pelvis): PLY, STL, OBJ or OFF, mm");
  app->add_option("--side", o.side, "right or left (overridden by --subject)")->capture_default_str();
  app->add_option("--frame", o.frame, "Input frame LPS or RAS (overridden by --subject)")->capture_default_str();
  app->add_option("--cor", o.cor,
                  "Centre of rotation: 'auto' (sphere fit of the femoral head, in any scan orientation) or X,Y,Z "
                  "in mm in the input files' frame")
      ->capture_default_str();
  app->add_flag("--allow-any-cor", o.allow_any_cor,
                "Accept a --cor outside the femoral head (research; otherwise an error naming the COR and the "
                "fitted head centre)");
  app->add_option("--head-region", o.head_region,
                  "X,Y,Z,R: fit the head sphere to femur vertices within R mm of (X,Y,Z), input frame");
}

void add_map_options(CLI::App* app, MapOptions& o) {
  std::string registered;
  for (const auto& [name, res] : scheme_names())
    registered += (registered.empty() ? "" : ", ") + name + " (" + res + ")";
  app->add_option("--scheme", o.scheme, "Sampling scheme of the maps: " + registered)->capture_default_str();
  app->add_option("--resolution", o.resolution,
                  "Resolution of the scheme (its own unit, listed with --scheme); default: the scheme's equivalent "
                  "of 0.5 deg node spacing");
  app->add_option("--precision", o.precision, "Alias of --resolution for equiangular grids: precision p in degrees");
  app->add_option("--turns", o.turns, "Alias of --resolution for the helix: k turns (w = k^2 nodes)");
  app->add_option("--spacing", o.spacing,
                  "Largest node spacing wanted, degrees, for any scheme: the coarsest resolution that reaches it "
                  "(instead of --resolution)");
  app->add_option("--sampling", o.sampling,
                  "auto, rasterize, resample, ray-cast (naive, small meshes only) or ray-cast-bvh (exact node values for any scheme)")
      ->capture_default_str();
  app->add_option("--mode", o.mode, "Distance mode: 'linear' (thesis Alg. 1) or 'exact' (ray-plane)")
      ->capture_default_str();
  app->add_option("--levels", o.levels, "Impingement thresholds in mm, decreasing, e.g. 4,2.667,1.333,0");
  app->add_option("--occlusion-tolerance", o.occlusion_tolerance,
                  "mm: vertices farther than their own first surface plus this are skipped (beyond reach)")
      ->capture_default_str();
  app->add_option("--max-radius", o.max_radius, "mm: test only vertices within this distance of the COR (0 = all)")
      ->capture_default_str();
  app->add_option("--sparse", o.sparse_region,
                  "mm: store both maps sparse, in tiles, keeping only tiles with a surface within this distance of the "
                  "COR ('inf': any surface, the same gaps bit for bit; 0 = dense maps)")
      ->capture_default_str();
  app->add_option("--discontinuity-tolerance", o.discontinuity_tolerance,
                  "mm: look-ups whose stencil may be off by more than this (depth discontinuities: rims, coverage "
                  "edges) are resolved by an exact ray cast")
      ->capture_default_str();
  app->add_option("--layers", o.layers,
                  "N: also a layered map of N crossings per node for each bone, so that vertices hidden behind their "
                  "own bone's nearer surface (trochanters, shaft, ilium) are tested too: extra-articular impingement "
                  "(0 = off, the thesis' single-layer maps)")
      ->capture_default_str();
  app->add_option("--extra-articular-radius", o.extra_articular_radius,
                  "mm: with --layers, test hidden vertices within this distance of the COR")
      ->capture_default_str();
  app->add_flag("--maps-only", o.maps_only,
                "No exact look-ups at depth discontinuities: the maps answer alone (the thesis' algorithm)");
}

void add_frame_options(CLI::App* app, FrameOptions& o) {
  app->add_option("--neutral", o.neutral,
                  "Zero pose: 'anatomical' (the femoral ISB frame parallel to the pelvic one, both found from the "
                  "bones or given as landmarks in subject.json) or 'scan' (the pose in the scanner; angles about "
                  "the input frame's axes: flexion about left-right, adduction about antero-posterior, rotation "
                  "about superior-inferior). Default: subject.json's \"neutral\", else anatomical");
  app->add_option("--pelvis-frame", o.pelvis_frame,
                  "Pelvic axes: 'isb' (Wu et al. 2002: ASIS and PSIS) or 'app' (anterior pelvic plane: ASIS and "
                  "pubic tubercles, as clinical ROM tools)")
      ->capture_default_str();
  app->add_flag("--reseat", o.reseat,
                "Move the femur so that its head centre lies on the acetabular sphere centre (Puls et al. 2010's "
                "equidistant method), for segmentations whose bones overlap at the scan pose; the translation is "
                "reported in summary.json (anatomical neutral only)");
  app->add_option("--femur-frame", o.femur_frame,
                  "Femoral medio-lateral axis: 'epicondyles' (ISB) or 'posterior-condyles' (posterior condylar axis)")
      ->capture_default_str();
}

const char* kPoseHelp =
    "FLEX,ADD,IR in degrees, ISB joint coordinate system (Wu et al. 2002): flexion about the pelvic "
    "medio-lateral axis (+ = knee forward), adduction about the floating axis (+ = knee towards the midline, "
    "negative = abduction), internal rotation about the femoral long axis (+ = front of the thigh turns "
    "inwards); mirrored for the left side so the signs mean the same. Zero is set by --neutral";

// ---- setting up a joint -------------------------------------------------------------------

// Everything one run needs: meshes in the working (RAS) frame, COR, frames, the joint.
struct Setup {
  std::string ball_path, socket_path;
  Side side = Side::right;
  FrameConvention frame = FrameConvention::RAS;
  Eigen::Matrix3d to_working = Eigen::Matrix3d::Identity();  // input frame -> working frame
  HipJointOptions options;
  SphereFitResult fit;
  std::string cor_method;
  std::optional<HipJoint> hip;
  double scan_pose_min_gap_mm = 0;  // least gap of both scans with the bones as scanned (after any re-seating)
  const Joint& joint() const { return hip->joint(); }
  const JointOptions& joint_options() const { return options.joint; }
};

double scheme_resolution(const MapOptions& m) {
  const int given = (m.resolution > 0) + (m.precision > 0) + (m.turns > 0) + (m.spacing > 0);
  require(given <= 1, "give one of --resolution, --precision, --turns and --spacing");
  if (m.spacing > 0) return resolution_for_spacing(m.scheme, m.spacing);
  if (m.resolution > 0) return m.resolution;
  if (m.precision > 0) return m.precision;
  if (m.turns > 0) return m.turns;
  return default_resolution(m.scheme);
}

Setup set_up(const InputOptions& in, const MapOptions& mo, const FrameOptions& fo) {
  Setup s;
  s.ball_path = in.ball;
  s.socket_path = in.socket;
  s.side = parse_side(in.side, "--side");
  s.frame = parse_frame(in.frame, "--frame");
  if (!fo.neutral.empty()) s.options.neutral = parse_neutral(fo.neutral, "--neutral");
  Landmarks given;
  if (!in.subject.empty()) {
    const SubjectInfo info = load_subject(in.subject);
    s.side = info.side;
    s.frame = info.frame;
    if (s.ball_path.empty()) s.ball_path = info.femur_path;
    if (s.socket_path.empty()) s.socket_path = info.pelvis_path;
    given = info.landmarks;
    if (fo.neutral.empty() && !info.neutral.empty()) s.options.neutral = parse_neutral(info.neutral, in.subject);
  }
  require(!s.ball_path.empty(), "--ball is required (or --subject)");
  require(!s.socket_path.empty(), "--socket is required (or --subject)");
  s.options.reseat = fo.reseat;
  s.options.frames.pelvis = parse_pelvis_frame_kind(fo.pelvis_frame, "--pelvis-frame");
  s.options.frames.femur = parse_femur_frame_kind(fo.femur_frame, "--femur-frame");
  // Validate the cheap options before the expensive work.
  JointOptions& jo = s.options.joint;
  jo.scheme = make_scheme(mo.scheme, scheme_resolution(mo));
  jo.mode = parse_distance_mode(mo.mode);
  jo.sampling = parse_sampling_method(mo.sampling);
  jo.occlusion_tolerance_mm = mo.occlusion_tolerance;
  jo.exact_at_discontinuities = !mo.maps_only;
  jo.discontinuity_tolerance_mm = mo.discontinuity_tolerance;
  jo.max_radius_mm = mo.max_radius > 0 ? mo.max_radius : std::numeric_limits<double>::infinity();
  require(!(mo.sparse_region < 0) && !std::isnan(mo.sparse_region),
          "--sparse " + std::to_string(mo.sparse_region) + ": must be a distance in mm >= 0, or inf");
  jo.sparse_maps = mo.sparse_region > 0;
  if (jo.sparse_maps) jo.sparse_region_mm = mo.sparse_region;
  if (!mo.levels.empty()) jo.levels = parse_levels(mo.levels);
  require(mo.layers >= 0 && mo.layers <= LayeredMap::kMaxLayers,
          "--layers " + std::to_string(mo.layers) + ": must be 0 (off) to " + std::to_string(LayeredMap::kMaxLayers));
  require(mo.extra_articular_radius > 0, "--extra-articular-radius must be > 0 mm");
  jo.layers = mo.layers;
  jo.extra_articular_radius_mm = mo.extra_articular_radius;

  TriangleMesh ball = load_mesh(s.ball_path), socket = load_mesh(s.socket_path);
  s.to_working = to_anatomical(s.frame);
  const Eigen::Matrix3d& M = s.to_working;
  transform_vertices(ball.V, M);
  transform_vertices(socket.V, M);
  for (auto& [name, p] : given) p = M * p;

  if (!in.head_region.empty()) {
    const auto v = parse_number_list(in.head_region, "--head-region", 4);
    s.fit = fit_sphere_in_region(ball, M * Eigen::Vector3d(v[0], v[1], v[2]), v[3]);
    s.cor_method = "sphere fit in region";
  } else if (given.count("hip_centre")) {
    s.fit.centre = given.at("hip_centre");
    s.fit.radius = s.fit.rms_residual = std::nan("");
    s.cor_method = "given (subject.json landmark hip_centre)";
  } else if (in.cor == "auto") {
    s.fit = locate_femoral_head(ball);
    s.cor_method = "automatic sphere fit (long axis, RANSAC + geometric)";
  } else {
    const auto v = parse_number_list(in.cor, "--cor", 3);
    s.fit.centre = M * Eigen::Vector3d(v[0], v[1], v[2]);
    s.fit.radius = s.fit.rms_residual = std::nan("");
    s.cor_method = "given";
    if (!in.allow_any_cor) {
      // A given COR must lie in the femoral head: compare with the head the bone itself shows.
      const SphereFitResult head = locate_femoral_head(ball);
      const double d = (s.fit.centre - head.centre).norm();
      if (d > head.radius) {
        const Eigen::Vector3d hc = M.transpose() * head.centre;
        std::ostringstream msg;
        msg << "--cor (" << v[0] << ", " << v[1] << ", " << v[2] << ") mm is " << d
            << " mm from the fitted femoral head centre (" << hc.x() << ", " << hc.y() << ", " << hc.z()
            << ") mm, farther than the head radius " << head.radius
            << " mm: the COR must lie in the head (input frame, mm); --allow-any-cor accepts it";
        throw Error(msg.str());
      }
    }
  }
  s.options.allow_cor_outside_ball = in.allow_any_cor;
  try {
    s.hip.emplace(std::move(ball), std::move(socket), s.side, s.fit, given, s.options);
  } catch (const Error& e) {
    if (s.options.neutral != Neutral::anatomical || fo.reseat) throw;
    throw Error(std::string(e.what()) +
                " [anatomical neutral needs a whole femur and pelvis, or landmarks in subject.json; --neutral scan "
                "uses the scan pose instead]");
  }
  for (const std::string& w : s.hip->warnings()) std::cerr << "impinge: warning: " << w << "\n";
  // Segmentations that overlap as scanned (no rotation in the joint frame is the scan pose).
  const PoseResult scan = s.joint().detect(Eigen::Matrix3d::Identity());
  s.scan_pose_min_gap_mm = std::fmin(scan.ball.min_gap_mm, scan.socket.min_gap_mm);
  if (s.scan_pose_min_gap_mm < 0)
    std::cerr << "impinge: warning: the bones overlap by " << -s.scan_pose_min_gap_mm
              << " mm at the scan pose (a segmentation overlap, not an impingement)"
              << (s.options.reseat ? "" : "; --reseat seats the head on the acetabular centre") << "\n";
  return s;
}

// ---- JSON ---------------------------------------------------------------------------------

nlohmann::json num_or_null(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }
nlohmann::json vec(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

nlohmann::json scan_json(const JointBody& body, const ScanSummary& s, double detection_ms,
                         const ImpingementLevels& levels, const ClockSummary* clock) {
  nlohmann::json j;
  if (clock != nullptr) {
    j["closest_clock_h"] = num_or_null(clock->closest_hour);
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
  j["min_gap_layered_mm"] = num_or_null(s.min_gap_layered_mm);
  j["min_gap_mm"] = num_or_null(s.min_gap_mm);
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

nlohmann::json frame_json(const AnatomicalFrame& f, const Eigen::Matrix3d& to_input, const char* quality_name) {
  nlohmann::json j;
  j["definition"] = f.definition;
  j["origin_mm"] = vec(to_input * f.origin);
  j["x_axis"] = vec(to_input * f.axes.col(0));
  j["y_axis"] = vec(to_input * f.axes.col(1));
  j["z_axis"] = vec(to_input * f.axes.col(2));
  nlohmann::json lm;
  for (const auto& [name, p] : f.landmarks)
    lm[name] = {{"position_mm", vec(to_input * p)}, {"source", f.landmark_source.count(name) ? f.landmark_source.at(name) : "found"}};
  j["landmarks"] = lm;
  j[quality_name] = num_or_null(f.quality_mm);
  return j;
}

// The parts of summary.json every command writes: inputs, COR, maps, frames.
nlohmann::json setup_json(const Setup& s) {
  const Eigen::Matrix3d to_input = s.to_working.transpose();
  const JointOptions& opt = s.joint_options();
  nlohmann::json j;
  j["impinge_version"] = IMPINGE_VERSION;
  j["ball_file"] = s.ball_path;
  j["socket_file"] = s.socket_path;
  j["side"] = s.side == Side::right ? "right" : "left";
  j["input_frame"] = s.frame == FrameConvention::LPS ? "LPS" : "RAS";
  j["cor_mm"] = vec(to_input * s.hip->cor());
  j["cor_method"] = s.cor_method;
  j["head_radius_mm"] = num_or_null(s.fit.radius);
  j["sphere_fit_rms_mm"] = num_or_null(s.fit.rms_residual);
  j["sphere_fit_points"] = s.fit.points_used;
  j["scheme"] = opt.scheme->name();
  j[opt.scheme->resolution_name()] = opt.scheme->resolution();
  j["max_node_spacing_deg"] = opt.scheme->max_node_spacing() * kRadToDeg;
  j["sampling_method"] = to_string(s.joint().ball().sampling.method);
  j["mode"] = to_string(opt.mode);
  j["levels_thresholds_mm"] = opt.levels.thresholds_mm;
  j["occlusion_tolerance_mm"] = opt.occlusion_tolerance_mm;
  j["exact_at_discontinuities"] = opt.exact_at_discontinuities && s.joint().ball().exact != nullptr;
  j["discontinuity_tolerance_mm"] = opt.discontinuity_tolerance_mm;
  j["nodes_marked"] = {{"ball", s.joint().ball().nodes_marked}, {"socket", s.joint().socket().nodes_marked}};
  j["neutral"] = s.options.neutral == Neutral::anatomical ? "anatomical" : "scan";
  j["warnings"] = s.hip->warnings();
  j["scan_pose_min_gap_mm"] = num_or_null(s.scan_pose_min_gap_mm);
  j["overlap_at_scan_pose"] = s.scan_pose_min_gap_mm < 0;
  j["pose_convention"] =
      "ISB joint coordinate system (Wu et al. 2002): flexion about the pelvic Z axis, adduction about the floating "
      "axis, internal rotation about the femoral y axis; flexion, adduction and internal rotation positive; left "
      "hips mirrored";
  if (const auto& frames = s.hip->frames()) {
    nlohmann::json f;
    AnatomicalFrame femur = frames->femur;
    femur.quality_mm = s.fit.rms_residual;
    f["pelvis"] = frame_json(frames->pelvis, to_input, "app_out_of_plane_mm");
    f["femur"] = frame_json(femur, to_input, "head_fit_rms_mm");
    f["scan_pose_deg"] = {{"flexion", frames->scan_pose.flexion_deg},
                          {"adduction", frames->scan_pose.adduction_deg},
                          {"internal_rotation", frames->scan_pose.internal_rotation_deg}};
    f["frames_ms"] = s.hip->frames_ms();
    const Acetabulum& A = *s.hip->acetabulum();
    const Eigen::Vector3d n = frames->pelvis.axes.transpose() * A.opening;
    const double m = s.side == Side::right ? 1.0 : -1.0;
    f["acetabulum"] = {
        {"sphere_centre_mm", vec(to_input * A.sphere.centre)},
        {"sphere_radius_mm", A.sphere.radius},
        {"sphere_fit_rms_mm", A.sphere.rms_residual},
        {"rim_centre_mm", vec(to_input * A.rim_centre)},
        {"rim_radius_mm", A.rim_radius_mm},
        {"rim_plane_rms_mm", A.rim_plane_rms_mm},
        {"opening", vec(to_input * A.opening)},
        {"radiographic_inclination_deg", std::atan2(m * n.z(), -n.y()) * kRadToDeg},
        {"radiographic_anteversion_deg", std::asin(std::clamp(n.x(), -1.0, 1.0)) * kRadToDeg},
        {"clock_twelve", vec(to_input * A.clock.twelve)},
        {"clock_three", vec(to_input * A.clock.three)},
        {"notch_coverage_deg", A.notch_coverage_deg},
        {"median_coverage_deg", A.median_coverage_deg},
        {"convention", "12 superior, 3 anterior on both sides, 6 at the acetabular notch (Blankenbaker et al. 2007); "
                       "inclination and anteversion radiographic (Murray 1993) in the pelvic frame"}};
    f["reseat_translation_mm"] = vec(to_input * s.hip->reseat_translation());
    f["reseat_distance_mm"] = s.hip->reseat_translation().norm();
    f["axes_note"] = "axes and positions in the input files' frame; x anterior, y superior, z right (ISB)";
    j["frames"] = f;
  }
  return j;
}

void write_json(const std::string& path, const nlohmann::json& j) {
  std::ofstream os(path);
  require(os.good(), path + ": cannot open for writing");
  os << j.dump(2) << "\n";
  require(os.good(), path + ": write failed");
}

// ---- meshes out ---------------------------------------------------------------------------

// Femur posed by R (joint frame) or the pelvis, in the input frame.
Vertices femur_input(const Setup& s, const Eigen::Matrix3d& R) {
  return (s.hip->posed_femur(R) * s.to_working).eval();  // rows: v^T M = (M^T v)^T, M^T = input <- working
}
Vertices pelvis_input(const Setup& s) { return (s.hip->pelvis_vertices() * s.to_working).eval(); }

std::vector<std::uint8_t> levels_of(const ScanGaps& g, const ImpingementLevels& levels) {
  std::vector<std::uint8_t> out(g.gap_mm.size());
  for (std::size_t i = 0; i < out.size(); ++i)
    out[i] = std::isnan(g.gap_mm[i]) ? 255 : static_cast<std::uint8_t>(levels.level(g.gap_mm[i]));
  return out;
}

void write_body_ply(const std::string& path, const Setup& s, const JointBody& body, const ScanGaps& gaps,
                    const Vertices& V, bool is_ball) {
  const ImpingementLevels& levels = s.joint_options().levels;
  const Eigen::Index n = body.mesh.V.rows();
  const std::vector<std::uint8_t> lv = levels_of(gaps, levels);
  Eigen::VectorXf gap(n);
  Eigen::Matrix<unsigned char, Eigen::Dynamic, 1> level(n);
  Eigen::Matrix<unsigned char, Eigen::Dynamic, 3, Eigen::RowMajor> rgb(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    gap[i] = gaps.gap_mm[k];
    level[i] = lv[k];
    const auto c = level_colour(level[i], levels.count(), is_ball);
    rgb.row(i) << c[0], c[1], c[2];
  }
  write_gap_ply(path, V, body.mesh.F, gap, level, rgb);
}

// Both bones in one PolyData: the femur posed by R, then the pelvis; arrays gap_mm, level, body.
void write_frame_vtp(const std::string& path, const Setup& s, const PoseResult& res, const Eigen::Matrix3d& R) {
  const JointBody& b = s.joint().ball();
  const JointBody& p = s.joint().socket();
  const Eigen::Index nb = b.mesh.V.rows(), np = p.mesh.V.rows();
  Vertices V(nb + np, 3);
  V.topRows(nb) = femur_input(s, R);
  V.bottomRows(np) = pelvis_input(s);
  Faces F(b.mesh.F.rows() + p.mesh.F.rows(), 3);
  F.topRows(b.mesh.F.rows()) = b.mesh.F;
  F.bottomRows(p.mesh.F.rows()) = p.mesh.F.array() + static_cast<int>(nb);
  PointArray gap{"gap_mm", {}, {}}, level{"level", {}, {}}, body{"body", {}, {}};
  gap.f32 = res.ball_gaps.gap_mm;
  gap.f32.insert(gap.f32.end(), res.socket_gaps.gap_mm.begin(), res.socket_gaps.gap_mm.end());
  level.u8 = levels_of(res.ball_gaps, s.joint_options().levels);
  const auto ls = levels_of(res.socket_gaps, s.joint_options().levels);
  level.u8.insert(level.u8.end(), ls.begin(), ls.end());
  body.u8.assign(static_cast<std::size_t>(nb), 0);
  body.u8.resize(static_cast<std::size_t>(nb + np), 1);
  write_vtp(path, V, F, {gap, level, body});
}

// ---- commands -----------------------------------------------------------------------------

// Shaded renders of an output folder by analysis/render_hip.py (matplotlib; Debian's python3-matplotlib).
void render(const std::string& out_dir) {
  const char* env = std::getenv("IMPINGE_ANALYSIS_DIR");
  const std::string script = std::string(env != nullptr ? env : IMPINGE_ANALYSIS_DIR) + "/render_hip.py";
  require(fs::exists(script), script + ": render script not found (set IMPINGE_ANALYSIS_DIR to impinge's analysis/ folder)");
  auto quote = [](const std::string& x) {
    std::string q = "'";
    for (char c : x) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
  };
  const int rc = std::system(("/usr/bin/python3 " + quote(script) + " " + quote(out_dir)).c_str());
  require(rc == 0, out_dir + ": --render failed (needs /usr/bin/python3 with numpy and matplotlib; "
                             "tools/install-deps installs them)");
}

int run_distance(const InputOptions& in, const MapOptions& mo, const FrameOptions& fo, const std::string& pose_text,
                 bool do_render, const std::string& out_dir) {
  const PoseAngles pose = parse_pose(pose_text);
  const Setup s = set_up(in, mo, fo);
  const Eigen::Matrix3d R = s.hip->femur_rotation(pose);
  const PoseResult res = s.joint().detect(R);

  fs::create_directories(out_dir);
  write_body_ply((fs::path(out_dir) / "ball_gaps.ply").string(), s, s.joint().ball(), res.ball_gaps,
                 femur_input(s, R), true);
  write_body_ply((fs::path(out_dir) / "socket_gaps.ply").string(), s, s.joint().socket(), res.socket_gaps,
                 pelvis_input(s), false);
  write_map_png((fs::path(out_dir) / "ball_map.png").string(), s.joint().ball().map);
  write_map_png((fs::path(out_dir) / "socket_map.png").string(), s.joint().socket().map);

  nlohmann::json j = setup_json(s);
  j["pose_deg"] = {pose.flexion_deg, pose.adduction_deg, pose.internal_rotation_deg};
  j["pose_names"] = {"flexion", "adduction", "internal_rotation"};
  ClockSummary ball_clock, socket_clock;
  s.hip->clocks(res, ball_clock, socket_clock);
  const bool clocks = s.hip->socket_clock().has_value();
  j["ball"] = scan_json(s.joint().ball(), res.ball, res.ball_detection_ms, s.joint_options().levels,
                        clocks ? &ball_clock : nullptr);
  j["socket"] = scan_json(s.joint().socket(), res.socket, res.socket_detection_ms, s.joint_options().levels,
                          clocks ? &socket_clock : nullptr);
  write_json((fs::path(out_dir) / "summary.json").string(), j);
  if (do_render) render(out_dir);
  std::cout << "ball: " << res.ball.vertices_tested << " tested, min gap " << res.ball.min_gap_mm << " mm, "
            << res.ball.vertices_penetrating << " penetrating; socket: " << res.socket.vertices_tested
            << " tested, min gap " << res.socket.min_gap_mm << " mm, " << res.socket.vertices_penetrating
            << " penetrating; written to " << out_dir << "\n";
  return 0;
}

struct MotionOutput {
  int vtp_every = 0;  // 0: automatic (every frame up to 100 frames, else at most 100 files)
  bool quiet = false;
};

int run_motion(const InputOptions& in, const MapOptions& mo, const FrameOptions& fo, const std::string& motion_path,
               const MotionOutput& mout, const std::string& out_dir) {
  const auto t_start = Clock::now();
  require(!in.subject.empty() || (!in.ball.empty() && !in.socket.empty()), "motion: --subject (or --ball and --socket) is required");
  // The motion file is read (and fully checked) before anything is built or written.
  Side side = parse_side(in.side, "--side");
  if (!in.subject.empty()) side = load_subject(in.subject).side;
  const Motion motion = load_motion(motion_path, side);
  require(mout.vtp_every >= 0, "--vtp-every must be >= 0");
  const auto t_setup = Clock::now();
  const Setup s = set_up(in, mo, fo);
  const double setup_ms = ms_since(t_setup);

  fs::create_directories(fs::path(out_dir) / "gaps");
  const std::size_t n = motion.frames();
  const int every = mout.vtp_every > 0 ? mout.vtp_every : static_cast<int>((n + 99) / 100);
  const ImpingementLevels& levels = s.joint_options().levels;
  std::ofstream csv(fs::path(out_dir) / "frames.csv");
  require(csv.good(), out_dir + "/frames.csv: cannot open for writing");
  csv << "frame,time_s,flexion_deg,adduction_deg,internal_rotation_deg,ball_min_gap_mm,socket_min_gap_mm,"
         "penetrating_area_mm2,ball_penetrating_area_mm2";
  for (int k = 0; k < levels.count(); ++k) csv << ",socket_level" << k << "_area_mm2";
  csv << ",socket_closest_clock_h,femur_closest_clock_h,socket_closest_x_mm,socket_closest_y_mm,socket_closest_z_mm,"
         "detection_ms\n";
  ClockSummary ball_clock, socket_clock;
  ball_clock.closest_hour = socket_clock.closest_hour = std::nan("");
  csv << std::setprecision(9);
  std::vector<PvdEntry> pvd;
  const bool bar = !mout.quiet && isatty(fileno(stderr));
  double detect_ms = 0, write_ms = 0;
  const JointBody& socket = s.joint().socket();
  PoseResult res;
  for (std::size_t f = 0; f < n; ++f) {
    const Eigen::Matrix3d R = s.hip->femur_rotation(motion.angles[f]);
    auto t0 = Clock::now();
    s.joint().detect(R, Eigen::Vector3d::Zero(), res);
    const double dms = ms_since(t0);
    detect_ms += dms;
    t0 = Clock::now();
    // Closest socket vertex (in the pelvic frame when anatomical, else the input frame).
    Eigen::Vector3d closest = Eigen::Vector3d::Constant(std::nan(""));
    float best = std::numeric_limits<float>::infinity();
    for (std::size_t i = 0; i < res.socket_gaps.gap_mm.size(); ++i)
      if (res.socket_gaps.gap_mm[i] < best)
        best = res.socket_gaps.gap_mm[i], closest = socket.relative.row(static_cast<Eigen::Index>(i)).transpose();
    if (std::isfinite(best)) {
      closest = s.hip->to_working(closest);
      closest = s.hip->frames() ? s.hip->frames()->pelvis.to_local(closest)
                                : Eigen::Vector3d(s.to_working.transpose() * closest);
    }
    const PoseAngles& a = motion.angles[f];
    csv << f << ',' << motion.time_s[f] << ',' << a.flexion_deg << ',' << a.adduction_deg << ','
        << a.internal_rotation_deg << ',' << res.ball.min_gap_mm << ',' << res.socket.min_gap_mm << ','
        << res.socket.area_penetrating_mm2 << ',' << res.ball.area_penetrating_mm2;
    for (double area : res.socket.level_area_mm2) csv << ',' << area;
    s.hip->clocks(res, ball_clock, socket_clock);
    csv << ',' << socket_clock.closest_hour << ',' << ball_clock.closest_hour;
    csv << ',' << closest.x() << ',' << closest.y() << ',' << closest.z() << ',' << dms << '\n';
    if (f % static_cast<std::size_t>(every) == 0) {
      std::ostringstream name;
      name << "gaps/frame_" << std::setw(6) << std::setfill('0') << f << ".vtp";
      write_frame_vtp((fs::path(out_dir) / name.str()).string(), s, res, R);
      pvd.push_back({motion.time_s[f], name.str()});
    }
    write_ms += ms_since(t0);
    if (bar && (f % 10 == 0 || f + 1 == n)) {
      const int w = 40, done = static_cast<int>(w * (f + 1) / n);
      std::fprintf(stderr, "\r[%s%s] %zu/%zu frames", std::string(static_cast<std::size_t>(done), '#').c_str(),
                   std::string(static_cast<std::size_t>(w - done), ' ').c_str(), f + 1, n);
      if (f + 1 == n) std::fprintf(stderr, "\n");
    }
  }
  require(csv.good(), out_dir + "/frames.csv: write failed");
  write_pvd((fs::path(out_dir) / "gaps.pvd").string(), pvd);
  nlohmann::json j = setup_json(s);
  j["motion_file"] = motion_path;
  j["motion_format"] = motion.format;
  j["motion_frames"] = n;
  j["vtp_every"] = every;
  j["vtp_files"] = pvd.size();
  j["timings_ms"] = {{"setup_total", setup_ms},
                     {"ball_sampling", s.joint().ball().sampling_ms},
                     {"socket_sampling", s.joint().socket().sampling_ms},
                     {"frames", s.hip->frames_ms()},
                     {"detection_total", detect_ms},
                     {"detection_per_frame", n ? detect_ms / static_cast<double>(n) : 0.0},
                     {"output", write_ms},
                     {"total", ms_since(t_start)}};
  write_json((fs::path(out_dir) / "summary.json").string(), j);
  if (!mout.quiet)
    std::cout << "motion: " << n << " frames in " << std::fixed << std::setprecision(1) << ms_since(t_start)
              << " ms (setup " << setup_ms << " ms, detection " << detect_ms << " ms); written to " << out_dir << "\n";
  return 0;
}

struct RomCliOptions {
  double threshold_mm = 0, step_deg = 2, max_deg = 150;
  bool no_map = false;
  bool envelope = false;
  int envelope_coarse = 4;
};

int run_rom(const InputOptions& in, const MapOptions& mo, const FrameOptions& fo, const RomCliOptions& ro,
            const std::string& out_dir) {
  const auto t_start = Clock::now();
  RomOptions o;
  o.threshold_mm = ro.threshold_mm;
  o.step_deg = ro.step_deg;
  o.max_deg = ro.max_deg;
  const Setup s = set_up(in, mo, fo);
  const double setup_ms = ms_since(t_start);
  const HipJoint& hip = *s.hip;
  const Eigen::Matrix3d to_input = s.to_working.transpose();
  // Pre-existing overlap at neutral (a segmentation's) is excluded, not taken for a limit. The
  // baseline's scan and the search bounds it builds count with the limits' time.
  auto t0 = Clock::now();
  const RomBaseline base = rom_baseline(hip, hip.femur_rotation({}), o);
  if (base.excluded_vertices > 0)
    std::cerr << "impinge: warning: " << base.excluded_vertices << " vertices are within " << o.threshold_mm
              << " mm at neutral (overlap before any motion); they are not counted in the limits\n";
  fs::create_directories(out_dir);
  std::ofstream lim(fs::path(out_dir) / "rom_limits.csv");
  require(lim.good(), out_dir + "/rom_limits.csv: cannot open for writing");
  lim << "motion,limit_deg,limited_by,socket_clock_h,femur_clock_h,min_gap_at_limit_mm,monotone,"
         "contact_at_start,"
         "contact_x_mm,contact_y_mm,contact_z_mm,evaluations\n"
      << std::setprecision(9);
  int evaluations = 0;
  std::int64_t looked_up = 0, skipped = 0;
  nlohmann::json limits = nlohmann::json::array();
  const std::vector<StandardMotion> motions = standard_motions();
  const std::vector<RomLimit> found = find_rom_limits(hip, motions, o, base);
  for (std::size_t k = 0; k < motions.size(); ++k) {
    const StandardMotion& m = motions[k];
    const RomLimit& l = found[k];
    evaluations += l.evaluations;
    looked_up += l.vertices_looked_up;
    skipped += l.vertices_skipped;
    const Eigen::Vector3d c = to_input * l.contact_mm;
    lim << m.name << ',' << l.limit_deg << ',' << to_string(l.limited_by) << ',' << l.socket_clock_h << ',' << l.femur_clock_h
        << ',' << l.min_gap_at_limit_mm << ',' << (l.monotone ? 1 : 0) << ','
        << (l.contact_at_start ? 1 : 0) << ','
        << c.x() << ',' << c.y() << ',' << c.z() << ',' << l.evaluations << '\n';
    limits.push_back({{"motion", m.name}, {"limit_deg", num_or_null(l.limit_deg)}, {"limited_by", to_string(l.limited_by)},
                      {"monotone", l.monotone}});
  }
  const double limits_ms = ms_since(t0);
  double map_ms = 0;
  std::size_t map_cells = 0;
  std::int64_t map_evaluations = 0;
  if (!ro.no_map) {
    t0 = Clock::now();
    std::vector<double> flex, add;
    for (int f = 0; f <= 120; f += 5) flex.push_back(f);
    for (int a = -20; a <= 40; a += 5) add.push_back(a);
    const std::vector<RomMapCell> cells = rom_map(hip, flex, add, o, base);
    map_ms = ms_since(t0);
    map_cells = cells.size();
    for (const RomMapCell& c : cells)
      looked_up += c.vertices_looked_up, skipped += c.vertices_skipped, map_evaluations += c.evaluations;
    std::ofstream map(fs::path(out_dir) / "rom_map.csv");
    require(map.good(), out_dir + "/rom_map.csv: cannot open for writing");
    map << "flexion_deg,adduction_deg,max_internal_rotation_deg,status\n" << std::setprecision(9);
    for (const RomMapCell& c : cells)
      map << c.flexion_deg << ',' << c.adduction_deg << ',' << c.max_internal_rotation_deg << ',' << to_string(c.status) << '\n';
  }
  double envelope_ms = 0;
  nlohmann::json envelope_json;
  if (ro.envelope) {
    t0 = Clock::now();
    RomEnvelopeOptions eo;
    eo.coarse_steps = ro.envelope_coarse;
    const RomEnvelope env = rom_envelope(hip, eo, o, base);
    envelope_ms = ms_since(t0);
    // Valid runs of internal rotation per (flexion, adduction): the envelope in a few thousand rows.
    std::ofstream ef(fs::path(out_dir) / "rom_envelope.csv");
    require(ef.good(), out_dir + "/rom_envelope.csv: cannot open for writing");
    ef << "flexion_deg,adduction_deg,internal_rotation_from_deg,internal_rotation_to_deg\n" << std::setprecision(9);
    std::int64_t valid = 0;
    for (std::size_t i = 0; i < env.flexion_deg.size(); ++i)
      for (std::size_t jj = 0; jj < env.adduction_deg.size(); ++jj) {
        const std::size_t nr = env.internal_rotation_deg.size();
        for (std::size_t k = 0; k < nr;) {
          if (!env.at(i, jj, k)) {
            ++k;
            continue;
          }
          std::size_t e = k;
          while (e + 1 < nr && env.at(i, jj, e + 1)) ++e;
          valid += static_cast<std::int64_t>(e - k + 1);
          ef << env.flexion_deg[i] << ',' << env.adduction_deg[jj] << ',' << env.internal_rotation_deg[k] << ','
             << env.internal_rotation_deg[e] << '\n';
          k = e + 1;
        }
      }
    looked_up += env.vertices_looked_up, skipped += env.vertices_skipped;
    envelope_json = {{"poses", env.poses},
                     {"poses_valid", valid},
                     {"poses_scanned", env.poses_evaluated},
                     {"grid", {{"flexion_deg", {eo.flexion_min_deg, eo.flexion_max_deg}},
                               {"adduction_deg", {eo.adduction_min_deg, eo.adduction_max_deg}},
                               {"internal_rotation_deg", {eo.internal_rotation_min_deg, eo.internal_rotation_max_deg}},
                               {"step_deg", eo.step_deg},
                               {"coarse_steps", eo.coarse_steps}}},
                     {"ms", envelope_ms},
                     {"poses_per_second", double(env.poses) / (envelope_ms / 1000)}};
  }
  nlohmann::json j = setup_json(s);
  j["threshold_mm"] = o.threshold_mm;
  j["search"] = {{"step_deg", o.step_deg}, {"max_deg", o.max_deg}, {"tolerance_deg", o.tolerance_deg}};
  if (ro.envelope) j["envelope"] = envelope_json;
  j["neutral_min_gap_mm"] = num_or_null(base.min_gap_mm);
  j["excluded_vertices"] = base.excluded_vertices;
  j["limits"] = limits;
  j["timings_ms"] = {{"setup_total", setup_ms},
                     {"ball_sampling", s.joint().ball().sampling_ms},
                     {"socket_sampling", s.joint().socket().sampling_ms},
                     {"limits", limits_ms},
                     {"rom_map", map_ms},
                     {"envelope", envelope_ms},
                     {"total", ms_since(t_start)}};
  j["rom_map_cells"] = map_cells;
  j["rom_map_evaluations"] = map_evaluations;
  j["limit_evaluations"] = evaluations;
  j["vertices_looked_up"] = looked_up;
  j["vertices_skipped_by_bounds"] = skipped;
  j["share_skipped"] = looked_up + skipped > 0 ? double(skipped) / double(looked_up + skipped) : 0.0;
  write_json((fs::path(out_dir) / "summary.json").string(), j);
  std::cout << "rom: " << standard_motions().size() << " limits in " << std::fixed << std::setprecision(0)
            << limits_ms << " ms, ROM map (" << map_cells << " cells) in " << map_ms << " ms"
            << (ro.envelope ? ", envelope in " + std::to_string(std::lround(envelope_ms)) + " ms" : std::string())
            << ", total "
            << ms_since(t_start) << " ms; written to " << out_dir << "\n";
  return 0;
}

int run_generate(int triangles, double cam, double coverage, const std::string& out_dir) {
  HipModelOptions o;
  o.target_triangles = triangles;
  o.cam_height_mm = cam;
  o.cup_coverage_deg = coverage;
  const HipModel h = make_hip_model(o);
  fs::create_directories(out_dir);
  write_ply((fs::path(out_dir) / "femur_r.ply").string(), h.ball);
  write_ply((fs::path(out_dir) / "pelvis.ply").string(), h.socket);
  nlohmann::json s = {{"side", "right"},
                      {"frame", "RAS"},
                      {"units", "mm"},
                      {"femur", "femur_r.ply"},
                      {"pelvis", "pelvis.ply"},
                      {"generated", true},
                      {"neutral", "scan"},
                      {"true_cor_mm", {h.cor.x(), h.cor.y(), h.cor.z()}},
                      {"head_radius_mm", o.head_radius_mm}};
  write_json((fs::path(out_dir) / "subject.json").string(), s);
  std::cout << "generated hip model: " << h.ball.F.rows() << " + " << h.socket.F.rows() << " triangles in " << out_dir
            << " (a proximal femur and a cup: neutral is the scan pose)\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"impinge: impingement detection in ball-and-socket joints by spherical distance maps"};
  app.set_version_flag("--version", std::string("impinge ") + IMPINGE_VERSION);
  app.require_subcommand(1);

  InputOptions in;
  MapOptions maps;
  FrameOptions frames;
  std::string pose = "0,0,0", out;
  auto* dist = app.add_subcommand("distance", "Per-vertex gap between ball (femur) and socket (pelvis) at one pose");
  add_input_options(dist, in);
  add_map_options(dist, maps);
  add_frame_options(dist, frames);
  dist->add_option("--pose", pose, kPoseHelp)->capture_default_str();
  bool do_render = false;
  dist->add_flag("--render", do_render,
                 "Also write shaded renders (render.png: anterior, lateral and the socket's medial view with the "
                 "acetabular clock face) with matplotlib");
  dist->add_option("--out", out, "Output folder")->required();

  std::string motion_file, motion_out;
  MotionOutput mout;
  auto* mot = app.add_subcommand(
      "motion", "Both scans at every frame of a motion (CSV: time_s, flexion_deg, adduction_deg, "
                "internal_rotation_deg; or OpenSim .mot/.sto with hip_flexion_r|l, hip_adduction_r|l, "
                "hip_rotation_r|l); maps built once. Writes frames.csv, gaps.pvd (ParaView) and summary.json");
  add_input_options(mot, in);
  add_map_options(mot, maps);
  add_frame_options(mot, frames);
  mot->add_option("--motion", motion_file, "Motion file: .csv, .mot or .sto")->required();
  mot->add_option("--vtp-every", mout.vtp_every,
                  "Write the posed bones (gaps/frame_N.vtp) every N frames; 0 = every frame up to 100 frames, "
                  "else at most 100 files")
      ->capture_default_str();
  mot->add_flag("--quiet", mout.quiet, "No progress bar or final line");
  mot->add_option("--out", motion_out, "Output folder")->required();

  RomCliOptions rom_opts;
  std::string rom_out;
  auto* rom = app.add_subcommand(
      "rom", "Range-of-motion limits from neutral for the standard motions (rom_limits.csv) and the ROM map: the "
             "largest internal rotation over flexion 0..120 x adduction -20..40 deg, step 5 (rom_map.csv)");
  add_input_options(rom, in);
  add_map_options(rom, maps);
  add_frame_options(rom, frames);
  rom->add_option("--threshold", rom_opts.threshold_mm,
                  "mm: the bones meet when the minimum gap is <= this (0: bone contact; a cartilage offset > 0)")
      ->capture_default_str();
  rom->add_option("--step", rom_opts.step_deg, "Coarse search step, deg (then bisection to 0.1 deg)")
      ->capture_default_str();
  rom->add_option("--max", rom_opts.max_deg, "Search no farther than this from the start, deg")->capture_default_str();
  rom->add_flag("--no-map", rom_opts.no_map, "Limits only, no ROM map");
  rom->add_flag("--envelope", rom_opts.envelope,
                "Also the ROM envelope: every pose of flexion -30..130 x adduction -50..40 x internal rotation -60..60 "
                "deg (1 deg steps) valid or in contact, by adaptive refinement (rom_envelope.csv: the valid runs of "
                "internal rotation)");
  rom->add_option("--envelope-coarse", rom_opts.envelope_coarse,
                  "Steps between the envelope's first poses (1: scan every pose; larger is faster and can miss a "
                  "region of contact smaller than a cell)")
      ->capture_default_str();
  rom->add_option("--out", rom_out, "Output folder")->required();

  auto* gen = app.add_subcommand("generate", "Write a generated hip model (femur_r.ply, pelvis.ply, subject.json)");
  int triangles = 3000;
  double cam = 0, coverage = 100;
  std::string gen_out;
  gen->add_option("--triangles", triangles, "Target triangles per model")->capture_default_str();
  gen->add_option("--cam", cam, "Cam bump height, mm")->capture_default_str();
  gen->add_option("--coverage", coverage, "Cup coverage angle, degrees")->capture_default_str();
  gen->add_option("--out", gen_out, "Output folder")->required();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    if (*dist) return run_distance(in, maps, frames, pose, do_render, out);
    if (*mot) return run_motion(in, maps, frames, motion_file, mout, motion_out);
    if (*rom) return run_rom(in, maps, frames, rom_opts, rom_out);
    if (*gen) return run_generate(triangles, cam, coverage, gen_out);
  } catch (const std::exception& e) {
    std::cerr << "impinge: error: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
