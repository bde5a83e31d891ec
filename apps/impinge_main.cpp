// impinge command-line interface: parse -> call the session layer -> write.
//   impinge distance --subject S.json | --ball FEMUR --socket PELVIS  [map, frame options] --pose FLEX,ADD,IR --out DIR
//   impinge motion   --subject S.json --motion FILE(.csv|.mot|.sto)   [map, frame options] --out DIR
//   impinge rom      --subject S.json [--threshold MM] [--envelope]   [map, frame options] --out DIR
//   impinge generate --triangles N --out DIR
// Options bind to SessionOptions (impinge/session/session.hpp); errors exit 2 with a one-line message.

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "impinge/core/error.hpp"
#include "impinge/core/timing.hpp"
#include "impinge/io/generated_models.hpp"
#include "impinge/io/mesh_io.hpp"
#include "impinge/io/motion.hpp"
#include "impinge/io/vtk_output.hpp"
#include "impinge/maps/map_image.hpp"
#include "impinge/session/outputs.hpp"
#include "impinge/session/records.hpp"
#include "impinge/session/runs.hpp"
#include "impinge/session/session.hpp"

#include "allocator.hpp"

using namespace impinge;
namespace fs = std::filesystem;

namespace {

// summary.json's common part: the session's set-up (setup_record) and the CLI's allocator.
nlohmann::json run_record(const Session& s) {
  nlohmann::json j = setup_record(s);
  j["allocator"] = allocator_description();
  return j;
}

// ---- options -------------------------------------------------------------------------------

// The CLI's text forms of options that SessionOptions holds as numbers (parsed by the session layer).
struct TextOptions {
  std::string cor = "auto", head_region, levels;
};

void add_input_options(CLI::App* app, SessionOptions& s, TextOptions& t) {
  SessionInput& o = s.input;
  app->add_option("--subject", o.subject,
                  "subject.json giving side, frame (LPS or RAS) and optional landmarks; supplies --ball/--socket");
  app->add_option("--ball", o.ball, "Ball mesh (femur): PLY, STL, OBJ or OFF, mm");
  app->add_option("--socket", o.socket, "Socket mesh (pelvis): PLY, STL, OBJ or OFF, mm");
  app->add_option("--side", o.side, "right or left (default: the subject's, else right; contradicting it is an error)");
  app->add_option("--frame", o.frame,
                  "Input frame LPS or RAS (default: the subject's, else RAS; contradicting it is an error)");
  app->add_option("--cor", t.cor,
                  "Centre of rotation: 'auto' (sphere fit of the femoral head, in any scan orientation) or X,Y,Z "
                  "in mm in the input files' frame")
      ->capture_default_str();
  app->add_flag("--allow-any-cor", s.cor.allow_any,
                "Accept a --cor outside the femoral head (research; otherwise an error naming the COR and the "
                "fitted head centre)");
  app->add_option("--head-region", t.head_region,
                  "X,Y,Z,R: fit the head sphere to femur vertices within R mm of (X,Y,Z), input frame");
}

void add_map_options(CLI::App* app, MapSettings& o, TextOptions& t) {
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
  app->add_option("--levels", t.levels, "Impingement thresholds in mm, decreasing, e.g. 4,2.667,1.333,0");
  app->add_option("--occlusion-tolerance", o.occlusion_tolerance_mm,
                  "mm: vertices farther than their own first surface plus this are skipped (beyond reach)")
      ->capture_default_str();
  app->add_option("--max-radius", o.max_radius_mm, "mm: test only vertices within this distance of the COR (0 = all)")
      ->capture_default_str();
  app->add_option("--sparse", o.sparse_mm,
                  "mm: store both maps sparse, in tiles, keeping only tiles with a surface within this distance of the "
                  "COR ('inf': any surface, the same gaps bit for bit; 0 = dense maps)")
      ->capture_default_str();
  app->add_option("--discontinuity-tolerance", o.discontinuity_tolerance_mm,
                  "mm: look-ups whose stencil may be off by more than this (depth discontinuities: rims, coverage "
                  "edges) are resolved by an exact ray cast")
      ->capture_default_str();
  app->add_option("--layers", o.layers,
                  "N: also a layered map of N crossings per node for each bone, so that vertices hidden behind their "
                  "own bone's nearer surface (trochanters, shaft, ilium) are tested too: extra-articular impingement "
                  "(0 = off, the thesis' single-layer maps)")
      ->capture_default_str();
  app->add_option("--layered-spacing", o.layered_spacing_deg,
                  "deg: the layered maps' largest node spacing (the scheme at the coarsest resolution reaching it, "
                  "never finer than the maps'; 0: the maps' own); their edges are exact ray casts")
      ->capture_default_str();
  app->add_option("--extra-articular-radius", o.extra_articular_radius_mm,
                  "mm: with --layers, test hidden vertices within this distance of the COR")
      ->capture_default_str();
  app->add_option("--distances", o.distances,
                  "on|off: beside each radial gap, the signed Euclidean distance to the other bone's surface (what "
                  "3D Slicer, VTK, Open3D and libigl report; negative inside it), exact, for every vertex (hidden "
                  "ones too) within --distance-reach of the other bone")
      ->capture_default_str();
  app->add_option("--levels-on", o.levels_on,
                  "distance|radial: what the impingement levels (colours, level areas, clock sectors) classify: the "
                  "Euclidean distance or the thesis' radial gap (default: the distance, or the radial gap with "
                  "--distances off)");
  app->add_option("--distance-reach", o.distance_reach_mm,
                  "mm: vertices proven farther than this from the other bone get no distance (0: the largest "
                  "--levels threshold)")
      ->capture_default_str();
  app->add_flag("--maps-only", o.maps_only,
                "No exact look-ups at depth discontinuities: the maps answer alone (the thesis' algorithm)");
}

void add_frame_options(CLI::App* app, FrameSettings& o) {
  app->add_option("--neutral", o.neutral,
                  "Zero pose: 'anatomical' (the femoral ISB frame parallel to the pelvic one, both found from the "
                  "bones or given as landmarks in subject.json) or 'scan' (the pose in the scanner; angles about "
                  "the input frame's axes: flexion about left-right, adduction about antero-posterior, rotation "
                  "about superior-inferior). Default: subject.json's \"neutral\", else anatomical");
  app->add_option("--pelvis-frame", o.pelvis_frame,
                  "Pelvic axes: 'isb' (Wu et al. 2002: ASIS and PSIS) or 'app' (anterior pelvic plane: ASIS and "
                  "pubic tubercles, as clinical ROM tools)")
      ->capture_default_str();
  app->add_option("--joint-centre", o.joint_centre,
                  "How the femur moves at each pose (Puls et al. 2010, Comput Aided Surg 15:75): 'femoral-head' "
                  "(rotation about the head centre: the thesis' method), 'acetabular' (about the acetabular "
                  "centre), 'combined' (the head centre placed on the acetabular centre) or 'equidistant' (at each "
                  "pose the femur is also translated so that the joint space over the lunate surface is as even as "
                  "possible). The translation is reported per pose and limit. Default: equidistant with anatomical "
                  "neutral, femoral-head with --neutral scan (which allows no other)")
      ->check(CLI::IsMember({"femoral-head", "acetabular", "combined", "equidistant"}));
  app->add_option("--femur-frame", o.femur_frame,
                  "Femoral medio-lateral axis: 'epicondyles' (ISB) or 'posterior-condyles' (posterior condylar axis)")
      ->capture_default_str();
}

const char* kPoseHelp =
    "FLEX,ADD,IR in degrees, ISB joint coordinate system (Wu et al. 2002): flexion about the pelvic "
    "medio-lateral axis (+ = knee forward), adduction about the floating axis (+ = knee towards the midline, "
    "negative = abduction), internal rotation about the femoral long axis (+ = front of the thigh turns "
    "inwards); mirrored for the left side so the signs mean the same. Zero is set by --neutral";

// ---- set-up and output --------------------------------------------------------------------

// The session of a command: the text options parsed, the joint built, its warnings printed.
Session open_session(SessionOptions s, const TextOptions& t) {
  s.cor.given = parse_cor(t.cor, "--cor");
  if (!t.head_region.empty()) s.cor.head_region = parse_head_region(t.head_region, "--head-region");
  if (!t.levels.empty()) s.maps.levels = parse_levels(t.levels).thresholds_mm;
  Session session(s);
  for (const std::string& w : session.warnings()) std::cerr << "impinge: warning: " << w << "\n";
  return session;
}

std::string in_dir(const std::string& dir, const std::string& name) { return (fs::path(dir) / name).string(); }

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

void progress_bar(std::size_t done, std::size_t n) {
  const int w = 40, filled = static_cast<int>(w * done / n);
  std::fprintf(stderr, "\r[%s%s] %zu/%zu frames", std::string(static_cast<std::size_t>(filled), '#').c_str(),
               std::string(static_cast<std::size_t>(w - filled), ' ').c_str(), done, n);
  if (done == n) std::fprintf(stderr, "\n");
}

// ---- commands -----------------------------------------------------------------------------

int run_distance(const SessionOptions& so, const TextOptions& t, const std::string& pose_text, bool do_render,
                 const std::string& out) {
  const PoseAngles pose = parse_pose(pose_text);
  const Session s = open_session(so, t);
  const FemurPose femur = s.hip().femur_pose(pose);
  const PoseResult res = s.joint().detect(femur.R, femur.t);
  fs::create_directories(out);
  write_pose_plys(in_dir(out, "ball_gaps.ply"), in_dir(out, "socket_gaps.ply"), s, res, femur);
  write_map_png(in_dir(out, "ball_map.png"), s.joint().ball().map);
  write_map_png(in_dir(out, "socket_map.png"), s.joint().socket().map);
  nlohmann::json j = run_record(s);
  j.update(pose_record(s, pose, femur, res));
  write_json(in_dir(out, "summary.json"), j);
  if (do_render) render(out);
  std::cout << "ball: " << res.ball.vertices_tested << " tested, min gap " << res.ball.min_gap_mm << " mm, "
            << res.ball.vertices_penetrating << " penetrating; socket: " << res.socket.vertices_tested
            << " tested, min gap " << res.socket.min_gap_mm << " mm, " << res.socket.vertices_penetrating
            << " penetrating; written to " << out << "\n";
  return 0;
}

struct MotionOutput {
  std::string file;
  int vtp_every = 0;  // 0: automatic (every frame up to 100 frames, else at most 100 files)
  bool quiet = false;
};

int run_motion(const SessionOptions& so, const TextOptions& t, const MotionOutput& mo, const std::string& out) {
  const auto t_start = Clock::now();
  // The motion file is read (and fully checked) before anything is built or written.
  const Motion motion = load_motion(mo.file, input_side(so.input));
  require(mo.vtp_every >= 0, "--vtp-every must be >= 0");
  const Session s = open_session(so, t);
  const double setup_ms = ms_since(t_start);

  fs::create_directories(fs::path(out) / "gaps");
  const std::size_t n = motion.frames();
  const int every = mo.vtp_every > 0 ? mo.vtp_every : static_cast<int>((n + 99) / 100);
  Table frames;
  frames.columns = motion_columns(s.joint_options().levels);
  std::vector<PvdEntry> pvd;
  const bool bar = !mo.quiet && isatty(fileno(stderr));
  const auto t_loop = Clock::now();
  const double detect_ms = run_motion(s, motion.angles, motion.time_s, [&](const MotionFrame& f) {
    frames.add(motion_row(f));
    if (f.index % static_cast<std::size_t>(every) == 0) {
      std::ostringstream name;
      name << "gaps/frame_" << std::setw(6) << std::setfill('0') << f.index << ".vtp";
      write_pose_vtp(in_dir(out, name.str()), s, *f.result, f.pose);
      pvd.push_back({f.time_s, name.str()});
    }
    if (bar && (f.index % 10 == 0 || f.index + 1 == n)) progress_bar(f.index + 1, n);
  });
  write_csv(in_dir(out, "frames.csv"), frames);
  write_pvd(in_dir(out, "gaps.pvd"), pvd);
  const double write_ms = ms_since(t_loop) - detect_ms;
  nlohmann::json j = run_record(s);
  j["motion_file"] = mo.file;
  j["motion_format"] = motion.format;
  j["motion_frames"] = n;
  j["vtp_every"] = every;
  j["vtp_files"] = pvd.size();
  j["timings_ms"] = {{"setup_total", setup_ms},
                     {"ball_sampling", s.joint().ball().sampling_ms},
                     {"socket_sampling", s.joint().socket().sampling_ms},
                     {"frames", s.hip().frames_ms()},
                     {"detection_total", detect_ms},
                     {"detection_per_frame", n ? detect_ms / static_cast<double>(n) : 0.0},
                     {"output", write_ms},
                     {"total", ms_since(t_start)}};
  write_json(in_dir(out, "summary.json"), j);
  if (!mo.quiet)
    std::cout << "motion: " << n << " frames in " << std::fixed << std::setprecision(1) << ms_since(t_start)
              << " ms (setup " << setup_ms << " ms, detection " << detect_ms << " ms); written to " << out << "\n";
  return 0;
}

int run_rom(const SessionOptions& options, const TextOptions& t, const RomRequest& q, const std::string& out) {
  const auto t_start = Clock::now();
  const Session s = open_session(rom_session_options(options, q.search), t);
  const double setup_ms = ms_since(t_start);
  const RomRun run = run_rom(s, q);
  if (run.baseline.excluded_vertices > 0)
    std::cerr << "impinge: warning: " << run.baseline.excluded_vertices << " vertices are within "
              << q.search.threshold_mm
              << " mm at neutral (overlap before any motion); they are not counted in the limits\n";
  fs::create_directories(out);
  write_csv(in_dir(out, "rom_limits.csv"), rom_limits_table(s, run));
  if (q.map) write_csv(in_dir(out, "rom_map.csv"), rom_map_table(run));
  if (q.envelope) write_csv(in_dir(out, "rom_envelope.csv"), rom_envelope_table(run));
  nlohmann::json j = run_record(s);
  j.update(rom_record(run));
  j["timings_ms"] = {{"setup_total", setup_ms},
                     {"ball_sampling", s.joint().ball().sampling_ms},
                     {"socket_sampling", s.joint().socket().sampling_ms},
                     {"limits", run.limits_ms},
                     {"rom_map", run.map_ms},
                     {"envelope", run.envelope_ms},
                     {"total", ms_since(t_start)}};
  write_json(in_dir(out, "summary.json"), j);
  std::cout << "rom: " << run.limits.size() << " limits in " << std::fixed << std::setprecision(0) << run.limits_ms
            << " ms, ROM map (" << run.map.size() << " cells) in " << run.map_ms << " ms"
            << (q.envelope ? ", envelope in " + std::to_string(std::lround(run.envelope_ms)) + " ms" : std::string())
            << ", total " << ms_since(t_start) << " ms; written to " << out << "\n";
  return 0;
}

int run_generate(const HipModelOptions& o, const std::string& out) {
  const HipModel h = make_hip_model(o);
  fs::create_directories(out);
  write_ply(in_dir(out, "femur_r.ply"), h.ball);
  write_ply(in_dir(out, "pelvis.ply"), h.socket);
  write_json(in_dir(out, "subject.json"), {{"side", "right"},
                                           {"frame", "RAS"},
                                           {"units", "mm"},
                                           {"femur", "femur_r.ply"},
                                           {"pelvis", "pelvis.ply"},
                                           {"generated", true},
                                           {"neutral", "scan"},
                                           {"true_cor_mm", {h.cor.x(), h.cor.y(), h.cor.z()}},
                                           {"head_radius_mm", o.head_radius_mm}});
  std::cout << "generated hip model: " << h.ball.F.rows() << " + " << h.socket.F.rows() << " triangles in " << out
            << " (a proximal femur and a cup: neutral is the scan pose)\n";
  return 0;
}

// The options every joint command shares.
void add_joint_options(CLI::App* cmd, SessionOptions& s, TextOptions& t) {
  add_input_options(cmd, s, t);
  add_map_options(cmd, s.maps, t);
  add_frame_options(cmd, s.frames);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"impinge: impingement detection in ball-and-socket joints by spherical distance maps"};
  app.set_version_flag("--version", std::string("impinge ") + IMPINGE_VERSION);
  app.require_subcommand(1);
  SessionOptions so;
  so.maps.layers = 4;  // the whole bone by default (issue 29): the hidden vertices too, extra-articular
  so.maps.distances = true;  // the Euclidean distance beside the radial gap by default (issue 26)
  TextOptions text;

