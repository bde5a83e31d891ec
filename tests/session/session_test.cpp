// The session layer: one set-up for every front end. Invariants:
// - the input frame is undone exactly: a hip given in LPS (x and y negated) has the gaps of the
//   same hip given in RAS bit for bit, its COR and posed vertices are reported back in LPS;
// - the COR policy: a head-region fit finds the generated head's analytic centre and radius; a
//   given COR outside the head is refused naming both centres (unless allow_any); a subject's
//   hip_centre landmark is used; a given COR wins over the landmark; a hip_centre off the head is refused in the
//   given COR's words;
// - a femur in centimetres is named as such before anything is fitted (a whole one: by its shaft's length);
// - bad options are refused before any file is read, naming the option;
// - the runs equal the library calls they wrap: run_motion's rows are Joint::detect's least gaps
//   at each pose, run_rom's limits find_rom_limits's;
// - a one-pose session (only_poses, cropped hierarchies) detects as a whole session, at the scan pose (its
//   kept scan) and at its poses;
// - tables refuse ragged rows and write RFC 4180 CSV.
#include "impinge/session/session.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <regex>
#include <sstream>
#include <thread>

#include <omp.h>

#include "impinge/casters/embree_ray_caster.hpp"
#include "impinge/core/error.hpp"
#include "impinge/io/generated_models.hpp"
#include "impinge/io/mesh_io.hpp"
#include "impinge/session/records.hpp"
#include "impinge/session/runs.hpp"
#include "test_support.hpp"

using namespace impinge;
namespace fs = std::filesystem;
using impinge::test::error_of;

namespace {

// The generated hip (2000 triangles) with a 2 mm cam bump, or without one (a spherical head).
const HipModel& model(bool cam = true) {
  static const HipModel h[2] = {[] {
                                  HipModelOptions o;
                                  o.target_triangles = 2000;
                                  o.cam_height_mm = 0;
                                  return make_hip_model(o);
                                }(),
                                [] {
                                  HipModelOptions o;
                                  o.target_triangles = 2000;
                                  o.cam_height_mm = 2;
                                  return make_hip_model(o);
                                }()};
  return h[cam ? 1 : 0];
}

// Options for the generated hip given in `frame` (its meshes converted from RAS), true COR given.
SessionOptions generated_options(const std::string& frame, bool cam = true) {
  const HipModel& h = model(cam);
  const Eigen::Matrix3d M = to_working_frame(frame == "LPS" ? FrameConvention::LPS : FrameConvention::RAS);
  SessionOptions o;
  o.input.ball_mesh = h.ball;
  o.input.socket_mesh = h.socket;
  transform_vertices(o.input.ball_mesh->V, M);  // RAS -> frame (M is its own inverse)
  transform_vertices(o.input.socket_mesh->V, M);
  o.input.frame = frame;
  o.cor.given = M * h.cor;
  o.hip.neutral = Neutral::scan;
  o.grid.precision = 1;
  return o;
}

// A real subject.json of the shared data, or "" when the folder is absent.
std::string test_data_subject() {
  const std::string p = std::string(IMPINGE_SHARED_DATA) + "/lhdl-ct/subject.json";
  return fs::exists(p) ? p : std::string();
}

}  // namespace

