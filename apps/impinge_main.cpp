// impinge command-line interface: parse -> call the session layer -> write.
//   impinge distance --subject S.json | --ball FEMUR --socket PELVIS  [map, frame options] --pose FLEX,ADD,IR --out DIR
//   impinge motion   --subject S.json --motion FILE(.csv|.mot|.sto)   [map, frame options] --out DIR
//   impinge rom      --subject S.json [--threshold MM] [--envelope]   [map, frame options] --out DIR
//   impinge generate --triangles N --out DIR
// Options bind to SessionOptions (impinge/session/session.hpp); errors exit 2 with a one-line message.

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <exception>
#include <cstdio>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>

#include "impinge/core/concurrent.hpp"
#include "impinge/core/error.hpp"
#include "impinge/core/timing.hpp"
#include "impinge/io/mesh_io.hpp"
#include "impinge/session/option_table.hpp"
#include "impinge/session/morphology_run.hpp"
#include "impinge/session/plan_run.hpp"
#include "impinge/session/outputs.hpp"
#include "impinge/session/records.hpp"
#include "impinge/session/runs.hpp"
#include "impinge/session/session.hpp"
#include "impinge/session/view.hpp"

#include "allocator.hpp"
#include "vtk_meshes.hpp"

using namespace impinge;
namespace fs = std::filesystem;

