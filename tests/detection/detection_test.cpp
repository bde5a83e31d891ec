// Detection (thesis Algorithm 2) against analytic gaps:
//  - concentric ball (r_b) and cup (r_c): every tested ball and socket vertex has gap r_c - r_b
//    within faceting + interpolation bounds that shrink with precision;
//  - moving ball and socket together (translation, rotation about z by whole grid steps) leaves
//    every gap unchanged;
//  - a ball pushed into the cup reports penetration with the analytic depth;
//  - vertices hidden behind their own first surface are skipped and counted, not reported;
//  - the fast scan with a translation matches CGAL's exact radial gap, and Joint::detect the
//    fast scan; a scan set keeps exactly the masked vertices;
//  - a scan's summary and clock summary match brute-force counts on random scans.
#include "impinge/detection/detection.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>

#include "impinge/anatomy/pose.hpp"
#include "impinge/clinical/clock_summary.hpp"
#include "impinge/casters/exact_reference.hpp"
#include "impinge/core/error.hpp"
#include "impinge/core/spherical_frame.hpp"
#include "impinge/detection/joint.hpp"
#include "impinge/io/generated_models.hpp"
#include "test_support.hpp"

using namespace impinge;

namespace {
double sagitta(double r, double edge_angle_rad) { return r * (1 - std::cos(edge_angle_rad / 2)); }
}  // namespace

TEST(Detection, ConcentricBallAndCupGiveRadiusDifference) {
  const Eigen::Vector3d cor(10, -20, 30);
  const double rb = 22, rc = 25;
  const int n = 360;  // 1 deg mesh
  const TriangleMesh ball = make_uv_sphere(rb, cor, n, n / 2, Eigen::Vector3d(0.3, 0.2, 0.93));
  const TriangleMesh cup = make_cup(rc, rc + 5, 100, cor, Eigen::Vector3d(-0.5, 0.1, 0.86), n, 100);
  // Faceting: cup mesh chords lie inside its sphere by <= sagitta over the cell diagonal; ball
  // vertices lie exactly on theirs. Interpolation of a constant-radius map adds the same order.
  const double facet = sagitta(rc, std::sqrt(2.0) * 2 * kPi / n) + sagitta(rb, std::sqrt(2.0) * 2 * kPi / n);
  // Equiangular at three precisions and the helix (USID) at two: the bound shrinks with the
  // scheme's node spacing h (resampled helix maps interpolate twice: 2 sagittas).
  const std::vector<std::pair<std::string, double>> schemes{
      {"equiangular", 1.0}, {"equiangular", 0.5}, {"equiangular", 0.25}, {"helix", 229}, {"helix", 458}};
  for (DistanceMode mode : {DistanceMode::exact, DistanceMode::linear}) {
    for (const auto& [name, res] : schemes) {
      JointOptions o;
      o.scheme = make_scheme(name, res);
      o.mode = mode;
      const Joint j(ball, cup, cor, o);
      const PoseResult r = j.detect(Eigen::Matrix3d::Identity());
      const double h = o.scheme->max_node_spacing();
      const double bound = facet + (name == "helix" ? 2 : 1) * sagitta(rc, std::sqrt(2.0) * h) + 1e-4;
      const double p = res;
      std::int64_t tested = 0;
      for (std::size_t i = 0; i < r.ball_gaps.gap_mm.size(); ++i) {
        if (r.ball_gaps.status[i] != ScanGaps::tested) continue;
        ++tested;
        ASSERT_NEAR(r.ball_gaps.gap_mm[i], rc - rb, bound) << "ball vertex " << i << " " << name << " " << p;
      }
      EXPECT_GT(tested, 1000);
      for (std::size_t i = 0; i < r.socket_gaps.gap_mm.size(); ++i)
        if (r.socket_gaps.status[i] == ScanGaps::tested) {
          ASSERT_NEAR(r.socket_gaps.gap_mm[i], rc - rb, bound) << "socket vertex " << i;
        }
      // the cup's outer shell is hidden behind its inner shell: skipped, not a 5 mm-farther gap
      EXPECT_GT(r.socket.vertices_beyond_reach, 1000);
      EXPECT_EQ(r.ball.vertices_penetrating, 0);
    }
  }
}

