#include "impinge/rasterize.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "impinge/error.hpp"
#include "impinge/spherical_frame.hpp"

namespace impinge {

DistanceMode parse_distance_mode(const std::string& name) {
  if (name == "linear") return DistanceMode::linear;
  if (name == "exact") return DistanceMode::exact;
  throw Error("distance mode '" + name + "': expected 'linear' or 'exact'");
}

const char* to_string(DistanceMode mode) { return mode == DistanceMode::linear ? "linear" : "exact"; }

namespace {

using V3 = Eigen::Vector3d;

/// Wrap an angle difference into (-pi, pi].
double wrap_pi(double a) {
  while (a > kPi) a -= 2 * kPi;
  while (a <= -kPi) a += 2 * kPi;
  return a;
}

bool on_axis(const V3& v) { return v.x() * v.x() + v.y() * v.y() <= 1e-24 * v.squaredNorm(); }

/// A triangle corner relative to the COR with its spherical coordinates, computed once per
/// mesh vertex (theta of a point on the axis is 0).
struct Corner {
  V3 p;  ///< position relative to the COR, mm
  V3 u;  ///< unit direction
  double d, phi, theta;
  bool axis;  ///< on the z axis (a pole vertex, thesis case 1)
};
Corner corner(const V3& v) {
  const SphericalCoordinates s = to_spherical(v);
  return {v, s.d > 0 ? V3(v / s.d) : V3::Zero(), s.d, s.phi, s.theta, on_axis(v)};
}

/// Range of z over the great-circle arc from unit u to unit v (interior extremes included).
void arc_z_range(const V3& u, const V3& v, double& zmin, double& zmax) {
  zmin = std::min(u.z(), v.z());
  zmax = std::max(u.z(), v.z());
  const V3 n = u.cross(v);
  const double nn = n.norm();
  if (nn < 1e-15) return;
  const V3 nh = n / nn;
  V3 e = V3::UnitZ() - nh.z() * nh;
  const double en = e.norm();
  if (en < 1e-15) return;
  e /= en;
  if (u.cross(e).dot(n) >= 0 && e.cross(v).dot(n) >= 0) zmax = std::max(zmax, e.z());
  const V3 f = -e;
  if (u.cross(f).dot(n) >= 0 && f.cross(v).dot(n) >= 0) zmin = std::min(zmin, f.z());
}

template <typename Scalar>
class Rasterizer {
 public:
  Rasterizer(RadialDistanceMapT<Scalar>& map, DistanceMode mode, SamplingStats& stats)
      : map_(map), mode_(mode), stats_(stats), grid_(map.grid()) {
    const int rows = grid_.rows(), cols = grid_.columns();
    const double h = grid_.step();
    sin_phi_.resize(rows);
    cos_phi_.resize(rows);
    for (int r = 0; r < rows; ++r) {
      sin_phi_[r] = std::sin(r * h);
      cos_phi_[r] = std::cos(r * h);
    }
    sin_phi_[0] = 0;  // both pole rows are exactly the pole direction
    cos_phi_[0] = 1;
    sin_phi_[rows - 1] = 0;
    cos_phi_[rows - 1] = -1;
    cos_theta_.resize(cols);
    sin_theta_.resize(cols);
    for (int c = 0; c < cols; ++c) {
      cos_theta_[c] = std::cos(c * h);
      sin_theta_[c] = std::sin(c * h);
    }
  }

  void triangle(const Corner& a, const Corner& b, const Corner& c) {
    ++stats_.triangles;
    const double det = a.p.dot(b.p.cross(c.p));
    if (!(std::abs(det) > 1e-12 * a.d * b.d * c.d)) {
      ++stats_.triangles_edge_on;
      return;
    }
    const bool north = in_cone(a.p, b.p, c.p, det, V3::UnitZ());
    const bool south = in_cone(a.p, b.p, c.p, det, -V3::UnitZ());
    if (north || south) ++stats_.pole_triangles;
    if (mode_ == DistanceMode::linear && (north || south)) {
      // Thesis Fig. 34: split at the pole so that each part has the pole as a corner.
      const Corner* axis_vertex = a.axis ? &a : b.axis ? &b : c.axis ? &c : nullptr;
      if (axis_vertex != nullptr) {  // case 1, vertex case: already a corner
        const Corner& p = *axis_vertex;
        const Corner& x = (&p == &a) ? b : a;
        const Corner& y = (&p == &c) ? b : c;
        cone(x, y, p, /*apex=*/true, north, south);
      } else {  // cases 2 and 3: the pole on an edge or inside the face
        const V3 n = (b.p - a.p).cross(c.p - a.p);
        const Corner p = corner(V3(0, 0, n.dot(a.p) / n.z()));
        cone(a, b, p, true, north, south);
        cone(b, c, p, true, north, south);
        cone(c, a, p, true, north, south);
      }
      return;
    }
    cone(a, b, c, false, north, south);
  }