namespace {

// summary.json's common part: the session's set-up (setup_record) and the CLI's allocator.
nlohmann::json run_record(const Session& s) {
  nlohmann::json j = setup_record(s);
  j["allocator"] = allocator_description();
  return j;
}

// ---- options: built from the session layer's option table (option_table.hpp) --------------

// The text (or flag) given to each row's option; the same storage for every subcommand (one parses).
struct CliValues {
  std::map<std::string, std::string> text;
  std::map<std::string, bool> flag;
};

// What --help shows as an option's value: its unit, its choices, or its kind.
std::string type_name(const OptionRow& r) {
  if (r.type == OptionType::choice) {
    std::string c;
    for (const std::string& x : r.choices) c += (c.empty() ? "" : "|") + x;
    return c;
  }
  if (r.type == OptionType::on_off) return "on|off";
  if (r.type == OptionType::point) return "auto|X,Y,Z mm";
  if (r.type == OptionType::region) return "X,Y,Z,R mm";
  if (r.type == OptionType::numbers) return r.unit.empty() ? "A,B,..." : "A,B,... " + r.unit;
  if (r.type == OptionType::path || r.type == OptionType::mesh) return "PATH";
  if (r.type == OptionType::integer) return r.unit.empty() ? "INT" : "INT " + r.unit;
  if (r.type == OptionType::number) return r.unit.empty() ? "NUMBER" : "NUMBER " + r.unit;
  return "TEXT";
}

// Every row of the table that `use` (a subcommand) takes, with the clinical preset's default.
void add_table_options(CLI::App* cmd, unsigned use, CliValues& v) {
  const RunOptions defaults = RunOptions::clinical();
  for (const OptionRow& r : option_table()) {
    if (!(r.uses & use)) continue;
    CLI::Option* o = nullptr;
    if (r.type == OptionType::flag) {
      o = cmd->add_flag("--" + r.name, v.flag[r.name], r.help);
    } else {
      o = cmd->add_option("--" + r.name, v.text[r.name], r.help)->type_name(type_name(r));
      const OptionValue d = r.get(defaults);
      if (!std::holds_alternative<std::monostate>(d) || r.type == OptionType::point) o->default_str(option_text(r, d));
    }
    if (r.required && !(r.optional_for & use)) o->required();
    for (const std::string& old : r.old_names) {  // a former name: accepted, not listed (group "": hidden)
      if (r.type == OptionType::flag)
        cmd->add_flag("--" + old, v.flag[old], r.help)->group("");
      else
        cmd->add_option("--" + old, v.text[old], r.help)->group("");
    }
  }
}

// The run's options: the clinical preset, then every option given, in the table's order (--preset first).
RunOptions given_options(const CLI::App* cmd, unsigned use, const CliValues& v) {
  RunOptions run = RunOptions::clinical();
  for (const OptionRow& r : option_table()) {
    if (!(r.uses & use)) continue;
    std::string name = r.name;  // the name given: the row's, or a former one (said, once)
    for (const std::string& old : r.old_names) {
      if (cmd->count("--" + old) == 0) continue;
      require(cmd->count("--" + r.name) == 0, "give --" + r.name + " or --" + old + " (its former name), not both");
      std::cerr << "impinge: warning: --" << old << " is deprecated and will be removed in the next release: use --"
                << r.name << "\n";
      name = old;
    }
    const std::string as = "--" + name;
    if (cmd->count(as) == 0) continue;
    r.set(run, r.type == OptionType::flag ? OptionValue(v.flag.at(name)) : parse_option_text(r, v.text.at(name), as),
          as);
  }
  return run;
}

// ---- set-up and output --------------------------------------------------------------------

// The session of a command (VTK meshes read through VTK's Python bindings), its warnings printed.
Session open_session(SessionOptions options) {
  cli::read_vtk_inputs(options.input);
  Session session(options);
  for (const std::string& w : session.warnings()) std::cerr << "impinge: warning: " << w << "\n";
  return session;
}

std::string in_dir(const std::string& dir, const std::string& name) { return (fs::path(dir) / name).string(); }

// Figures of an output folder by an analysis/ script (matplotlib; Debian's python3-matplotlib): render_hip.py
// (distance) or render_plan.py (plan).
void render(const std::string& out_dir, const char* name = "render_hip.py") {
  const char* env = std::getenv("IMPINGE_ANALYSIS_DIR");
  const std::string script = std::string(env != nullptr ? env : IMPINGE_ANALYSIS_DIR) + "/" + name;
  require(fs::exists(script), script + ": render script not found (set IMPINGE_ANALYSIS_DIR to impinge's analysis/ folder)");
  const int rc = std::system(("/usr/bin/python3 " + cli::shell_quote(script) + " " + cli::shell_quote(out_dir)).c_str());
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

int run_distance(const RunOptions& o) {
  const auto t_start = Clock::now();
  const std::string& out = o.command.out;
  const PoseAngles pose = parse_pose(o.command.pose);
  SessionOptions so = o.session;
  so.query_strategy = query_strategy_for_poses(so.query_strategy, 1);  // auto: one pose, direct (the layered maps would not pay back)
  so.only_poses = {pose};  // direct: the distance hierarchies cropped to it
  const Session s = open_session(so);
  const double setup_ms = ms_since(t_start);
  auto t = Clock::now();
  const FemurPose femur = s.hip().femur_pose(pose);
  const PoseResult res = s.detect(femur);  // at the scan pose, the set-up's own scan of it
  const double pose_ms = ms_since(t);
  t = Clock::now();
  begin_output_folder(out, "distance");
  // The map images beside the gap files (on their own threads); the gap files' error first.
  run_both([&] { write_pose_plys(in_dir(out, "femur_gaps.ply"), in_dir(out, "pelvis_gaps.ply"), s, res, femur); },
           [&] { write_map_pngs(out, s); });
  nlohmann::json j = run_record(s);
  j.update(pose_record(s, pose, femur, res));
  // Where a one-pose run's time goes (issue 52): the set-up (reading and checking the meshes, the head fit, the
  // frames, both maps, their marks and casters, the distance hierarchies; the bodies on two threads, so their parts
  // overlap), the pose (the joint centre's translation and both scans) and the output.
  const JointBody& ball = s.joint().ball();
  const JointBody& socket = s.joint().socket();
  j["timings_ms"] = {{"setup_total", setup_ms},
                     {"frames", s.hip().frames_ms()},
                     {"femur_sampling", ball.sampling_ms},
                     {"pelvis_sampling", socket.sampling_ms},
                     {"femur_marking", ball.marking_ms},
                     {"pelvis_marking", socket.marking_ms},
                     {"femur_layered_sampling", ball.layered_sampling.sampling_ms},
                     {"pelvis_layered_sampling", socket.layered_sampling.sampling_ms},
                     {"pose", pose_ms},
                     {"femur_detection", res.ball_detection_ms},
                     {"pelvis_detection", res.socket_detection_ms},
                     {"femur_distance", res.ball_distance_ms},
                     {"pelvis_distance", res.socket_distance_ms},
                     {"output", ms_since(t)},
                     {"total", ms_since(t_start)}};
  write_json(in_dir(out, "summary.json"), j);
  if (o.command.render) render(out);  // reads summary.json; a failure leaves the folder marked incomplete
  end_output_folder(out);
  std::cout << "femur: " << res.ball.vertices_tested << " tested, min gap " << res.ball.min_gap_mm << " mm, "
            << res.ball.vertices_penetrating << " penetrating; pelvis: " << res.socket.vertices_tested
            << " tested, min gap " << res.socket.min_gap_mm << " mm, " << res.socket.vertices_penetrating
            << " penetrating; written to " << out << "\n";
  return 0;
}

int run_motion(const RunOptions& o) {
  const auto t_start = Clock::now();
  const CommandArguments& mo = o.command;
  const std::string& out = mo.out;
  // The motion file is read (and fully checked) before anything is built or written.
  const Motion motion = load_motion(mo.motion, input_side(o.session.input));
  SessionOptions so = o.session;
  so.query_strategy = query_strategy_for_poses(so.query_strategy, motion.frames());  // auto: by the number of frames
  const Session s = open_session(so);
  const double setup_ms = ms_since(t_start);

  begin_output_folder(out, "motion", {"gaps"});
  const std::size_t n = motion.frames();
  const bool bar = !mo.quiet && isatty(fileno(stderr));
  const MotionFiles files = write_motion_files(out, s, motion, mo.vtp_every, [&](std::size_t done, std::size_t total) {
    if (bar && ((done - 1) % 10 == 0 || done == total)) progress_bar(done, total);
  });
  const double detect_ms = files.detect_ms, write_ms = files.write_ms;
  nlohmann::json j = run_record(s);
  j["motion_file"] = mo.motion;
  j["motion_format"] = motion.format;
  j["motion_frames"] = n;
  j["vtp_every"] = files.vtp_every;
  j["vtp_files"] = files.vtp_files;
  j["timings_ms"] = {{"setup_total", setup_ms},
                     {"femur_sampling", s.joint().ball().sampling_ms},
                     {"pelvis_sampling", s.joint().socket().sampling_ms},
                     {"frames", s.hip().frames_ms()},
                     {"detection_total", detect_ms},
                     {"detection_per_frame", n ? detect_ms / static_cast<double>(n) : 0.0},
                     {"output", write_ms},
                     {"total", ms_since(t_start)}};
  write_json(in_dir(out, "summary.json"), j);
  end_output_folder(out);
  if (!mo.quiet)
    std::cout << "motion: " << n << " frames in " << std::fixed << std::setprecision(1) << ms_since(t_start)
              << " ms (setup " << setup_ms << " ms, detection " << detect_ms << " ms); written to " << out << "\n";
  return 0;
}

int run_rom(const RunOptions& o) {
  const auto t_start = Clock::now();
  const RomRequest& q = o.rom;
  const std::string& out = o.command.out;
  const Session s = open_session(rom_session_options(o.session, q.search));
  const double setup_ms = ms_since(t_start);
  const RomRun run = run_rom(s, q);
  if (run.baseline.excluded_vertices > 0)
    std::cerr << "impinge: warning: " << run.baseline.excluded_vertices << " vertices are within "
              << q.search.threshold_mm
              << " mm at neutral (overlap before any motion); they are not counted in the limits\n";
  begin_output_folder(out, "rom");
  write_csv(in_dir(out, "rom_limits.csv"), rom_limits_table(s, run));
  if (q.map) write_csv(in_dir(out, "rom_map.csv"), rom_map_table(run));
  if (q.envelope) write_csv(in_dir(out, "rom_envelope.csv"), rom_envelope_table(run));
  if (run.labrum) write_ply(in_dir(out, "labrum.ply"), labrum_input(s, run));
  nlohmann::json j = run_record(s);
  j.update(rom_record(run));
  j["timings_ms"] = {{"setup_total", setup_ms},
                     {"femur_sampling", s.joint().ball().sampling_ms},
                     {"pelvis_sampling", s.joint().socket().sampling_ms},
                     {"limits", run.limits_ms},
                     {"limits_other_frame", run.other_limits_ms},
                     {"rom_map", run.map_ms},
                     {"envelope", run.envelope_ms},
                     {"total", ms_since(t_start)}};
  write_json(in_dir(out, "summary.json"), j);
  end_output_folder(out);
  std::cout << "rom: " << run.limits.size() << " limits in " << std::fixed << std::setprecision(0) << run.limits_ms
            << " ms, ROM map (" << run.map.size() << " cells) in " << run.map_ms << " ms"
            << (q.envelope ? ", envelope in " + std::to_string(std::lround(run.envelope_ms)) + " ms" : std::string())
            << ", total " << ms_since(t_start) << " ms; written to " << out << "\n";
  return 0;
}

int run_morphology(const RunOptions& o) {
  const std::string& out = o.command.out;
  SessionOptions so = o.session;
  cli::read_vtk_inputs(so.input);
  const MorphologyRun run = run_morphology(so);
  for (const std::string& w : run.warnings) std::cerr << "impinge: warning: " << w << "\n";
  begin_output_folder(out, "morphology");
  write_morphology_ply(in_dir(out, "femur_sphericity.ply"), run);
  nlohmann::json j = morphology_record(run);
  j["impinge_version"] = IMPINGE_VERSION;
  write_json(in_dir(out, "morphology.json"), j);
  write_json(in_dir(out, "summary.json"), {{"impinge_version", IMPINGE_VERSION}, {"command", "morphology"}, {"ms", run.ms}});
  end_output_folder(out);
  const Morphology& m = run.morphology;
  std::cout << std::fixed << std::setprecision(1) << "morphology: head radius " << m.head_radius_mm
            << " mm, alpha max " << m.alpha_max_deg << " deg at " << std::setprecision(0) << m.alpha_max_hour
            << " o'clock, femoral version " << std::setprecision(1) << m.version_posterior_condylar_shaft_deg
            << " deg (posterior condylar, across the shaft; " << m.version_posterior_condylar_deg
            << " across the mechanical axis), acetabular anteversion " << m.orientation_app.anteversion_deg
            << " deg (anterior pelvic plane), LCE "
            << m.lateral_centre_edge_deg << " deg; written to " << out << "\n";
  return 0;
}

int run_plan(const RunOptions& o) {
  const std::string& out = o.command.out;
  SessionOptions so = o.session;
  cli::read_vtk_inputs(so.input);
  const PlanRun run = run_plan(so, o.rom, o.plan);
  for (const std::string& w : run.warnings) std::cerr << "impinge: warning: " << w << "\n";
  begin_output_folder(out, "plan");
  write_plan_meshes(out, run);
  nlohmann::json j = plan_record(run);
  j["impinge_version"] = IMPINGE_VERSION;
  write_json(in_dir(out, "plan.json"), j);
  write_json(in_dir(out, "summary.json"),
             {{"impinge_version", IMPINGE_VERSION}, {"command", "plan"}, {"ms", run.total_ms}, {"all_targets_met", run.all_met}});
  if (o.command.render) render(out, "render_plan.py");
  end_output_folder(out);
  const BoneResection& f = run.plan.femur;
  const BoneResection& p = run.plan.pelvis;
  std::cout << std::fixed << std::setprecision(1) << "plan: ";
  if (f.allowed) std::cout << "femur " << f.volume_mm3 << " mm^3 (deepest cut " << f.deepest_cut_mm << " mm)";
  if (f.allowed && p.allowed) std::cout << ", ";
  if (p.allowed) std::cout << "pelvis " << p.volume_mm3 << " mm^3 (deepest cut " << p.deepest_cut_mm << " mm)";
  std::cout << "; targets:";
  // A limit as the summary prints it: its angle to 0.1 deg, or its status.
  auto limit = [](double deg, RomLimitStatus status) {
    return std::isnan(deg) ? std::string(to_string(status))
                           : std::to_string(static_cast<double>(std::lround(deg * 10)) / 10.0).substr(0, 5);
  };
  for (const PlanTargetCheck& c : run.targets) {
    std::cout << " " << c.name;
    if (!std::isnan(c.target_deg) && c.labral_before && c.labral_after)  // --labrum: both, the labral one targeted
      std::cout << " bony " << limit(c.before.limit_deg, c.before.status) << "->"
                << limit(c.after.limit_deg, c.after.status) << ", labral (targeted) "
                << limit(c.labral_before->limit_deg, c.labral_before->status) << "->"
                << limit(c.labral_after->limit_deg, c.labral_after->status) << "/" << c.target_deg;
    else if (!std::isnan(c.target_deg))
      std::cout << " " << limit(c.before.limit_deg, c.before.status) << "->" << limit(c.after.limit_deg, c.after.status)
                << "/" << c.target_deg;
    if (c.clearance_poses > 0)
      std::cout << " clearance " << std::setprecision(2) << c.clearance_least_mm << std::setprecision(1) << " mm";
    std::cout << (c.met ? " met" : c.limit_met ? " MISSED (clearance)" : " MISSED") << ";";
  }
  std::cout << " " << std::setprecision(0) << run.total_ms << " ms; written to " << out << "\n";
  if (!run.all_met && !o.plan.allow_partial) {
    std::cerr << "impinge: error: the plan misses a target (plan.json says which and why); --allow-partial accepts "
                 "that\n";
    return 3;
  }
  return 0;
}

int run_generate(const RunOptions& run) {
  const std::string& out = run.command.out;
  const HipModel h = write_generated_hip(out, run.generate);
  std::cout << "generated hip model: " << h.ball.F.rows() << " + " << h.socket.F.rows() << " triangles in " << out
            << " (a proximal femur and a cup: neutral is the scan pose)\n";
  return 0;
}

// The options given to `cmd` on the command line as its tokens ("--name=value", "--flag"), for the rows with `use`
// that are not the view's own (those whose only use is `use_view`): what the viewer's server parses again.
std::vector<std::string> given_tokens(const CLI::App* cmd, unsigned use, const CliValues& v) {
  std::vector<std::string> out;
  for (const OptionRow& r : option_table()) {
    if (!(r.uses & use) || r.uses == use_view) continue;
    std::vector<std::string> names = {r.name};
    names.insert(names.end(), r.old_names.begin(), r.old_names.end());
    for (const std::string& n : names) {
      if (cmd->count("--" + n) == 0) continue;
      if (r.type == OptionType::flag) {
        if (v.flag.at(n)) out.push_back("--" + n);
      } else {
        out.push_back("--" + n + "=" + v.text.at(n));
      }
    }
  }
  return out;
}

// `impinge view`: the options checked here (the table's rows for view), then the server runs in this process's place
// (exec), so Ctrl-C and the exit status are its own.
int run_view(const RunOptions& o, const std::vector<std::string>& tokens) {
  const std::string warning = view_host_warning(o.view.host);
  if (!warning.empty()) std::cerr << "impinge: warning: " << warning << "\n";
  const ViewCommand c = view_command(o.view, tokens, IMPINGE_PYTHON_BUILD_DIR);
  const char* old = std::getenv("PYTHONPATH");
  const std::string path = c.python_path + (old != nullptr && *old != '\0' ? ":" + std::string(old) : "");
  setenv("PYTHONPATH", path.c_str(), 1);
  std::vector<char*> argv;
  for (const std::string& a : c.argv) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  std::cout.flush();
  execvp(argv[0], argv.data());
  throw Error("impinge view: cannot run " + c.argv[0] + ": " + std::strerror(errno));
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"impinge: impingement detection in ball-and-socket joints by spherical distance maps"};
  app.set_version_flag("--version", std::string("impinge ") + IMPINGE_VERSION);
  app.require_subcommand(1);
  CliValues values;
  struct Command {
    CLI::App* app;
    unsigned use;
    int (*run)(const RunOptions&);
  };
  const std::vector<Command> commands = {
      {app.add_subcommand("distance", "Per-vertex gap between ball (femur) and socket (pelvis) at one pose"),
       use_distance, run_distance},
      {app.add_subcommand("motion",
                          "Both scans at every frame of a motion (CSV: time_s, flexion_deg, adduction_deg, "
                          "internal_rotation_deg; or OpenSim .mot/.sto with hip_flexion_r|l, hip_adduction_r|l, "
                          "hip_rotation_r|l); maps built once. Writes frames.csv, gaps.pvd (ParaView) and summary.json"),
       use_motion, run_motion},
      {app.add_subcommand("rom",
                          "Range-of-motion limits from neutral for the standard motions (rom_limits.csv) and the ROM "
                          "map: the largest internal rotation over flexion x adduction (rom_map.csv)"),
       use_rom, run_rom},
      {app.add_subcommand("morphology",
                          "The hip's shape as clinicians measure it (morphology.json): femoral head radius and "
                          "sphericity, neck-shaft angle, femoral version, alpha angle per clock hour, head-neck "
                          "offset; acetabular sphere, version, inclination, centre-edge angles, coverage. No maps"),
       use_morphology, run_morphology},
      {app.add_subcommand("plan",
                          "Resection plan: the least bone to remove (the cam, a rim) so that target motions run free "
                          "of impingement, checked by the ROM search on the resected bones (--labrum: the labral "
                          "limits targeted, the femur cut to clear the labrum too). Writes plan.json, "
                          "femur_resected.ply/.vtp (per-vertex resection_mm), labrum.ply (--labrum) and summary.json"),
       use_plan, run_plan},
      {app.add_subcommand("generate", "Write a generated hip model (femur_r.ply, pelvis.ply, subject.json)"),
       use_generate, run_generate},
  };
  CLI::App* view = app.add_subcommand(
      "view",
      "Joint3D in the browser (thesis sec. 3.4): a local page where the hip moves with sliders and the impingement "
      "levels, gaps or distances are coloured on both bones, each pose detected as `impinge distance --query-strategy maps` detects it. "
      "Takes distance's inputs and settings; prints the page's address (with its access token)");
  for (const Command& c : commands) add_table_options(c.app, c.use, values);
  add_table_options(view, use_view, values);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; a usage error (unknown option, missing value, ...) exits 2 as every other error
    // does (CLI11's own codes are 100 and up).
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  try {
    for (const Command& c : commands)
      if (*c.app) return c.run(given_options(c.app, c.use, values));
    if (*view) return run_view(given_options(view, use_view, values), given_tokens(view, use_view, values));
  } catch (const std::bad_alloc&) {
    std::cerr << "impinge: error: out of memory: the meshes or maps do not fit in this machine's memory; try a "
                 "coarser --resolution, fewer --layers or a larger --layered-spacing\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "impinge: error: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
