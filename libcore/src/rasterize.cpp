#include "impinge/rasterize.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>
#endif

#include "impinge/error.hpp"
#include "impinge/fast_angles.hpp"
#include "impinge/spherical_frame.hpp"
#include "simd_clones.hpp"

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
  double d, phi, theta;
  bool axis;                                               ///< on the z axis (a pole vertex, thesis case 1)
  V3 u() const { return d > 0 ? V3(p / d) : V3::Zero(); }  ///< unit direction
};
/// Angles by fast_angles.hpp (within 1e-13 rad of libm's): they only place bounding boxes
/// (padded by 1e-4 steps) and feed linear mode's interpolation.
Corner corner(const V3& v) {
  Corner k{v, v.norm(), 0, 0, on_axis(v)};
  if (k.d > 0) fast_spherical_angles(v.x(), v.y(), v.z(), k.phi, k.theta);
  if (k.theta >= 2 * kPi) k.theta -= 2 * kPi;
  return k;
}

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

/// Exact-mode rows r0..r1 of one triangle's box. For a node of row r and column c the three
/// edge functions are f_e = sin(phi_r) (e_e.x cos(theta_c) + e_e.y sin(theta_c)) + cos(phi_r) e_e.z
/// (e_e: the oriented edge normals); the node is inside the cone when all are >= 0, and its
/// distance is adet / (f0 + f1 + f2), where the ray meets the plane; the nearer value is kept.
/// The columns are given as up to three contiguous segments (the box may wrap across theta =
/// 0/360). Branch-free inner loops; the whole triangle in one call so the vectorised clone
/// (AVX-512 / AVX2, chosen at run time) is dispatched once per triangle.
struct ExactBox {
  int r0, r1, nseg, seg[3][2];
  int seg_offset[3];  ///< the box's own (unwrapped) column = stored column + offset, per segment
  double e[9], adet;
};

/// The box of rows r0..r1 and unwrapped columns c0..c1 (c0 may be negative, c1 may reach past the
/// last column: the box wraps across theta = 0/360) as up to three contiguous segments.
ExactBox make_box(int r0, int r1, int c0, int c1, int cols, const Eigen::Vector3d& e0, const Eigen::Vector3d& e1,
                  const Eigen::Vector3d& e2, double adet) {
  ExactBox b;
  b.r0 = r0, b.r1 = r1, b.nseg = 0;
  auto add = [&](int lo, int hi, int offset) {
    b.seg[b.nseg][0] = lo, b.seg[b.nseg][1] = hi, b.seg_offset[b.nseg] = offset, ++b.nseg;
  };
  if (c0 < 0) add(c0 + cols, cols - 1, -cols);
  add(std::max(c0, 0), std::min(c1, cols - 1), 0);
  if (c1 >= cols) add(0, c1 - cols, cols);
  for (int k = 0; k < 3; ++k) b.e[k] = e0[k], b.e[3 + k] = e1[k], b.e[6 + k] = e2[k];
  b.adet = adet;
  return b;
}

/// The three edge functions of one row (coefficients folded with sin and cos of its phi).
struct RowEdges {
  double a0, b0, c0, a1, b1, c1, a2, b2, c2;
  RowEdges(const double* e, double sp, double cp)
      : a0(sp * e[0]),
        b0(sp * e[1]),
        c0(cp * e[2]),
        a1(sp * e[3]),
        b1(sp * e[4]),
        c1(cp * e[5]),
        a2(sp * e[6]),
        b2(sp * e[7]),
        c2(cp * e[8]) {}
  /// Inside the cone (all three >= 0); `sum` = f0 + f1 + f2 (the ray-plane denominator).
  bool inside(double ct, double st, double& sum) const {
    const double f0 = a0 * ct + b0 * st + c0, f1 = a1 * ct + b1 * st + c1, f2 = a2 * ct + b2 * st + c2;
    sum = f0 + f1 + f2;
    return std::min(std::min(f0, f1), f2) >= 0;
  }
};

