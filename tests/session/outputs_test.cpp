// The session layer's outputs (outputs.hpp). Invariants: a pose's PLY files hold every vertex of each bone in
// the input's order, at the posed positions Session reports (femur_input, pelvis_input) within float rounding,
// with the scan's gap and distance per vertex (NaN kept) and the level ImpingementLevels gives that value
// (brute force); an output folder is marked incomplete until its run ends, a previous summary.json is gone
// from the start, and a subfolder that is a symbolic link is refused.
#include "impinge/session/outputs.hpp"

#include <unistd.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "impinge/core/atomic_file.hpp"
#include "impinge/core/error.hpp"
#include "test_support.hpp"

using namespace impinge;
namespace fs = std::filesystem;

namespace {

const Session& session() { return test::generated_session("LPS"); }

struct PlyVertex {
  float x, y, z, gap, quality, distance;
  std::uint8_t level, undecided = 0;
};

// The vertices of a PLY that write_gap_ply wrote (binary: x y z gap_mm quality [distance_mm sign_undecided] level r
// g b).
std::vector<PlyVertex> read_gap_ply(const std::string& path, bool with_distance) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  std::size_t n = 0;
  while (std::getline(in, line) && line != "end_header")
    if (line.rfind("element vertex ", 0) == 0) n = std::stoul(line.substr(15));
  std::vector<PlyVertex> v(n);
  for (PlyVertex& p : v) {
    float f[6];
    in.read(reinterpret_cast<char*>(f), static_cast<std::streamsize>(sizeof(float) * (with_distance ? 6 : 5)));
    p = {f[0], f[1], f[2], f[3], f[4], with_distance ? f[5] : std::nanf("")};
    char rest[5];
    in.read(rest, with_distance ? 5 : 4);
    p.undecided = with_distance ? static_cast<std::uint8_t>(rest[0]) : 0;
    p.level = static_cast<std::uint8_t>(rest[with_distance ? 1 : 0]);
  }
  EXPECT_TRUE(in.good()) << path;
  return v;
}

bool same_float(float a, float b) { return (std::isnan(a) && std::isnan(b)) || a == b; }

}  // namespace

TEST(Outputs, PosePlysHoldEveryVertexPosedWithItsGapAndLevel) {
  const Session& s = session();
  const std::string d = (fs::temp_directory_path() / "impinge_outputs_plys").string();
  fs::create_directories(d);
  const FemurPose pose = s.hip().femur_pose({30, 5, 10});
  const PoseResult r = s.joint().detect(pose.R, pose.t);
  write_pose_plys(d + "/ball.ply", d + "/socket.ply", s, r, pose);
  const ImpingementLevels& levels = s.joint_options().levels;
  for (const bool ball : {true, false}) {
    const std::vector<PlyVertex> v = read_gap_ply(d + (ball ? "/ball.ply" : "/socket.ply"), true);
    const Vertices P = ball ? s.femur_input(pose) : s.pelvis_input();
    const ScanGaps& g = ball ? r.ball_gaps : r.socket_gaps;
    ASSERT_EQ(v.size(), static_cast<std::size_t>(P.rows()));
    std::size_t tested = 0;
    for (std::size_t i = 0; i < v.size(); ++i) {
      const Eigen::Vector3d p(v[i].x, v[i].y, v[i].z);
      EXPECT_LT((p - P.row(static_cast<Eigen::Index>(i)).transpose()).norm(), 1e-4) << i;
      EXPECT_TRUE(same_float(v[i].gap, g.gap_mm[i])) << i;
      EXPECT_TRUE(same_float(v[i].distance, g.distance_mm[i])) << i;
      EXPECT_EQ(v[i].undecided, g.distance_sign_undecided[i]) << i;
      // The level by brute force: the levels' quantity (the distance where distances are on), 255 without one.
      const float q = g.distance_mm[i];
      const std::uint8_t want = std::isnan(q) ? (std::isnan(g.gap_mm[i]) ? 255 : 0) : levels.level(q);
      EXPECT_EQ(v[i].level, want) << i;
      tested += !std::isnan(g.gap_mm[i]);
    }
    EXPECT_GT(tested, 100u);
  }
}

TEST(Outputs, FolderIsMarkedIncompleteUntilItsRunEnds) {
  const fs::path d = fs::temp_directory_path() / "impinge_outputs_folder";
  fs::remove_all(d);
  fs::create_directories(d);
  write_file_atomically((d / "summary.json").string(), "{}\n");  // a previous run's
  begin_output_folder(d.string(), "test", {"gaps"});
  EXPECT_TRUE(fs::exists(d / kIncompleteMarker));
  EXPECT_FALSE(fs::exists(d / "summary.json"));
  EXPECT_TRUE(fs::is_directory(d / "gaps"));
  end_output_folder(d.string());
  EXPECT_FALSE(fs::exists(d / kIncompleteMarker));
  // A subfolder that is a link would write outside the folder.
  fs::remove_all(d / "gaps");
  fs::create_directory_symlink(fs::temp_directory_path(), d / "gaps");
  try {
    begin_output_folder(d.string(), "test", {"gaps"});
    FAIL() << "a symbolic link subfolder was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("symbolic link"), std::string::npos) << e.what();
  }
}

