// The labrum body (labrum.hpp) against its definition. Invariants, on a generated spherical cup with a flat rim
// (make_cup: inner radius 24.5 mm, wall 6 mm, coverage 100 deg; the rim is the cone at 100 deg from the pole
// between radii 24.5 and 30.5 mm), its acetabulum found by find_acetabulum:
// - the base lies on the rim: both base corners at 100 deg from the pole (within 1 deg) and between the rim's
//   inner and outer radii (within 0.1 mm); the inner corner on the cup's inner sphere;
// - each cross-section is a right triangle of base `width` and height `height` (1e-9 mm), the apex along the
//   cup sphere's tangent (within 1e-3 rad: the fitted centre's offset) out of the acetabulum (the analytic opening);
// - the ring is closed and consistently oriented (every edge in exactly two triangles, once each way; Euler
//   characteristic 0, a torus), and outward: its volume (divergence theorem) is positive and equals Pappus'
//   (cross-section area x the path of its centroid about the axis) within 1 %, and every triangle's normal points
//   away from the path of the cross-sections' centroids;
// - a width or height outside (0, 15] mm, or NaN, is an error naming it, its value and the range.
#include "impinge/anatomy/labrum.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <utility>

#include "impinge/core/error.hpp"
#include "impinge/io/generated_models.hpp"

using namespace impinge;

namespace {
constexpr double kInner = 24.5, kOuter = 30.5, kCoverageDeg = 100;

struct Cup {
  Eigen::Vector3d c{3, -2, 5};
  Eigen::Vector3d pole = Eigen::Vector3d(0.2, -0.3, -1).normalized();  // the deepest direction
  Acetabulum a;
};

Cup cup() {
  Cup k;
  const TriangleMesh m = make_cup(kInner, kOuter, kCoverageDeg, k.c, k.pole, 144, 80);
  k.a = find_acetabulum(m, k.c, 22.0, AnatomicalFrame{});
  return k;
}

double polar_deg(const Cup& k, const Eigen::Vector3d& p) {
  return std::acos(std::clamp((p - k.c).normalized().dot(k.pole), -1.0, 1.0)) * 180 / M_PI;
}
}  // namespace

TEST(Labrum, BaseOnTheRimWithTheGivenWidthAndHeight) {
  const Cup k = cup();
  const double w = 5.3, h = 7.0;
  const TriangleMesh L = make_labrum(k.a, w, h, "cup");
  ASSERT_EQ(L.V.rows(), 3 * static_cast<Eigen::Index>(k.a.rim.size()));
  ASSERT_GE(k.a.rim.size(), 36u);
  const Eigen::Vector3d out = -k.pole;  // the analytic opening
  for (Eigen::Index i = 0; i < L.V.rows() / 3; ++i) {
    const Eigen::Vector3d I = L.V.row(3 * i), O = L.V.row(3 * i + 1), A = L.V.row(3 * i + 2);
    for (const Eigen::Vector3d& p : {I, O}) {
      EXPECT_NEAR(polar_deg(k, p), kCoverageDeg, 1.0) << i;
      EXPECT_GE((p - k.c).norm(), kInner - 0.1) << i;
      EXPECT_LE((p - k.c).norm(), kOuter + 0.1) << i;
    }
    EXPECT_NEAR((I - k.c).norm(), kInner, 0.1) << i;
    EXPECT_NEAR((O - I).norm(), w, 1e-9) << i;
    const Eigen::Vector3d base = (O - I).normalized();
    const Eigen::Vector3d up = (A - I) - (A - I).dot(base) * base;  // the apex above the base line
    EXPECT_NEAR(up.norm(), h, 1e-9) << i;
    // Tangent to the cup's sphere at I (within the fitted centre's offset from the true one: 1e-3 rad).
    EXPECT_NEAR((A - I).normalized().dot((I - k.c).normalized()), 0, 1e-3) << i;
    EXPECT_GT((A - I).dot(out), 0) << i;              // out of the acetabulum
  }
}

TEST(Labrum, ClosedConsistentlyOrientedAndOutward) {
  const Cup k = cup();
  const double w = 5.3, h = 7.0;
  const TriangleMesh L = make_labrum(k.a, w, h, "cup");
  std::map<std::pair<int, int>, int> directed;
  for (Eigen::Index f = 0; f < L.F.rows(); ++f)
    for (int e = 0; e < 3; ++e) ++directed[{L.F(f, e), L.F(f, (e + 1) % 3)}];
  std::size_t undirected = 0;
  for (const auto& [edge, count] : directed) {
    EXPECT_EQ(count, 1) << edge.first << "-" << edge.second;  // never twice the same way
    EXPECT_EQ(directed.count({edge.second, edge.first}), 1u) << edge.first << "-" << edge.second;
    undirected += edge.first < edge.second;
  }
  EXPECT_EQ(L.V.rows() - static_cast<Eigen::Index>(undirected) + L.F.rows(), 0);  // a torus
  // Volume and outward normals.
  const auto m = L.V.rows() / 3;
  auto centroid = [&](Eigen::Index i) {
    return Eigen::Vector3d((L.V.row(3 * (i % m)) + L.V.row(3 * (i % m) + 1) + L.V.row(3 * (i % m) + 2)) / 3);
  };
  double volume = 0, path = 0;
  for (Eigen::Index i = 0; i < m; ++i) {
    const Eigen::Vector3d g = centroid(i) - k.c;
    path += (g - g.dot(k.pole) * k.pole).norm();
  }
  path = 2 * M_PI * path / static_cast<double>(m);
  for (Eigen::Index f = 0; f < L.F.rows(); ++f) {
    const Eigen::Vector3d p0 = L.V.row(L.F(f, 0)), p1 = L.V.row(L.F(f, 1)), p2 = L.V.row(L.F(f, 2));
    volume += p0.dot(p1.cross(p2)) / 6;
    const Eigen::Index i = f / 6;  // the triangles between sections i and i + 1
    const Eigen::Vector3d axis_point = (centroid(i) + centroid(i + 1)) / 2;
    EXPECT_GT((p1 - p0).cross(p2 - p0).dot((p0 + p1 + p2) / 3 - axis_point), 0) << f;
  }
  EXPECT_NEAR(volume, w * h / 2 * path, 0.01 * w * h / 2 * path);
}

TEST(Labrum, DimensionsOutsideTheirRangeAreErrorsNamingThem) {
  const Cup k = cup();
  for (const auto& [w, h, what] : {std::tuple{0.0, 7.0, "width 0 mm"}, std::tuple{-1.0, 7.0, "width -1 mm"},
                                   std::tuple{16.0, 7.0, "width 16 mm"}, std::tuple{5.3, 0.0, "height 0 mm"},
                                   std::tuple{5.3, 100.0, "height 100 mm"}, std::tuple{5.3, std::nan(""), "height nan mm"}}) {
    try {
      make_labrum(k.a, w, h, "cup");
      ADD_FAILURE() << what;
    } catch (const Error& e) {
      const std::string s = e.what();
      EXPECT_NE(s.find(what), std::string::npos) << s;
      EXPECT_NE(s.find("(0, 15] mm"), std::string::npos) << s;
    }
  }
}