TEST(Session, LpsInputGivesTheRasGapsAndReportsInLps) {
  const Session ras(generated_options("RAS")), lps(generated_options("LPS"));
  const Eigen::Matrix3d flip = Eigen::Vector3d(-1, -1, 1).asDiagonal();
  EXPECT_TRUE(lps.head_centre_input().isApprox(flip * ras.head_centre_input(), 1e-12));
  EXPECT_TRUE(ras.head_centre_input().isApprox(model().cor, 1e-12));
  for (const PoseAngles& a : {PoseAngles{0, 0, 0}, PoseAngles{30, -10, 5}, PoseAngles{-20, 15, 40}}) {
    const PoseResult r = ras.hip().detect(a), l = lps.hip().detect(a);
    ASSERT_EQ(r.ball_gaps.gap_mm.size(), l.ball_gaps.gap_mm.size());
    for (std::size_t i = 0; i < r.ball_gaps.gap_mm.size(); ++i)
      EXPECT_TRUE(r.ball_gaps.gap_mm[i] == l.ball_gaps.gap_mm[i] ||
                  (std::isnan(r.ball_gaps.gap_mm[i]) && std::isnan(l.ball_gaps.gap_mm[i])));
    EXPECT_EQ(r.socket.min_gap_mm, l.socket.min_gap_mm);
    // Posed vertices come back in each input frame: LPS = flip RAS.
    const Vertices vr = ras.femur_input(ras.hip().femur_pose(a)), vl = lps.femur_input(lps.hip().femur_pose(a));
    EXPECT_LT((vl - vr * flip).cwiseAbs().maxCoeff(), 1e-9);
    // A rotation given in the input frame reaches the joint frame unchanged in effect.
    const Eigen::Matrix3d Rin = lps.input_rotation(lps.hip().femur_rotation(a));
    const auto [Rj, tj] = lps.joint_motion(Rin, Eigen::Vector3d::Zero());
    EXPECT_TRUE(Rj.isApprox(lps.hip().femur_rotation(a), 1e-12));
    EXPECT_EQ(tj.norm(), 0.0);
  }
  const nlohmann::json rec = setup_record(lps);
  EXPECT_EQ(rec["input_frame"], "LPS");
  EXPECT_NEAR(rec["head_centre_mm"][0].get<double>(), -model().cor.x(), 1e-9);
}

TEST(Session, HeadRegionFindsTheAnalyticHead) {
  SessionOptions o = generated_options("RAS", false);  // a spherical head: vertices on the sphere
  o.cor.given.reset();
  const double r = HipModelOptions{}.head_radius_mm;
  const Eigen::Vector3d c = model(false).cor;
  o.cor.head_region = Eigen::Vector4d(c.x() + 0.2, c.y(), c.z(), r + 0.5);  // the head, not the neck
  const Session s(o);
  EXPECT_LT((s.head_centre_input() - c).norm(), 0.05);
  EXPECT_NEAR(s.head().radius, r, 0.05);
  EXPECT_EQ(s.cor_method(), "sphere fit in region");
}

TEST(Session, CorPolicyChecksAndOrder) {
  const auto real = test_data_subject();
  if (real.empty()) GTEST_SKIP() << "shared data absent";
  SessionOptions o;
  o.input.subject = real;
  o.hip.neutral = Neutral::scan;
  o.grid.precision = 2;
  const LoadedInput in = load_input(o.input);
  const CorResult automatic = find_centre_of_rotation(in, {});
  EXPECT_GT(automatic.head.radius, 15);
  EXPECT_LT(automatic.head.radius, 35);
  // 10 mm beyond the head's surface: refused, naming the fitted centre.
  CorOptions far;
  far.given = in.to_working.transpose() *
              (automatic.head.centre + Eigen::Vector3d(automatic.head.radius + 10, 0, 0));
  EXPECT_NE(error_of([&] { find_centre_of_rotation(in, far); }).find("from the fitted femoral head centre"),
            std::string::npos);
  far.allow_any = true;
  EXPECT_EQ(find_centre_of_rotation(in, far).method, "given");
  // A landmark hip_centre is used; a given COR wins over it.
  LoadedInput with = in;
  with.landmarks["hip_centre"] = automatic.head.centre + Eigen::Vector3d(1, 0, 0);
  EXPECT_TRUE(find_centre_of_rotation(with, {}).head.centre.isApprox(with.landmarks["hip_centre"]));
  CorOptions given;
  given.given = in.to_working.transpose() * automatic.head.centre;
  EXPECT_TRUE(find_centre_of_rotation(with, given).head.centre.isApprox(automatic.head.centre, 1e-12));
  given.head_region = Eigen::Vector4d(0, 0, 0, 10);
  EXPECT_NE(error_of([&] { find_centre_of_rotation(in, given); }).find("not both"), std::string::npos);
}

