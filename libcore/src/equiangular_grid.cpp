#include "impinge/equiangular_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>
#endif
#include <sstream>

#include "impinge/error.hpp"
#include "impinge/spherical_frame.hpp"
#include "cpu_dispatch.hpp"
#include "simd_clones.hpp"

namespace impinge {

double matched_equiangular_precision(double spacing_rad) {
  return 180.0 / std::max(1.0, std::round(180.0 / (spacing_rad * kRadToDeg)));
}

EquiangularGrid::EquiangularGrid(double precision_deg) : precision_deg_(precision_deg) {
  std::ostringstream os;
  os << "precision " << precision_deg << " deg: must be in (0, 90] and divide 180 evenly";
  require(std::isfinite(precision_deg) && precision_deg > 0 && precision_deg <= 90, os.str());
  const double n = 180.0 / precision_deg;
  require(std::abs(n - std::round(n)) <= 1e-9 * n, os.str());
  rows_ = static_cast<int>(std::lround(n)) + 1;
  cols_ = 2 * (rows_ - 1);
  step_ = kPi / (rows_ - 1);
  inv_step_ = 1.0 / step_;
  require(num_nodes() < std::int64_t(1) << 31, os.str() + " (more than 2^31 nodes)");
}

Eigen::Vector3d EquiangularGrid::node_direction(std::int64_t i) const {
  const int r = static_cast<int>(i / cols_);
  const int c = static_cast<int>(i % cols_);
  if (r == 0) return {0, 0, 1};
  if (r == rows_ - 1) return {0, 0, -1};
  return direction(r * step_, c * step_);
}

std::int64_t EquiangularGrid::node(const Eigen::Vector3d& u) const {
  const SphericalCoordinates s = to_spherical(u);
  const int r = static_cast<int>(std::lround(s.phi / step_));
  if (r <= 0) return 0;
  if (r >= rows_ - 1) return std::int64_t(rows_ - 1) * cols_;
  int c = static_cast<int>(std::lround(s.theta / step_));
  if (c >= cols_) c -= cols_;
  return std::int64_t(r) * cols_ + c;
}

void EquiangularGrid::node_angles(std::int64_t first, std::int64_t count, double* phi, double* theta) const {
  for (std::int64_t j = 0; j < count; ++j) {
    const std::int64_t i = first + j;
    phi[j] = static_cast<double>(i / cols_) * step_;
    theta[j] = static_cast<double>(i % cols_) * step_;
  }
}

namespace {
/// Pass 1 of the look-up: cell (base node index, column step to the next column) and the
/// fractional position (t along phi, s along theta) of n directions. Branch-free so it
/// vectorises; cloned for AVX-512 and AVX2 and chosen at run time.
IMPINGE_SIMD_CLONES
void locate_cells(const double* __restrict x, const double* __restrict y, const double* __restrict z, int n,
                  double inv_step, int rows, int cols, std::int32_t* __restrict base, std::int32_t* __restrict dc,
                  double* __restrict t, double* __restrict s) {
  for (int j = 0; j < n; ++j) {
    double phi, theta;
    fast_spherical_angles(x[j], y[j], z[j], phi, theta);
    const double fr = phi * inv_step;
    const int r0 = std::min(static_cast<int>(fr), rows - 2);
    const double fc = theta * inv_step;
    int c0 = static_cast<int>(fc);
    s[j] = fc - c0;
    t[j] = fr - r0;
    c0 = c0 >= cols ? c0 - cols : c0;
    dc[j] = c0 + 1 == cols ? 1 - cols : 1;
    base[j] = r0 * cols + c0;
  }
}

/// Pass 2: bilinear interpolation of the four nodes of each cell (gathers when vectorised).
/// Non-finite results (a node without surface) are resolved by the caller.
template <typename Scalar, bool kMarked = false>
inline void bilinear_body(const Scalar* __restrict values, const std::int32_t* __restrict base,
                          const std::int32_t* __restrict dc, const double* __restrict t, const double* __restrict s,
                          int n, int cols, double* __restrict out) {
  for (int j = 0; j < n; ++j) {
    const Scalar u0 = values[base[j]], u1 = values[base[j] + dc[j]], u2 = values[base[j] + cols],
                 u3 = values[base[j] + cols + dc[j]];
    const double v0 = u0, v1 = u1, v2 = u2, v3 = u3;
    const double w0 = (1 - t[j]) * (1 - s[j]), w1 = (1 - t[j]) * s[j], w2 = t[j] * (1 - s[j]), w3 = t[j] * s[j];
    out[j] = w0 * v0 + w1 * v1 + w2 * v2 + w3 * v3;
    if constexpr (kMarked) {
      // A marked node (depth discontinuity): -inf, for the caller to resolve exactly.
      if (has_discontinuity_mark(u0) | has_discontinuity_mark(u1) | has_discontinuity_mark(u2) |
          has_discontinuity_mark(u3))
        out[j] = -std::numeric_limits<double>::infinity();
    }
  }
}
template <bool kMarked>
void bilinear_generic(const float* values, const std::int32_t* base, const std::int32_t* dc, const double* t,
                      const double* s, int n, int cols, double* out) {
  bilinear_body<float, kMarked>(values, base, dc, t, s, n, cols, out);
}

#if defined(__GNUC__) && defined(__x86_64__)
/// bilinear_body for float maps with AVX2 gathers (vgatherdps): 8 points at a time, the four
/// node values gathered, the weights and the sum in double in two 4-lane halves, in the same
/// operation order as the generic body (so the same values).
template <bool kMarked>
__attribute__((target("avx2,fma"))) void bilinear_avx2(const float* values, const std::int32_t* base,
                                                       const std::int32_t* dc, const double* t, const double* s, int n,
                                                       int cols, double* out) {
  const __m256i vcols = _mm256_set1_epi32(cols);
  const __m256d one = _mm256_set1_pd(1.0);
  const __m256d minus_inf = _mm256_set1_pd(-std::numeric_limits<double>::infinity());
  const __m256i lsb = _mm256_set1_epi32(1);
  int j = 0;
  for (; j + 8 <= n; j += 8) {
    const __m256i b = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(base + j));
    const __m256i d = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(dc + j));
    const __m256i b2 = _mm256_add_epi32(b, vcols);
    const __m256 v0 = _mm256_i32gather_ps(values, b, 4), v1 = _mm256_i32gather_ps(values, _mm256_add_epi32(b, d), 4),
                 v2 = _mm256_i32gather_ps(values, b2, 4), v3 = _mm256_i32gather_ps(values, _mm256_add_epi32(b2, d), 4);
    __m256i marked = _mm256_setzero_si256();
    if constexpr (kMarked) {  // lanes with a marked node: all ones
      const __m256i any = _mm256_or_si256(_mm256_or_si256(_mm256_castps_si256(v0), _mm256_castps_si256(v1)),
                                          _mm256_or_si256(_mm256_castps_si256(v2), _mm256_castps_si256(v3)));
      marked = _mm256_cmpeq_epi32(_mm256_and_si256(any, lsb), lsb);
    }
    for (int h = 0; h < 2; ++h) {
      const __m256d a0 = _mm256_cvtps_pd(h ? _mm256_extractf128_ps(v0, 1) : _mm256_castps256_ps128(v0));
      const __m256d a1 = _mm256_cvtps_pd(h ? _mm256_extractf128_ps(v1, 1) : _mm256_castps256_ps128(v1));
      const __m256d a2 = _mm256_cvtps_pd(h ? _mm256_extractf128_ps(v2, 1) : _mm256_castps256_ps128(v2));
      const __m256d a3 = _mm256_cvtps_pd(h ? _mm256_extractf128_ps(v3, 1) : _mm256_castps256_ps128(v3));
      const __m256d tt = _mm256_loadu_pd(t + j + 4 * h), ss = _mm256_loadu_pd(s + j + 4 * h);
      const __m256d ut = _mm256_sub_pd(one, tt), us = _mm256_sub_pd(one, ss);
      const __m256d w0 = _mm256_mul_pd(ut, us), w1 = _mm256_mul_pd(ut, ss), w2 = _mm256_mul_pd(tt, us),
                    w3 = _mm256_mul_pd(tt, ss);
      const __m256d r = _mm256_add_pd(
          _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(w0, a0), _mm256_mul_pd(w1, a1)), _mm256_mul_pd(w2, a2)),
          _mm256_mul_pd(w3, a3));
      if constexpr (kMarked) {
        const __m256d mh = _mm256_castsi256_pd(
            _mm256_cvtepi32_epi64(h ? _mm256_extracti128_si256(marked, 1) : _mm256_castsi256_si128(marked)));
        _mm256_storeu_pd(out + j + 4 * h, _mm256_blendv_pd(r, minus_inf, mh));
      } else {
        _mm256_storeu_pd(out + j + 4 * h, r);
      }
    }
  }
  if (j < n) bilinear_body<float, kMarked>(values, base + j, dc + j, t + j, s + j, n - j, cols, out + j);
}
#endif

