// The distance scan (detection/surface_distance.hpp, Joint with distances) against CGAL:
// - every measured vertex's distance equals CGAL's AABB-tree closest distance of the posed vertex to the
//   other mesh (unsigned, 1e-6 mm), and its sign the inside/outside of the majority of three rays'
//   crossing parities through CGAL (independent code), wherever the vertex is more than 0.01 mm off the
//   surface;
// - every vertex left without a distance is farther than the reach by CGAL;
// - on a generated hip pushed into its cup and on every shared subject at rest and at 10 poses up to
//   110 deg flexion (the Done-when of issue 26);
// - distance hierarchies cropped to the poses asked for change no gap, status or distance, at those poses and
//   at others.
#include "impinge/detection/surface_distance.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <optional>
#include <random>

#include "impinge/casters/exact_reference.hpp"
#include "impinge/core/error.hpp"
#include "impinge/detection/joint.hpp"
#include "impinge/io/generated_models.hpp"
#include "test_support.hpp"

using namespace impinge;

namespace {
// Whether two float arrays are the same value for value (NaN where the other is NaN), naming the first vertex that is not.
::testing::AssertionResult same_floats(const std::vector<float>& a, const std::vector<float>& b) {
  if (a.size() != b.size())
    return ::testing::AssertionFailure() << a.size() << " values against " << b.size();
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::isnan(a[i]) != std::isnan(b[i]) || (!std::isnan(a[i]) && a[i] != b[i]))
      return ::testing::AssertionFailure() << "vertex " << i << ": " << a[i] << " against " << b[i];
  return ::testing::AssertionSuccess();
}
using impinge::test::inside_by_parity;

struct Checked {
  std::int64_t measured = 0, far = 0, signs = 0;
  double worst = 0;
};

/// Check one scan's distances (body `own` posed by x -> cor + R (x - cor) + t into `other`'s frame).
void check_scan(const TriangleMesh& own, const Eigen::Vector3d& cor, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                const ExactReference& other, const std::vector<float>& distance, double reach, double max_radius,
                std::mt19937_64& rng, Checked& c, const std::string& what) {
  ASSERT_EQ(static_cast<Eigen::Index>(distance.size()), own.V.rows());
  std::uniform_real_distribution<double> U(0, 1);
  for (Eigen::Index i = 0; i < own.V.rows(); ++i) {
    const Eigen::Vector3d p = own.V.row(i).transpose() - cor;
    if (p.norm() > max_radius) continue;
    const Eigen::Vector3d q = cor + R * p + t;
    const float d = distance[static_cast<std::size_t>(i)];
    if (std::isnan(d)) {
      // Left out: CGAL must put it beyond the reach.
      if (U(rng) < 0.05) {  // a sample: the far vertices are many
        ASSERT_GT(other.closest_distance(q), reach - 1e-6) << what << " vertex " << i;
        ++c.far;
      }
      continue;
    }
    ++c.measured;
    const double exact = other.closest_distance(q);
    c.worst = std::max(c.worst, std::abs(std::abs(static_cast<double>(d)) - exact));
    ASSERT_NEAR(std::abs(d), exact, 1e-4) << what << " vertex " << i;
    if (exact > 0.01 && (exact < 1 || U(rng) < 0.1)) {
      ASSERT_EQ(d < 0, inside_by_parity(other, q)) << what << " vertex " << i << " distance " << d;
      ++c.signs;
    }
  }
}