TEST(Session, BadOptionsAreRefusedBeforeAnyFileIsRead) {
  // The subject file does not exist: each error must be about the option, not the file.
  auto refused = [](const std::function<void(SessionOptions&)>& set, const std::string& expected) {
    SessionOptions o;
    o.input.subject = "/nonexistent/subject.json";
    set(o);
    const std::string e = error_of([&] { Session s(o); });
    EXPECT_NE(e.find(expected), std::string::npos) << e;
    EXPECT_EQ(e.find("nonexistent"), std::string::npos) << e;
  };
  // The typed fields are checked against their declared ranges (JointOptions::k...Range), the same the option
  // table's rows use; text choices are checked by the rows (option_table_test).
  refused([](SessionOptions& o) { o.grid.precision = 1, o.grid.spacing = 1; }, "give one of resolution");
  refused([](SessionOptions& o) { o.grid.precision = 200; }, "precision 200 deg is outside the valid range [0, 90]");
  refused([](SessionOptions& o) { o.hip.joint.layers = 99; },
          "JointOptions::layers 99 is outside the valid range [0, 16]");
  refused([](SessionOptions& o) { o.hip.joint.sparse_maps = true, o.hip.joint.sparse_region_mm = -1; },
          "sparse_region_mm -1 mm is outside the valid range (0, inf] mm");
  refused([](SessionOptions& o) { o.grid.scheme = "hexagon"; }, "hexagon");
  refused([](SessionOptions& o) { o.hip.ball_map_file = "a.map"; }, "both map files");
  refused([](SessionOptions& o) { o.hip.joint.levels.thresholds_mm = {1, 2}; }, "not below");
  refused([](SessionOptions& o) { o.hip.joint.discontinuity_tolerance_mm = 0; },
          "discontinuity_tolerance_mm 0 mm is outside the valid range (0, 1000] mm");
  refused([](SessionOptions& o) { o.hip.joint.layered_spacing_deg = 120; }, "layered_spacing_deg 120 deg");
  refused([](SessionOptions& o) { o.hip.joint.extra_articular_radius_mm = 0; }, "extra_articular_radius_mm 0 mm");
  refused([](SessionOptions& o) { o.max_memory_gb = -1; }, "max-memory -1 GB");
  refused([](SessionOptions& o) { o.hip.joint.levels_on = LevelQuantity::distance; }, "needs the distances on");
  refused([](SessionOptions& o) { o.hip.joint.scheme = make_scheme("helix", 100), o.grid.precision = 1; }, "not both");
  EXPECT_NE(error_of([] { parse_cor("1,2", "--cor"); }).find("--cor"), std::string::npos);
  EXPECT_NE(error_of([] { parse_head_region("1,2,3,-4", "--head-region"); }).find("radius"), std::string::npos);
  EXPECT_FALSE(parse_cor("auto", "--cor").has_value());
}

TEST(Session, SideOrFrameContradictingTheSubjectIsAnError) {
  const fs::path d = fs::temp_directory_path() / "impinge_session_test";
  fs::create_directories(d);
  write_ply((d / "femur.ply").string(), model().ball);
  write_ply((d / "pelvis.ply").string(), model().socket);
  std::ofstream((d / "subject.json").string())
      << R"({"side": "right", "frame": "RAS", "units": "mm", "femur": "femur.ply", "pelvis": "pelvis.ply"})";
  SessionInput in;
  in.subject = (d / "subject.json").string();
  EXPECT_EQ(input_side(in), Side::right);
  in.side = "left";
  EXPECT_NE(error_of([&] { load_input(in); }).find("side 'left' contradicts"), std::string::npos);
  in.side = "right";
  in.frame = "LPS";
  EXPECT_NE(error_of([&] { load_input(in); }).find("frame 'LPS' contradicts"), std::string::npos);
  in.frame.clear();
  in.ball_mesh = model().ball;
  in.ball = "femur.ply";
  EXPECT_NE(error_of([&] { load_input(in); }).find("not both"), std::string::npos);
}

