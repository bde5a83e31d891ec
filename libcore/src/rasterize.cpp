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
#include "cpu_dispatch.hpp"
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

bool in_cone(const V3& a, const V3& b, const V3& c, double det, const V3& d) {
  const double s = det > 0 ? 1.0 : -1.0;
  return s * d.dot(b.cross(c)) >= 0 && s * d.dot(c.cross(a)) >= 0 && s * d.dot(a.cross(b)) >= 0;
}

/// The precision-independent set-up of the cone through corners (ka, kb, kc) with
/// det = a . (b x c) != 0 (triangle_cone.hpp). `north` / `south`: the cone holds that pole.
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

/// Rows r0..r1 and unwrapped columns c0..c1 of a cone's box on a grid of step h (rad), given
/// as inv_h = 1 / h.
struct Box {
  int r0, r1, c0, c1;
};
Box box_of(const TriangleCone& t, double inv_h, int rows, int cols) {
  constexpr double pad = 1e-4;  // in steps; acos near +-1 loses ~1e-8 rad
  Box b{std::max(0, static_cast<int>(std::ceil(t.phi_min * inv_h - pad))),
        std::min(rows - 1, static_cast<int>(std::floor(t.phi_max * inv_h + pad))), 0, cols - 1};
  if (!t.full_theta) {
    b.c0 = static_cast<int>(std::ceil(t.theta_min * inv_h - pad));
    b.c1 = static_cast<int>(std::floor(t.theta_max * inv_h + pad));
  }
  return b;
}

/// Per-triangle constants of the row spans in column units (triangle_cone.hpp): edge k allows
/// the columns within W of near[k] (the copy of alpha_k / h nearest the box's middle) when
/// W <= cols / 4, else forbids those strictly within cols / 2 - W of far[k] (the copy of the
/// opposite azimuth nearest the middle). Edges that bound no span get pad = +inf.
struct SpanSetup {
  double c0, c1, inv_h, half, quarter;
  double k[3], pad[3], near[3], far[3];
};
SpanSetup span_setup(const TriangleCone& t, const Box& b, double inv_h, int cols) {
  SpanSetup p;
  p.c0 = b.c0, p.c1 = b.c1, p.inv_h = inv_h, p.half = 0.5 * cols, p.quarter = 0.25 * cols;
  const double mid = 0.5 * (b.c0 + b.c1), inv_cols = 1.0 / cols;
  for (int k = 0; k < 3; ++k) {
    double a = t.alpha[k] * inv_h;
    a += cols * std::round((mid - a) * inv_cols);
    p.near[k] = a;
    p.far[k] = a <= mid ? a + p.half : a - p.half;
    p.k[k] = t.k[k];
    p.pad[k] = t.span_edge[k] ? t.pad[k] : std::numeric_limits<double>::infinity();
  }
  return p;
}

/// Absolute padding (rad) of a span's ends: fast_acos_coarse's error and 1e-9.
constexpr double kSpanAnglePad = kFastAcosCoarseMaxError + 1e-9;

/// Narrow the span L..H of one row (cot phi = ct, 1 / sqrt(sin phi) = rs) by edge k, whose arc
/// is widened by d columns, and the inner span Li..Hi by the same limits moved inwards by 2 d
/// (the arc shrunk by d instead: a subset of the cone). `split` is set when the inner span
/// cannot be trusted: the edge bounds no span or the row is a pole row (d infinite), the
/// edge's forbidden arc, or that arc grown by 2 d (so a tangent edge's empty arc counts), lies
/// inside the span, or the arc is within 2 d of the wide case's limit.
inline void edge_span(const SpanSetup& P, int k, double ct, double rs, double& L, double& H, double& Li,
                      double& Hi, bool& split) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  const double x = std::min(std::max(P.k[k] * ct, -1.0), 1.0);
  const double w = fast_acos_coarse(x);
  const double d = (P.pad[k] * rs + kSpanAnglePad) * P.inv_h + 1e-6;
  const double W = w * P.inv_h + d;
  const double V = P.half - W;
  const bool narrow = W <= P.quarter;
  const bool cut_low = P.far[k] - V < L;
  const bool cut_high = (P.far[k] + V > H) & !cut_low;
  split = split || !(d < inf) ||
          (!narrow && ((!cut_low && !cut_high && V + 2 * d > 0) || W - 2 * d <= P.quarter));
  const double wide_low = cut_low ? P.far[k] + V : -inf, wide_high = cut_high ? P.far[k] - V : inf;
  const double low = narrow ? P.near[k] - W : wide_low, high = narrow ? P.near[k] + W : wide_high;
  L = std::max(L, low), H = std::min(H, high);
  Li = std::max(Li, low + 2 * d), Hi = std::min(Hi, high - 2 * d);
}

/// Whether every node of span L..H (edge_span's result) is certainly inside the cone: the inner
/// span Li..Hi holds the same nodes and nothing set `split`.
inline bool span_is_sure(double L, double H, double Li, double Hi, bool split) {
  return !split && std::ceil(L) == std::ceil(Li) && std::floor(H) == std::floor(Hi);
}

/// Row spans lo[i] .. hi[i] (unwrapped columns, empty when lo > hi) of rows r0 + i, i <= r1 - r0,
/// of a cone whose box is narrower than 180 deg. Bit i % 8 of sure[i / 8] is set when every
/// node of the span is certainly inside the cone (the inner span holds the same nodes). Row
/// tables: cot_phi (0 at the pole rows) and rsqrt_sin_phi (+inf at the pole rows, which so keep
/// the whole box and are never sure). Returns the number of nodes in the spans.
std::int64_t row_spans_scalar(const SpanSetup& P, int r0, int r1, const double* cot_phi, const double* rsqrt_sin_phi,
                              int* lo, int* hi, std::uint8_t* sure) {
  std::int64_t nodes = 0;
  for (int r = r0; r <= r1; ++r) {
    double L = P.c0, H = P.c1, Li = P.c0, Hi = P.c1;
    bool split = false;
    for (int k = 0; k < 3; ++k) edge_span(P, k, cot_phi[r], rsqrt_sin_phi[r], L, H, Li, Hi, split);
    const int i = r - r0;
    lo[i] = static_cast<int>(std::ceil(L)), hi[i] = static_cast<int>(std::floor(H));
    const bool certain = span_is_sure(L, H, Li, Hi, split);
    if (i % 8 == 0) sure[i / 8] = 0;
    sure[i / 8] |= static_cast<std::uint8_t>(certain ? 1u << (i % 8) : 0u);
    nodes += std::max(0, hi[i] - lo[i] + 1);
  }
  return nodes;
}

