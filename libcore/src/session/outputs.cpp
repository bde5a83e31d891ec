#include "impinge/session/outputs.hpp"
#include "impinge/core/concurrent.hpp"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <ctime>
#include <exception>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <new>
#include <sstream>

#include "impinge/core/atomic_file.hpp"
#include "impinge/core/error.hpp"
#include "impinge/core/range.hpp"
#include "impinge/io/mesh_io.hpp"
#include "impinge/io/subject.hpp"
#include "impinge/io/vtk_output.hpp"
#include "impinge/maps/map_image.hpp"
#include "impinge/session/records.hpp"
#include "impinge/session/runs.hpp"

namespace impinge {

namespace fs = std::filesystem;

namespace {

std::string this_host() {
  char name[256] = {};
  return gethostname(name, sizeof name - 1) == 0 ? std::string(name) : std::string("unknown-host");
}

// Whether process `pid` of this machine still runs (EPERM: it runs as another user).
bool process_alive(long pid) { return pid > 0 && (kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM); }

// Take `dir`'s lock (kOutputLock) for this process, or throw naming the run that holds it.
void take_output_lock(const fs::path& dir, const std::string& command, const std::string& when) {
  const fs::path lock = dir / kOutputLock;
  const std::string host = this_host();
  const std::string mine = std::to_string(getpid()) + " " + host + " impinge " + command + " " + when + "\n";
  for (int attempt = 0; attempt < 3; ++attempt) {
    const int fd = ::open(lock.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd >= 0) {
      const bool written = ::write(fd, mine.data(), mine.size()) == static_cast<ssize_t>(mine.size());
      const bool closed = ::close(fd) == 0;
      if (written && closed) return;
      std::error_code ec;
      fs::remove(lock, ec);
      throw Error(lock.string() + ": cannot write the output folder's lock (is the disk full?)");
    }
    const int err = errno;
    require(err == EEXIST, [&] { return lock.string() + ": cannot create the output folder's lock (" +
                                         std::string(std::strerror(err)) + ")"; });
    long pid = 0;
    std::string holder_host, word, holder_command, started;
    {
      std::ifstream in(lock);
      in >> pid >> holder_host >> word >> holder_command >> started;
    }
    const bool ours = pid == static_cast<long>(getpid()) && holder_host == host;
    const bool live_here = holder_host == host && process_alive(pid) && !ours;
    require(!live_here, [&] {
      return dir.string() + ": in use by impinge " + holder_command + " (pid " + std::to_string(pid) + ", since " +
             started + "): wait for it to end, or give another --out";
    });
    require(pid <= 0 || holder_host == host || holder_host.empty(), [&] {
      return dir.string() + ": in use by impinge " + holder_command + " on " + holder_host + " (pid " +
             std::to_string(pid) + ", since " + started + "); if that run has ended, remove " + lock.string();
    });
    std::error_code ec;  // left by a run that ended (or empty: a full disk): taken over
    fs::remove(lock, ec);
  }
  throw Error(lock.string() + ": another run takes the folder at the same moment; try again");
}

// Remove the files of command_outputs(command) a previous run left in `dir` (a pattern's folder must not be a link).
void remove_previous_outputs(const std::string& dir, const std::string& command) {
  for (const std::string& name : command_outputs(command)) {
    const fs::path p = fs::path(dir) / name;
    const std::string leaf = p.filename().string();
    const std::size_t star = leaf.find('*');
    std::error_code ec;
    if (star == std::string::npos) {
      if (fs::is_regular_file(fs::symlink_status(p)) || fs::is_symlink(fs::symlink_status(p))) fs::remove(p, ec);
    } else if (fs::is_directory(fs::symlink_status(p.parent_path()))) {
      const std::string head = leaf.substr(0, star), tail = leaf.substr(star + 1);
      for (const auto& e : fs::directory_iterator(p.parent_path(), ec)) {
        const std::string n = e.path().filename().string();
        if (n.size() >= head.size() + tail.size() && n.compare(0, head.size(), head) == 0 &&
            n.compare(n.size() - tail.size(), tail.size(), tail) == 0)
          fs::remove(e.path(), ec);
      }
    }
    require(!ec, [&] { return p.string() + ": cannot remove a previous run's file (" + ec.message() + ")"; });
  }
}

// Create `subfolders`, remove a previous run's outputs and write kIncompleteMarker (begin_output_folder).
void prepare_output_folder(const std::string& dir, const std::string& command,
                           const std::vector<std::string>& subfolders);

void release_output_lock(const fs::path& dir) {
  const fs::path lock = dir / kOutputLock;
  long pid = 0;
  std::string host;
  {
    std::ifstream in(lock);
    in >> pid >> host;
  }
  std::error_code ec;
  if (pid == static_cast<long>(getpid()) && host == this_host()) fs::remove(lock, ec);  // only our own
}

}  // namespace

void begin_output_folder(const std::string& dir, const std::string& command, const std::vector<std::string>& subfolders) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  require(fs::is_directory(dir), [&] { return dir + ": cannot create the output folder (" + ec.message() + ")"; });
  const std::time_t start = std::time(nullptr);
  char started[32];
  std::strftime(started, sizeof started, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&start));
  take_output_lock(dir, command, started);
  try {
    prepare_output_folder(dir, command, subfolders);
  } catch (...) {
    release_output_lock(dir);
    throw;
  }
}