void check_joint(const Joint& joint, const std::vector<Eigen::Matrix3d>& poses, const Eigen::Vector3d& t,
                 const std::string& name) {
  const ExactReference ball(joint.ball().mesh), socket(joint.socket().mesh);
  std::mt19937_64 rng(11);
  Checked c;
  const double reach = joint.options().reach_mm();
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const Eigen::Matrix3d& R = poses[k];
    const PoseResult r = joint.detect(R, t);
    const std::string what = name + " pose " + std::to_string(k);
    check_scan(joint.ball().mesh, joint.cor(), R, t, socket, r.ball_gaps.distance_mm, reach,
               joint.options().max_radius_mm, rng, c, what + " ball");
    // Socket vertices into the ball's frame: cor + R^T (p - cor - t).
    check_scan(joint.socket().mesh, joint.cor(), R.transpose(), -(R.transpose() * t), ball,
               r.socket_gaps.distance_mm, reach, joint.options().max_radius_mm, rng, c, what + " socket");
    // The radial gap bounds the distance's size from above (its point along the ray lies on the other
    // surface), to the maps' interpolation error.
    for (const ScanGaps* g : {&r.ball_gaps, &r.socket_gaps})
      for (std::size_t i = 0; i < g->gap_mm.size(); ++i)
        if (std::isfinite(g->gap_mm[i]) && std::isfinite(g->distance_mm[i])) {
          ASSERT_LE(std::abs(g->distance_mm[i]), std::abs(g->gap_mm[i]) + 0.05) << what << " vertex " << i;
        }
  }
  EXPECT_GT(c.measured, 100) << name;
  EXPECT_GT(c.signs, 50) << name;
  std::cout << name << ": " << c.measured << " distances (worst " << c.worst << " mm), " << c.signs
            << " signs, " << c.far << " far vertices checked\n";
}

std::vector<Eigen::Matrix3d> flexion_poses() {
  std::vector<Eigen::Matrix3d> poses{Eigen::Matrix3d::Identity()};
  for (int k = 0; k < 10; ++k) {
    const double flex = (-20 + 13 * k) * M_PI / 180, add = (k % 3 - 1) * 10 * M_PI / 180,
                 rot = (k % 4 - 1.5) * 12 * M_PI / 180;
    poses.push_back((Eigen::AngleAxisd(flex, Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(add, Eigen::Vector3d::UnitY()) *
                     Eigen::AngleAxisd(rot, Eigen::Vector3d::UnitZ()))
                        .toRotationMatrix());
  }
  return poses;
}
}  // namespace

TEST(SurfaceDistance, ScanSetCoversTheRegionInSmallClusters) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> U(-50, 50);
  Vertices P(1000, 3);
  for (Eigen::Index i = 0; i < P.rows(); ++i) P.row(i) << U(rng), U(rng), U(rng);
  const DistanceScanSet s = make_distance_scan_set(P, 60, 16);
  std::vector<int> seen(1000, 0);
  for (std::int64_t c = 0; c < s.clusters(); ++c) {
    const auto b = s.cluster_begin[static_cast<std::size_t>(c)], e = s.cluster_begin[static_cast<std::size_t>(c) + 1];
    EXPECT_LE(e - b, 16);
    for (auto k = b; k < e; ++k) {
      ++seen[static_cast<std::size_t>(s.index[static_cast<std::size_t>(k)])];
      EXPECT_LE((s.position[static_cast<std::size_t>(k)] - s.centre[static_cast<std::size_t>(c)]).norm(),
                s.radius[static_cast<std::size_t>(c)] + 1e-12);
    }
  }
  for (Eigen::Index i = 0; i < P.rows(); ++i) EXPECT_EQ(seen[static_cast<std::size_t>(i)], P.row(i).norm() <= 60) << i;
  EXPECT_THROW(make_distance_scan_set(P, 60, 0), Error);
  EXPECT_THROW(make_distance_scan_set(P, 0, 8), Error);
}