TEST(Detection, MovingBothBodiesTogetherLeavesGapsUnchanged) {
  HipModelOptions ho;
  ho.target_triangles = 3000;
  ho.cam_height_mm = 2;
  const HipModel h = make_hip_model(ho);
  JointOptions o;
  o.scheme = make_scheme("equiangular", 0.5);
  // The maps alone: with exact look-ups at depth discontinuities, which look-ups are resolved
  // exactly depends on node values to rounding, and exact and interpolated gaps there differ by up
  // to the discontinuity tolerance (depth_discontinuity_test.cpp tests that path).
  o.exact_at_discontinuities = false;
  const Eigen::Matrix3d pose = pose_rotation({20, 10, 5}, Side::right);
  const PoseResult a = Joint(h.ball, h.socket, h.cor, o).detect(pose);
  // Rigid motion of the whole joint: translate, and rotate about z by 7 grid steps (the map's
  // grid then maps onto itself, so the gaps must agree to rounding).
  const Eigen::Matrix3d Rz = Eigen::AngleAxisd(7 * 0.5 * kDegToRad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d t(-40, 13, 100);
  const TriangleMesh ball2 = test::transformed(h.ball, Rz, t), socket2 = test::transformed(h.socket, Rz, t);
  const Eigen::Vector3d cor2 = Rz * h.cor + t;
  const PoseResult b = Joint(ball2, socket2, cor2, o).detect(Rz * pose * Rz.transpose());
  ASSERT_EQ(a.ball_gaps.gap_mm.size(), b.ball_gaps.gap_mm.size());
  int compared = 0;
  for (std::size_t i = 0; i < a.ball_gaps.gap_mm.size(); ++i) {
    ASSERT_EQ(a.ball_gaps.status[i], b.ball_gaps.status[i]) << i;
    if (a.ball_gaps.status[i] != ScanGaps::tested) continue;
    ++compared;
    EXPECT_NEAR(a.ball_gaps.gap_mm[i], b.ball_gaps.gap_mm[i], 1e-4) << i;
  }
  for (std::size_t i = 0; i < a.socket_gaps.gap_mm.size(); ++i)
    if (a.socket_gaps.status[i] == ScanGaps::tested) {
      EXPECT_NEAR(a.socket_gaps.gap_mm[i], b.socket_gaps.gap_mm[i], 1e-4) << i;
    }
  EXPECT_GT(compared, 100);
}

TEST(Detection, PushedBallReportsPenetrationDepth) {
  // Ball of radius 22 in a cup of radius 23, ball centre moved 3 mm toward the cup pole: the
  // deepest ball vertex is 2 mm beyond the cup surface (analytic: 22 + 3 - 23).
  const Eigen::Vector3d cor = Eigen::Vector3d::Zero(), axis = Eigen::Vector3d(0.2, -0.3, 0.93).normalized();
  const TriangleMesh ball = make_uv_sphere(22, cor + 3 * axis, 240, 120, Eigen::Vector3d(1, 0, 0.2));
  const TriangleMesh cup = make_cup(23, 28, 90, cor, axis, 240, 60);
  JointOptions o;
  o.scheme = make_scheme("equiangular", 0.25);
  o.occlusion_tolerance_mm = 10;  // the shifted ball is not star-shaped about cor in the same way
  const PoseResult r = Joint(ball, cup, cor, o).detect(Eigen::Matrix3d::Identity());
  EXPECT_NEAR(r.ball.min_gap_mm, -2.0, 0.05);
  EXPECT_GT(r.ball.vertices_penetrating, 100);
  EXPECT_GT(r.ball.area_penetrating_mm2, 0);
  EXPECT_GT(r.ball.level_vertices.back(), 0);  // purple
}

TEST(Detection, ScanOfMaskedAndNoSurfaceVertices) {
  // Direct use of scan_gaps: masked vertices are beyond reach, directions the map does not
  // cover are no surface, and gaps follow the sign convention of each side.
  RadialDistanceMap map{EquiangularGrid(1)};
  for (std::int64_t i = 0; i < map.num_nodes() / 2; ++i) map.data()[i] = 10;  // northern half only
  Vertices P(4, 3);
  P << 0, 0, 8,  // inside the 10 mm surface: gap 2 (inside) / -2 (outside)
      0, 0, 12,  // beyond it
      0, 0, -5,  // southern: no surface
      0, 0, 9;   // masked
  std::vector<std::uint8_t> mask{1, 1, 1, 0};
  ScanGaps g;
  scan_gaps(P, Eigen::Matrix3d::Identity(), mask, map, ScanSide::inside, g);
  EXPECT_FLOAT_EQ(g.gap_mm[0], 2);
  EXPECT_FLOAT_EQ(g.gap_mm[1], -2);
  EXPECT_EQ(g.status[2], ScanGaps::no_surface);
  EXPECT_EQ(g.status[3], ScanGaps::beyond_reach);
  scan_gaps(P, Eigen::Matrix3d::Identity(), mask, map, ScanSide::outside, g);
  EXPECT_FLOAT_EQ(g.gap_mm[0], -2);
  const ScanSummary s = summarize_scan(g, Eigen::VectorXd::Ones(4), ImpingementLevels{});
  EXPECT_EQ(s.vertices_tested, 2);
  EXPECT_EQ(s.vertices_no_surface, 1);
  EXPECT_EQ(s.vertices_beyond_reach, 1);
  EXPECT_EQ(s.vertices_penetrating, 1);
  EXPECT_FLOAT_EQ(s.min_gap_mm, -2);
}

// summarize_scan against a brute-force reading of its documentation, on random scans that mix every status
// with and without a gap and a distance (a vertex beyond reach may still carry either: ScanGaps is public),
// levels on the radial gap and on the distance; and clock_summary against the same reading of its own.
TEST(Detection, ScanSummaryMatchesABruteForceCount) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  const ImpingementLevels levels;  // 4, 2.667, 1.333, 0 mm
  for (int trial = 0; trial < 80; ++trial) {
    const std::size_t n = 1 + static_cast<std::size_t>(u(rng) * 600);
    ScanGaps g;
    const bool has_distance = trial % 4 != 0;
    Eigen::VectorXd area(static_cast<Eigen::Index>(n));
    std::vector<double> hours(n);
    // Half the trials as a real scan is: mostly runs of untested vertices (beyond reach, neither gap nor
    // distance), which the summaries skip eight at a time, broken by single vertices of every kind.
    const double untested = trial % 2 == 0 ? 0.95 : 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      if (u(rng) < untested) {
        g.status.push_back(ScanGaps::beyond_reach);
        g.gap_mm.push_back(std::nanf(""));
        if (has_distance) g.distance_mm.push_back(std::nanf(""));
        area[static_cast<Eigen::Index>(i)] = 0.1 + u(rng);
        hours[i] = u(rng) * 12;
        continue;
      }
      const auto status = static_cast<std::uint8_t>(std::min(3.0, std::floor(u(rng) * 4)));
      g.status.push_back(status);
      const bool gap = status == ScanGaps::tested || status == ScanGaps::tested_layered || u(rng) < 0.1;
      g.gap_mm.push_back(gap ? static_cast<float>(u(rng) * 12 - 4) : std::nanf(""));
      if (has_distance) g.distance_mm.push_back(u(rng) < 0.5 ? static_cast<float>(u(rng) * 10 - 3) : std::nanf(""));
      area[static_cast<Eigen::Index>(i)] = 0.1 + u(rng);
      hours[i] = u(rng) < 0.1 ? std::nan("") : u(rng) * 12;
    }
    g.distance_winding = trial;
    for (LevelQuantity q : {LevelQuantity::radial_gap, LevelQuantity::distance}) {
      const ScanSummary s = summarize_scan(g, area, levels, q);
      const bool by_distance = q == LevelQuantity::distance && has_distance;
      std::int64_t tested = 0, layered = 0, no_surface = 0, beyond = 0, penetrating = 0, measured = 0, inside = 0;
      double min_gap = INFINITY, min_layered = INFINITY, min_distance = INFINITY, a_pen = 0, a_in = 0;
      std::vector<std::int64_t> count(static_cast<std::size_t>(levels.count()), 0);
      std::vector<double> level_area(count.size(), 0.0), sector(static_cast<std::size_t>(12 * levels.count()), 0.0);
      double closest = INFINITY, closest_hour = std::nan("");
      for (std::size_t i = 0; i < n; ++i) {
        const double a = area[static_cast<Eigen::Index>(i)], gap = g.gap_mm[i];
        const double d = has_distance ? g.distance_mm[i] : std::nan("");
        const bool is_tested = g.status[i] == ScanGaps::tested || g.status[i] == ScanGaps::tested_layered;
        beyond += g.status[i] == ScanGaps::beyond_reach;
        no_surface += g.status[i] == ScanGaps::no_surface;
        if (is_tested) {
          ++tested;
          min_gap = std::min(min_gap, gap);
          if (g.status[i] == ScanGaps::tested_layered) ++layered, min_layered = std::min(min_layered, gap);
          if (gap <= 0) ++penetrating, a_pen += a;
        }
        if (!std::isnan(d)) {
          ++measured;
          min_distance = std::min(min_distance, d);
          if (d < 0) ++inside, a_in += a;
        }
        int level = 255;
        if (by_distance)
          level = !std::isnan(d) ? levels.level(d) : is_tested ? 0 : 255;
        else if (!std::isnan(gap))
          level = levels.level(gap);
        if (level == 255) continue;
        ++count[static_cast<std::size_t>(level)];
        level_area[static_cast<std::size_t>(level)] += a;
        if (std::isnan(hours[i])) continue;
        sector[static_cast<std::size_t>(ClockFace::sector(hours[i]) * levels.count() + level)] += a;
        const double value = by_distance ? d : gap;
        if (value < closest) closest = value, closest_hour = hours[i];
      }
      EXPECT_EQ(s.vertices, static_cast<std::int64_t>(n));
      EXPECT_EQ(s.vertices_tested, tested);
      EXPECT_EQ(s.vertices_tested_layered, layered);
      EXPECT_EQ(s.vertices_no_surface, no_surface);
      EXPECT_EQ(s.vertices_beyond_reach, beyond);
      EXPECT_EQ(s.vertices_penetrating, penetrating);
      EXPECT_NEAR(s.area_penetrating_mm2, a_pen, 1e-9);
      EXPECT_EQ(s.vertices_distance, measured);
      EXPECT_EQ(s.vertices_inside, inside);
      EXPECT_NEAR(s.area_inside_mm2, a_in, 1e-9);
      EXPECT_EQ(s.distance_winding, trial);
      if (tested > 0) EXPECT_EQ(s.min_gap_mm, min_gap); else EXPECT_TRUE(std::isnan(s.min_gap_mm));
      if (layered > 0) EXPECT_EQ(s.min_gap_layered_mm, min_layered); else EXPECT_TRUE(std::isnan(s.min_gap_layered_mm));
      if (measured > 0) EXPECT_EQ(s.min_distance_mm, min_distance); else EXPECT_TRUE(std::isnan(s.min_distance_mm));
      EXPECT_EQ(s.levels_on, by_distance ? LevelQuantity::distance : LevelQuantity::radial_gap);
      EXPECT_EQ(s.level_vertices, count);
      for (std::size_t k = 0; k < count.size(); ++k) EXPECT_NEAR(s.level_area_mm2[k], level_area[k], 1e-9);
      ClockSummary c;
      clock_summary(g, hours, area, levels, c, q);
      ASSERT_EQ(c.sector_level_area_mm2.size(), sector.size());
      for (std::size_t k = 0; k < sector.size(); ++k) EXPECT_NEAR(c.sector_level_area_mm2[k], sector[k], 1e-9);
      if (std::isnan(closest_hour)) EXPECT_TRUE(std::isnan(c.closest_hour)); else EXPECT_EQ(c.closest_hour, closest_hour);
    }
  }
  // Arrays of different lengths are refused, naming the counts.
  ScanGaps bad;
  bad.gap_mm = {1.0f, 2.0f};
  bad.status = {ScanGaps::tested};
  EXPECT_THROW(summarize_scan(bad, Eigen::VectorXd::Ones(2), levels), Error);
  ClockSummary c;
  EXPECT_THROW(clock_summary(bad, std::vector<double>(2, 1.0), Eigen::VectorXd::Ones(2), levels, c), Error);
  bad.status.push_back(ScanGaps::tested);
  EXPECT_THROW(summarize_scan(bad, Eigen::VectorXd::Ones(3), levels), Error);
  bad.distance_mm = {0.5f};
  EXPECT_THROW(summarize_scan(bad, Eigen::VectorXd::Ones(2), levels), Error);
  EXPECT_THROW(clock_summary(bad, std::vector<double>(2, 1.0), Eigen::VectorXd::Ones(2), levels, c), Error);
}