namespace {

void prepare_output_folder(const std::string& dir, const std::string& command,
                           const std::vector<std::string>& subfolders) {
  std::error_code ec;
  remove_previous_outputs(dir, command);
  for (const std::string& sub : subfolders) {
    const fs::path p = fs::path(dir) / sub;
    require(!fs::is_symlink(fs::symlink_status(p)),
            [&] { return p.string() + ": a symbolic link in the output folder; refusing to write through it"; });
    fs::create_directories(p, ec);
    require(fs::is_directory(p), [&] { return p.string() + ": cannot create it (" + ec.message() + ")"; });
  }
  const std::time_t now = std::time(nullptr);
  char when[32];
  std::strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  write_file_atomically((fs::path(dir) / kIncompleteMarker).string(),
                        "impinge " + command + " started writing here at " + std::string(when) +
                            "; the outputs are complete when summary.json is written and this file is removed.\n");
  fs::remove(fs::path(dir) / "summary.json", ec);
  require(!ec, [&] { return dir + "/summary.json: cannot remove a previous run's (" + ec.message() + ")"; });
}

}  // namespace

std::vector<std::string> command_outputs(const std::string& command) {
  std::vector<std::string> out;
  if (command == "distance")
    out = {"femur_gaps.ply", "pelvis_gaps.ply", "femur_map.png", "pelvis_map.png", "render.png",
           "render_anterior.png", "render_lateral.png", "render_acetabulum_medial.png"};
  else if (command == "motion")
    out = {"frames.csv", "gaps.pvd", "gaps/frame_*.vtp"};
  else if (command == "rom")
    out = {"rom_limits.csv", "rom_map.csv", "rom_envelope.csv", "labrum.ply"};
  else if (command == "morphology")
    out = {"morphology.json", "femur_sphericity.ply"};
  else if (command == "plan")
    out = {"plan.json", "femur_resected.ply", "femur_resected.vtp", "pelvis_resected.ply", "pelvis_resected.vtp",
           "plan.png", "labrum.ply"};
  else
    return out;
  out.push_back("summary.json");
  return out;
}

void end_output_folder(const std::string& dir) {
  std::error_code ec;
  fs::remove(fs::path(dir) / kIncompleteMarker, ec);
  require(!ec, [&] { return dir + "/" + kIncompleteMarker + ": cannot remove it (" + ec.message() + ")"; });
  release_output_lock(dir);
}

std::vector<std::uint8_t> vertex_levels(const ScanGaps& g, const ImpingementLevels& levels, LevelQuantity levels_on) {
  std::vector<std::uint8_t> out(g.gap_mm.size());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = vertex_level(g, i, levels, levels_on);
  return out;
}

namespace {
// One bone's gaps as a PLY: vertices V (input frame), gap_mm, level and its colour.
void write_body_ply(const std::string& path, const ImpingementLevels& levels, LevelQuantity levels_on,
                    const JointBody& body,
                    const ScanGaps& gaps, const Vertices& V, bool is_ball) {
  const Eigen::Index n = body.mesh.V.rows();
  const std::vector<std::uint8_t> lv = vertex_levels(gaps, levels, levels_on);
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
  if (gaps.distance_mm.empty()) {
    write_gap_ply(path, V, body.mesh.F, gap, level, rgb);
  } else {
    const Eigen::VectorXf distance = Eigen::Map<const Eigen::VectorXf>(gaps.distance_mm.data(), n);
    write_gap_ply(path, V, body.mesh.F, gap, level, rgb, &distance,
                  gaps.distance_sign_undecided.empty() ? nullptr : &gaps.distance_sign_undecided);
  }
}
}  // namespace

void write_pose_plys(const std::string& ball_path, const std::string& socket_path, const Session& s,
                     const PoseResult& res, const FemurPose& pose) {
  const ImpingementLevels& levels = s.joint_options().levels;
  const LevelQuantity on = s.joint_options().level_quantity();
  // The socket's file on a second thread; the ball's error first if both fail.
  run_both([&] { write_body_ply(ball_path, levels, on, s.joint().ball(), res.ball_gaps, s.femur_input(pose), true); },
           [&] { write_body_ply(socket_path, levels, on, s.joint().socket(), res.socket_gaps, s.pelvis_input(), false); });
}