  std::string pose = "0,0,0", out;
  bool do_render = false;
  auto* dist = app.add_subcommand("distance", "Per-vertex gap between ball (femur) and socket (pelvis) at one pose");
  add_joint_options(dist, so, text);
  dist->add_option("--pose", pose, kPoseHelp)->capture_default_str();
  dist->add_flag("--render", do_render,
                 "Also write shaded renders (render.png: anterior, lateral and the socket's medial view with the "
                 "acetabular clock face) with matplotlib");
  dist->add_option("--out", out, "Output folder")->required();

  MotionOutput mo;
  auto* mot = app.add_subcommand(
      "motion", "Both scans at every frame of a motion (CSV: time_s, flexion_deg, adduction_deg, "
                "internal_rotation_deg; or OpenSim .mot/.sto with hip_flexion_r|l, hip_adduction_r|l, "
                "hip_rotation_r|l); maps built once. Writes frames.csv, gaps.pvd (ParaView) and summary.json");
  add_joint_options(mot, so, text);
  mot->add_option("--motion", mo.file, "Motion file: .csv, .mot or .sto")->required();
  mot->add_option("--vtp-every", mo.vtp_every,
                  "Write the posed bones (gaps/frame_N.vtp) every N frames; 0 = every frame up to 100 frames, "
                  "else at most 100 files")
      ->capture_default_str();
  mot->add_flag("--quiet", mo.quiet, "No progress bar or final line");
  mot->add_option("--out", out, "Output folder")->required();