// order_in_boxes: a permutation (each index with its own coordinates) whose aligned runs are compact:
// - on a line, every aligned run of each size lies wholly before the next (median splits in 1-D sort the
//   runs);
// - three tight clusters 100 mm apart along x, of 32 x 13, 32 x 29 and 32 x 7 vertices (not powers of two),
//   given shuffled: every aligned run of 32 holds one cluster's vertices only, so its ball is the cluster's
//   size, not the distance between clusters (a range holding two clusters is split along x, its longest
//   axis, at a multiple of 32, and so is every cluster's share of it).
TEST(SurfaceDistance, OrderInBoxesKeepsEveryAlignedRunCompact) {
  auto set_of = [](const std::vector<Eigen::Vector3d>& p) {
    ScanSet s;
    s.vertices = static_cast<std::int64_t>(p.size()) + 5;
    for (std::size_t k = 0; k < p.size(); ++k) {
      s.index.push_back(static_cast<std::int32_t>(k + 5));  // indices need not be 0..k-1
      s.x.push_back(p[k].x()), s.y.push_back(p[k].y()), s.z.push_back(p[k].z());
    }
    return s;
  };
  auto is_permutation_of = [](const ScanSet& out, const ScanSet& in) {
    if (out.size() != in.size() || out.vertices != in.vertices) return false;
    std::vector<int> seen(static_cast<std::size_t>(in.vertices), 0);
    for (std::int64_t k = 0; k < out.size(); ++k) {
      const auto j = static_cast<std::size_t>(out.index[static_cast<std::size_t>(k)] - 5);  // the input's position
      const auto o = static_cast<std::size_t>(k);
      if (in.x[j] != out.x[o] || in.y[j] != out.y[o] || in.z[j] != out.z[o]) return false;
      ++seen[j];
    }
    return std::count(seen.begin(), seen.end(), 1) == in.size();
  };
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> U(0, 1);
  // On a line (1,000 vertices, 0..1000 mm, shuffled).
  std::vector<Eigen::Vector3d> line;
  for (int k = 0; k < 1000; ++k) line.emplace_back(1000 * U(rng), 0, 0);
  const ScanSet in_line = set_of(line);
  const ScanSet out_line = order_in_boxes(in_line, {32, 128});
  EXPECT_TRUE(is_permutation_of(out_line, in_line));
  for (const std::int64_t run : {32, 128}) {
    for (std::int64_t a = 0; a + run < out_line.size(); a += run) {
      double max_before = -1, min_after = 2000;
      for (std::int64_t k = a; k < a + run; ++k) max_before = std::max(max_before, out_line.x[static_cast<std::size_t>(k)]);
      for (std::int64_t k = a + run; k < std::min(a + 2 * run, out_line.size()); ++k)
        min_after = std::min(min_after, out_line.x[static_cast<std::size_t>(k)]);
      EXPECT_LE(max_before, min_after) << "runs of " << run << " at " << a;
    }
  }
  // Three clusters (1 mm cubes, 100 mm apart), shuffled.
  const std::vector<Eigen::Vector3d> corner{{0, 0, 0}, {200, 0, 0}, {100, 0, 0}};
  const std::vector<int> sizes{32 * 13, 32 * 29, 32 * 7};
  std::vector<Eigen::Vector3d> p;
  for (std::size_t c = 0; c < corner.size(); ++c)
    for (int k = 0; k < sizes[c]; ++k) p.push_back(corner[c] + Eigen::Vector3d(U(rng), U(rng), U(rng)));
  std::shuffle(p.begin(), p.end(), rng);
  const ScanSet in = set_of(p);
  const ScanSet out = order_in_boxes(in, {32, 128, 1024});
  ASSERT_TRUE(is_permutation_of(out, in));
  auto cluster_of = [&](std::int64_t k) {
    const Eigen::Vector3d q(out.x[static_cast<std::size_t>(k)], out.y[static_cast<std::size_t>(k)], out.z[static_cast<std::size_t>(k)]);
    for (std::size_t c = 0; c < corner.size(); ++c)
      if ((q - corner[c]).cwiseAbs().maxCoeff() <= 1) return static_cast<int>(c);
    return -1;
  };
  int mixed = 0;
  for (std::int64_t a = 0; a < out.size(); a += 32)
    for (std::int64_t k = a + 1; k < a + 32; ++k) mixed += cluster_of(k) != cluster_of(a);
  EXPECT_EQ(mixed, 0);
  // The input order (shuffled) mixes them: the check can fail.
  int mixed_in = 0;
  for (std::int64_t a = 0; a < in.size(); a += 32)
    mixed_in += (Eigen::Vector3d(in.x[static_cast<std::size_t>(a)], in.y[static_cast<std::size_t>(a)], 0) -
                 Eigen::Vector3d(in.x[static_cast<std::size_t>(a + 1)], in.y[static_cast<std::size_t>(a + 1)], 0))
                    .norm() > 50;
  EXPECT_GT(mixed_in, 0);
  EXPECT_EQ(order_in_boxes(ScanSet{}, {32}).size(), 0);
  EXPECT_THROW(order_in_boxes(in, {}), Error);
  EXPECT_THROW(order_in_boxes(in, {0}), Error);
  EXPECT_THROW(order_in_boxes(in, {32, 48}), Error);
}