template <bool kMarked>
void bilinear(const float* values, const std::int32_t* base, const std::int32_t* dc, const double* t, const double* s,
              int n, int cols, double* out) {
#if defined(__GNUC__) && defined(__x86_64__)
  if (detail::use_avx2_fma()) return bilinear_avx2<kMarked>(values, base, dc, t, s, n, cols, out);
#endif
  bilinear_generic<kMarked>(values, base, dc, t, s, n, cols, out);
}
template <bool kMarked>
void bilinear(const double* values, const std::int32_t* base, const std::int32_t* dc, const double* t, const double* s,
              int n, int cols, double* out) {
  bilinear_body<double, kMarked>(values, base, dc, t, s, n, cols, out);
}
/// Non-finite interpolated values become NaN; returns true when one of them lies on a row or
/// column of the grid (a zero weight: the caller's exact slow path decides). Branch-free.
IMPINGE_SIMD_CLONES
bool mark_no_surface(double* __restrict out, const double* __restrict t, const double* __restrict s, int n) {
  int edge = 0;
  for (int j = 0; j < n; ++j) {
    const int bad = !(std::abs(out[j]) <= std::numeric_limits<double>::max());  // inf or NaN
    if (out[j] == -std::numeric_limits<double>::infinity()) continue;  // a marked look-up (never a sum)
    const int interior = (t[j] > 0) & (t[j] < 1) & (s[j] > 0) & (s[j] < 1);
    edge |= bad & (1 - interior);
    out[j] = bad ? std::numeric_limits<double>::quiet_NaN() : out[j];
  }
  return edge != 0;
}
}  // namespace