// The same gaps, statuses and distances bit for bit (NaN included).
testing::AssertionResult same_scan(const ScanGaps& a, const ScanGaps& b) {
  auto bits = [](const std::vector<float>& x, const std::vector<float>& y) {
    return x.size() == y.size() && (x.empty() || std::memcmp(x.data(), y.data(), x.size() * sizeof(float)) == 0);
  };
  if (!bits(a.gap_mm, b.gap_mm)) return testing::AssertionFailure() << "the gaps differ";
  if (!bits(a.distance_mm, b.distance_mm)) return testing::AssertionFailure() << "the distances differ";
  if (a.status != b.status) return testing::AssertionFailure() << "the statuses differ";
  return testing::AssertionSuccess();
}

// A one-pose session (only_poses, direct set-up: cropped distance hierarchies) keeps its set-up's scan of the
// scan pose and hands it out for that pose: its detect equals a whole session's Joint::detect there, and at a
// pose it was set up for, bit for bit; distances on, so that the crop is exercised too.
TEST(Session, OnePoseSessionDetectsAsAWholeSession) {
  SessionOptions whole_options = generated_options("LPS");
  whole_options.query_strategy = "maps";
  whole_options.hip.joint.distances = true;
  SessionOptions one_options = whole_options;
  one_options.query_strategy = "direct";
  one_options.only_poses = {{0, 0, 0}, {40, 10, -5}};
  const Session whole(whole_options), one(one_options);
  ASSERT_TRUE(one.joint_options().distances);
  for (const PoseAngles& a : one_options.only_poses) {
    const FemurPose pose = one.hip().femur_pose(a);
    const PoseResult got = one.detect(pose);
    const PoseResult want = whole.joint().detect(pose.R, pose.t);
    EXPECT_TRUE(same_scan(got.ball_gaps, want.ball_gaps)) << a.flexion_deg;
    EXPECT_TRUE(same_scan(got.socket_gaps, want.socket_gaps)) << a.flexion_deg;
    EXPECT_EQ(got.ball.min_gap_mm, want.ball.min_gap_mm);
    EXPECT_EQ(got.socket.vertices_penetrating, want.socket.vertices_penetrating);
  }
  // The scan pose itself, and a whole session's detect (which keeps nothing) at it.
  const FemurPose scan = one.hip().scan_pose();
  EXPECT_TRUE(same_scan(one.detect(scan).ball_gaps, whole.detect(scan).ball_gaps));
  EXPECT_TRUE(same_scan(one.detect(scan).socket_gaps, whole.joint().detect(scan.R, scan.t).socket_gaps));
}

TEST(Session, MotionRunEqualsDetectAtEachPose) {
  const Session s(generated_options("LPS"));
  const std::vector<PoseAngles> poses = {{0, 0, 0}, {40, 10, -5}, {80, -15, 30}, {-15, 5, 45}};
  Table t;
  t.columns = motion_columns(s.joint_options().levels);
  run_motion(s, poses, {0.0, 0.5, 1.0, 1.5}, [&](const MotionFrame& f) { t.add(motion_row(f)); });
  ASSERT_EQ(t.rows.size(), poses.size());
  const auto ball = t.column("femur_min_gap_mm"), socket = t.column("pelvis_min_gap_mm"), time = t.column("time_s");
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const PoseResult r = s.joint().detect(s.hip().femur_rotation(poses[k]));
    EXPECT_EQ(ball[k].get<double>(), r.ball.min_gap_mm);
    EXPECT_EQ(socket[k].get<double>(), r.socket.min_gap_mm);
    EXPECT_EQ(time[k].get<double>(), 0.5 * double(k));
  }
  EXPECT_THROW(run_motion(s, poses, {0.0}, [](const MotionFrame&) {}), Error);
}