  RomRequest rq;
  bool no_map = false;
  auto* rom = app.add_subcommand(
      "rom", "Range-of-motion limits from neutral for the standard motions (rom_limits.csv) and the ROM map: the "
             "largest internal rotation over flexion 0..120 x adduction -20..40 deg, step 5 (rom_map.csv)");
  add_joint_options(rom, so, text);
  rom->add_option("--threshold", rq.search.threshold_mm,
                  "mm: the bones meet when the minimum gap is <= this less --contact-depth (0: bone contact; a "
                  "cartilage offset > 0)")
      ->capture_default_str();
  rom->add_option("--contact-depth", rq.search.contact_depth_mm,
                  "mm: a contact must reach this far past the threshold to end a search; a shallower graze is "
                  "within the data's error (map interpolation, an MRI surface's roughness) and the joint's play "
                  "(0: the first touch)")
      ->capture_default_str();
  std::string metric = "distance";
  rom->add_option("--metric", metric,
                  "radial|distance: what --threshold is compared with: the thesis' radial gap (along the ray from the "
                  "COR; the thesis') or the signed Euclidean distance to the other bone (what a depth or a cartilage "
                  "offset means: where the ray runs inside the other bone, the radial gap reads a depth of tens of "
                  "mm for a graze). At or below 0 mm the radial scan screens the distance's (about 1.2x the radial "
                  "search's time); a --threshold above 0 costs a full distance scan per pose (about 10x)")
      ->capture_default_str();
  std::string contacts = "impingement";
  rom->add_option("--contacts", contacts,
                  "Which contacts end a search: 'impingement' (the head-neck junction, neck or trochanters against "
                  "the rim or the pelvis beyond it; the head's joint surface meeting the lunate surface, the joint "
                  "space closing, is left out), 'articular' (only that: where the joint space closes) or 'all' "
                  "(every vertex, the thesis' criterion). Anatomical neutral only (the zones need the acetabulum); "
                  "rom_limits.csv's contact_class says which ended each limit")
      ->capture_default_str();
  rom->add_option("--step", rq.search.step_deg, "Coarse search step, deg (then bisection to 0.1 deg)")
      ->capture_default_str();
  rom->add_option("--max", rq.search.max_deg, "Search no farther than this from the start, deg")->capture_default_str();
  rom->add_flag("--no-map", no_map, "Limits only, no ROM map");
  rom->add_flag("--envelope", rq.envelope,
                "Also the ROM envelope: every pose of flexion -30..130 x adduction -50..40 x internal rotation -60..60 "
                "deg (1 deg steps) valid or in contact, by adaptive refinement (rom_envelope.csv: the valid runs of "
                "internal rotation)");
  rom->add_option("--envelope-coarse", rq.envelope_options.coarse_steps,
                  "Steps between the envelope's first poses (1: scan every pose; larger is faster and can miss a "
                  "region of contact smaller than a cell)")
      ->capture_default_str();
  rom->add_option("--out", out, "Output folder")->required();

  HipModelOptions gen_o;
  gen_o.target_triangles = 3000;
  gen_o.cam_height_mm = 0;
  gen_o.cup_coverage_deg = 100;
  auto* gen = app.add_subcommand("generate", "Write a generated hip model (femur_r.ply, pelvis.ply, subject.json)");
  gen->add_option("--triangles", gen_o.target_triangles, "Target triangles per model")->capture_default_str();
  gen->add_option("--cam", gen_o.cam_height_mm, "Cam bump height, mm")->capture_default_str();
  gen->add_option("--coverage", gen_o.cup_coverage_deg, "Cup coverage angle, degrees")->capture_default_str();
  gen->add_option("--out", out, "Output folder")->required();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    if (*dist) return run_distance(so, text, pose, do_render, out);
    if (*mot) return run_motion(so, text, mo, out);
    rq.map = !no_map;
    rq.search.contacts = parse_rom_contacts(contacts, "--contacts");
    rq.search.metric = parse_rom_metric(metric, "--metric");
    if (*rom) return run_rom(so, text, rq, out);
    if (*gen) return run_generate(gen_o, out);
  } catch (const std::exception& e) {
    std::cerr << "impinge: error: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
