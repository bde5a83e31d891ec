#include "impinge/anatomy/labrum.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <vector>

#include "impinge/core/error.hpp"

namespace impinge {

namespace {
// The rim points in the order of their azimuth about the opening n through the rim centre m.
std::vector<Eigen::Vector3d> rim_by_azimuth(const Acetabulum& a) {
  const Eigen::Vector3d n = a.opening.normalized();
  Eigen::Vector3d e1 = n.unitOrthogonal();
  const Eigen::Vector3d e2 = n.cross(e1);
  std::vector<std::pair<double, Eigen::Vector3d>> v;
  for (const Eigen::Vector3d& p : a.rim) {
    const Eigen::Vector3d d = p - a.rim_centre;
    v.emplace_back(std::atan2(d.dot(e2), d.dot(e1)), p);
  }
  std::sort(v.begin(), v.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  std::vector<Eigen::Vector3d> out;
  for (const auto& [psi, p] : v) out.push_back(p);
  return out;
}
}  // namespace

TriangleMesh make_labrum(const Acetabulum& a, double width_mm, double height_mm, const std::string& source) {
  const std::string ctx = source + ": labrum";
  require(LabrumOptions::kWidthRange.contains(width_mm), [&] {
    return ctx + ": width " + shortest_decimal(width_mm) + " mm is outside " + LabrumOptions::kWidthRange.text() + " mm";
  });
  require(LabrumOptions::kHeightRange.contains(height_mm), [&] {
    return ctx + ": height " + shortest_decimal(height_mm) + " mm is outside " + LabrumOptions::kHeightRange.text() +
           " mm";
  });
  const Eigen::Vector3d c = a.sphere.centre;
  const double R = a.sphere.radius;
  require(c.allFinite() && std::isfinite(R) && R > 0 && a.opening.allFinite() && a.opening.norm() > 0,
          ctx + ": the acetabular sphere or opening is not finite");
  require(a.rim.size() >= 8, ctx + ": only " + std::to_string(a.rim.size()) + " rim points (at least 8)");
  const Eigen::Vector3d n = a.opening.normalized();
  const std::vector<Eigen::Vector3d> rim = rim_by_azimuth(a);
  const auto m = static_cast<Eigen::Index>(rim.size());
  TriangleMesh L;
  L.source = ctx;
  L.V.resize(3 * m, 3);
  for (Eigen::Index i = 0; i < m; ++i) {
    const Eigen::Vector3d u = (rim[static_cast<std::size_t>(i)] - c).normalized();
    const Eigen::Vector3d t = (n - n.dot(u) * u).normalized();  // the sphere's tangent out of the acetabulum
    const Eigen::Vector3d inner = c + R * u;
    L.V.row(3 * i) = inner.transpose();                               // I: inner base corner, on the sphere
    L.V.row(3 * i + 1) = (c + (R + width_mm) * u).transpose();        // O: outer base corner
    L.V.row(3 * i + 2) = (inner + height_mm * t).transpose();         // A: apex, the free margin
  }
  require(L.V.allFinite(), ctx + ": a rim point lies on the opening axis through the acetabular centre");
  // Consecutive cross-sections joined by three quads (I-O, O-A, A-I), the last to the first.
  L.F.resize(6 * m, 3);
  for (Eigen::Index i = 0; i < m; ++i) {
    const Eigen::Index j = (i + 1) % m;
    for (int k = 0; k < 3; ++k) {
      const int k1 = (k + 1) % 3;
      const Eigen::Index a0 = 3 * i + k, a1 = 3 * i + k1, b0 = 3 * j + k, b1 = 3 * j + k1;
      L.F.row(6 * i + 2 * k) << static_cast<int>(a0), static_cast<int>(b0), static_cast<int>(b1);
      L.F.row(6 * i + 2 * k + 1) << static_cast<int>(a0), static_cast<int>(b1), static_cast<int>(a1);
    }
  }
  // Outward: the enclosed volume (divergence theorem) positive, else every triangle turned.
  double volume6 = 0;
  for (Eigen::Index f = 0; f < L.F.rows(); ++f) {
    const Eigen::Vector3d p0 = L.V.row(L.F(f, 0)), p1 = L.V.row(L.F(f, 1)), p2 = L.V.row(L.F(f, 2));
    volume6 += p0.dot(p1.cross(p2));
  }
  if (volume6 < 0) L.F.col(1).swap(L.F.col(2));
  return L;
}

}  // namespace impinge