// Frames are scanned in blocks on every thread and handed over in order, on the calling thread, while the
// next block is scanned: 40 poses (several blocks) on one thread and on two give the same rows, frame by
// frame, each the detection at that frame's pose; an error thrown by the callback stops the run there.
TEST(Session, MotionRunOnTwoThreadsEqualsOneInOrder) {
  const Session s(generated_options("RAS"));
  std::vector<PoseAngles> poses;
  for (int k = 0; k < 40; ++k) poses.push_back({2.5 * k, 10 * std::sin(0.3 * k), 20 * std::cos(0.2 * k)});
  auto run_on = [&](int threads) {
    omp_set_num_threads(threads);
    Table t;
    t.columns = motion_columns(s.joint_options().levels);
    std::vector<std::size_t> order;
    const std::thread::id caller = std::this_thread::get_id();
    run_motion(s, poses, {}, [&](const MotionFrame& f) {
      EXPECT_EQ(std::this_thread::get_id(), caller) << f.index;  // on the calling thread, as documented
      order.push_back(f.index);
      PoseResult r;
      s.joint().detect(f.pose.R, f.pose.t, r);
      EXPECT_EQ(f.result->ball.min_gap_mm, r.ball.min_gap_mm) << f.index;
      EXPECT_EQ(f.result->socket.min_gap_mm, r.socket.min_gap_mm) << f.index;
      nlohmann::json row = motion_row(f);
      row.erase(row.size() - 1);  // detection_ms
      t.rows.push_back(row);
    });
    for (std::size_t k = 0; k < order.size(); ++k) EXPECT_EQ(order[k], k);
    return t;
  };
  const int before = omp_get_max_threads();
  const Table one = run_on(1), two = run_on(2);
  omp_set_num_threads(before);
  ASSERT_EQ(one.rows.size(), poses.size());
  ASSERT_EQ(two.rows.size(), poses.size());
  for (std::size_t k = 0; k < poses.size(); ++k) EXPECT_EQ(one.rows[k].dump(), two.rows[k].dump()) << k;
  std::size_t delivered = 0;
  EXPECT_THROW(run_motion(s, poses, {},
                          [&](const MotionFrame& f) {
                            ++delivered;
                            if (f.index == 20) throw Error("stop at frame 20");
                          }),
               Error);
  EXPECT_EQ(delivered, 21u);
  // A pose that cannot be scanned (a NaN angle) at frame 25: every frame before it is handed over, in
  // order, then its error is thrown; on one thread and on two.
  std::vector<PoseAngles> bad = poses;
  bad[25].flexion_deg = std::nan("");
  for (int threads : {1, 2}) {
    omp_set_num_threads(threads);
    std::vector<std::size_t> seen;
    EXPECT_THROW(run_motion(s, bad, {}, [&](const MotionFrame& f) { seen.push_back(f.index); }), Error) << threads;
    ASSERT_EQ(seen.size(), 25u) << threads;
    for (std::size_t k = 0; k < seen.size(); ++k) EXPECT_EQ(seen[k], k);
  }
  omp_set_num_threads(before);
}

TEST(Session, RomRunEqualsTheLibraryCalls) {
  const Session s(generated_options("RAS"));
  RomRequest q;
  q.map_flexion_deg = {0, 60};
  q.map_adduction_deg = {0, 10};
  const RomRun run = run_rom(s, q);
  const RomBaseline base = rom_baseline(s.hip(), s.hip().femur_rotation({}), q.search);
  const std::vector<RomLimit> direct = find_rom_limits(s.hip(), standard_motions(), q.search, base);
  ASSERT_EQ(run.limits.size(), direct.size());
  const Table t = rom_limits_table(s, run);
  const auto limit = t.column("limit_deg");
  for (std::size_t k = 0; k < direct.size(); ++k) {
    EXPECT_TRUE(run.limits[k].limit_deg == direct[k].limit_deg ||
                (std::isnan(run.limits[k].limit_deg) && std::isnan(direct[k].limit_deg)));
    if (std::isnan(direct[k].limit_deg))
      EXPECT_TRUE(limit[k].is_null());
    else
      EXPECT_EQ(limit[k].get<double>(), direct[k].limit_deg);
  }
  // Scan neutral has no pelvic frame: no limit in either, and the run says why; the published ranges are there,
  // each with its source, the active (living subjects) and the simulated bony ones in their own columns.
  EXPECT_TRUE(run.other_limits.empty());
  EXPECT_FALSE(run.other_frame_note.empty());
  const auto isb = t.column("limit_isb_deg"), app = t.column("limit_app_deg"), status_app = t.column("status_app");
  const auto normal = t.column("normal_deg"), normal_source = t.column("normal_source");
  const auto bony = t.column("bony_normal_deg"), bony_source = t.column("bony_normal_source");
  for (std::size_t k = 0; k < direct.size(); ++k) {
    EXPECT_TRUE(isb[k].is_null() && app[k].is_null() && status_app[k].is_null());
    EXPECT_EQ(normal[k].is_null(), normal_source[k].get<std::string>().empty());
    EXPECT_EQ(bony[k].is_null(), bony_source[k].get<std::string>().empty());
    if (!bony[k].is_null()) {
      EXPECT_NE(bony_source[k], normal_source[k]);
    }
  }
  EXPECT_FALSE(normal[0].is_null());  // flexion: AAOS
  EXPECT_EQ(run.motions[8].name, "fadir");
  EXPECT_FALSE(bony[8].is_null());
  EXPECT_EQ(run.map.size(), 4u);
  EXPECT_EQ(rom_map_table(run).rows.size(), 4u);
  EXPECT_TRUE(rom_envelope_table(run).rows.empty());
}

