#include "sampling/raster_row_spans.hpp"

#include <limits>

#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>
#endif

#include "impinge/core/fast_angles.hpp"
#include "impinge/core/spherical_frame.hpp"
#include "core/cpu_dispatch.hpp"
#include "sampling/raster_tables.hpp"

namespace impinge::detail {

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

namespace {

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

}  // namespace

std::int64_t row_spans(const SpanSetup& P, int r0, int r1, const double* cot_phi, const double* rsqrt_sin_phi, int* lo,
                       int* hi, std::uint8_t* sure) {
#if defined(__GNUC__) && defined(__x86_64__)
  if (detail::use_avx512()) return row_spans_avx512(P, r0, r1, cot_phi, rsqrt_sin_phi, lo, hi, sure);
#endif
  return row_spans_scalar(P, r0, r1, cot_phi, rsqrt_sin_phi, lo, hi, sure);
}

}  // namespace impinge::detail