// Issue 80: a run owns its --out. The lock names its holder; a live holder on this machine or any on another host is
// refused; a lock left by a run that ended (its process gone) or an empty one (a full disk) is taken over; the run's own
// lock goes at its end.
TEST(Outputs, ARunLocksItsFolderAndALockLeftBehindIsTakenOver) {
  const fs::path d = fs::temp_directory_path() / ("impinge_outputs_lock_" + std::to_string(getpid()));
  fs::remove_all(d);
  begin_output_folder(d.string(), "rom");
  std::string holder;
  std::getline(std::ifstream(d / kOutputLock), holder);
  EXPECT_EQ(holder.rfind(std::to_string(getpid()) + " ", 0), 0u) << holder;
  EXPECT_NE(holder.find(" impinge rom "), std::string::npos) << holder;
  end_output_folder(d.string());
  EXPECT_FALSE(fs::exists(d / kOutputLock));
  char host[256] = {};
  gethostname(host, sizeof host - 1);
  // Held by a live process of this machine (pid 1 always runs): refused, naming it.
  write_file_atomically((d / kOutputLock).string(), std::string("1 ") + host + " impinge motion 2026-01-01T00:00:00Z\n");
  const std::string e = test::error_of([&] { begin_output_folder(d.string(), "distance"); });
  EXPECT_NE(e.find("in use by impinge motion (pid 1, since 2026-01-01T00:00:00Z)"), std::string::npos) << e;
  // On another host: refused, saying how to free it.
  write_file_atomically((d / kOutputLock).string(), "4321 elsewhere impinge plan 2026-01-01T00:00:00Z\n");
  EXPECT_NE(test::error_of([&] { begin_output_folder(d.string(), "distance"); }).find("on elsewhere"),
            std::string::npos);
  // Left by a process that ended (a pid above the kernel's pid_max), or empty: taken over.
  for (const std::string stale : {std::string("99999999 ") + host + " impinge rom 2026-01-01T00:00:00Z\n",
                                  std::string()}) {
    write_file_atomically((d / kOutputLock).string(), stale);
    begin_output_folder(d.string(), "distance");
    std::getline(std::ifstream(d / kOutputLock), holder);
    EXPECT_EQ(holder.rfind(std::to_string(getpid()) + " ", 0), 0u) << holder;
    end_output_folder(d.string());
  }
  fs::remove_all(d);
}

// Issue 80: a reused --out holds only the new run's files: a run removes its command's whole output set that an
// earlier run left (a plan's pelvis_resected.* beside a femur-only plan, a motion's extra frames), and nothing else.
TEST(Outputs, AReusedFolderKeepsNoFileOfTheCommandsEarlierRun) {
  const fs::path d = fs::temp_directory_path() / ("impinge_outputs_reused_" + std::to_string(getpid()));
  fs::remove_all(d);
  fs::create_directories(d / "gaps");
  for (const char* f : {"plan.json", "pelvis_resected.ply", "pelvis_resected.vtp", "plan.png", "summary.json",
                        "notes.txt", "femur_gaps.ply", "gaps/frame_000007.vtp", "gaps/mine.txt"})
    write_file_atomically((d / f).string(), "earlier\n");
  begin_output_folder(d.string(), "plan");
  for (const char* gone : {"plan.json", "pelvis_resected.ply", "pelvis_resected.vtp", "plan.png", "summary.json"})
    EXPECT_FALSE(fs::exists(d / gone)) << gone;
  for (const char* kept : {"notes.txt", "femur_gaps.ply", "gaps/frame_000007.vtp", "gaps/mine.txt"})
    EXPECT_TRUE(fs::exists(d / kept)) << kept;  // not the plan's: the user's, distance's, motion's
  end_output_folder(d.string());
  begin_output_folder(d.string(), "motion", {"gaps"});
  EXPECT_FALSE(fs::exists(d / "gaps/frame_000007.vtp"));
  EXPECT_TRUE(fs::exists(d / "gaps/mine.txt"));
  end_output_folder(d.string());
  for (const std::string c : {"distance", "motion", "rom", "morphology", "plan"})
    EXPECT_EQ(command_outputs(c).back(), "summary.json") << c;
  fs::remove_all(d);
}

TEST(Outputs, AtomicWriteReplacesALinkAndLeavesItsTargetAlone) {
  const fs::path d = fs::temp_directory_path() / "impinge_outputs_atomic";
  fs::remove_all(d);
  fs::create_directories(d);
  write_file_atomically((d / "target.txt").string(), "precious\n");
  fs::create_symlink(d / "target.txt", d / "out.txt");
  write_file_atomically((d / "out.txt").string(), "new\n");
  EXPECT_FALSE(fs::is_symlink(d / "out.txt"));
  std::ifstream t(d / "target.txt"), o(d / "out.txt");
  std::stringstream a, b;
  a << t.rdbuf(), b << o.rdbuf();
  EXPECT_EQ(a.str(), "precious\n");
  EXPECT_EQ(b.str(), "new\n");
  for (const auto& e : fs::directory_iterator(d))
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
  // A folder that does not exist: an error naming the file, nothing left behind.
  try {
    write_file_atomically((d / "nope" / "x.csv").string(), "x");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("nope/x.csv"), std::string::npos) << e.what();
  }
}