/// The first min(n, 8) of 8 lanes (n >= 1): the mask of a vector step with n items left.
inline std::uint8_t first_lanes(int n) { return n >= 8 ? std::uint8_t(0xff) : std::uint8_t((1u << n) - 1); }

#if defined(__GNUC__) && defined(__x86_64__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"  // GCC 12's own AVX-512 headers (false positives)
/// One edge's arc for 8 rows in AVX-512 (edge_span's cases): the arc of column half-width W
/// about nearv, or the complement of the arc of half-width half - W about farv, intersected
/// with L..H, and the inner span Li..Hi; adds to `split` the lanes that cannot be sure
/// (edge_span).
__attribute__((target("avx512f,avx512vl,avx512dq"), always_inline)) inline void narrow_by_arc(
    __m512d W, __m512d d, __m512d nearv, __m512d farv, __m512d half, __m512d quarter, __m512d& L, __m512d& H,
    __m512d& Li, __m512d& Hi, __mmask8& split) {
  const __m512d inf = _mm512_set1_pd(std::numeric_limits<double>::infinity());
  const __m512d V = _mm512_sub_pd(half, W);
  const __mmask8 narrow = _mm512_cmp_pd_mask(W, quarter, _CMP_LE_OQ);
  const __mmask8 cut_low = _mm512_cmp_pd_mask(_mm512_sub_pd(farv, V), L, _CMP_LT_OQ);
  const __mmask8 cut_high = _mm512_cmp_pd_mask(_mm512_add_pd(farv, V), H, _CMP_GT_OQ) & __mmask8(~cut_low);
  const __m512d d2 = _mm512_add_pd(d, d);
  const __mmask8 inner_arc = __mmask8(~(cut_low | cut_high)) &
                             _mm512_cmp_pd_mask(_mm512_add_pd(V, d2), _mm512_setzero_pd(), _CMP_GT_OQ);
  const __mmask8 wide_limit = _mm512_cmp_pd_mask(_mm512_sub_pd(W, d2), quarter, _CMP_LE_OQ);
  split |= __mmask8(_mm512_cmp_pd_mask(d, inf, _CMP_NLT_UQ) | (__mmask8(~narrow) & (inner_arc | wide_limit)));
  const __m512d wide_low = _mm512_mask_blend_pd(cut_low, _mm512_sub_pd(_mm512_setzero_pd(), inf), _mm512_add_pd(farv, V));
  const __m512d wide_high = _mm512_mask_blend_pd(cut_high, inf, _mm512_sub_pd(farv, V));
  const __m512d low = _mm512_mask_blend_pd(narrow, wide_low, _mm512_sub_pd(nearv, W));
  const __m512d high = _mm512_mask_blend_pd(narrow, wide_high, _mm512_add_pd(nearv, W));
  L = _mm512_max_pd(L, low), H = _mm512_min_pd(H, high);
  Li = _mm512_max_pd(Li, _mm512_add_pd(low, d2)), Hi = _mm512_min_pd(Hi, _mm512_sub_pd(high, d2));
}