void write_pose_vtp(const std::string& path, const Session& s, const PoseResult& res, const FemurPose& pose) {
  const JointBody& b = s.joint().ball();
  const JointBody& p = s.joint().socket();
  const Eigen::Index nb = b.mesh.V.rows(), np = p.mesh.V.rows();
  Vertices V(nb + np, 3);
  V.topRows(nb) = s.femur_input(pose);
  V.bottomRows(np) = s.pelvis_input();
  Faces F(b.mesh.F.rows() + p.mesh.F.rows(), 3);
  F.topRows(b.mesh.F.rows()) = b.mesh.F;
  F.bottomRows(p.mesh.F.rows()) = p.mesh.F.array() + static_cast<int>(nb);
  PointArray gap{"gap_mm", {}, {}}, level{"level", {}, {}}, body{"body", {}, {}};
  gap.f32 = res.ball_gaps.gap_mm;
  gap.f32.insert(gap.f32.end(), res.socket_gaps.gap_mm.begin(), res.socket_gaps.gap_mm.end());
  level.u8 = vertex_levels(res.ball_gaps, s.joint_options().levels, s.joint_options().level_quantity());
  const auto ls = vertex_levels(res.socket_gaps, s.joint_options().levels, s.joint_options().level_quantity());
  level.u8.insert(level.u8.end(), ls.begin(), ls.end());
  body.u8.assign(static_cast<std::size_t>(nb), 0);
  body.u8.resize(static_cast<std::size_t>(nb + np), 1);
  if (res.ball_gaps.distance_mm.empty()) {
    write_vtp(path, V, F, {gap, level, body});
    return;
  }
  PointArray distance{"distance_mm", {}, {}};
  distance.f32 = res.ball_gaps.distance_mm;
  distance.f32.insert(distance.f32.end(), res.socket_gaps.distance_mm.begin(), res.socket_gaps.distance_mm.end());
  PointArray undecided{"sign_undecided", {}, {}};  // 1 where the other mesh cannot decide the sign
  undecided.u8 = res.ball_gaps.distance_sign_undecided;
  undecided.u8.insert(undecided.u8.end(), res.socket_gaps.distance_sign_undecided.begin(),
                      res.socket_gaps.distance_sign_undecided.end());
  if (undecided.u8.size() != distance.f32.size()) undecided.u8.assign(distance.f32.size(), 0);
  write_vtp(path, V, F, {gap, distance, undecided, level, body});
}

void write_map_pngs(const std::string& dir, const Session& s) {
  const std::filesystem::path d(dir);
  try {
    run_both([&] { write_map_png((d / "femur_map.png").string(), s.joint().ball().map); },
             [&] { write_map_png((d / "pelvis_map.png").string(), s.joint().socket().map); });
  } catch (const std::bad_alloc&) {
    const RadialDistanceMap& m = s.joint().ball().map;
    throw OutOfMemory("out of memory drawing the maps' images (femur_map.png, pelvis_map.png in " + dir + ") of " +
                      std::to_string(m.num_nodes()) + " nodes each (" + m.scheme().resolution_name() + " " +
                      shortest_decimal(m.scheme().resolution()) + "): coarsen --precision (or --resolution), or "
                      "free memory");
  }
}

HipModel write_generated_hip(const std::string& dir, const HipModelOptions& o) {
  const HipModel h = make_hip_model(o);
  begin_output_folder(dir, "generate");
  const std::filesystem::path d(dir);
  write_ply((d / "femur_r.ply").string(), h.ball);
  write_ply((d / "pelvis.ply").string(), h.socket);
  SubjectInfo info;
  info.side = Side::right;
  info.frame = FrameConvention::RAS;
  info.femur_path = (d / "femur_r.ply").string();
  info.pelvis_path = (d / "pelvis.ply").string();
  info.neutral = "scan";  // a proximal femur and a cup: no whole bones for anatomical frames
  info.generated = true;
  info.true_cor_mm = h.cor;
  info.head_radius_mm = o.head_radius_mm;
  save_subject((d / "subject.json").string(), info);
  end_output_folder(dir);
  return h;
}

MotionFiles write_motion_files(const std::string& dir, const Session& s, const Motion& motion, int vtp_every,
                               const std::function<void(std::size_t, std::size_t)>& on_frame) {
  const std::filesystem::path d(dir);
  const std::size_t n = motion.frames();
  MotionFiles out;
  out.vtp_every = vtp_every > 0 ? vtp_every : static_cast<int>((n + 99) / 100);
  Table frames;
  frames.columns = motion_columns(s.joint_options().levels);
  std::vector<PvdEntry> pvd;
  const auto t_loop = std::chrono::steady_clock::now();
  out.detect_ms = run_motion(s, motion.angles, motion.time_s, [&](const MotionFrame& f) {
    frames.add(motion_row(f));
    if (f.index % static_cast<std::size_t>(out.vtp_every) == 0) {
      std::ostringstream name;
      name << "gaps/frame_" << std::setw(6) << std::setfill('0') << f.index << ".vtp";
      write_pose_vtp((d / name.str()).string(), s, *f.result, f.pose);
      pvd.push_back({f.time_s, name.str()});
    }
    if (on_frame) on_frame(f.index + 1, n);
  });
  write_csv((d / "frames.csv").string(), frames);
  write_pvd((d / "gaps.pvd").string(), pvd);
  out.vtp_files = pvd.size();
  out.write_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t_loop).count() - out.detect_ms;
  return out;
}

}  // namespace impinge