/// Keep the nearer value at a covered node; count nodes that had no surface before.
template <typename Scalar>
inline void keep_nearer(Scalar& node, bool inside, Scalar v, std::int64_t& newly) {
  const Scalar old = node;
  newly += (inside && old == std::numeric_limits<Scalar>::infinity()) ? 1 : 0;
  node = inside && v < old ? v : old;
}
/// Distance of a node: adet / sum, in the map's precision (float maps divide in float: within
/// 1.5 ulp of the correctly rounded value, 1e-5 mm at 100 mm; double maps in double).
inline float node_distance(double adet, double sum, float) {
  return static_cast<float>(adet) / static_cast<float>(sum);
}
inline double node_distance(double adet, double sum, double) { return adet / sum; }

/// Returns the number of nodes that had no surface before and have one now.
template <typename Scalar>
inline std::int64_t exact_rows_body(Scalar* __restrict map, int cols, const ExactBox& box,
                                    const double* __restrict sin_phi, const double* __restrict cos_phi,
                                    const double* __restrict cos_theta, const double* __restrict sin_theta) {
  std::int64_t newly = 0;
  for (int r = box.r0; r <= box.r1; ++r) {
    const RowEdges edges(box.e, sin_phi[r], cos_phi[r]);
    Scalar* __restrict row = map + std::int64_t(r) * cols;
    for (int g = 0; g < box.nseg; ++g)
      for (int j = box.seg[g][0]; j <= box.seg[g][1]; ++j) {
        double sum;
        const bool inside = edges.inside(cos_theta[j], sin_theta[j], sum);
        keep_nearer(row[j], inside, node_distance(box.adet, sum, Scalar{}), newly);
      }
  }
  return newly;
}
IMPINGE_SIMD_CLONES
std::int64_t exact_rows_generic(float* map, int cols, const ExactBox& box, const double* sin_phi, const double* cos_phi,
                                const double* cos_theta, const double* sin_theta) {
  return exact_rows_body(map, cols, box, sin_phi, cos_phi, cos_theta, sin_theta);
}

#if defined(__GNUC__) && defined(__x86_64__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"  // GCC 12's own _mm512_cvtpd_ps (a false positive)
/// exact_rows_body for float maps in AVX-512 with masked loads and stores: the short spans of
/// small triangles (a few dozen nodes) run without scalar remainders. Same arithmetic as the
/// generic body (double edge functions, float division), so the same values.
__attribute__((target("avx512f,avx512vl,avx512dq"))) std::int64_t exact_rows_avx512(
    float* map, int cols, const ExactBox& box, const double* sin_phi, const double* cos_phi, const double* cos_theta,
    const double* sin_theta) {
  const double* e = box.e;
  const __m256 adet = _mm256_set1_ps(static_cast<float>(box.adet));
  const __m256 none = _mm256_set1_ps(std::numeric_limits<float>::infinity());
  const __m512d zero = _mm512_setzero_pd();
  std::int64_t newly = 0;
  for (int r = box.r0; r <= box.r1; ++r) {
    const double sp = sin_phi[r], cp = cos_phi[r];
    const __m512d a0 = _mm512_set1_pd(sp * e[0]), b0 = _mm512_set1_pd(sp * e[1]), c0 = _mm512_set1_pd(cp * e[2]),
                  a1 = _mm512_set1_pd(sp * e[3]), b1 = _mm512_set1_pd(sp * e[4]), c1 = _mm512_set1_pd(cp * e[5]),
                  a2 = _mm512_set1_pd(sp * e[6]), b2 = _mm512_set1_pd(sp * e[7]), c2 = _mm512_set1_pd(cp * e[8]);
    float* row = map + std::int64_t(r) * cols;
    if (r + 2 <= box.r1)  // rows are a whole map row apart: no hardware prefetcher follows them
      for (int g = 0; g < box.nseg; ++g)
        for (int j = box.seg[g][0]; j <= box.seg[g][1]; j += 16)
          _mm_prefetch(reinterpret_cast<const char*>(row + 2 * std::int64_t(cols) + j), _MM_HINT_T0);
    for (int g = 0; g < box.nseg; ++g) {
      const int lo = box.seg[g][0], hi = box.seg[g][1];
      for (int j = lo; j <= hi; j += 8) {
        const int left = hi - j + 1;
        const __mmask8 m = left >= 8 ? __mmask8(0xFF) : __mmask8((1u << left) - 1u);
        const __m512d ct = _mm512_maskz_loadu_pd(m, cos_theta + j), st = _mm512_maskz_loadu_pd(m, sin_theta + j);
        // Same operation order as the generic body: a * ct + b * st + c.
        const __m512d f0 = _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(a0, ct), _mm512_mul_pd(b0, st)), c0);
        const __m512d f1 = _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(a1, ct), _mm512_mul_pd(b1, st)), c1);
        const __m512d f2 = _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(a2, ct), _mm512_mul_pd(b2, st)), c2);
        const __mmask8 inside = _mm512_mask_cmp_pd_mask(
            _mm512_mask_cmp_pd_mask(_mm512_mask_cmp_pd_mask(m, f0, zero, _CMP_GE_OQ), f1, zero, _CMP_GE_OQ), f2, zero,
            _CMP_GE_OQ);
        if (!inside) continue;
        const __m256 sum = _mm512_cvtpd_ps(_mm512_add_pd(_mm512_add_pd(f0, f1), f2));
        const __m256 v = _mm256_div_ps(adet, sum);
        const __m256 old = _mm256_maskz_loadu_ps(inside, row + j);
        newly += __builtin_popcount(_mm256_mask_cmp_ps_mask(inside, old, none, _CMP_EQ_OQ));
        _mm256_mask_storeu_ps(row + j, _mm256_mask_cmp_ps_mask(inside, v, old, _CMP_LT_OQ), v);
      }
    }
  }
  return newly;
}
#pragma GCC diagnostic pop
#endif