 private:
  static bool in_cone(const V3& a, const V3& b, const V3& c, double det, const V3& d) {
    const double s = det > 0 ? 1.0 : -1.0;
    return s * d.dot(b.cross(c)) >= 0 && s * d.dot(c.cross(a)) >= 0 && s * d.dot(a.cross(b)) >= 0;
  }

  /// Rasterise the cone of triangle (a, b, c). With `apex`, c lies on the z axis (the pole
  /// corner) and linear mode uses the trapezoid interpolation of thesis Fig. 34. `north` /
  /// `south`: the cone holds that pole (computed once per mesh triangle; a part split at a pole
  /// holds the same pole at its apex and never the other).
  void cone(const Corner& ka, const Corner& kb, const Corner& kc, bool apex, bool north, bool south) {
    const V3 &a = ka.p, &b = kb.p, &c = kc.p;
    const double det = a.dot(b.cross(c));
    if (!(std::abs(det) > 1e-12 * ka.d * kb.d * kc.d)) return;  // empty part
    const double s = det > 0 ? 1.0 : -1.0;
    const V3 e0 = s * b.cross(c), e1 = s * c.cross(a), e2 = s * a.cross(b);
    const double adet = std::abs(det);
    const int rows = grid_.rows(), cols = grid_.columns();
    const double h = grid_.step();

    // Bounding rows: phi range of the spherical triangle, poles included.
    const V3 &ua = ka.u, &ub = kb.u, &uc = kc.u;
    double zlo = 1, zhi = -1, lo, hi;
    arc_z_range(ua, ub, lo, hi);
    zlo = std::min(zlo, lo), zhi = std::max(zhi, hi);
    arc_z_range(ub, uc, lo, hi);
    zlo = std::min(zlo, lo), zhi = std::max(zhi, hi);
    arc_z_range(uc, ua, lo, hi);
    zlo = std::min(zlo, lo), zhi = std::max(zhi, hi);
    const double phi_min = north ? 0.0 : std::acos(std::clamp(zhi, -1.0, 1.0));
    const double phi_max = south ? kPi : std::acos(std::clamp(zlo, -1.0, 1.0));
    constexpr double pad = 1e-4;  // in steps; acos near +-1 loses ~1e-8 rad
    const int r0 = std::max(0, static_cast<int>(std::ceil(phi_min / h - pad)));
    const int r1 = std::min(rows - 1, static_cast<int>(std::floor(phi_max / h + pad)));

    // Bounding columns: the smallest arc holding the corners' azimuths (< 180 deg when the
    // cone holds no pole: azimuth is monotone along a great circle that misses the axis).
    int c0 = 0, c1 = cols - 1;
    bool full = north || south || ka.axis || kb.axis || kc.axis;
    if (!full) {
      const double tb = ka.theta + wrap_pi(kb.theta - ka.theta);
      const double tc = ka.theta + wrap_pi(kc.theta - ka.theta);
      const double tmin = std::min({ka.theta, tb, tc}), tmax = std::max({ka.theta, tb, tc});
      if (tmax - tmin >= kPi) {
        full = true;
      } else {
        c0 = static_cast<int>(std::ceil(tmin / h - pad));
        c1 = static_cast<int>(std::floor(tmax / h + pad));
        if (tmin < 0 || tmax >= 2 * kPi) ++stats_.seam_triangles;
      }
    }

    // Linear-mode set-up: corners in the (theta, phi) plane, theta unwrapped around a.
    const double ta = ka.theta, tb = ka.theta + wrap_pi(kb.theta - ka.theta),
                 tc = ka.theta + wrap_pi(kc.theta - ka.theta);
    const double area2 = (tb - ta) * (kc.phi - ka.phi) - (tc - ta) * (kb.phi - ka.phi);
    const double dtheta_ab = wrap_pi(kb.theta - ka.theta);

    for (int r = r0; r <= r1; ++r) {
      const double sp = sin_phi_[r], cp = cos_phi_[r];
      const double A0 = sp * e0.x(), B0 = sp * e0.y(), C0 = cp * e0.z();
      const double A1 = sp * e1.x(), B1 = sp * e1.y(), C1 = cp * e1.z();
      const double A2 = sp * e2.x(), B2 = sp * e2.y(), C2 = cp * e2.z();
      Scalar* row = map_.data() + std::int64_t(r) * cols;
      const double phi = r * h;
      for (int cc = c0; cc <= c1; ++cc) {
        const int col = cc < 0 ? cc + cols : (cc >= cols ? cc - cols : cc);
        const double ct = cos_theta_[col], st = sin_theta_[col];
        const double f0 = A0 * ct + B0 * st + C0;
        const double f1 = A1 * ct + B1 * st + C1;
        const double f2 = A2 * ct + B2 * st + C2;
        if (f0 < 0 || f1 < 0 || f2 < 0) continue;
        double value;
        if (mode_ == DistanceMode::exact) {
          value = adet / (f0 + f1 + f2);
        } else if (apex) {
          value = apex_value(ka, kb, kc, dtheta_ab, phi, col * h);
        } else {
          value = planar_value(ka, kb, kc, ta, tb, tc, area2, phi, col * h, adet / (f0 + f1 + f2));
        }
        const Scalar v = static_cast<Scalar>(value);
        if (v < row[col]) row[col] = v;
      }
      stats_.node_tests += (c1 - c0 + 1);
    }
  }