/// row_spans_scalar for 8 rows at a time in AVX-512: the same operations (fast_acos_coarse),
/// with fused multiply-adds, so the ends may differ by rounding
/// (1e-16 rad), far inside the spans' padding: both are supersets of the covered nodes, and
/// both mark sure only rows whose nodes are certainly covered.
__attribute__((target("avx512f,avx512vl,avx512dq"))) std::int64_t row_spans_avx512(
    const SpanSetup& P, int r0, int r1, const double* cot_phi, const double* rsqrt_sin_phi, int* lo, int* hi,
    std::uint8_t* sure) {
  const __m512d one = _mm512_set1_pd(1.0), minus_one = _mm512_set1_pd(-1.0), zero = _mm512_setzero_pd();
  const __m512d pi = _mm512_set1_pd(kPi);
  const __m512d inv_h = _mm512_set1_pd(P.inv_h), half = _mm512_set1_pd(P.half), quarter = _mm512_set1_pd(P.quarter);
  const __m512d abs_pad = _mm512_set1_pd(kSpanAnglePad), col_pad = _mm512_set1_pd(1e-6);
  const double* q = kFastAcosCoarseCoefficients;
  std::int64_t nodes = 0;
  for (int r = r0; r <= r1; r += 8) {
    const int left = r1 - r + 1;
    const __mmask8 m = first_lanes(left);
    const __m512d ct = _mm512_maskz_loadu_pd(m, cot_phi + r), rs = _mm512_maskz_loadu_pd(m, rsqrt_sin_phi + r);
    __m512d L = _mm512_set1_pd(P.c0), H = _mm512_set1_pd(P.c1), Li = L, Hi = H;
    __mmask8 split = 0;
    for (int k = 0; k < 3; ++k) {
      const __m512d x = _mm512_min_pd(_mm512_max_pd(_mm512_mul_pd(_mm512_set1_pd(P.k[k]), ct), minus_one), one);
      // w = fast_acos_coarse(x)
      const __m512d ax = _mm512_abs_pd(x);
      __m512d poly = _mm512_set1_pd(q[0]);
      for (int i = 1; i < 8; ++i) poly = _mm512_fmadd_pd(poly, ax, _mm512_set1_pd(q[i]));
      const __m512d root = _mm512_mul_pd(_mm512_sqrt_pd(_mm512_max_pd(zero, _mm512_sub_pd(one, ax))), poly);
      const __m512d w = _mm512_mask_blend_pd(_mm512_cmp_pd_mask(x, zero, _CMP_LT_OQ), root, _mm512_sub_pd(pi, root));
      // W = w / h + d, d = (pad rs + kSpanAnglePad) / h + 1e-6 (edge_span)
      const __m512d d = _mm512_fmadd_pd(_mm512_fmadd_pd(_mm512_set1_pd(P.pad[k]), rs, abs_pad), inv_h, col_pad);
      const __m512d W = _mm512_fmadd_pd(w, inv_h, d);
      narrow_by_arc(W, d, _mm512_set1_pd(P.near[k]), _mm512_set1_pd(P.far[k]), half, quarter, L, H, Li, Hi, split);
    }
    const __m512d Lc = _mm512_roundscale_pd(L, _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC);
    const __m512d Hf = _mm512_roundscale_pd(H, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
    // span_is_sure
    const __mmask8 certain =
        __mmask8(~split) &
        _mm512_cmp_pd_mask(Lc, _mm512_roundscale_pd(Li, _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC), _CMP_EQ_OQ) &
        _mm512_cmp_pd_mask(Hf, _mm512_roundscale_pd(Hi, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC), _CMP_EQ_OQ);
    sure[(r - r0) / 8] = static_cast<std::uint8_t>(certain & m);
    const __m256i l = _mm512_cvtpd_epi32(Lc), u = _mm512_cvtpd_epi32(Hf);
    _mm256_mask_storeu_epi32(lo + (r - r0), m, l);
    _mm256_mask_storeu_epi32(hi + (r - r0), m, u);
    const __m256i count = _mm256_max_epi32(_mm256_add_epi32(_mm256_sub_epi32(u, l), _mm256_set1_epi32(1)),
                                           _mm256_setzero_si256());
    alignas(32) int c[8];
    _mm256_store_si256(reinterpret_cast<__m256i*>(c), _mm256_maskz_mov_epi32(m, count));
    for (int i = 0; i < 8; ++i) nodes += c[i];
  }
  return nodes;
}
#pragma GCC diagnostic pop
#endif

std::int64_t row_spans(const SpanSetup& P, int r0, int r1, const double* cot_phi, const double* rsqrt_sin_phi, int* lo,
                       int* hi, std::uint8_t* sure) {
#if defined(__GNUC__) && defined(__x86_64__)
  if (detail::use_avx512()) return row_spans_avx512(P, r0, r1, cot_phi, rsqrt_sin_phi, lo, hi, sure);
#endif
  return row_spans_scalar(P, r0, r1, cot_phi, rsqrt_sin_phi, lo, hi, sure);
}

/// The stored columns of unwrapped span lo..hi (lo >= -cols, hi < 2 cols) as up to three
/// contiguous pieces seg[g][0] .. seg[g][1]; returns their number (0 when lo > hi).
inline int segments(int lo, int hi, int cols, int (&seg)[3][2]) {
  int n = 0;
  if (lo > hi) return 0;
  if (lo < 0) seg[n][0] = lo + cols, seg[n][1] = std::min(hi, -1) + cols, ++n;
  if (hi >= 0 && lo < cols) seg[n][0] = std::max(lo, 0), seg[n][1] = std::min(hi, cols - 1), ++n;
  if (hi >= cols) seg[n][0] = std::max(lo, cols) - cols, seg[n][1] = hi - cols, ++n;
  return n;
}

/// Linear mode's box: rows r0..r1 and the columns as up to three contiguous segments (the box
/// may wrap across theta = 0/360), with the cone's edge normals e and adet.
struct WrappedBox {
  int r0, r1, nseg, seg[3][2];
  int seg_offset[3];  ///< the box's own (unwrapped) column = stored column + offset, per segment
  double e[9], bias[3], adet;
};

/// The box of rows r0..r1 and unwrapped columns c0..c1 (c0 may be negative, c1 may reach past the
/// last column: the box wraps across theta = 0/360) as up to three contiguous segments.
WrappedBox make_box(const Box& bx, int cols, const TriangleCone& t) {
  const int r0 = bx.r0, r1 = bx.r1, c0 = bx.c0, c1 = bx.c1;
  WrappedBox b;
  b.r0 = r0, b.r1 = r1, b.nseg = 0;
  auto add = [&](int lo, int hi, int offset) {
    b.seg[b.nseg][0] = lo, b.seg[b.nseg][1] = hi, b.seg_offset[b.nseg] = offset, ++b.nseg;
  };
  if (c0 < 0) add(c0 + cols, cols - 1, -cols);
  add(std::max(c0, 0), std::min(c1, cols - 1), 0);
  if (c1 >= cols) add(0, c1 - cols, cols);
  std::copy(t.e, t.e + 9, b.e);
  std::copy(t.bias, t.bias + 3, b.bias);
  b.adet = t.adet;
  return b;
}

/// The three edge functions of one row (coefficients folded with sin and cos of its phi), each
/// raised by its tolerance `bias` (kEdgeAngleTolerance).
struct RowEdges {
  double a0, b0, c0, a1, b1, c1, a2, b2, c2;
  RowEdges(const double* e, const double* bias, double sp, double cp)
      : a0(sp * e[0]),
        b0(sp * e[1]),
        c0(cp * e[2] + bias[0]),
        a1(sp * e[3]),
        b1(sp * e[4]),
        c1(cp * e[5] + bias[1]),
        a2(sp * e[6]),
        b2(sp * e[7]),
        c2(cp * e[8] + bias[2]) {}
  /// Inside the cone (all three >= 0, each within its tolerance); `sum` = f0 + f1 + f2.
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

/// Per-row and per-column trigonometry of one grid, made once per thread and precision.
struct GridTables {
  double step = 0;
  std::vector<double> sin_phi, cos_phi, cot_phi, rsqrt_sin_phi, inv_sin_phi, cos_theta, sin_theta;
};
const GridTables& grid_tables(const EquiangularGrid& grid) {
  thread_local GridTables t;
  if (t.step == grid.step() && !t.sin_phi.empty()) return t;
  const int rows = grid.rows(), cols = grid.columns();
  const double h = grid.step();
  t.step = h;
  t.sin_phi.resize(rows), t.cos_phi.resize(rows), t.cot_phi.resize(rows), t.rsqrt_sin_phi.resize(rows);
  t.inv_sin_phi.resize(rows);
  for (int r = 0; r < rows; ++r) {
    t.sin_phi[r] = std::sin(r * h);
    t.cos_phi[r] = std::cos(r * h);
  }
  t.sin_phi[0] = 0;  // both pole rows are exactly the pole direction
  t.cos_phi[0] = 1;
  t.sin_phi[rows - 1] = 0;
  t.cos_phi[rows - 1] = -1;
  for (int r = 0; r < rows; ++r) {
    const bool pole = t.sin_phi[r] <= 0;  // the pole rows keep the whole box (row_spans)
    t.cot_phi[r] = pole ? 0.0 : t.cos_phi[r] / t.sin_phi[r];
    t.rsqrt_sin_phi[r] = pole ? std::numeric_limits<double>::infinity() : 1 / std::sqrt(t.sin_phi[r]);
    t.inv_sin_phi[r] = pole ? 1.0 : 1 / t.sin_phi[r];  // scales the edge tolerance like the edge functions
  }
  t.cos_theta.resize(cols), t.sin_theta.resize(cols);
  for (int c = 0; c < cols; ++c) {
    t.cos_theta[c] = std::cos(c * h);
    t.sin_theta[c] = std::sin(c * h);
  }
  return t;
}

/// One cone's rows r0..r1 with their spans lo[r - r0] .. hi[r - r0] (unwrapped columns), for
/// the exact-mode kernels: e (the three edge normals), n (the face normal) and adet as in
/// TriangleCone; sure (or null): bit i % 8 of sure[i / 8] set when every node of row r0 + i's
/// span is certainly inside the cone (row_spans).
struct SpanRows {
  int r0, r1;
  const int* lo;
  const int* hi;
  const std::uint8_t* sure;
  const double* e;
  const double* bias;  ///< the cone's edge tolerances (kEdgeAngleTolerance |e_k|)
  const double* n;
  double adet;
};

/// Exact mode over a cone's row spans. For a node of row r (polar angle phi, sin phi > 0) and
/// column c the three edge functions, divided by sin phi (which keeps their signs), are
/// f_k = e_k.x cos(theta_c) + e_k.y sin(theta_c) + cot(phi_r) e_k.z; the node is inside the cone
/// when all are >= -bias_k / sin phi (kEdgeAngleTolerance), and its distance is (adet / sin phi) / g with g = n.x cos(theta_c) +
/// n.y sin(theta_c) + cot(phi_r) n.z, where the ray meets the plane (double g, division in the
/// map's precision); the nearer value is kept. The two pole rows (sin phi = 0: one direction,
/// (0, 0, +-1)) use f_k = cos(phi) e_k.z, g = cos(phi) n.z and adet. A negated edge normal
/// negates f exactly, so two triangles sharing an edge still cover every node on it
/// (watertight). On a sure row (S.sure) every node of the span is inside and only the distances
/// are computed. Branch-free inner loops; the whole triangle in one call so the vectorised
/// clone is dispatched once per triangle. Returns the number of nodes that had no surface
/// before and have one now.
template <typename Scalar>
inline std::int64_t exact_rows_body(Scalar* __restrict map, int cols, const SpanRows& S, const GridTables& T) {
  const double* e = S.e;
  const double* bias = S.bias;
  const double* n = S.n;
  const double* __restrict cos_theta = T.cos_theta.data();
  const double* __restrict sin_theta = T.sin_theta.data();
  std::int64_t newly = 0;
  for (int r = S.r0; r <= S.r1; ++r) {
    const double sp = T.sin_phi[r];
    const bool pole = sp <= 0;
    const double ex = pole ? 0.0 : 1.0;  // pole rows: no azimuth term
    const double ez = pole ? T.cos_phi[r] : T.cot_phi[r];
    const double ib = T.inv_sin_phi[r];
    const double a0 = ex * e[0], b0 = ex * e[1], c0 = ez * e[2] + ib * bias[0], a1 = ex * e[3], b1 = ex * e[4],
                 c1 = ez * e[5] + ib * bias[1], a2 = ex * e[6], b2 = ex * e[7], c2 = ez * e[8] + ib * bias[2],
                 an = ex * n[0], bn = ex * n[1], cn = ez * n[2];
    const double adet = pole ? S.adet : S.adet / sp;
    Scalar* __restrict row = map + std::int64_t(r) * cols;
    const int i = r - S.r0;
    const bool sure = S.sure != nullptr && ((S.sure[i >> 3] >> (i & 7)) & 1);
    int seg[3][2];
    const int nseg = segments(S.lo[i], S.hi[i], cols, seg);
    for (int g = 0; g < nseg; ++g) {
      if (sure) {  // every node of the span is inside: only the distances
        for (int j = seg[g][0]; j <= seg[g][1]; ++j)
          keep_nearer(row[j], true, node_distance(adet, an * cos_theta[j] + (bn * sin_theta[j] + cn), Scalar{}),
                      newly);
        continue;
      }
      for (int j = seg[g][0]; j <= seg[g][1]; ++j) {
        const double ct = cos_theta[j], st = sin_theta[j];
        const double f0 = a0 * ct + (b0 * st + c0), f1 = a1 * ct + (b1 * st + c1), f2 = a2 * ct + (b2 * st + c2);
        const bool inside = std::min(std::min(f0, f1), f2) >= 0;
        keep_nearer(row[j], inside, node_distance(adet, an * ct + (bn * st + cn), Scalar{}), newly);
      }
    }
  }
  return newly;
}
IMPINGE_SIMD_CLONES
std::int64_t exact_rows_generic(float* map, int cols, const SpanRows& S, const GridTables& T) {
  return exact_rows_body(map, cols, S, T);
}

#if defined(__GNUC__) && defined(__x86_64__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"  // GCC 12's own _mm512_cvtpd_ps (a false positive)
/// A row's coefficients for the AVX-512 steps: f_k = x_k cos + y_k sin + c_k, g = xn cos + yn sin + cn.
struct RowCoefficients {
  __m512d x0, y0, c0, x1, y1, c1, x2, y2, c2, xn, yn, cn;
  __m256 adet;
};

/// One 8-node step of exact_rows_avx512 at stored columns j.. (lanes m) of `row`; with `test`
/// the edge functions decide which lanes are inside, else all lanes m are (a sure row). Returns
/// the nodes newly covered.
template <bool test>
__attribute__((target("avx512f,avx512vl,avx512dq"), always_inline)) inline int exact_step_avx512(
    float* row, int j, __mmask8 m, const double* cos_theta, const double* sin_theta, const RowCoefficients& R) {
  const __m256 none = _mm256_set1_ps(std::numeric_limits<float>::infinity());
  const __m512d ct = _mm512_maskz_loadu_pd(m, cos_theta + j), st = _mm512_maskz_loadu_pd(m, sin_theta + j);
  __mmask8 inside = m;
  if constexpr (test) {
    const __m512d f0 = _mm512_fmadd_pd(R.x0, ct, _mm512_fmadd_pd(R.y0, st, R.c0));
    const __m512d f1 = _mm512_fmadd_pd(R.x1, ct, _mm512_fmadd_pd(R.y1, st, R.c1));
    const __m512d f2 = _mm512_fmadd_pd(R.x2, ct, _mm512_fmadd_pd(R.y2, st, R.c2));
    inside = _mm512_mask_cmp_pd_mask(m, _mm512_min_pd(_mm512_min_pd(f0, f1), f2), _mm512_setzero_pd(), _CMP_GE_OQ);
  }
  const __m256 g = _mm512_cvtpd_ps(_mm512_fmadd_pd(R.xn, ct, _mm512_fmadd_pd(R.yn, st, R.cn)));
  const __m256 v = _mm256_div_ps(R.adet, g);
  const __m256 old = _mm256_maskz_loadu_ps(inside, row + j);
  _mm256_mask_storeu_ps(row + j, _mm256_mask_cmp_ps_mask(inside, v, old, _CMP_LT_OQ), v);
  return __builtin_popcount(_mm256_mask_cmp_ps_mask(inside, old, none, _CMP_EQ_OQ));
}

/// exact_step_avx512 over stored columns first..last of `row`; returns the nodes newly covered.
template <bool test>
__attribute__((target("avx512f,avx512vl,avx512dq"), always_inline)) inline std::int64_t exact_run_avx512(
    float* row, int first, int last, const double* cos_theta, const double* sin_theta, const RowCoefficients& R) {
  std::int64_t newly = 0;
  for (int j = first; j <= last; j += 8)
    newly += exact_step_avx512<test>(row, j, first_lanes(last - j + 1), cos_theta, sin_theta, R);
  return newly;
}

/// exact_rows_body for float maps in AVX-512 with masked loads and stores: the short spans of
/// small triangles (a few dozen nodes) run without scalar remainders. Same arithmetic as the
/// generic body (double edge functions, float division), with fused multiply-adds. The
/// per-row work is kept small (it is about half of the time at 0.05 deg): sure rows skip the
/// edge functions, the normals' x and y stay in registers for the whole triangle, and rows
/// across the seam run in a separate loop. No software prefetch: with MapStart::reset the map
/// lines are in L2 (a prefetch two rows ahead was within noise even without it).
__attribute__((target("avx512f,avx512vl,avx512dq"))) std::int64_t exact_rows_avx512(float* map, int cols,
                                                                                 const SpanRows& S,
                                                                                 const GridTables& T) {
  const double* e = S.e;
  const double e2 = e[2], e5 = e[5], e8 = e[8], n2 = S.n[2];
  RowCoefficients R;
  R.x0 = _mm512_set1_pd(e[0]), R.y0 = _mm512_set1_pd(e[1]), R.x1 = _mm512_set1_pd(e[3]),
  R.y1 = _mm512_set1_pd(e[4]), R.x2 = _mm512_set1_pd(e[6]), R.y2 = _mm512_set1_pd(e[7]);
  R.xn = _mm512_set1_pd(S.n[0]), R.yn = _mm512_set1_pd(S.n[1]);
  const double* cos_theta = T.cos_theta.data();
  const double* sin_theta = T.sin_theta.data();
  const int* __restrict lo_of = S.lo;
  const int* __restrict hi_of = S.hi;
  const std::uint8_t* sure = S.sure;
  const int r0 = S.r0, r1 = S.r1;
  const double adet = S.adet;
  std::int64_t newly = 0;
  for (int r = r0; r <= r1; ++r) {
    const int i = r - r0, lo = lo_of[i], hi = hi_of[i];
    if (lo > hi) continue;
    const double sp = T.sin_phi[r];
    const bool pole = sp <= 0;
    const double ez = pole ? T.cos_phi[r] : T.cot_phi[r];
    R.cn = _mm512_set1_pd(ez * n2);
    R.adet = _mm256_set1_ps(static_cast<float>(pole ? adet : adet / sp));
    float* row = map + std::int64_t(r) * cols;
    const bool plain = !pole && lo >= 0 && hi < cols;  // the common case: a span that does not wrap
    if (plain && sure != nullptr && ((sure[i >> 3] >> (i & 7)) & 1)) {
      newly += exact_run_avx512<false>(row, lo, hi, cos_theta, sin_theta, R);
      continue;
    }
    const double ib = T.inv_sin_phi[r];
    R.c0 = _mm512_set1_pd(ez * e2 + ib * S.bias[0]), R.c1 = _mm512_set1_pd(ez * e5 + ib * S.bias[1]),
    R.c2 = _mm512_set1_pd(ez * e8 + ib * S.bias[2]);
    if (plain) {
      newly += exact_run_avx512<true>(row, lo, hi, cos_theta, sin_theta, R);
      continue;
    }
    RowCoefficients P = R;  // the seam or a pole row
    if (pole) {
      const __m512d zero = _mm512_setzero_pd();
      P.x0 = P.y0 = P.x1 = P.y1 = P.x2 = P.y2 = P.xn = P.yn = zero;
    }
    int seg[3][2];
    const int nseg = segments(lo, hi, cols, seg);
    for (int g = 0; g < nseg; ++g) newly += exact_run_avx512<true>(row, seg[g][0], seg[g][1], cos_theta, sin_theta, P);
  }
  return newly;
}
#pragma GCC diagnostic pop
#endif

std::int64_t exact_rows(float* map, int cols, const SpanRows& S, const GridTables& T) {
#if defined(__GNUC__) && defined(__x86_64__)
  if (detail::use_avx512()) return exact_rows_avx512(map, cols, S, T);
#endif
  return exact_rows_generic(map, cols, S, T);
}
IMPINGE_SIMD_CLONES
std::int64_t exact_rows(double* map, int cols, const SpanRows& S, const GridTables& T) {
  return exact_rows_body(map, cols, S, T);
}

/// Linear-mode (thesis Algorithm 1) rows of one triangle's box away from the poles: the same
/// cone test as exact mode, and at covered nodes the barycentric interpolation of the corner
/// distances in the (theta, phi) plane (planar_value's formula, theta unwrapped as the box's own
/// column index), clamped to the triangle. Branch-free; vectorised clones.
struct LinearBox {
  WrappedBox box;
  double h, ta, tb, tc, pa, pb, pc, da, db, dc, inv_area2;
};
template <typename Scalar>
inline std::int64_t linear_rows_body(Scalar* __restrict map, int cols, const LinearBox& L,
                                     const double* __restrict sin_phi, const double* __restrict cos_phi,
                                     const double* __restrict cos_theta, const double* __restrict sin_theta) {
  const WrappedBox& box = L.box;
  std::int64_t newly = 0;
  for (int r = box.r0; r <= box.r1; ++r) {
    const RowEdges edges(box.e, box.bias, sin_phi[r], cos_phi[r]);
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

/// Boxes narrower than this many columns (plus one) are tested whole (measured on lhdl-ct's
/// pelvis at 0.05 deg: 16 is about 7 % faster than spans everywhere; the map is the same).
constexpr int kMinSpanBox = 16;

/// Rows reset together by MapStart::reset with a plan: 512 KiB of map, half of this machine's
/// per-core L2 (lhdl-ct pelvis at 0.05 deg: 128 KiB 19-21 ms, 256 KiB 18 ms, 512 KiB 17-17.8 ms,
/// 1 MiB 18-19 ms; the cones that start in a band reach into the next ones).
constexpr std::size_t kResetBandBytes = 512 * 1024;

template <typename Scalar>
class Rasterizer {
 public:
  Rasterizer(RadialDistanceMapT<Scalar>& map, DistanceMode mode, SamplingStats& stats, int keep_sign, bool row_spans)
      : map_(map),
        mode_(mode),
        stats_(stats),
        grid_(equiangular_grid_of(map.scheme())),
        keep_sign_(keep_sign),
        row_spans_(row_spans),
        t_(grid_tables(grid_)),
        inv_h_(1 / grid_.step()) {}

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
    if (mode_ == DistanceMode::exact) {
      exact_cone(make_cone(a, b, c, det, north, south));
      return;
    }
    if (north || south) ++stats_.pole_triangles;
    if (north || south) {
      // Thesis Fig. 34: split at the pole so that each part has the pole as a corner.
      const Corner* axis_vertex = a.axis ? &a : b.axis ? &b : c.axis ? &c : nullptr;
      if (axis_vertex != nullptr) {  // case 1, vertex case: already a corner
        const Corner& p = *axis_vertex;
        const Corner& x = (&p == &a) ? b : a;
        const Corner& y = (&p == &c) ? b : c;
        linear_cone(x, y, p, /*apex=*/true, north, south);
      } else {  // cases 2 and 3: the pole on an edge or inside the face
        const V3 n = (b.p - a.p).cross(c.p - a.p);
        const Corner p = corner(V3(0, 0, n.dot(a.p) / n.z()));
        linear_cone(a, b, p, true, north, south);
        linear_cone(b, c, p, true, north, south);
        linear_cone(c, a, p, true, north, south);
      }
      return;
    }
    linear_cone(a, b, c, false, north, south);
  }

  /// Exact mode: the nodes of the cone's row spans (or of its whole box without row spans).
  void exact_cone(const TriangleCone& t) { exact_cone(t, box_of(t, inv_h_, grid_.rows(), grid_.columns())); }

  /// Exact mode with every node first set to no surface, in bands of rows: each band is reset
  /// just before the cones that start in it are drawn, so that their map lines are still in the
  /// cache (the rows a cone reaches below its band are reset with it). Same map as a reset
  /// followed by exact_cone over `cones` in order: a node's value is the minimum over the cones
  /// covering it, whatever the order.
  void exact_cones_fresh(const std::vector<TriangleCone>& cones) {
    const int rows = grid_.rows(), cols = grid_.columns();
    const int band = std::max(1, static_cast<int>(kResetBandBytes / (sizeof(Scalar) * std::size_t(cols))));
    const int bands = (rows + band - 1) / band;
    thread_local std::vector<Box> boxes;
    thread_local std::vector<std::int32_t> order, start;
    const std::size_t n = cones.size();
    boxes.resize(n), order.resize(n), start.assign(std::size_t(bands) + 1, 0);
    for (std::size_t i = 0; i < n; ++i) {
      boxes[i] = box_of(cones[i], inv_h_, rows, cols);
      if (boxes[i].r1 >= boxes[i].r0) ++start[std::size_t(boxes[i].r0 / band) + 1];
    }
    for (int g = 0; g < bands; ++g) start[std::size_t(g) + 1] += start[std::size_t(g)];
    std::vector<std::int32_t> next(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < n; ++i)
      if (boxes[i].r1 >= boxes[i].r0) order[std::size_t(next[std::size_t(boxes[i].r0 / band)]++)] = std::int32_t(i);
    Scalar* map = map_.data();
    int reset = 0;  // rows 0 .. reset - 1 are reset
    const auto reset_to = [&](int r) {
      if (r <= reset) return;
      std::fill(map + std::int64_t(reset) * cols, map + std::int64_t(r) * cols, RadialDistanceMapT<Scalar>::no_surface());
      reset = r;
    };
    for (int g = 0; g < bands; ++g) {
      const auto b0 = std::size_t(start[std::size_t(g)]), b1 = std::size_t(start[std::size_t(g) + 1]);
      int need = std::min(rows, (g + 1) * band);
      for (std::size_t j = b0; j < b1; ++j) need = std::max(need, boxes[std::size_t(order[j])].r1 + 1);
      reset_to(need);
      for (std::size_t j = b0; j < b1; ++j) {
        if (j + 4 < b1) {  // the cones of a band are scattered in the plan (Z order)
          const char* ahead = reinterpret_cast<const char*>(&cones[std::size_t(order[j + 4])]);
          for (std::size_t line = 0; line < sizeof(TriangleCone); line += 64) __builtin_prefetch(ahead + line);
        }
        exact_cone(cones[std::size_t(order[j])], boxes[std::size_t(order[j])]);
      }
    }
    reset_to(rows);
  }

  /// exact_cone with the cone's box b (box_of).
  void exact_cone(const TriangleCone& t, const Box& b) {
    const int cols = grid_.columns();
    if (t.north || t.south) ++stats_.pole_triangles;
    if (t.seam) ++stats_.seam_triangles;
    if (b.r1 < b.r0) return;
    const auto n = static_cast<std::size_t>(b.r1 - b.r0 + 1);
    if (lo_.size() < n) lo_.resize(n), hi_.resize(n), sure_.resize(n / 8 + 1);
    // Rows of 16 columns or fewer take one or two vector steps anyway: no spans for them.
    const std::uint8_t* sure = nullptr;
    if (row_spans_ && !t.full_theta && b.c1 - b.c0 >= kMinSpanBox) {
      stats_.node_tests += row_spans(span_setup(t, b, inv_h_, cols), b.r0, b.r1, t_.cot_phi.data(),
                                     t_.rsqrt_sin_phi.data(), lo_.data(), hi_.data(), sure_.data());
      sure = sure_.data();
    } else {
      std::fill(lo_.begin(), lo_.begin() + std::ptrdiff_t(n), b.c0);
      std::fill(hi_.begin(), hi_.begin() + std::ptrdiff_t(n), b.c1);
      stats_.node_tests += std::int64_t(n) * (b.c1 - b.c0 + 1);
    }
    const SpanRows S{b.r0, b.r1, lo_.data(), hi_.data(), sure, t.e, t.bias, t.n, t.adet};
    newly_covered_ += exact_rows(map_.data(), cols, S, t_);
  }

 private:
  /// Linear mode: rasterise the cone of triangle (a, b, c). With `apex`, c lies on the z axis
  /// (the pole corner) and the trapezoid interpolation of thesis Fig. 34 is used. `north` /
  /// `south`: the cone holds that pole (computed once per mesh triangle; a part split at a pole
  /// holds the same pole at its apex and never the other).
  void linear_cone(const Corner& ka, const Corner& kb, const Corner& kc, bool apex, bool north, bool south) {
    const V3 &a = ka.p, &b = kb.p, &c = kc.p;
    const double det = a.dot(b.cross(c));
    if (!(std::abs(det) > 1e-12 * ka.d * kb.d * kc.d)) return;  // empty part
    const TriangleCone t = make_cone(ka, kb, kc, det, north, south);
    const int rows = grid_.rows(), cols = grid_.columns();
    const double h = grid_.step();
    const Box bx = box_of(t, inv_h_, rows, cols);
    const int r0 = bx.r0, r1 = bx.r1, c0 = bx.c0, c1 = bx.c1;
    if (t.seam) ++stats_.seam_triangles;
    const bool full = t.full_theta;

    // Corners in the (theta, phi) plane, theta unwrapped around a.
    const double ta = ka.theta, tb = ka.theta + wrap_pi(kb.theta - ka.theta),
                 tc = ka.theta + wrap_pi(kc.theta - ka.theta);
    const double area2 = (tb - ta) * (kc.phi - ka.phi) - (tc - ta) * (kb.phi - ka.phi);
    const double dtheta_ab = wrap_pi(kb.theta - ka.theta);

    if (!apex && !full && std::abs(area2) >= 1e-18) {  // away from the poles: vectorised
      LinearBox L{make_box(bx, cols, t), h, ta, tb, tc, ka.phi, kb.phi, kc.phi, ka.d, kb.d, kc.d, 1 / area2};
      if (r1 >= r0)
        newly_covered_ += linear_rows(map_.data(), cols, L, t_.sin_phi.data(), t_.cos_phi.data(), t_.cos_theta.data(),
                                      t_.sin_theta.data());
      stats_.node_tests += std::int64_t(std::max(0, r1 - r0 + 1)) * (c1 - c0 + 1);
      return;
    }
    const V3 e0(t.e[0], t.e[1], t.e[2]), e1(t.e[3], t.e[4], t.e[5]), e2(t.e[6], t.e[7], t.e[8]);
    for (int r = r0; r <= r1; ++r) {
      const double sp = t_.sin_phi[r], cp = t_.cos_phi[r];
      const double A0 = sp * e0.x(), B0 = sp * e0.y(), C0 = cp * e0.z();
      const double A1 = sp * e1.x(), B1 = sp * e1.y(), C1 = cp * e1.z();
      const double A2 = sp * e2.x(), B2 = sp * e2.y(), C2 = cp * e2.z();
      Scalar* row = map_.data() + std::int64_t(r) * cols;
      const double phi = r * h;
      for (int cc = c0; cc <= c1; ++cc) {
        const int col = cc < 0 ? cc + cols : (cc >= cols ? cc - cols : cc);
        const double ct = t_.cos_theta[col], st = t_.sin_theta[col];
        const double f0 = A0 * ct + B0 * st + C0;
        const double f1 = A1 * ct + B1 * st + C1;
        const double f2 = A2 * ct + B2 * st + C2;
        if (f0 < 0 || f1 < 0 || f2 < 0) continue;
        const double value = apex ? apex_value(ka, kb, kc, dtheta_ab, phi, col * h)
                                  : planar_value(ka, kb, kc, ta, tb, tc, area2, phi, col * h, t.adet / (f0 + f1 + f2));
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
  bool row_spans_;                  ///< exact mode: test only the row spans (else whole boxes)
  const GridTables& t_;             ///< this grid's trigonometry
  double inv_h_;                    ///< 1 / the grid's step (1/rad)
  std::int64_t newly_covered_ = 0;  ///< nodes that had no surface and now have one
  std::vector<int> lo_, hi_;        ///< row spans of the current cone
  std::vector<std::uint8_t> sure_;  ///< their sure bits (row_spans)
};

/// Spherical coordinates of every vertex relative to `cor` (a vertex is shared by about six
/// triangles). Reused between calls on this thread: a fresh multi-megabyte buffer would be
/// page-faulted in on every call.
const std::vector<Corner>& vertex_corners(const TriangleMesh& mesh, const Eigen::Vector3d& cor) {
  thread_local std::vector<Corner> corners;
  corners.resize(static_cast<std::size_t>(mesh.V.rows()));
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i)
    corners[static_cast<std::size_t>(i)] = corner(mesh.V.row(i).transpose() - cor);
  return corners;
}

}  // namespace

std::vector<TriangleCone> triangle_cones(const TriangleMesh& mesh, const Eigen::Vector3d& cor,
                                         const std::vector<std::int32_t>& faces, std::int64_t* edge_on) {
  const std::vector<Corner>& k = vertex_corners(mesh, cor);
  std::vector<TriangleCone> cones;
  cones.reserve(faces.size());
  std::int64_t skipped = 0;
  for (const std::int32_t f : faces) {
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
  if (edge_on != nullptr) *edge_on = skipped;
  return cones;
}

template <typename Scalar>
SamplingStats rasterize(const TriangleMesh& mesh, const Eigen::Vector3d& cor, DistanceMode mode,
                        RadialDistanceMapT<Scalar>& map, const FaceCulling* culling, bool row_spans, MapStart start) {
  require(cor.allFinite(), mesh.source + ": centre of rotation is not finite");
  validate_mesh(mesh);  // a bad index is an error before anything is read or changed
  (void)equiangular_grid_of(map.scheme());  // throws for a map that is not equiangular, before anything is changed
  const bool planned = culling != nullptr && mode == DistanceMode::exact;
  // The plan's cones: the kept triangles (all when culling is disabled), set up once.
  if (planned && (culling->cor != cor || culling->mesh_fingerprint != mesh_fingerprint(mesh)))
    throw Error(mesh.source + ": face culling plan was made for another mesh or centre of rotation");
  const bool banded = planned && start == MapStart::reset;  // the reset fused with the drawing
  if (start == MapStart::reset && !banded)
    std::fill(map.data(), map.data() + map.num_nodes(), RadialDistanceMapT<Scalar>::no_surface());
  SamplingStats stats;
  const int keep = planned && culling->enabled ? culling->keep_sign : 0;
  Rasterizer<Scalar> raster(map, mode, stats, keep, row_spans);
  if (planned) {
    if (banded) {
      raster.exact_cones_fresh(culling->cones);
    } else {
      for (const TriangleCone& t : culling->cones) raster.exact_cone(t);
    }
    const auto kept = static_cast<std::int64_t>(culling->triangle_order.size());
    stats.triangles = mesh.F.rows();
    stats.triangles_edge_on = culling->cones_edge_on;
    stats.triangles_culled = mesh.F.rows() - kept;
  } else {
    const std::vector<Corner>& k = vertex_corners(mesh, cor);
    for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
      raster.triangle(k[static_cast<std::size_t>(mesh.F(f, 0))], k[static_cast<std::size_t>(mesh.F(f, 1))],
                      k[static_cast<std::size_t>(mesh.F(f, 2))]);
  }
  stats.nodes_covered = raster.newly_covered();
  return stats;
}

template SamplingStats rasterize<float>(const TriangleMesh&, const Eigen::Vector3d&, DistanceMode,
                                        RadialDistanceMapT<float>&, const FaceCulling*, bool, MapStart);
template SamplingStats rasterize<double>(const TriangleMesh&, const Eigen::Vector3d&, DistanceMode,
                                         RadialDistanceMapT<double>&, const FaceCulling*, bool, MapStart);

RadialDistanceMap rasterize_map(const TriangleMesh& mesh, const Eigen::Vector3d& cor, double precision_deg,
                                DistanceMode mode, SamplingStats* stats) {
  RadialDistanceMap map{EquiangularGrid(precision_deg)};
  const SamplingStats s = rasterize(mesh, cor, mode, map);
  if (stats != nullptr) *stats = s;
  return map;
}

}  // namespace impinge
