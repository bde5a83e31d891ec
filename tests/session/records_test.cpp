// The session layer's records (records.hpp) and runs (runs.hpp) against brute force on the same scans.
// Invariants: a scan's record counts its statuses and penetrating vertices as a count over the per-vertex
// arrays does, and its least gap and distance are their minima; summary.json's three centres are consistent
// (the maps' centre is the head centre plus the seat) and in the input frame; a motion row has a cell per
// column; a ROM run asked for its map alone computes no limit and the map that rom_map computes.
#include "impinge/session/records.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "impinge/session/runs.hpp"
#include "test_support.hpp"

using namespace impinge;

namespace {

const Session& session() { return test::generated_session("RAS"); }

}  // namespace

TEST(Records, ScanRecordCountsAsTheVertexArraysDo) {
  const Session& s = session();
  const FemurPose pose = s.hip().femur_pose({40, 0, 30});  // deep enough to penetrate
  const PoseResult r = s.joint().detect(pose.R, pose.t);
  for (const bool ball : {true, false}) {
    const ScanGaps& g = ball ? r.ball_gaps : r.socket_gaps;
    const nlohmann::json j = scan_record(ball ? s.joint().ball() : s.joint().socket(), ball ? r.ball : r.socket, 0,
                                         s.joint_options().levels, nullptr);
    std::int64_t tested = 0, no_surface = 0, beyond = 0, penetrating = 0;
    double least = std::numeric_limits<double>::infinity(), least_distance = least;
    for (std::size_t i = 0; i < g.gap_mm.size(); ++i) {
      tested += g.status[i] == ScanGaps::tested || g.status[i] == ScanGaps::tested_layered;
      no_surface += g.status[i] == ScanGaps::no_surface;
      beyond += g.status[i] == ScanGaps::beyond_reach;
      if (!std::isnan(g.gap_mm[i])) least = std::min(least, double(g.gap_mm[i])), penetrating += g.gap_mm[i] <= 0;
      if (!std::isnan(g.distance_mm[i])) least_distance = std::min(least_distance, double(g.distance_mm[i]));
    }
    EXPECT_EQ(j["vertices"].get<std::int64_t>(), static_cast<std::int64_t>(g.gap_mm.size()));
    EXPECT_EQ(j["vertices_tested"].get<std::int64_t>(), tested);
    EXPECT_EQ(j["vertices_no_surface"].get<std::int64_t>(), no_surface);
    EXPECT_EQ(j["vertices_beyond_reach"].get<std::int64_t>(), beyond);
    EXPECT_EQ(j["vertices_penetrating"].get<std::int64_t>(), penetrating);
    EXPECT_FLOAT_EQ(j["min_gap_mm"].get<float>(), float(least));
    EXPECT_FLOAT_EQ(j["min_distance_mm"].get<float>(), float(least_distance));
  }
  EXPECT_GT(r.ball.vertices_penetrating + r.socket.vertices_penetrating, 0);
}

TEST(Records, SetupRecordNamesThreeConsistentCentres) {
  const Session& s = session();
  const nlohmann::json j = setup_record(s);
  auto vec = [&](const char* k) {
    return Eigen::Vector3d(j[k][0].get<double>(), j[k][1].get<double>(), j[k][2].get<double>());
  };
  EXPECT_LT((vec("head_centre_mm") - s.head_centre_input()).norm(), 1e-12);
  EXPECT_LT((vec("map_centre_mm") - (s.head_centre_input() + s.to_input(s.hip().seat_mm()))).norm(), 1e-9);
  EXPECT_FALSE(j.contains("acetabular_centre_mm"));  // scan neutral: no acetabulum
  EXPECT_FALSE(j.contains("cor_mm"));
  EXPECT_TRUE(number_or_null(std::nan("")).is_null());
  EXPECT_EQ(number_or_null(2.5).get<double>(), 2.5);
}

TEST(Runs, MotionRowsHaveACellPerColumn) {
  const Session& s = session();
  std::size_t rows = 0;
  const std::vector<std::string> columns = motion_columns(s.joint_options().levels);
  run_motion(s, {{0, 0, 0}, {30, 5, 10}, {60, -5, 20}}, {0, 0.5, 1}, [&](const MotionFrame& f) {
    EXPECT_EQ(motion_row(f).size(), columns.size());
    EXPECT_EQ(f.index, rows);
    ++rows;
  });
  EXPECT_EQ(rows, 3u);
}

TEST(Runs, AMapAloneComputesNoLimitAndTheLibrarysMap) {
  const Session& s = session();
  RomRequest q;
  q.limits = false;
  q.map_flexion_deg = {0, 45, 90};
  q.map_adduction_deg = {-10, 10};
  const RomRun run = run_rom(s, q);
  EXPECT_TRUE(run.limits.empty());
  const RomBaseline base = rom_baseline(s.hip(), s.hip().femur_rotation({}), q.search);
  const std::vector<RomMapCell> direct = rom_map(s.hip(), q.map_flexion_deg, q.map_adduction_deg, q.search, base);
  ASSERT_EQ(run.map.size(), direct.size());
  for (std::size_t k = 0; k < direct.size(); ++k) {
    const double a = run.map[k].max_internal_rotation_deg, b = direct[k].max_internal_rotation_deg;
    EXPECT_TRUE((std::isnan(a) && std::isnan(b)) || a == b) << k;
  }
  EXPECT_EQ(rom_map_table(run).rows.size(), 6u);
  EXPECT_TRUE(rom_limits_table(s, run).rows.empty());
}