template <typename Scalar, bool kMarked>
void EquiangularGrid::lookup_soa(const Scalar* values, const double* x, const double* y, const double* z,
                                 std::int64_t n, double* out) const {
  constexpr int kChunk = 128;
  std::int32_t base[kChunk], dc[kChunk];
  double t[kChunk], s[kChunk];
  for (std::int64_t b = 0; b < n; b += kChunk) {
    const int m = static_cast<int>(std::min<std::int64_t>(kChunk, n - b));
    locate_cells(x + b, y + b, z + b, m, inv_step_, rows_, cols_, base, dc, t, s);
    bilinear<kMarked>(values, base, dc, t, s, m, cols_, out + b);
    // A node without surface (+inf) makes the sum non-finite: the result is NaN, unless that
    // node's weight is exactly 0 (a direction exactly on a row or column), which goes to the
    // exact slow path. The first loop is branch-free; the second almost never does anything.
    const bool any_edge = mark_no_surface(out + b, t, s, m);
    if (!any_edge) continue;
    for (int j = 0; j < m; ++j) {
      if (!std::isnan(out[b + j]) || (t[j] > 0 && t[j] < 1 && s[j] > 0 && s[j] < 1)) continue;
      const std::int64_t nd[4] = {base[j], base[j] + dc[j], base[j] + cols_, base[j] + cols_ + dc[j]};
      const double w[4] = {(1 - t[j]) * (1 - s[j]), (1 - t[j]) * s[j], t[j] * (1 - s[j]), t[j] * s[j]};
      out[b + j] = slow_path(values, nd, w);
    }
  }
}

void EquiangularGrid::interpolate_many_soa(const float* values, const double* x, const double* y, const double* z,
                                           std::int64_t n, double* out) const {
  lookup_soa(values, x, y, z, n, out);
}
void EquiangularGrid::interpolate_many_soa(const double* values, const double* x, const double* y, const double* z,
                                           std::int64_t n, double* out) const {
  lookup_soa(values, x, y, z, n, out);
}
void EquiangularGrid::interpolate_many_soa_marked(const float* values, const double* x, const double* y,
                                                  const double* z, std::int64_t n, double* out) const {
  lookup_soa<float, true>(values, x, y, z, n, out);
}
void EquiangularGrid::interpolate_many_soa_marked(const double* values, const double* x, const double* y,
                                                  const double* z, std::int64_t n, double* out) const {
  lookup_soa<double, true>(values, x, y, z, n, out);
}

}  // namespace impinge