// The fast scan with a translation against the exact radial gap (CGAL), and the scan set: the
// head pushed into the cup gives every gap within the map's interpolation error of the exact one,
// and Joint::detect with the same translation reports the same gaps per vertex.
TEST(Detection, TranslatedScanMatchesTheExactRadialGap) {
  if (!have_exact_reference()) GTEST_SKIP() << "no CGAL in this build";
  HipModelOptions o;
  o.target_triangles = 3000;
  o.cam_height_mm = 2;
  const HipModel h = make_hip_model(o);
  JointOptions jo;
  jo.scheme = make_scheme("equiangular", 0.25);
  const Joint joint(h.ball, h.socket, h.cor, jo);
  const ExactReference socket_ref(h.socket);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.1, Eigen::Vector3d(0.3, 1, 0.2).normalized()).toRotationMatrix();
  const Eigen::Vector3d t = 3.0 * (h.socket.V.colwise().mean().transpose() - h.cor).normalized();
  const ScanSet& set = joint.ball().scan_set;
  ASSERT_GT(set.size(), 100);
  std::vector<float> gaps(std::size_t(set.size()));
  const std::int64_t refined =
      scan_gaps_compact(set, R, t, joint.socket().map, ScanSide::inside, gaps.data(), joint.socket().exact.get());
  const PoseResult res = joint.detect(R, t);
  EXPECT_EQ(refined, res.ball_gaps.refined);
  EXPECT_EQ(refined, res.ball.vertices_refined);
  int compared = 0, penetrating = 0;
  for (std::int64_t j = 0; j < set.size(); ++j) {
    const std::size_t i = std::size_t(set.index[std::size_t(j)]);
    EXPECT_TRUE(std::isnan(gaps[j]) ? std::isnan(res.ball_gaps.gap_mm[i]) : gaps[j] == res.ball_gaps.gap_mm[i]) << j;
    const Eigen::Vector3d q = R * Eigen::Vector3d(set.x[j], set.y[j], set.z[j]) + t;
    const auto hit = socket_ref.first_hit(h.cor, q.normalized());
    if (!hit || std::isnan(gaps[j])) continue;
    ++compared;
    penetrating += gaps[j] < 0;
    EXPECT_NEAR(gaps[j], *hit - q.norm(), 0.02) << j;
  }
  EXPECT_GT(compared, 100);
  EXPECT_GT(penetrating, 0);  // a 3 mm push towards the cup closes its 2.5 mm cartilage space
  // Vertices outside the set are beyond reach; the set holds each masked vertex once.
  std::int64_t beyond = 0;
  for (auto st : res.ball_gaps.status) beyond += st == ScanGaps::beyond_reach;
  EXPECT_EQ(beyond + set.size(), set.vertices);
}

