#include "sampling/raster_exact_kernels.hpp"

#include <algorithm>
#include <limits>

#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>
#endif

#include "core/cpu_dispatch.hpp"
#include "core/simd_clones.hpp"

namespace impinge::detail {

namespace {

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

IMPINGE_SIMD_CLONES
std::int64_t exact_rows_double(double* map, int cols, const SpanRows& S, const GridTables& T) {
  return exact_rows_body(map, cols, S, T);
}

}  // namespace

std::int64_t exact_rows(float* map, int cols, const SpanRows& S, const GridTables& T) {
#if defined(__GNUC__) && defined(__x86_64__)
  if (detail::use_avx512()) return exact_rows_avx512(map, cols, S, T);
#endif
  return exact_rows_generic(map, cols, S, T);
}
std::int64_t exact_rows(double* map, int cols, const SpanRows& S, const GridTables& T) {
  return exact_rows_double(map, cols, S, T);
}


}  // namespace impinge::detail
