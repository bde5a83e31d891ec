// The exact mesh-to-mesh distance (mesh_contact.cpp). Oracles:
// - closed forms: two triangles whose edges cross at right angles at a distance d, the nearest points
//   inside both edges (no vertex is nearest: a per-vertex test reads more), read d; a triangle
//   piercing another reads 0;
// - dense sampling: over random triangle pairs, the distance is at most the least distance between
//   points sampled on both (any point pair is an upper bound) and within the sampling's spacing of it;
// - brute force over every pair of triangles of two small meshes, with counted masks (a pair counts
//   when either triangle does), at random poses; and FCL's distance (an independent BVH) on separated
//   poses when the build has FCL.
#include "impinge/detection/mesh_contact.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>
#include <set>

#include "impinge/casters/fcl_collision.hpp"
#include "impinge/core/error.hpp"
#include "impinge/io/generated_models.hpp"

using namespace impinge;
using Eigen::Vector3d;

TEST(TriangleDistance, EdgesCrossingBetweenVerticesReadTheirDistance) {
  // A's top edge along x at z = 0 (x in [-10, 10]), B's bottom edge along y at z = d: their nearest points
  // are the middles of both edges; every vertex lies at least 10 mm from the other triangle.
  for (const double d : {0.0, 0.3, 2.5}) {
    const Vector3d a[3] = {{-10, 0, 0}, {10, 0, 0}, {0, 0, -10}};
    const Vector3d b[3] = {{0, -10, d}, {0, 10, d}, {0, 0, d + 10}};
    Vector3d pa, pb;
    EXPECT_NEAR(triangle_distance(a, b, pa, pb), d, 1e-12);
    EXPECT_NEAR(pa.norm(), 0, 1e-12);
    EXPECT_NEAR((pb - Vector3d(0, 0, d)).norm(), 0, 1e-12);
  }
  // B pierces A's interior (no edge of A meets B): 0, at the piercing point.
  const Vector3d a[3] = {{-10, -10, 0}, {10, -10, 0}, {0, 10, 0}};
  const Vector3d b[3] = {{0, 0, -1}, {0, 0, 5}, {1, 1, 5}};
  Vector3d pa, pb;
  EXPECT_EQ(triangle_distance(a, b, pa, pb), 0);
  EXPECT_NEAR(pa.norm(), 0, 1e-12);
}

TEST(TriangleDistance, NoFartherThanAnySampledPairAndWithinTheSpacing) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-5, 5);
  const int n = 30;  // samples per side of each triangle
  for (int trial = 0; trial < 200; ++trial) {
    Vector3d a[3], b[3];
    for (auto& p : a) p = Vector3d(u(rng), u(rng), u(rng));
    const Vector3d shift(u(rng), u(rng), u(rng));
    for (auto& p : b) p = Vector3d(u(rng), u(rng), u(rng)) + shift;
    Vector3d pa, pb;
    const double d = triangle_distance(a, b, pa, pb);
    EXPECT_NEAR((pa - pb).norm(), d, 1e-9);
    auto samples = [n](const Vector3d* t) {
      std::vector<Vector3d> s;
      for (int i = 0; i <= n; ++i)
        for (int j = 0; i + j <= n; ++j) s.push_back(t[0] + (t[1] - t[0]) * i / n + (t[2] - t[0]) * j / n);
      return s;
    };
    const auto sa = samples(a), sb = samples(b);
    double sampled = 1e300;
    for (const auto& p : sa)
      for (const auto& q : sb) sampled = std::min(sampled, (p - q).norm());
    auto longest = [](const Vector3d* t) {
      return std::max({(t[1] - t[0]).norm(), (t[2] - t[1]).norm(), (t[0] - t[2]).norm()});
    };
    // A point of a triangle lies within (longest edge) / n of a sample.
    const double spacing = (longest(a) + longest(b)) / n;
    EXPECT_LE(d, sampled + 1e-9) << trial;
    EXPECT_GE(d, sampled - spacing) << trial;
  }
}

namespace {
// The least distance over every counted pair (either triangle counted), by brute force.
double brute_force(const TriangleMesh& a, const TriangleMesh& b, const Eigen::Matrix3d& R, const Vector3d& t,
                   const std::vector<std::uint8_t>& ca, const std::vector<std::uint8_t>& cb) {
  double best = std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i < a.F.rows(); ++i) {
    Vector3d pa[3];
    for (int c = 0; c < 3; ++c) pa[c] = R * a.V.row(a.F(i, c)).transpose() + t;
    for (Eigen::Index j = 0; j < b.F.rows(); ++j) {
      if (!ca[i] && !cb[j]) continue;
      Vector3d pb[3], x, y;
      for (int c = 0; c < 3; ++c) pb[c] = b.V.row(b.F(j, c)).transpose();
      best = std::min(best, triangle_distance(pa, pb, x, y));
    }
  }
  return best;
}
}  // namespace