TEST(Detection, ScanSetRejectsAMaskOfTheWrongSize) {
  const Vertices P = Vertices::Random(10, 3);
  EXPECT_THROW(make_scan_set(P, std::vector<std::uint8_t>(9, 1)), Error);
  const ScanSet s = make_scan_set(P, std::vector<std::uint8_t>{1, 0, 1, 0, 1, 0, 1, 0, 1, 0});
  EXPECT_EQ(s.size(), 5);
  std::vector<std::int32_t> idx = s.index;
  std::sort(idx.begin(), idx.end());
  EXPECT_EQ(idx, (std::vector<std::int32_t>{0, 2, 4, 6, 8}));
  for (std::int64_t j = 0; j < s.size(); ++j) EXPECT_EQ(s.x[j], P(s.index[j], 0));
}

// The two bodies are built as their parts on two threads (run_task_graph): a bad mesh on either side is still an
// error naming that mesh's file, and a joint built twice gives the same maps and gaps.
TEST(Detection, JointBuiltOnTwoThreadsNamesTheBadMeshAndIsDeterministic) {
  const Eigen::Vector3d cor(0, 0, 0);
  TriangleMesh ball = make_uv_sphere(22, cor, 90, 45, Eigen::Vector3d::UnitZ());
  TriangleMesh cup = make_cup(25, 30, 100, cor, Eigen::Vector3d::UnitZ(), 90, 30);
  ball.source = "ball.ply", cup.source = "cup.ply";
  JointOptions o;
  o.scheme = make_scheme("equiangular", 1.0);
  o.layers = 2;
  const Joint a(ball, cup, cor, o), b(ball, cup, cor, o);
  const PoseResult ra = a.detect(Eigen::Matrix3d::Identity()), rb = b.detect(Eigen::Matrix3d::Identity());
  for (std::int64_t i = 0; i < a.socket().map.num_nodes(); ++i) ASSERT_EQ(a.socket().map.at(i), b.socket().map.at(i));
  ASSERT_EQ(ra.ball_gaps.gap_mm.size(), rb.ball_gaps.gap_mm.size());
  for (std::size_t i = 0; i < ra.socket_gaps.gap_mm.size(); ++i)
    ASSERT_TRUE(ra.socket_gaps.gap_mm[i] == rb.socket_gaps.gap_mm[i] ||
                (std::isnan(ra.socket_gaps.gap_mm[i]) && std::isnan(rb.socket_gaps.gap_mm[i])));
  TriangleMesh bad_cup = cup, bad_ball = ball;
  bad_cup.V(7, 1) = std::nan("");
  bad_ball.V(3, 0) = std::numeric_limits<double>::infinity();
  auto message = [&](const TriangleMesh& x, const TriangleMesh& y) {
    try {
      const Joint j(x, y, cor, o);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(ball, bad_cup).find("cup.ply"), std::string::npos) << message(ball, bad_cup);
  EXPECT_NE(message(bad_ball, cup).find("ball.ply"), std::string::npos) << message(bad_ball, cup);
  // Both bad: the ball's error, as a serial build would have shown it (its parts rank before the socket's).
  EXPECT_NE(message(bad_ball, bad_cup).find("ball.ply"), std::string::npos) << message(bad_ball, bad_cup);
}