TEST(SurfaceDistance, GeneratedHipPushedIntoItsCupMatchesCgal) {
  if (!SignedDistanceQuery::available() || !have_exact_reference()) GTEST_SKIP() << "needs Embree or CGAL, and CGAL";
  HipModelOptions ho;
  ho.target_triangles = 6000;
  ho.cam_height_mm = 3;
  const HipModel m = make_hip_model(ho);
  JointOptions o;
  o.distances = true;
  o.layers = 2;
  const Joint joint(m.ball, m.socket, m.cor, o);
  std::vector<Eigen::Matrix3d> poses;
  for (int k = 0; k < 6; ++k)
    poses.push_back(Eigen::AngleAxisd((15.0 * k - 20) * M_PI / 180, Eigen::Vector3d(0.6, 0.8, 0).normalized()).toRotationMatrix());
  check_joint(joint, poses, Eigen::Vector3d::Zero(), "generated");
}

TEST(SurfaceDistance, HeadPushedIntoAWatertightCupMatchesCgal) {
  if (!SignedDistanceQuery::available() || !have_exact_reference()) GTEST_SKIP() << "needs Embree or CGAL, and CGAL";
  // A head (r 22 mm) in a closed, manifold cup (24.5 to 30.5 mm, 100 deg coverage), pushed 3.5 mm into the
  // cup wall: the head penetrates it by about 1 mm (negative distances; signs by CGAL's ray parity).
  const Eigen::Vector3d c(10, -5, 20);
  const TriangleMesh head = make_uv_sphere(22, c, 120, 60, Eigen::Vector3d(0.2, 0.1, 1).normalized());
  const TriangleMesh cup = make_cup(24.5, 30.5, 100, c, Eigen::Vector3d(0.3, 0.2, 1).normalized(), 120, 40);
  ASSERT_EQ(SignedDistanceQuery(head).irregular_edges(), 0);
  ASSERT_EQ(SignedDistanceQuery(cup).irregular_edges(), 0);
  JointOptions o;
  o.distances = true;
  const Joint joint(head, cup, c, o);
  std::vector<Eigen::Matrix3d> poses;
  for (int k = 0; k < 4; ++k)
    poses.push_back(Eigen::AngleAxisd((25.0 * k - 30) * M_PI / 180, Eigen::Vector3d(0.6, 0.8, 0).normalized()).toRotationMatrix());
  const Eigen::Vector3d push = 3.5 * Eigen::Vector3d(0.3, 0.2, 1).normalized();
  check_joint(joint, poses, push, "cup, pushed");
  const PoseResult r = joint.detect(Eigen::Matrix3d::Identity(), push);
  EXPECT_GT(r.ball.vertices_inside, 0);
  EXPECT_NEAR(r.ball.min_distance_mm, -1.0, 0.05);
  EXPECT_NEAR(r.socket.min_distance_mm, -1.0, 0.05);
}

TEST(SurfaceDistance, ReachAndBadInput) {
  if (!SignedDistanceQuery::available()) GTEST_SKIP() << "needs Embree or CGAL";
  const HipModel m = make_hip_model({});
  JointOptions o;
  o.distances = true;
  o.distance_reach_mm = -1;
  EXPECT_THROW(Joint(m.ball, m.socket, m.cor, o), Error);
  o.distance_reach_mm = 1;
  const Joint narrow(m.ball, m.socket, m.cor, o);
  o.distance_reach_mm = 8;
  const Joint wide(m.ball, m.socket, m.cor, o);
  const PoseResult a = narrow.detect(Eigen::Matrix3d::Identity()), b = wide.detect(Eigen::Matrix3d::Identity());
  // The head sits 2.5 mm from the cup: nothing within 1 mm, most of the head within 8 mm.
  EXPECT_EQ(a.ball.vertices_distance, 0);
  EXPECT_GT(b.ball.vertices_distance, 100);
  EXPECT_NEAR(b.ball.min_distance_mm, 2.5, 0.1);
  const SignedDistanceQuery q(m.socket);
  const DistanceScanSet s = make_distance_scan_set(wide.ball().relative, 100);
  std::vector<float> out, wrong(3);
  EXPECT_THROW(scan_distances(s, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), m.cor, q, 0, {}, out), Error);
  EXPECT_THROW(scan_distances(s, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), m.cor, q, 4, wrong, out), Error);
}

