// impinge command-line interface.
//   impinge distance --ball FEMUR --socket PELVIS [--subject subject.json] [--cor auto|X,Y,Z]
//                    [--precision DEG] [--mode linear|exact] [--pose FLEX,ABD,ROT] --out DIR
//   impinge generate --triangles N --out DIR
// Errors exit non-zero with a one-line message.

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "impinge/error.hpp"
#include "impinge/generated_models.hpp"
#include "impinge/joint.hpp"
#include "impinge/map_image.hpp"
#include "impinge/mesh_io.hpp"
#include "impinge/parse.hpp"
#include "impinge/pose.hpp"
#include "impinge/sampling.hpp"
#include "impinge/sphere_fit.hpp"
#include "impinge/spherical_frame.hpp"
#include "impinge/subject.hpp"

using namespace impinge;
namespace fs = std::filesystem;

namespace {

nlohmann::json scan_json(const JointBody& body, const ScanSummary& s, double detection_ms,
                         const ImpingementLevels& levels) {
  nlohmann::json j;
  j["vertices"] = s.vertices;
  j["vertices_tested"] = s.vertices_tested;
  j["vertices_no_surface"] = s.vertices_no_surface;
  j["vertices_beyond_reach"] = s.vertices_beyond_reach;
  j["min_gap_mm"] = std::isnan(s.min_gap_mm) ? nlohmann::json(nullptr) : nlohmann::json(s.min_gap_mm);
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
  j["triangles"] = body.mesh.F.rows();
  j["degenerate_triangles_skipped"] = body.mesh.degenerate_faces_skipped;
  j["triangles_edge_on"] = body.sampling.raster.triangles_edge_on;
  j["pole_triangles"] = body.sampling.raster.pole_triangles;
  j["seam_triangles"] = body.sampling.raster.seam_triangles;
  j["sampling_ms"] = body.sampling_ms;
  j["detection_ms"] = detection_ms;
  return j;
}

void write_body_ply(const std::string& path, const JointBody& body, const ScanGaps& gaps, const Eigen::Matrix3d& R,
                    const Eigen::Vector3d& cor, const Eigen::Matrix3d& to_input, const ImpingementLevels& levels,
                    bool is_ball) {
  const Eigen::Index n = body.mesh.V.rows();
  Vertices V(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) V.row(i) = (to_input * (cor + R * body.relative.row(i).transpose())).transpose();
  Eigen::VectorXf gap(n);
  Eigen::Matrix<unsigned char, Eigen::Dynamic, 1> level(n);
  Eigen::Matrix<unsigned char, Eigen::Dynamic, 3, Eigen::RowMajor> rgb(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    gap[i] = gaps.gap_mm[k];
    level[i] = std::isnan(gaps.gap_mm[k]) ? 255 : levels.level(gaps.gap_mm[k]);
    const auto c = level_colour(level[i], levels.count(), is_ball);
    rgb.row(i) << c[0], c[1], c[2];
  }
  write_gap_ply(path, V, body.mesh.F, gap, level, rgb);
}

int run_distance(const std::string& ball_path_in, const std::string& socket_path_in, const std::string& subject_path,
                 const std::string& cor_text, const std::string& head_region, const std::string& scheme_name,
                 double resolution, const std::string& sampling_text, const std::string& mode_text,
                 const std::string& pose_text, const std::string& side_text, const std::string& frame_text,
                 const std::string& levels_text, double occlusion_tol, double max_radius, const std::string& out_dir) {
  std::string ball_path = ball_path_in, socket_path = socket_path_in;
  Side side = parse_side(side_text, "--side");
  FrameConvention frame = parse_frame(frame_text, "--frame");
  if (!subject_path.empty()) {
    const SubjectInfo s = load_subject(subject_path);
    side = s.side;
    frame = s.frame;
    if (ball_path.empty()) ball_path = s.femur_path;
    if (socket_path.empty()) socket_path = s.pelvis_path;
  }
  require(!ball_path.empty(), "--ball is required (or --subject)");
  require(!socket_path.empty(), "--socket is required (or --subject)");
  JointOptions opt;
  opt.scheme = make_scheme(scheme_name, resolution);  // validates before the expensive work
  opt.mode = parse_distance_mode(mode_text);
  opt.sampling = parse_sampling_method(sampling_text);
  opt.occlusion_tolerance_mm = occlusion_tol;
  opt.max_radius_mm = max_radius > 0 ? max_radius : std::numeric_limits<double>::infinity();
  if (!levels_text.empty()) opt.levels = parse_levels(levels_text);
  const PoseAngles pose = parse_pose(pose_text);
  const Eigen::Matrix3d R = pose_rotation(pose, side);

  TriangleMesh ball = load_mesh(ball_path), socket = load_mesh(socket_path);
  const Eigen::Matrix3d M = to_anatomical(frame);
  transform_vertices(ball.V, M);
  transform_vertices(socket.V, M);

  SphereFitResult fit;
  std::string cor_method;
  if (!head_region.empty()) {
    const auto v = parse_number_list(head_region, "--head-region", 4);
    fit = fit_sphere_in_region(ball, M * Eigen::Vector3d(v[0], v[1], v[2]), v[3]);
    cor_method = "sphere fit in region";
  } else if (cor_text == "auto") {
    fit = fit_femoral_head(ball);
    cor_method = "automatic sphere fit (RANSAC + geometric)";
  } else {
    const auto v = parse_number_list(cor_text, "--cor", 3);
    fit.centre = M * Eigen::Vector3d(v[0], v[1], v[2]);
    fit.radius = std::numeric_limits<double>::quiet_NaN();
    fit.rms_residual = std::numeric_limits<double>::quiet_NaN();
    cor_method = "given";
  }
  const Joint joint(std::move(ball), std::move(socket), fit.centre, opt);
  const PoseResult res = joint.detect(R);

  fs::create_directories(out_dir);
  const Eigen::Matrix3d to_input = M.transpose();
  write_body_ply((fs::path(out_dir) / "ball_gaps.ply").string(), joint.ball(), res.ball_gaps, R, fit.centre, to_input,
                 opt.levels, true);
  write_body_ply((fs::path(out_dir) / "socket_gaps.ply").string(), joint.socket(), res.socket_gaps,
                 Eigen::Matrix3d::Identity(), fit.centre, to_input, opt.levels, false);
  write_map_png((fs::path(out_dir) / "ball_map.png").string(), joint.ball().map);
  write_map_png((fs::path(out_dir) / "socket_map.png").string(), joint.socket().map);

  auto num_or_null = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
  const Eigen::Vector3d cor_in = to_input * fit.centre;
  nlohmann::json j;
  j["ball_file"] = ball_path;
  j["socket_file"] = socket_path;
  j["side"] = side == Side::right ? "right" : "left";
  j["input_frame"] = frame == FrameConvention::LPS ? "LPS" : "RAS";
  j["cor_mm"] = {cor_in.x(), cor_in.y(), cor_in.z()};
  j["cor_method"] = cor_method;
  j["head_radius_mm"] = num_or_null(fit.radius);
  j["sphere_fit_rms_mm"] = num_or_null(fit.rms_residual);
  j["sphere_fit_points"] = fit.points_used;
  const auto* grid = dynamic_cast<const EquiangularGrid*>(opt.scheme.get());
  j["scheme"] = opt.scheme->name();
  j[opt.scheme->resolution_name()] = opt.scheme->resolution();
  j["precision_deg"] = grid ? nlohmann::json(grid->precision_deg()) : nlohmann::json(nullptr);
  j["max_node_spacing_deg"] = opt.scheme->max_node_spacing() * kRadToDeg;
  j["sampling_method"] = to_string(joint.ball().sampling.method);
  j["mode"] = to_string(opt.mode);
  j["pose_deg"] = {pose.flexion_deg, pose.abduction_deg, pose.rotation_deg};
  j["pose_axes"] = "flexion about medio-lateral, abduction about antero-posterior, rotation about superior-inferior";
  j["levels_thresholds_mm"] = opt.levels.thresholds_mm;
  j["occlusion_tolerance_mm"] = opt.occlusion_tolerance_mm;
  j["ball"] = scan_json(joint.ball(), res.ball, res.ball_detection_ms, opt.levels);
  j["socket"] = scan_json(joint.socket(), res.socket, res.socket_detection_ms, opt.levels);
  std::ofstream os(fs::path(out_dir) / "summary.json");
  require(os.good(), out_dir + "/summary.json: cannot open for writing");
  os << j.dump(2) << "\n";
  std::cout << "ball: " << res.ball.vertices_tested << " tested, min gap " << res.ball.min_gap_mm << " mm, "
            << res.ball.vertices_penetrating << " penetrating; socket: " << res.socket.vertices_tested
            << " tested, min gap " << res.socket.min_gap_mm << " mm, " << res.socket.vertices_penetrating
            << " penetrating; written to " << out_dir << "\n";
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
                      {"true_cor_mm", {h.cor.x(), h.cor.y(), h.cor.z()}},
                      {"head_radius_mm", o.head_radius_mm}};
  std::ofstream os(fs::path(out_dir) / "subject.json");
  require(os.good(), out_dir + "/subject.json: cannot open for writing");
  os << s.dump(2) << "\n";
  std::cout << "generated hip model: " << h.ball.F.rows() << " + " << h.socket.F.rows() << " triangles in " << out_dir
            << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"impinge: impingement detection in ball-and-socket joints by spherical distance maps"};
  app.require_subcommand(1);

  auto* dist = app.add_subcommand("distance", "Per-vertex gap between ball (femur) and socket (pelvis) at one pose");
  std::string ball, socket, subject, cor = "auto", head_region, mode = "exact", pose = "0,0,0", out, side = "right",
                                     frame = "RAS", levels, scheme = "equiangular", sampling = "auto";
  double precision = 0.5, turns = 0, resolution = 0, occlusion_tol = 1.0, max_radius = 0;
  dist->add_option("--ball", ball, "Ball mesh (femur): PLY, STL, OBJ or OFF, mm");
  dist->add_option("--socket", socket, "Socket mesh (pelvis): PLY, STL, OBJ or OFF, mm");
  dist->add_option("--subject", subject,
                   "subject.json giving side and frame (LPS or RAS); supplies --ball/--socket when omitted");
  dist->add_option("--cor", cor,
                   "Centre of rotation: 'auto' (sphere fit of the femoral head) or X,Y,Z in mm in the "
                   "input files' frame")
      ->capture_default_str();
  dist->add_option("--head-region", head_region,
                   "X,Y,Z,R: fit the head sphere to femur vertices within R mm of (X,Y,Z), input frame");
  std::string registered;
  for (const auto& [name, res] : scheme_names())
    registered += (registered.empty() ? "" : ", ") + name + " (" + res + ")";
  dist->add_option("--scheme", scheme, "Sampling scheme of the maps: " + registered)->capture_default_str();
  dist->add_option("--resolution", resolution, "Resolution parameter of the scheme (any scheme)");
  dist->add_option("--precision", precision,
                   "Equiangular precision p in degrees (180/p integral); the resolution "
                   "when neither --resolution nor --turns is given")
      ->capture_default_str();
  dist->add_option("--turns", turns, "Helix turns k (w = k^2 nodes; thesis Table 6: 229, 458, 2292, 4584)");
  dist->add_option("--sampling", sampling, "auto, rasterize, resample or ray-cast (naive, small meshes only)")
      ->capture_default_str();
  dist->add_option("--mode", mode, "Distance mode: 'linear' (thesis Alg. 1) or 'exact' (ray-plane)")
      ->capture_default_str();
  dist->add_option("--pose", pose,
                   "FLEX,ABD,ROT in degrees about the subject's anatomical axes through the COR: flexion about the "
                   "medio-lateral axis (+ = knee forward), abduction about the antero-posterior axis (+ = knee "
                   "outward), rotation about the superior-inferior axis (+ = internal). Applied to the ball as "
                   "R = Rx(flex) Ry(abd) Rz(rot), mirrored for the left side")
      ->capture_default_str();
  dist->add_option("--side", side, "right or left (overridden by --subject)")->capture_default_str();
  dist->add_option("--frame", frame, "Input frame LPS or RAS (overridden by --subject)")->capture_default_str();
  dist->add_option("--levels", levels, "Impingement thresholds in mm, decreasing, e.g. 4,2.667,1.333,0");
  dist->add_option("--occlusion-tolerance", occlusion_tol,
                   "mm: vertices farther than their own first surface plus this are skipped (beyond reach)")
      ->capture_default_str();
  dist->add_option("--max-radius", max_radius, "mm: test only vertices within this distance of the COR (0 = all)")
      ->capture_default_str();
  dist->add_option("--out", out, "Output folder")->required();

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
    if (*dist)
      return run_distance(ball, socket, subject, cor, head_region, scheme,
                          resolution > 0 ? resolution : (turns > 0 ? turns : precision), sampling, mode, pose, side,
                          frame, levels, occlusion_tol, max_radius, out);
    if (*gen) return run_generate(triangles, cam, coverage, gen_out);
  } catch (const std::exception& e) {
    std::cerr << "impinge: error: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