std::int64_t exact_rows(float* map, int cols, const ExactBox& box, const double* sin_phi, const double* cos_phi,
                        const double* cos_theta, const double* sin_theta) {
#if defined(__GNUC__) && defined(__x86_64__)
  static const bool avx512 =
      __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512dq");
  if (avx512) return exact_rows_avx512(map, cols, box, sin_phi, cos_phi, cos_theta, sin_theta);
#endif
  return exact_rows_generic(map, cols, box, sin_phi, cos_phi, cos_theta, sin_theta);
}
IMPINGE_SIMD_CLONES
std::int64_t exact_rows(double* map, int cols, const ExactBox& box, const double* sin_phi, const double* cos_phi,
                        const double* cos_theta, const double* sin_theta) {
  return exact_rows_body(map, cols, box, sin_phi, cos_phi, cos_theta, sin_theta);
}

/// Linear-mode (thesis Algorithm 1) rows of one triangle's box away from the poles: the same
/// cone test as exact mode, and at covered nodes the barycentric interpolation of the corner
/// distances in the (theta, phi) plane (planar_value's formula, theta unwrapped as the box's own
/// column index), clamped to the triangle. Branch-free; vectorised clones.
struct LinearBox {
  ExactBox box;
  double h, ta, tb, tc, pa, pb, pc, da, db, dc, inv_area2;
};
template <typename Scalar>
inline std::int64_t linear_rows_body(Scalar* __restrict map, int cols, const LinearBox& L,
                                     const double* __restrict sin_phi, const double* __restrict cos_phi,
                                     const double* __restrict cos_theta, const double* __restrict sin_theta) {
  const ExactBox& box = L.box;
  std::int64_t newly = 0;
  for (int r = box.r0; r <= box.r1; ++r) {
    const RowEdges edges(box.e, sin_phi[r], cos_phi[r]);
    const double phi = r * L.h;
    Scalar* __restrict row = map + std::int64_t(r) * cols;
    for (int g = 0; g < box.nseg; ++g)
      for (int j = box.seg[g][0]; j <= box.seg[g][1]; ++j) {
        double sum;
        const bool inside = edges.inside(cos_theta[j], sin_theta[j], sum);
        const double tn = (j + box.seg_offset[g]) * L.h;
        double lb = ((tn - L.ta) * (L.pc - L.pa) - (L.tc - L.ta) * (phi - L.pa)) * L.inv_area2;
        double lc = ((L.tb - L.ta) * (phi - L.pa) - (tn - L.ta) * (L.pb - L.pa)) * L.inv_area2;
        double la = 1 - lb - lc;
        la = std::max(la, 0.0), lb = std::max(lb, 0.0), lc = std::max(lc, 0.0);
        keep_nearer(row[j], inside, static_cast<Scalar>((la * L.da + lb * L.db + lc * L.dc) / (la + lb + lc)), newly);
      }
  }
  return newly;
}
IMPINGE_SIMD_CLONES
std::int64_t linear_rows(float* map, int cols, const LinearBox& L, const double* sin_phi, const double* cos_phi,
                         const double* cos_theta, const double* sin_theta) {
  return linear_rows_body(map, cols, L, sin_phi, cos_phi, cos_theta, sin_theta);
}
IMPINGE_SIMD_CLONES
std::int64_t linear_rows(double* map, int cols, const LinearBox& L, const double* sin_phi, const double* cos_phi,
                         const double* cos_theta, const double* sin_theta) {
  return linear_rows_body(map, cols, L, sin_phi, cos_phi, cos_theta, sin_theta);
}