// The generated hip pushed 3 mm into its cup (distances of both signs) for the memory's tests: the ball's
// scan set against the cup's surface (q), the reach (mm), the scans' outputs and memory, and the poses of a
// motion (a rotation by deg about one axis).
class DistanceMemory : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!SignedDistanceQuery::available()) GTEST_SKIP() << "needs Embree or CGAL";
    query.emplace(m.socket);
  }
  static Eigen::Matrix3d pose(double deg) {
    return Eigen::AngleAxisd(deg * M_PI / 180, Eigen::Vector3d(0.6, 0.8, 0).normalized()).toRotationMatrix();
  }
  HipModel m = [] {
    HipModelOptions ho;
    ho.target_triangles = 6000;
    return make_hip_model(ho);
  }();
  std::optional<SignedDistanceQuery> query;
  DistanceScanSet s = make_distance_scan_set(m.ball.V.rowwise() - m.cor.transpose(), 100);
  double reach = 4;
  Eigen::Vector3d push = 3 * Eigen::Vector3d::UnitZ();
  std::vector<float> plain, remembered;  // a scan without memory, and with `memory`
  DistanceScanMemory memory;
};

TEST_F(DistanceMemory, ChangesNoDistanceOrSign) {
  // Scanned without memory and with the memory of the poses before it along a motion (seeds and empty
  // balls), of a pose far off, of garbage seeds, of another surface and of another size: every distance equal
  // bit for bit, and the memory's empty balls do spare searches (or the test would not test them).
  const SignedDistanceQuery& q = *query;
  std::int64_t measured = 0, negative = 0, recalled = 0;
  auto same = [&](const std::string& what) { ASSERT_TRUE(same_floats(plain, remembered)) << what; };
  for (double deg : {-10.0, -9.5, -9.0, -8.5, -8.0, 30.0, -7.0, -7.5}) {  // a motion, one pose far off, and back
    const DistanceScanStats a = scan_distances(s, pose(deg), push, m.cor, q, reach, {}, plain);
    const DistanceScanStats b = scan_distances(s, pose(deg), push, m.cor, q, reach, {}, remembered, &memory);
    ASSERT_EQ(memory.seed.size(), s.index.size());
    EXPECT_EQ(memory.query, q.id());
    same(std::to_string(deg) + " deg");
    EXPECT_EQ(a.measured, b.measured);
    EXPECT_EQ(a.clusters_pruned, b.clusters_pruned);
    EXPECT_LE(b.searches, a.searches);
    recalled += b.vertices_recalled + b.clusters_recalled;
    for (const float d : plain) measured += !std::isnan(d), negative += d < 0;
  }
  EXPECT_GT(measured, 500);
  EXPECT_GT(negative, 10);
  EXPECT_GT(recalled, 100);
  for (std::size_t k = 0; k < memory.seed.size(); ++k)
    memory.seed[k] = static_cast<std::int32_t>(k % 3 == 0 ? -5 : 1000000 + k);  // no triangle of the mesh
  scan_distances(s, pose(-7), push, m.cor, q, reach, {}, plain);
  scan_distances(s, pose(-7), push, m.cor, q, reach, {}, remembered, &memory);
  same("garbage seeds");
  // The memory of another surface (the cup 20 mm away: its empty balls are not this cup's) is reset,
  // not read.
  TriangleMesh moved = m.socket;
  moved.V.rowwise() += Eigen::RowVector3d(0, 0, 20);
  const SignedDistanceQuery other(moved);
  ASSERT_NE(other.id(), q.id());
  DistanceScanMemory elsewhere;
  for (double deg : {-7.0, -6.5}) scan_distances(s, pose(deg), push, m.cor, other, reach, {}, remembered, &elsewhere);
  EXPECT_EQ(elsewhere.query, other.id());
  scan_distances(s, pose(-6.5), push, m.cor, q, reach, {}, plain);
  const DistanceScanStats c = scan_distances(s, pose(-6.5), push, m.cor, q, reach, {}, remembered, &elsewhere);
  same("memory of another surface");
  EXPECT_EQ(elsewhere.query, q.id());
  EXPECT_EQ(c.vertices_recalled + c.clusters_recalled, 0);
  DistanceScanMemory sized_wrong;  // of another set: reset, not read
  sized_wrong.query = q.id();
  sized_wrong.seed.assign(3, 7);
  sized_wrong.empty_radius.assign(3, 1e6f);
  sized_wrong.empty_centre.assign(3, Eigen::Vector3f::Zero());
  scan_distances(s, pose(-6.5), push, m.cor, q, reach, {}, remembered, &sized_wrong);
  EXPECT_EQ(sized_wrong.seed.size(), s.index.size());
  same("memory of another size");
}

