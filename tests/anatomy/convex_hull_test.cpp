// The convex hull (anatomy/convex_hull.cpp; CGAL's quickhull after leaving out the points strictly inside
// the hull of 26 extreme points). Invariants, against closed-form answers:
// - points on a sphere with many points strictly inside it, shuffled together: the hull's vertices are
//   exactly the sphere's points (every point of a sphere is extreme), its triangles are closed (each
//   edge in two), outward, and every input point lies on the inner side of every triangle;
// - a cube's corners with points inside it, on its faces and on its edges: the 8 corners and 12
//   triangles, nothing else;
// - bad input (fewer than 4 points, coplanar points, a non-finite coordinate) is an error.
#include "impinge/anatomy/convex_hull.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>

#include "impinge/core/error.hpp"

using namespace impinge;

namespace {
// Every input point on the inner side of every triangle (within tol mm), each undirected edge in
// exactly two triangles, and every triangle facing away from `inside`.
void expect_closed_convex_and_outward(const Vertices& P, const ConvexHull& h, const Eigen::Vector3d& inside, double tol) {
  std::map<std::pair<int, int>, int> edges;
  for (Eigen::Index f = 0; f < h.triangles.rows(); ++f) {
    const Eigen::Vector3d a = P.row(h.triangles(f, 0)).transpose(), b = P.row(h.triangles(f, 1)).transpose(),
                          c = P.row(h.triangles(f, 2)).transpose();
    const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
    EXPECT_GT(n.dot(a - inside), 0) << "triangle " << f << " faces inwards";
    double worst = -std::numeric_limits<double>::infinity();
    for (Eigen::Index i = 0; i < P.rows(); ++i) worst = std::max(worst, n.dot(P.row(i).transpose() - a));
    EXPECT_LE(worst, tol) << "a point lies outside triangle " << f;
    for (int k = 0; k < 3; ++k) {
      const int u = h.triangles(f, k), v = h.triangles(f, (k + 1) % 3);
      ++edges[{std::min(u, v), std::max(u, v)}];
    }
  }
  for (const auto& [e, n] : edges) EXPECT_EQ(n, 2) << "edge " << e.first << "-" << e.second;
}
}  // namespace

TEST(ConvexHull, SpherePointsAmongInteriorPointsAreExactlyTheHull) {
  if (!have_convex_hull()) GTEST_SKIP() << "needs CGAL";
  const Eigen::Vector3d centre(10, -20, 30);
  const double R = 50;
  const int on_sphere = 400, inside = 20000;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Eigen::Vector3d> pts;
  std::vector<bool> extreme;
  for (int k = 0; k < on_sphere; ++k) {  // a Fibonacci sphere
    const double z = 1 - (2 * k + 1.0) / on_sphere, rho = std::sqrt(1 - z * z), az = 2.399963229728653 * k;
    pts.push_back(centre + R * Eigen::Vector3d(rho * std::cos(az), rho * std::sin(az), z));
    extreme.push_back(true);
  }
  while (static_cast<int>(pts.size()) < on_sphere + inside) {  // strictly inside: within 0.95 R
    const Eigen::Vector3d d(u(rng), u(rng), u(rng));
    if (d.norm() > 1) continue;
    pts.push_back(centre + 0.95 * R * d);
    extreme.push_back(false);
  }
  std::vector<std::size_t> order(pts.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), rng);
  Vertices P(static_cast<Eigen::Index>(pts.size()), 3);
  std::set<Eigen::Index> want;
  for (std::size_t i = 0; i < order.size(); ++i) {
    P.row(static_cast<Eigen::Index>(i)) = pts[order[i]].transpose();
    if (extreme[order[i]]) want.insert(static_cast<Eigen::Index>(i));
  }
  const ConvexHull h = convex_hull(P);
  EXPECT_EQ(std::set<Eigen::Index>(h.vertices.begin(), h.vertices.end()), want);
  for (Eigen::Index f = 0; f < h.triangles.rows(); ++f)
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(want.count(h.triangles(f, k))) << "triangle " << f;
  EXPECT_EQ(h.triangles.rows(), 2 * on_sphere - 4);  // Euler: a closed triangulation of V points
  expect_closed_convex_and_outward(P, h, centre, 1e-9 * R);
}

TEST(ConvexHull, CubeCornersAmongFaceEdgeAndInteriorPoints) {
  if (!have_convex_hull()) GTEST_SKIP() << "needs CGAL";
  std::vector<Eigen::Vector3d> pts;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int k = 0; k < 3000; ++k) {
    Eigen::Vector3d p(u(rng), u(rng), u(rng));
    if (k % 3 == 1) p[k % 3] = k % 2 ? 1 : -1;                            // on a face
    if (k % 3 == 2) p[0] = k % 4 < 2 ? 1 : -1, p[1] = k % 5 < 2 ? 1 : -1;  // on an edge
    pts.push_back(20 * p);
  }
  std::set<Eigen::Index> corners;
  for (int c = 0; c < 8; ++c) {
    corners.insert(static_cast<Eigen::Index>(pts.size()));
    pts.push_back(20 * Eigen::Vector3d(c & 1 ? 1 : -1, c & 2 ? 1 : -1, c & 4 ? 1 : -1));
  }
  Vertices P(static_cast<Eigen::Index>(pts.size()), 3);
  for (std::size_t i = 0; i < pts.size(); ++i) P.row(static_cast<Eigen::Index>(i)) = pts[i].transpose();
  const ConvexHull h = convex_hull(P);
  EXPECT_EQ(std::set<Eigen::Index>(h.vertices.begin(), h.vertices.end()), corners);
  EXPECT_EQ(h.triangles.rows(), 12);
  expect_closed_convex_and_outward(P, h, Eigen::Vector3d::Zero(), 1e-9);
}

TEST(ConvexHull, BadInputIsAnError) {
  if (!have_convex_hull()) GTEST_SKIP() << "needs CGAL";
  Vertices three(3, 3);
  three << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  EXPECT_THROW(convex_hull(three), Error);
  Vertices flat(5, 3);
  flat << 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 0.5, 0.2, 0;
  EXPECT_THROW(convex_hull(flat), Error);
  Vertices bad(4, 3);
  bad << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, std::nan("");
  EXPECT_THROW(convex_hull(bad), Error);
}