template <typename Scalar>
class Rasterizer {
 public:
  Rasterizer(RadialDistanceMapT<Scalar>& map, DistanceMode mode, SamplingStats& stats, int keep_sign)
      : map_(map), mode_(mode), stats_(stats), grid_(map.grid()), keep_sign_(keep_sign) {
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

  /// Nodes that had no surface before this rasteriser and have one now.
  std::int64_t newly_covered() const { return newly_covered_; }

  void triangle(const Corner& a, const Corner& b, const Corner& c) {
    ++stats_.triangles;
    const double det = a.p.dot(b.p.cross(c.p));
    if (!(std::abs(det) > 1e-12 * a.d * b.d * c.d)) {
      ++stats_.triangles_edge_on;
      return;
    }
    if (keep_sign_ != 0 && (det > 0 ? 1 : -1) != keep_sign_) {  // never the nearest hit (face_culling.hpp)
      ++stats_.triangles_culled;
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
    const V3 ua = ka.u(), ub = kb.u(), uc = kc.u();
    double zlo = 1, zhi = -1, lo, hi;
    arc_z_range(ua, ub, lo, hi);
    zlo = std::min(zlo, lo), zhi = std::max(zhi, hi);
    arc_z_range(ub, uc, lo, hi);
    zlo = std::min(zlo, lo), zhi = std::max(zhi, hi);
    arc_z_range(uc, ua, lo, hi);
    zlo = std::min(zlo, lo), zhi = std::max(zhi, hi);
    zhi = std::clamp(zhi, -1.0, 1.0), zlo = std::clamp(zlo, -1.0, 1.0);
    const double phi_min = north ? 0.0 : fast_polar_angle(std::sqrt((1 - zhi) * (1 + zhi)), zhi);
    const double phi_max = south ? kPi : fast_polar_angle(std::sqrt((1 - zlo) * (1 + zlo)), zlo);
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

    if (mode_ == DistanceMode::exact) {
      const ExactBox box = make_box(r0, r1, c0, c1, cols, e0, e1, e2, adet);
      if (r1 >= r0)
        newly_covered_ +=
            exact_rows(map_.data(), cols, box, sin_phi_.data(), cos_phi_.data(), cos_theta_.data(), sin_theta_.data());
      stats_.node_tests += std::int64_t(std::max(0, r1 - r0 + 1)) * (c1 - c0 + 1);
      return;
    }
    if (!apex && !full && std::abs(area2) >= 1e-18) {  // linear mode away from the poles: vectorised
      LinearBox L{make_box(r0, r1, c0, c1, cols, e0, e1, e2, adet),
                  h,
                  ta,
                  tb,
                  tc,
                  ka.phi,
                  kb.phi,
                  kc.phi,
                  ka.d,
                  kb.d,
                  kc.d,
                  1 / area2};
      if (r1 >= r0)
        newly_covered_ +=
            linear_rows(map_.data(), cols, L, sin_phi_.data(), cos_phi_.data(), cos_theta_.data(), sin_theta_.data());
      stats_.node_tests += std::int64_t(std::max(0, r1 - r0 + 1)) * (c1 - c0 + 1);
      return;
    }
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
        const double value = apex ? apex_value(ka, kb, kc, dtheta_ab, phi, col * h)
                                  : planar_value(ka, kb, kc, ta, tb, tc, area2, phi, col * h, adet / (f0 + f1 + f2));
        const Scalar v = static_cast<Scalar>(value);
        newly_covered_ += row[col] == RadialDistanceMapT<Scalar>::no_surface() ? 1 : 0;
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
  int keep_sign_;                   ///< 0: no culling
  std::int64_t newly_covered_ = 0;  ///< nodes that had no surface and now have one
  std::vector<double> sin_phi_, cos_phi_, cos_theta_, sin_theta_;
};

}  // namespace

template <typename Scalar>
SamplingStats rasterize(const TriangleMesh& mesh, const Eigen::Vector3d& cor, DistanceMode mode,
                        RadialDistanceMapT<Scalar>& map, const FaceCulling* culling) {
  require(cor.allFinite(), mesh.source + ": centre of rotation is not finite");
  SamplingStats stats;
  const int keep = (culling != nullptr && culling->enabled && mode == DistanceMode::exact) ? culling->keep_sign : 0;
  Rasterizer<Scalar> raster(map, mode, stats, keep);
  // Spherical coordinates once per vertex (a vertex is shared by about six triangles).
  // Reused between calls on this thread: a fresh multi-megabyte buffer would be page-faulted in
  // on every call.
  thread_local std::vector<Corner> corners;
  corners.resize(static_cast<std::size_t>(mesh.V.rows()));
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i)
    corners[static_cast<std::size_t>(i)] = corner(mesh.V.row(i).transpose() - cor);
  auto draw = [&](Eigen::Index f) {
    raster.triangle(corners[static_cast<std::size_t>(mesh.F(f, 0))], corners[static_cast<std::size_t>(mesh.F(f, 1))],
                    corners[static_cast<std::size_t>(mesh.F(f, 2))]);
  };
  if (keep != 0 && !culling->triangle_order.empty()) {
    // The plan's order holds the kept triangles only: account for the culled ones here.
    for (const std::int32_t f : culling->triangle_order) {
      if (f < 0 || f >= mesh.F.rows()) throw Error(mesh.source + ": face culling plan does not match the mesh");
      draw(f);
    }
    stats.triangles_culled += mesh.F.rows() - static_cast<std::int64_t>(culling->triangle_order.size());
    stats.triangles += mesh.F.rows() - static_cast<std::int64_t>(culling->triangle_order.size());
  } else {
    for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) draw(f);
  }
  stats.nodes_covered = raster.newly_covered();
  return stats;
}

template SamplingStats rasterize<float>(const TriangleMesh&, const Eigen::Vector3d&, DistanceMode,
                                        RadialDistanceMapT<float>&, const FaceCulling*);
template SamplingStats rasterize<double>(const TriangleMesh&, const Eigen::Vector3d&, DistanceMode,
                                         RadialDistanceMapT<double>&, const FaceCulling*);

RadialDistanceMap rasterize_map(const TriangleMesh& mesh, const Eigen::Vector3d& cor, double precision_deg,
                                DistanceMode mode, SamplingStats* stats) {
  RadialDistanceMap map{EquiangularGrid(precision_deg)};
  const SamplingStats s = rasterize(mesh, cor, mode, map);
  if (stats != nullptr) *stats = s;
  return map;
}

}  // namespace impinge