TEST_F(DistanceMemory, LearnsAlongAMotionNotAtAJump) {
  // The memory's new facts (empty balls, nearby triangles) cost extra walks; they are learnt only where the
  // cluster moved within their margins since the scan before (a step of a motion), not at a first scan or
  // after a jump (a motion of scattered poses). Whatever is learnt, every distance equals the memoryless scan's.
  const SignedDistanceQuery& q = *query;
  auto learnt = [&] {
    std::int64_t n = static_cast<std::int64_t>(memory.nearby.size());
    for (const float r : memory.empty_radius) n += r > 0;
    for (const float r : memory.cluster_empty_radius) n += r > 0;
    return n;
  };
  auto scan = [&](double deg) {
    scan_distances(s, pose(deg), push, m.cor, q, reach, {}, plain);
    scan_distances(s, pose(deg), push, m.cor, q, reach, {}, remembered, &memory);
    EXPECT_TRUE(same_floats(plain, remembered)) << deg << " deg";
  };
  scan(-10);  // the first scan: nothing to tell a step from a jump
  EXPECT_EQ(learnt(), 0);
  scan(-9.9);  // a step (a vertex at 60 mm moves 0.1 mm)
  const std::int64_t after_step = learnt();
  EXPECT_GT(after_step, 100);
  scan(30);  // a jump of 40 deg: nothing new learnt
  EXPECT_EQ(learnt(), after_step);
  scan(30.1);  // a step again: learning again
  EXPECT_GT(learnt(), after_step);
}

class RealDistance : public ::testing::TestWithParam<std::string> {};

TEST_P(RealDistance, EveryMeasuredVertexMatchesCgalAtRestAndTenPoses) {
  if (!SignedDistanceQuery::available() || !have_exact_reference()) GTEST_SKIP() << "needs Embree or CGAL, and CGAL";
  const auto real = test::load_real_joint(GetParam());
  if (!real) GTEST_SKIP() << "shared data absent";
  JointOptions o;
  o.distances = true;
  o.layers = 4;
  o.max_radius_mm = 150;
  const Joint joint(real->femur, real->pelvis, real->cor, o);
  check_joint(joint, flexion_poses(), Eigen::Vector3d::Zero(), GetParam());
}

INSTANTIATE_TEST_SUITE_P(Shared, RealDistance, ::testing::Values("lhdl-ct", "mc22", "mc22-left", "tlem2-mri"));

