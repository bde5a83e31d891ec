#include "sampling/raster_cone_setup.hpp"

#include <algorithm>
#include <cmath>

#include "impinge/core/fast_angles.hpp"

namespace impinge {

namespace detail {

Corner corner(const V3& v) {
  Corner k{v, v.norm(), 0, 0, on_axis(v)};
  if (k.d > 0) fast_spherical_angles(v.x(), v.y(), v.z(), k.phi, k.theta);
  if (k.theta >= 2 * kPi) k.theta -= 2 * kPi;
  return k;
}


namespace {
/// Range of z over the great-circle arc from unit u to unit v (interior extremes included).
/// With n = u x v, the highest point of the great circle, e ~ z - (n.z / n.n) n, lies inside the
/// arc iff z . (n x u) >= 0 and z . (v x n) >= 0 (the lowest: both <= 0), and its height is
/// sqrt(1 - n.z^2 / n.n). Two cross-product z components, at most one sqrt.
void arc_z_range(const V3& u, const V3& v, double& zmin, double& zmax) {
  zmin = std::min(u.z(), v.z());
  zmax = std::max(u.z(), v.z());
  const V3 n = u.cross(v);
  const double nn = n.squaredNorm();
  if (nn < 1e-30) return;
  const double su = n.x() * u.y() - n.y() * u.x();  // z . (n x u)
  const double sv = v.x() * n.y() - v.y() * n.x();  // z . (v x n)
  if (su >= 0 && sv >= 0) zmax = std::max(zmax, std::sqrt(std::max(0.0, 1 - n.z() * n.z() / nn)));
  if (su <= 0 && sv <= 0) zmin = std::min(zmin, -std::sqrt(std::max(0.0, 1 - n.z() * n.z() / nn)));
}

}  // namespace

TriangleCone make_cone(const Corner& ka, const Corner& kb, const Corner& kc, double det, bool north, bool south) {
  TriangleCone t;
  const V3 &a = ka.p, &b = kb.p, &c = kc.p;
  const double s = det > 0 ? 1.0 : -1.0;
  const V3 e[3] = {s * b.cross(c), s * c.cross(a), s * a.cross(b)};
  const V3 n = s * (b - a).cross(c - a);
  for (int i = 0; i < 3; ++i) t.n[i] = n[i];
  for (int k = 0; k < 3; ++k) {
    for (int i = 0; i < 3; ++i) t.e[3 * k + i] = e[k][i];
    // (edge normals are products of mm coordinates: no overflow, so no std::hypot, which is slow)
    const double rho = std::sqrt(e[k].x() * e[k].x() + e[k].y() * e[k].y()), norm = e[k].norm();
    t.span_edge[k] = rho > 1e-12 * norm;
    t.alpha[k] = t.span_edge[k] ? fast_azimuth(e[k].y(), e[k].x()) : 0.0;
    t.k[k] = t.span_edge[k] ? -e[k].z() / rho : 0.0;
    t.pad[k] = t.span_edge[k] ? 2e-7 / std::sqrt(rho / norm) : 1.0;
    t.bias[k] = kEdgeAngleTolerance * norm;
  }
  t.adet = std::abs(det);
  t.north = north, t.south = south;

  // Polar range of the spherical triangle, poles included.
  const V3 ua = ka.u(), ub = kb.u(), uc = kc.u();
  double zlo = 1, zhi = -1, lo, hi;
  arc_z_range(ua, ub, lo, hi);
  zlo = std::min(zlo, lo), zhi = std::max(zhi, hi);
  arc_z_range(ub, uc, lo, hi);
  zlo = std::min(zlo, lo), zhi = std::max(zhi, hi);
  arc_z_range(uc, ua, lo, hi);
  zlo = std::min(zlo, lo), zhi = std::max(zhi, hi);
  zhi = std::clamp(zhi, -1.0, 1.0), zlo = std::clamp(zlo, -1.0, 1.0);
  t.phi_min = north ? 0.0 : fast_polar_angle(std::sqrt((1 - zhi) * (1 + zhi)), zhi);
  t.phi_max = south ? kPi : fast_polar_angle(std::sqrt((1 - zlo) * (1 + zlo)), zlo);

  // Azimuth range: the smallest arc holding the corners' azimuths (< 180 deg when the cone
  // holds no pole: azimuth is monotone along a great circle that misses the axis).
  t.full_theta = north || south || ka.axis || kb.axis || kc.axis;
  const double tb = ka.theta + wrap_pi(kb.theta - ka.theta), tc = ka.theta + wrap_pi(kc.theta - ka.theta);
  t.theta_min = std::min({ka.theta, tb, tc}), t.theta_max = std::max({ka.theta, tb, tc});
  if (t.theta_max - t.theta_min >= kPi) t.full_theta = true;
  t.seam = !t.full_theta && (t.theta_min < 0 || t.theta_max >= 2 * kPi);
  return t;
}


const std::vector<Corner>& vertex_corners(const TriangleMesh& mesh, const Eigen::Vector3d& cor) {
  thread_local std::vector<Corner> corners;
  corners.resize(static_cast<std::size_t>(mesh.V.rows()));
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i)
    corners[static_cast<std::size_t>(i)] = corner(mesh.V.row(i).transpose() - cor);
  return corners;
}


}  // namespace detail

using namespace detail;

std::int64_t detail::append_triangle_cones(const TriangleMesh& mesh, const std::vector<Corner>& k,
                                           const std::vector<std::int32_t>& faces, std::size_t begin, std::size_t end,
                                           std::vector<TriangleCone>& cones) {
  std::int64_t skipped = 0;
  // The faces come in the plan's order (Z order of direction), not the mesh's: each one's row of F and its
  // three corners are cache misses unless fetched ahead (the rows 16 faces ahead, the corners 8).
  const std::size_t n = end;
  for (std::size_t i = begin; i < n; ++i) {
    if (i + 16 < n) __builtin_prefetch(&mesh.F(faces[i + 16], 0));
    if (i + 8 < n) {
      const auto g = faces[i + 8];
      for (int j = 0; j < 3; ++j) __builtin_prefetch(&k[static_cast<std::size_t>(mesh.F(g, j))]);
    }
    const std::int32_t f = faces[i];
    const Corner &a = k[static_cast<std::size_t>(mesh.F(f, 0))], &b = k[static_cast<std::size_t>(mesh.F(f, 1))],
                 &c = k[static_cast<std::size_t>(mesh.F(f, 2))];
    const double det = a.p.dot(b.p.cross(c.p));
    if (!(std::abs(det) > 1e-12 * a.d * b.d * c.d)) {
      ++skipped;
      continue;
    }
    cones.push_back(make_cone(a, b, c, det, in_cone(a.p, b.p, c.p, det, V3::UnitZ()),
                              in_cone(a.p, b.p, c.p, det, -V3::UnitZ())));
  }
  return skipped;
}

std::vector<TriangleCone> triangle_cones(const TriangleMesh& mesh, const Eigen::Vector3d& cor,
                                         const std::vector<std::int32_t>& faces, std::int64_t* edge_on) {
  std::vector<TriangleCone> cones;
  cones.reserve(faces.size());
  const std::int64_t skipped = append_triangle_cones(mesh, vertex_corners(mesh, cor), faces, 0, faces.size(), cones);
  if (edge_on != nullptr) *edge_on = skipped;
  return cones;
}

}  // namespace impinge