TEST(MeshContact, TheTreesGiveTheBruteForceLeastOverTheCountedPairs) {
  const TriangleMesh a = make_uv_sphere(10, Vector3d::Zero(), 16, 9);
  const TriangleMesh b = make_cup(11, 14, 100, Vector3d(0.5, 0, 0), Vector3d::UnitZ(), 18, 6);
  std::mt19937 rng(3);
  std::bernoulli_distribution half(0.5);
  std::vector<std::uint8_t> ca(a.F.rows()), cb(b.F.rows());
  for (auto& c : ca) c = half(rng);
  for (auto& c : cb) c = half(rng);
  const MeshContact all(a.V, a.F, b.V, b.F), some(a.V, a.F, b.V, b.F, ca, cb);
  const std::vector<std::uint8_t> every_a(a.F.rows(), 1), every_b(b.F.rows(), 1);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI), shift(-3, 3);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(angle(rng), Vector3d(shift(rng), shift(rng), 1).normalized()).toRotationMatrix();
    const Vector3d t(shift(rng), shift(rng), shift(rng));
    const MeshContact::Closest x = all.least(R, t, {}), y = some.least(R, t, {});
    EXPECT_NEAR(x.distance, brute_force(a, b, R, t, every_a, every_b), 1e-12) << trial;
    EXPECT_NEAR(y.distance, brute_force(a, b, R, t, ca, cb), 1e-12) << trial;
    EXPECT_NEAR((x.on_a - x.on_b).norm(), x.distance, 1e-9);
    // Within a reach: the same least when it is within, none beyond.
    MeshContact::Query q;
    q.reach = x.distance + 0.01;
    EXPECT_EQ(all.least(R, t, q).distance, x.distance);
    q.reach = x.distance - 0.01;
    EXPECT_TRUE(std::isinf(all.least(R, t, q).distance) || x.distance < 0.01);
  }
  EXPECT_THROW(MeshContact(a.V, a.F, b.V, b.F, {1, 0}, {}), Error);
}

TEST(MeshContact, AgreesWithFclOnSeparatedPoses) {
  if (!have_fcl()) GTEST_SKIP() << "FCL missing in this build";
  const TriangleMesh a = make_uv_sphere(10, Vector3d::Zero(), 24, 12);
  const TriangleMesh b = make_cup(13, 16, 100, Vector3d::Zero(), Vector3d::UnitZ(), 24, 8);
  const FclJoint fcl(a, b, Vector3d::Zero());
  const MeshContact mine(a.V, a.F, b.V, b.F);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI), shift(-2.5, 2.5);
  int compared = 0;
  for (int trial = 0; trial < 30; ++trial) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(angle(rng), Vector3d::UnitX()).toRotationMatrix();
    const Vector3d t(shift(rng), shift(rng), shift(rng));
    const double d = mine.least(R, t, {}).distance;
    if (d < 1e-3) continue;  // FCL reports no distance for meshes that cross
    ++compared;
    EXPECT_NEAR(d, fcl.distance(R, t), 1e-6) << trial;
  }
  EXPECT_GT(compared, 10);
}

// The walk passes over pairs of nodes and of faces by lower bounds (counted boxes, faces' spheres and planes):
// at every reach, whether a counted pair lies within it and which pairs do are brute force's.
TEST(MeshContact, WithinAReachTheSamePairsAsBruteForce) {
  const TriangleMesh a = make_uv_sphere(10, Vector3d::Zero(), 16, 9);
  const TriangleMesh b = make_cup(11, 14, 100, Vector3d(0.5, 0, 0), Vector3d::UnitZ(), 18, 6);
  std::mt19937 rng(7);
  std::bernoulli_distribution half(0.5);
  std::vector<std::uint8_t> ca(a.F.rows()), cb(b.F.rows(), 0);
  for (auto& c : ca) c = half(rng);
  const MeshContact some(a.V, a.F, b.V, b.F, ca, cb);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI), shift(-3, 3);
  int met = 0, apart = 0;  // reaches with some pair within, with none: the test sees both
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(angle(rng), Vector3d(shift(rng), shift(rng), 1).normalized()).toRotationMatrix();
    const Vector3d t(shift(rng), shift(rng), shift(rng));
    for (const double reach : {0.0, 0.3, 1.0, 2.5}) {
      std::set<std::pair<std::int64_t, std::int64_t>> expected;  // counted pairs within the reach
      for (Eigen::Index i = 0; i < a.F.rows(); ++i) {
        if (!ca[static_cast<std::size_t>(i)]) continue;
        Vector3d pa[3], pb[3], x, y;
        for (int c = 0; c < 3; ++c) pa[c] = R * a.V.row(a.F(i, c)).transpose() + t;
        for (Eigen::Index j = 0; j < b.F.rows(); ++j) {
          for (int c = 0; c < 3; ++c) pb[c] = b.V.row(b.F(j, c)).transpose();
          if (triangle_distance(pa, pb, x, y) <= reach) expected.emplace(i, j);
        }
      }
      using Pairs = std::set<std::pair<std::int64_t, std::int64_t>>;
      const auto found = some.pairs_within(R, t, reach, {});
      EXPECT_EQ(Pairs(found.begin(), found.end()), expected)
          << trial << " " << reach;
      MeshContact::Query q;
      q.reach = reach, q.first = true;
      EXPECT_EQ(some.least(R, t, q).distance <= reach, !expected.empty()) << trial << " " << reach;
      ++(expected.empty() ? apart : met);
    }
  }
  EXPECT_GT(met, 0);
  EXPECT_GT(apart, 0);
}