  /// Thesis linear mode: barycentric interpolation in the (theta, phi) plane.
  static double planar_value(const Corner& ka, const Corner& kb, const Corner& kc, double ta, double tb, double tc,
                             double area2, double phi, double theta, double exact) {
    if (std::abs(area2) < 1e-18) return exact;  // collapsed in the grid: no 2-D interpolant
    const double tn = ta + wrap_pi(theta - ta);
    double lb = ((tn - ta) * (kc.phi - ka.phi) - (tc - ta) * (phi - ka.phi)) / area2;
    double lc = ((tb - ta) * (phi - ka.phi) - (tn - ta) * (kb.phi - ka.phi)) / area2;
    double la = 1 - lb - lc;
    // Nodes inside the 3-D cone but just outside the straight-edged 2-D triangle: clamp to it.
    la = std::max(la, 0.0), lb = std::max(lb, 0.0), lc = std::max(lc, 0.0);
    const double sum = la + lb + lc;
    return (la * ka.d + lb * kb.d + lc * kc.d) / sum;
  }

  /// Thesis Fig. 34: corner p (kc) on the axis, the others x (ka), y (kb). Linear in theta
  /// along the edge x-y, then linear in phi from the pole to that edge.
  static double apex_value(const Corner& kx, const Corner& ky, const Corner& kp, double dtheta, double phi,
                           double theta) {
    double s = 0.5;
    if (std::abs(dtheta) > 1e-15) s = std::clamp(wrap_pi(theta - kx.theta) / dtheta, 0.0, 1.0);
    const double phi_e = (1 - s) * kx.phi + s * ky.phi;
    const double d_e = (1 - s) * kx.d + s * ky.d;
    const double span = std::abs(phi_e - kp.phi);
    const double u = span > 1e-15 ? std::clamp(std::abs(phi - kp.phi) / span, 0.0, 1.0) : 1.0;
    return (1 - u) * kp.d + u * d_e;
  }

  RadialDistanceMapT<Scalar>& map_;
  DistanceMode mode_;
  SamplingStats& stats_;
  const EquiangularGrid& grid_;
  std::vector<double> sin_phi_, cos_phi_, cos_theta_, sin_theta_;
};

}  // namespace

template <typename Scalar>
SamplingStats rasterize(const TriangleMesh& mesh, const Eigen::Vector3d& cor, DistanceMode mode,
                        RadialDistanceMapT<Scalar>& map) {
  require(cor.allFinite(), mesh.source + ": centre of rotation is not finite");
  SamplingStats stats;
  Rasterizer<Scalar> raster(map, mode, stats);
  // Spherical coordinates once per vertex (a vertex is shared by about six triangles).
  std::vector<Corner> corners(static_cast<std::size_t>(mesh.V.rows()));
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i)
    corners[static_cast<std::size_t>(i)] = corner(mesh.V.row(i).transpose() - cor);
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
    raster.triangle(corners[static_cast<std::size_t>(mesh.F(f, 0))], corners[static_cast<std::size_t>(mesh.F(f, 1))],
                    corners[static_cast<std::size_t>(mesh.F(f, 2))]);
  stats.nodes_covered = map.nodes_covered();
  return stats;
}

template SamplingStats rasterize<float>(const TriangleMesh&, const Eigen::Vector3d&, DistanceMode,
                                        RadialDistanceMapT<float>&);
template SamplingStats rasterize<double>(const TriangleMesh&, const Eigen::Vector3d&, DistanceMode,
                                         RadialDistanceMapT<double>&);

RadialDistanceMap rasterize_map(const TriangleMesh& mesh, const Eigen::Vector3d& cor, double precision_deg,
                                DistanceMode mode, SamplingStats* stats) {
  RadialDistanceMap map{EquiangularGrid(precision_deg)};
  const SamplingStats s = rasterize(mesh, cor, mode, map);
  if (stats != nullptr) *stats = s;
  return map;
}

}  // namespace impinge