TEST(Session, TablesRefuseRaggedRowsAndQuoteText) {
  Table t;
  t.columns = {"a", "b"};
  t.add({1, "x,y"});
  EXPECT_THROW(t.add({1}), Error);
  t.add({number_or_null(std::nan("")), "say \"hi\""});
  EXPECT_THROW(t.column("c"), Error);
  const fs::path p = fs::temp_directory_path() / "impinge_table_test.csv";
  write_csv(p.string(), t);
  std::ifstream is(p);
  std::stringstream ss;
  ss << is.rdbuf();
  EXPECT_EQ(ss.str(), "a,b\n1,\"x,y\"\nnan,\"say \"\"hi\"\"\"\n");
}

namespace {
// The 95th percentile of |x|.
double p95(std::vector<double> x) {
  for (double& v : x) v = std::fabs(v);
  std::sort(x.begin(), x.end());
  return x.empty() ? std::nan("") : x[static_cast<std::size_t>(0.95 * double(x.size() - 1))];
}
}  // namespace

// A given COR is the femoral head centre the radial gaps at the scan pose are measured about, under the
// default (equidistant) joint-centre method too: the femur's gaps at detect(I, 0) against an exact ray
// cast from that centre (Embree, watertight) on the first-surface vertices; and the outputs name the
// head, acetabular and maps' centres apart.
class GivenCor : public ::testing::TestWithParam<const char*> {};