// scan_layered_near (the layered scan that leaves out clusters beyond the reach) against scan_layered
// over the same vertices and against CGAL: a vertex it looks up gets scan_layered's gap bit for bit; a
// vertex it skips is outside the other bone (CGAL's ray parity) and farther than the reach from it (CGAL's
// closest distance). A head pushed 6 mm into a 6 mm cup wall, so that some vertices lie deeper inside the
// wall than the reach: with single-vertex clusters (radius 0) the distance query alone would skip them,
// and the inside test must keep them.
TEST(SurfaceDistance, LayeredScanLeavesOutOnlyWhatIsOutsideAndBeyondTheReach) {
  if (!SignedDistanceQuery::available() || !have_exact_reference()) GTEST_SKIP() << "needs Embree or CGAL, and CGAL";
  const Eigen::Vector3d c(10, -5, 20), axis = Eigen::Vector3d(0.3, 0.2, 1).normalized();
  const TriangleMesh head = make_uv_sphere(22, c, 120, 60, Eigen::Vector3d(0.2, 0.1, 1).normalized());
  const TriangleMesh cup = make_cup(24.5, 30.5, 100, c, axis, 120, 40);
  JointOptions o;
  o.layers = 2;
  const Joint joint(head, cup, c, o);
  ASSERT_NE(joint.socket().layered, nullptr);
  const SignedDistanceQuery other(cup);
  const ExactReference ref(cup);
  const ScanSet set = make_scan_set(joint.ball().relative, std::vector<std::uint8_t>(head.V.rows(), 1));
  std::int64_t skipped = 0, scanned = 0, deep = 0;
  for (const int cluster_size : {1, 32})
    for (const double push : {0.0, 3.5, 6.0})
      for (const double reach : {0.5, 2.0}) {
        const ScanClusters clusters = cluster_scan_set(set, cluster_size);
        const Eigen::Matrix3d R =
            Eigen::AngleAxisd(push * M_PI / 90, Eigen::Vector3d(0.6, 0.8, 0).normalized()).toRotationMatrix();
        const Eigen::Vector3d t = push * axis;
        std::vector<float> all(static_cast<std::size_t>(set.size())), near(all.size());
        scan_layered(set, R, t, *joint.socket().layered, all.data(), joint.socket().caster.get());
        const LayeredNearStats st = scan_layered_near(set, clusters, R, t, *joint.socket().layered, c, other, reach,
                                                      near.data(), joint.socket().caster.get());
        std::int64_t skipped_here = 0;
        for (std::int64_t j = 0; j < set.size(); ++j) {
          const auto k = static_cast<std::size_t>(j);
          const Eigen::Vector3d q = c + R * Eigen::Vector3d(set.x[k], set.y[k], set.z[k]) + t;
          const std::string what = "size " + std::to_string(cluster_size) + " push " + std::to_string(push) +
                                   " reach " + std::to_string(reach) + " vertex " + std::to_string(j);
          if (near[k] == std::numeric_limits<float>::infinity()) {
            ++skipped_here;
            ASSERT_GT(ref.closest_distance(q), reach) << what;
            ASSERT_FALSE(inside_by_parity(ref, q)) << what;
            continue;
          }
          ++scanned;
          if (std::isnan(all[k])) {
            ASSERT_TRUE(std::isnan(near[k])) << what;
          } else {
            ASSERT_EQ(near[k], all[k]) << what;
          }
          deep += inside_by_parity(ref, q) && ref.closest_distance(q) > reach;
        }
        EXPECT_EQ(st.vertices_scanned, set.size() - skipped_here) << cluster_size;
        skipped += skipped_here;
      }
  EXPECT_GT(skipped, 0);
  EXPECT_GT(scanned, 0);
  EXPECT_GT(deep, 0);  // vertices deeper inside than the reach were looked up, not skipped
  const ScanClusters clusters = cluster_scan_set(set);
  std::vector<float> out(static_cast<std::size_t>(set.size()));
  EXPECT_THROW(scan_layered_near(set, clusters, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(),
                                 *joint.socket().layered, c, other, 0, out.data(), nullptr),
               Error);
  EXPECT_THROW(cluster_scan_set(set, 0), Error);
}