TEST_P(GivenCor, IsTheCentreOfTheRadialGapsAtTheScanPose) {
  const std::string json = std::string(IMPINGE_SHARED_DATA) + "/" + GetParam() + "/subject.json";
  if (!fs::exists(json)) GTEST_SKIP() << "shared data absent: " << json;
  if (!have_embree()) GTEST_SKIP() << "no Embree in this build";
  SessionOptions o;
  o.input.subject = json;
  const LoadedInput in = load_input(o.input);
  const Eigen::Vector3d fitted = find_centre_of_rotation(in, {}).head.centre;  // working frame
  // A head centre 0.6 mm off the fitted one, given in the input frame.
  const Eigen::Vector3d given_working = fitted + Eigen::Vector3d(0.4, -0.3, 0.33);
  o.cor.given = in.to_working.transpose() * given_working;
  o.grid.precision = 0.1;
  o.hip.joint.layers = 4;
  o.hip.joint.distances = true;
  const Session s(o);
  ASSERT_EQ(s.hip().joint_centre().method(), JointCentreMethod::equidistant);
  EXPECT_LT((s.head_centre_input() - *o.cor.given).norm(), 1e-9);
  EXPECT_LT((s.map_centre_input() - *o.cor.given).norm(), 1e-9);
  ASSERT_TRUE(s.acetabular_centre_input());
  EXPECT_GT((*s.acetabular_centre_input() - *o.cor.given).norm(), 0.1);
  const auto [R, t] = s.joint_motion(Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  const PoseResult r = s.joint().detect(R, t);
  const Vertices femur = s.femur_input(FemurPose{R, t});  // input frame, as scanned
  EXPECT_LT((femur - in.femur.V * in.to_working).norm(), 1e-6);
  // The reference: exact first hits from the given centre (working frame).
  const EmbreeRayCaster pelvis(in.pelvis, given_working, true), own(in.femur, given_working, true);
  std::vector<double> err;
  for (Eigen::Index i = 0; i < in.femur.V.rows(); ++i) {
    if (r.ball_gaps.status[static_cast<std::size_t>(i)] != ScanGaps::tested) continue;
    const Eigen::Vector3d d = in.femur.V.row(i).transpose() - given_working;
    const float first_own = own.first_hit(float(d.x()), float(d.y()), float(d.z()));
    if (first_own < d.norm() - 0.05) continue;  // behind the femur's own nearer surface
    const float hit = pelvis.first_hit(float(d.x()), float(d.y()), float(d.z()));
    if (!std::isfinite(hit)) continue;
    err.push_back(double(r.ball_gaps.gap_mm[static_cast<std::size_t>(i)]) - (double(hit) - d.norm()));
  }
  ASSERT_GT(err.size(), 500u);
  std::cout << GetParam() << ": p95 " << p95(err) << " mm over " << err.size() << " first-surface femur vertices\n";
  EXPECT_LT(p95(err), 0.05) << err.size() << " first-surface femur vertices";
  const nlohmann::json rec = setup_record(s);
  for (const char* key : {"head_centre_mm", "acetabular_centre_mm", "map_centre_mm"}) EXPECT_TRUE(rec.contains(key)) << key;
  EXPECT_FALSE(rec.contains("cor_mm"));
}

INSTANTIATE_TEST_SUITE_P(Shared, GivenCor, ::testing::Values("lhdl-ct", "mc22", "mc22-left", "tlem2-mri"));

// The pivot each joint-centre method names (pivot_input, summary.json's pivot_mm) is the point the posed femur
// turns about: the rigid motion taking the femur's scan vertices to their posed positions (input frame, fitted by
// Umeyama's least squares over every vertex, an oracle independent of how the session poses) leaves the pivot where
// it is at any pose, for femoral-head and acetabular; for combined it takes the femoral head centre onto it (the head
// seated on the acetabular centre); equidistant names none (its centre moves with each pose).
TEST(Session, ThePivotIsTheFixedPointOfTheFemursMotion) {
  const std::string json = std::string(IMPINGE_SHARED_DATA) + "/lhdl-ct/subject.json";
  if (!fs::exists(json)) GTEST_SKIP() << "shared data absent: " << json;
  for (const JointCentreMethod method : {JointCentreMethod::femoral_head, JointCentreMethod::acetabular,
                                         JointCentreMethod::combined, JointCentreMethod::equidistant}) {
    SessionOptions o;
    o.input.subject = json;
    o.grid.precision = 1.0;
    o.hip.joint_centre = method;
    const Session s(o);
    const auto pivot = pivot_input(s);
    EXPECT_EQ(setup_record(s)["pivot_mm"].is_null(), !pivot.has_value()) << to_string(method);
    if (method == JointCentreMethod::equidistant) {
      EXPECT_FALSE(pivot) << "equidistant names no fixed pivot";
      continue;
    }
    ASSERT_TRUE(pivot) << to_string(method);
    const Vertices scan = s.femur_input(s.hip().scan_pose());
    const Vertices posed = s.femur_input(s.hip().femur_pose({50, 10, 20}));
    const Eigen::Matrix4d m = Eigen::umeyama(scan.transpose(), posed.transpose(), false);
    const Eigen::Vector3d moved_from = method == JointCentreMethod::combined ? s.head_centre_input() : *pivot;
    const Eigen::Vector3d moved = m.topLeftCorner<3, 3>() * moved_from + m.topRightCorner<3, 1>();
    EXPECT_LT((moved - *pivot).norm(), 1e-6) << to_string(method);
    if (method == JointCentreMethod::femoral_head) EXPECT_LT((*pivot - s.head_centre_input()).norm(), 1e-12);
    if (method != JointCentreMethod::femoral_head) EXPECT_LT((*pivot - *s.acetabular_centre_input()).norm(), 1e-12);
  }
}

// A landmark hip_centre off the head is refused as a given COR is, in the same words (check_cor_in_head): the
// generated head (radius 22 mm) and a point 25 mm from its centre; inside the head, or with allow_any, accepted.
TEST(Session, AHipCentreOffTheHeadIsRefusedAsTheCorIs) {
  SessionOptions o = generated_options("RAS", false);
  o.cor.given.reset();
  const Eigen::Vector3d off = model(false).cor + Eigen::Vector3d(25, 0, 0);
  o.input.landmarks["hip_centre"] = off;
  const LoadedInput in = load_input(o.input);
  const std::string as_landmark = error_of([&] { find_centre_of_rotation(in, {}); });
  CorOptions as_cor;
  as_cor.given = off;
  const LoadedInput plain = load_input(generated_options("RAS", false).input);
  const std::string as_given = error_of([&] { find_centre_of_rotation(plain, as_cor); });
  // The head is fitted to the generated polyhedron's surface (fit_sphere_to_surface), whose flat triangles lie
  // within the 22 mm sphere through its vertices: 25 and 22 mm to 0.1 mm.
  std::smatch m;
  ASSERT_TRUE(std::regex_search(as_landmark, m,
                                std::regex("^landmark hip_centre \\(85, -20, 30\\) mm is ([0-9.]+) mm from the fitted "
                                           "femoral head centre .* farther than the head radius ([0-9.]+) mm")))
      << as_landmark;
  EXPECT_NEAR(std::stod(m[1].str()), 25, 0.1) << as_landmark;
  EXPECT_NEAR(std::stod(m[2].str()), 22, 0.1) << as_landmark;
  EXPECT_EQ(as_landmark.substr(std::string("landmark hip_centre").size()), as_given.substr(std::string("cor").size()));
  CorOptions any;
  any.allow_any = true;
  EXPECT_EQ(find_centre_of_rotation(in, any).head.centre, off);
  LoadedInput inside = in;
  inside.landmarks["hip_centre"] = model(false).cor + Eigen::Vector3d(0, 0, 21);
  EXPECT_TRUE(find_centre_of_rotation(inside, {}).fitted_head);
}

// Units: a femur that shows its shaft and is 45 long (an ellipsoid 45 x 9 x 9, as a whole femur in centimetres) is
// refused asking whether it is in centimetres, the same ten times larger is read; the generated hip in centimetres
// (10 across) is refused as centimetres or inches, in metres as metres.
TEST(Session, AMeshInCentimetresIsNamedBeforeAnythingIsFitted) {
  const auto ellipsoid = [](double scale) {
    return make_radial_surface(
        [&](const Eigen::Vector3d& u) {
          return scale / std::sqrt(std::pow(u.x() / 4.5, 2) + std::pow(u.y() / 4.5, 2) + std::pow(u.z() / 22.5, 2));
        },
        Eigen::Vector3d::Zero(), 24, 24, Eigen::Vector3d::UnitZ());
  };
  SessionInput input;
  input.ball_mesh = ellipsoid(1);
  input.socket_mesh = model().socket;
  std::string e = error_of([&] { load_input(input); });
  EXPECT_NE(e.find("generated radial surface: the femur is 45 long and 5 times as long as wide"), std::string::npos)
      << e;
  EXPECT_NE(e.find("is the mesh in centimetres (scale by 10)?"), std::string::npos) << e;
  input.ball_mesh = ellipsoid(10);
  EXPECT_EQ(error_of([&] { load_input(input); }), "(no error)");
  for (const auto& [scale, unit] : {std::pair{0.1, "centimetres (scale by 10) or inches (by 25.4)?"},
                                    std::pair{0.001, "metres (scale by 1000) or inches (by 25.4)?"}}) {
    input.ball_mesh = model().ball;
    input.socket_mesh = model().socket;
    input.ball_mesh->V *= scale;
    input.socket_mesh->V *= scale;
    e = error_of([&] { load_input(input); });
    EXPECT_NE(e.find(unit), std::string::npos) << e;
  }
}