// Distance hierarchies cropped to the poses asked for (JointOptions::cropped_distance_queries, one `impinge distance`)
// against the whole meshes' (tested against CGAL above): every gap, status and distance of both bodies the same bit
// for bit, at the poses cropped for (the scan pose and a pose flexed 60 deg and pushed 2 mm into the cup, where more
// is in reach) and at one it was not (answered by the whole hierarchies, built at their first use); with the direct
// set-up (exact casts for the hidden vertices, which the hierarchies prune) and with the layered maps. A detect
// before the crop is refused.
TEST(SurfaceDistance, CroppedHierarchiesChangeNoResult) {
  if (!SignedDistanceQuery::available()) GTEST_SKIP() << "needs Embree or CGAL";
  struct Case {
    std::string name;
    TriangleMesh ball, socket;
    Eigen::Vector3d cor;
  };
  std::vector<Case> cases;
  {
    HipModelOptions ho;
    ho.target_triangles = 6000;
    ho.cam_height_mm = 3;
    const HipModel m = make_hip_model(ho);
    cases.push_back({"generated", m.ball, m.socket, m.cor});
  }
  for (const char* name : {"lhdl-ct", "mc22-left"})
    if (const auto real = test::load_real_joint(name)) cases.push_back({name, real->femur, real->pelvis, real->cor});
  const Eigen::Vector3d axis = Eigen::Vector3d(0.6, 0.8, 0).normalized();
  const std::vector<std::pair<Eigen::Matrix3d, Eigen::Vector3d>> cropped_for{
      {Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()},
      {Eigen::AngleAxisd(60 * M_PI / 180, axis).toRotationMatrix(), Eigen::Vector3d(0, 0, 2)}};
  const std::pair<Eigen::Matrix3d, Eigen::Vector3d> other_pose{
      Eigen::AngleAxisd(-35 * M_PI / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix(), Eigen::Vector3d::Zero()};
  for (const Case& c : cases)
    for (const bool layered_maps : {false, true}) {
      JointOptions o;
      o.distances = true;
      o.layers = 2;
      o.layered_maps = layered_maps;
      o.max_radius_mm = 150;
      const Joint whole(c.ball, c.socket, c.cor, o);
      o.cropped_distance_queries = true;
      Joint crop(c.ball, c.socket, c.cor, o);
      EXPECT_EQ(crop.ball().distance_query, nullptr);
      EXPECT_THROW(crop.detect(Eigen::Matrix3d::Identity()), Error);
      crop.crop_distance_queries(cropped_for);
      ASSERT_TRUE(crop.ball().distance_query->cropped());
      // The generated cup lies wholly within reach of the head's clusters; a real pelvis mostly does not.
      if (c.name != "generated") {
        EXPECT_LT(crop.socket().distance_query->triangles(), whole.socket().distance_query->triangles() / 2) << c.name;
      }
      std::vector<std::pair<Eigen::Matrix3d, Eigen::Vector3d>> poses = cropped_for;
      poses.push_back(other_pose);
      for (std::size_t k = 0; k < poses.size(); ++k) {
        const PoseResult a = whole.detect(poses[k].first, poses[k].second);
        const PoseResult b = crop.detect(poses[k].first, poses[k].second);
        const std::string what = c.name + (layered_maps ? " maps" : " direct") + " pose " + std::to_string(k);
        for (const auto& [x, y] : {std::pair{&a.ball_gaps, &b.ball_gaps}, std::pair{&a.socket_gaps, &b.socket_gaps}}) {
          ASSERT_TRUE(same_floats(x->gap_mm, y->gap_mm)) << what << " gaps";
          ASSERT_TRUE(same_floats(x->distance_mm, y->distance_mm)) << what << " distances";
          ASSERT_EQ(x->status, y->status) << what;
        }
        if (k == 0 && c.name == "generated") {  // at rest nothing lies deeper than the reach: the crop answers alone
          EXPECT_EQ(crop.ball().distance_query->cropped_fallbacks() + crop.socket().distance_query->cropped_fallbacks(), 0);
        }
      }
      // The pose it was not cropped for went to the whole hierarchies.
      EXPECT_GT(crop.ball().distance_query->cropped_fallbacks() + crop.socket().distance_query->cropped_fallbacks(), 0)
          << c.name;
    }
  Joint bad(cases[0].ball, cases[0].socket, cases[0].cor, [] {
    JointOptions o;
    o.distances = true;
    o.cropped_distance_queries = true;
    return o;
  }());
  EXPECT_THROW(bad.crop_distance_queries({{Eigen::Matrix3d::Constant(std::nan("")), Eigen::Vector3d::Zero()}}), Error);
}
