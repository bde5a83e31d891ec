#include "impinge/maps/radial_distance_map.hpp"

#include <cstring>

#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>
#endif

#include "impinge/core/error.hpp"
#include "core/cpu_dispatch.hpp"

namespace impinge {

namespace {

/// Node values of a dense map: values[i].
template <typename Scalar>
struct DenseValues {
  const Scalar* v;
  Scalar operator[](std::int32_t i) const { return v[i]; }
};
/// Node values of a sparse map: through the table of tile numbers.
template <typename Scalar>
struct TiledValues {
  const Scalar* stored;
  const std::uint32_t* tiles;
  Scalar operator[](std::int32_t i) const {
    constexpr int kBits = RadialDistanceMapT<Scalar>::kTileBits;
    return stored[(std::size_t(tiles[i >> kBits]) << kBits) | std::size_t(i & ((1 << kBits) - 1))];
  }
};

/// A stencil with a node without surface (+inf): NaN unless every such node has weight exactly 0.
template <typename Values>
double slow_path(const Values& values, const std::int32_t* nd, const double* w, int n, int j) {
  double acc = 0;
  for (int k = 0; k < 4; ++k) {
    const double wk = w[k * n + j];
    if (wk == 0) continue;
    const double d = values[nd[k * n + j]];
    if (!std::isfinite(d)) return std::numeric_limits<double>::quiet_NaN();
    acc += wk * d;
  }
  return acc;
}

/// Combine block stencil j (nodes[k n + j], w[k n + j]) with the node values: out[j] =
/// w0 d0 + w1 d1 + w2 d2 + w3 d3 in that order (no fused multiply-add), the slow path for a
/// non-finite sum, -inf for a marked node (kMarked).
template <bool kMarked, typename Values>
inline void combine_one(const Values& values, const std::int32_t* nd, const double* w, int n, int j, double* out) {
  const auto u0 = values[nd[j]], u1 = values[nd[n + j]], u2 = values[nd[2 * n + j]], u3 = values[nd[3 * n + j]];
  const double v = w[j] * double(u0) + w[n + j] * double(u1) + w[2 * n + j] * double(u2) + w[3 * n + j] * double(u3);
  out[j] = std::isfinite(v) ? v : slow_path(values, nd, w, n, j);
  if constexpr (kMarked) {
    if (has_discontinuity_mark(u0) | has_discontinuity_mark(u1) | has_discontinuity_mark(u2) |
        has_discontinuity_mark(u3))
      out[j] = -std::numeric_limits<double>::infinity();
  }
}
template <bool kMarked, typename Values>
void combine_generic(const Values& values, const std::int32_t* nd, const double* w, int n, double* out) {
  for (int j = 0; j < n; ++j) combine_one<kMarked>(values, nd, w, n, j, out);
}

#if defined(__GNUC__) && defined(__x86_64__)
/// combine_generic for dense float maps with AVX2 gathers (vgatherdps), 8 points at a time: the four
/// node values gathered, products and sums in double in two 4-lane halves in the generic order (so
/// the same values: AVX2 without FMA, so no multiply-add is fused); non-finite sums and marks are
/// settled afterwards as in the generic body.
template <bool kMarked>
__attribute__((target("avx2"))) void combine_avx2(const float* values, const std::int32_t* nd, const double* w,
                                                       int n, double* out) {
  const __m256d minus_inf = _mm256_set1_pd(-std::numeric_limits<double>::infinity());
  const __m256i lsb = _mm256_set1_epi32(1);
  int j = 0;
  bool any_bad = false;
  for (; j + 8 <= n; j += 8) {
    const __m256 v0 = _mm256_i32gather_ps(values, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(nd + j)), 4);
    const __m256 v1 =
        _mm256_i32gather_ps(values, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(nd + n + j)), 4);
    const __m256 v2 =
        _mm256_i32gather_ps(values, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(nd + 2 * n + j)), 4);
    const __m256 v3 =
        _mm256_i32gather_ps(values, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(nd + 3 * n + j)), 4);
    __m256i marked = _mm256_setzero_si256();
    if constexpr (kMarked) {  // lanes with a marked node: all ones
      const __m256i any = _mm256_or_si256(_mm256_or_si256(_mm256_castps_si256(v0), _mm256_castps_si256(v1)),
                                          _mm256_or_si256(_mm256_castps_si256(v2), _mm256_castps_si256(v3)));
      marked = _mm256_cmpeq_epi32(_mm256_and_si256(any, lsb), lsb);
    }
    for (int h = 0; h < 2; ++h) {
      const int o = j + 4 * h;
      const __m256d a0 = _mm256_cvtps_pd(h ? _mm256_extractf128_ps(v0, 1) : _mm256_castps256_ps128(v0));
      const __m256d a1 = _mm256_cvtps_pd(h ? _mm256_extractf128_ps(v1, 1) : _mm256_castps256_ps128(v1));
      const __m256d a2 = _mm256_cvtps_pd(h ? _mm256_extractf128_ps(v2, 1) : _mm256_castps256_ps128(v2));
      const __m256d a3 = _mm256_cvtps_pd(h ? _mm256_extractf128_ps(v3, 1) : _mm256_castps256_ps128(v3));
      const __m256d r = _mm256_add_pd(
          _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(_mm256_loadu_pd(w + o), a0),
                                      _mm256_mul_pd(_mm256_loadu_pd(w + n + o), a1)),
                        _mm256_mul_pd(_mm256_loadu_pd(w + 2 * n + o), a2)),
          _mm256_mul_pd(_mm256_loadu_pd(w + 3 * n + o), a3));
      // Non-finite sums (inf - inf is NaN, so compare |r| <= max): settled below.
      const __m256d fin = _mm256_cmp_pd(_mm256_andnot_pd(_mm256_set1_pd(-0.0), r),
                                        _mm256_set1_pd(std::numeric_limits<double>::max()), _CMP_LE_OQ);
      any_bad |= _mm256_movemask_pd(fin) != 0xF;
      if constexpr (kMarked) {
        const __m256d mh = _mm256_castsi256_pd(
            _mm256_cvtepi32_epi64(h ? _mm256_extracti128_si256(marked, 1) : _mm256_castsi256_si128(marked)));
        _mm256_storeu_pd(out + o, _mm256_blendv_pd(r, minus_inf, mh));
      } else {
        _mm256_storeu_pd(out + o, r);
      }
    }
  }
  if (any_bad) {
    for (int i = 0; i < j; ++i) {
      if (out[i] == -std::numeric_limits<double>::infinity() && kMarked) continue;  // a marked look-up
      if (!std::isfinite(out[i])) out[i] = slow_path(DenseValues<float>{values}, nd, w, n, i);
    }
  }
  for (; j < n; ++j) combine_one<kMarked>(DenseValues<float>{values}, nd, w, n, j, out);  // the tail
}
#endif

template <bool kMarked, typename Scalar>
void combine(const Scalar* dense, const Scalar* stored, const std::uint32_t* tiles, const std::int32_t* nd,
             const double* w, int n, double* out) {
  if (tiles != nullptr) return combine_generic<kMarked>(TiledValues<Scalar>{stored, tiles}, nd, w, n, out);
#if defined(__GNUC__) && defined(__x86_64__)
  if constexpr (std::is_same_v<Scalar, float>) {
    if (detail::use_avx2_fma()) return combine_avx2<kMarked>(dense, nd, w, n, out);
  }
#endif
  combine_generic<kMarked>(DenseValues<Scalar>{dense}, nd, w, n, out);
}

}  // namespace

template <typename Scalar>
RadialDistanceMapT<Scalar>::RadialDistanceMapT(std::shared_ptr<const SamplingScheme> scheme)
    : scheme_(std::move(scheme)) {
  require(scheme_ != nullptr, "radial distance map: no sampling scheme");
  num_nodes_ = scheme_->num_nodes();
  require(num_nodes_ <= kMaxMapNodes, "radial distance map: the '" + scheme_->name() + "' scheme at resolution " +
                                          std::to_string(scheme_->resolution()) + " has " +
                                          std::to_string(num_nodes_) + " nodes, more than a map holds (2^31 - 1)");
  distance_.assign(static_cast<std::size_t>(num_nodes_), no_surface());
}

template <typename Scalar>
Scalar* RadialDistanceMapT<Scalar>::data() {
  require(tiles_.empty(), "radial distance map: a sparse map is read-only (fill a dense map, then make_sparse)");
  return distance_.data();
}
template <typename Scalar>
const Scalar* RadialDistanceMapT<Scalar>::data() const {
  require(tiles_.empty(), "radial distance map: a sparse map has no dense array (read it with at())");
  return distance_.data();
}

template <typename Scalar>
std::size_t RadialDistanceMapT<Scalar>::bytes() const {
  return distance_.capacity() * sizeof(Scalar) + stored_.capacity() * sizeof(Scalar) +
         tiles_.capacity() * sizeof(std::uint32_t);
}

template <typename Scalar>
std::int64_t RadialDistanceMapT<Scalar>::nodes_covered() const {
  if (tiles_.empty())
    return std::count_if(distance_.begin(), distance_.end(), [](Scalar d) { return d != no_surface(); });
  return std::count_if(stored_.begin(), stored_.end(), [](Scalar d) { return d != no_surface(); });  // the empty
                                                                                                     // tile adds 0
}

template <typename Scalar>
std::int64_t RadialDistanceMapT<Scalar>::tiles_stored() const {
  if (tiles_.empty()) return tiles_total();
  return static_cast<std::int64_t>(stored_.size() / std::size_t(kTileNodes)) - 1;  // less the empty tile
}

template <typename Scalar>
std::size_t RadialDistanceMapT<Scalar>::make_sparse(double region_mm) {
  require(!std::isnan(region_mm) && region_mm > 0,
          "radial distance map: sparse region " + std::to_string(region_mm) + " mm must be positive");
  if (!tiles_.empty()) return 0;
  const std::size_t before = bytes();
  const std::int64_t nt = tiles_total();
  std::vector<std::uint8_t> keep(static_cast<std::size_t>(nt), 0);
  std::int64_t kept = 0;
  for (std::int64_t t = 0; t < nt; ++t) {
    const std::int64_t a = t * kTileNodes, b = std::min(num_nodes_, a + kTileNodes);
    for (std::int64_t i = a; i < b; ++i) {
      const Scalar d = distance_[static_cast<std::size_t>(i)];
      if (d != no_surface() && double(d) <= region_mm) {
        keep[static_cast<std::size_t>(t)] = 1, ++kept;
        break;
      }
    }
  }
  if (kept == nt) return 0;  // nothing to leave out: stay dense (no tile table, no copy)
  // The empty tile, then the stored tiles back to back, each a full tile (the last one padded
  // with "no surface").
  stored_.assign(static_cast<std::size_t>((kept + 1) * kTileNodes), no_surface());
  tiles_.assign(static_cast<std::size_t>(nt), 0u);
  std::uint32_t s = 1;
  for (std::int64_t t = 0; t < nt; ++t) {
    if (!keep[static_cast<std::size_t>(t)]) continue;
    const std::int64_t a = t * kTileNodes, b = std::min(num_nodes_, a + kTileNodes);
    std::copy(distance_.begin() + a, distance_.begin() + b, stored_.begin() + std::int64_t(s) * kTileNodes);
    tiles_[static_cast<std::size_t>(t)] = s++;
  }
  decltype(distance_)().swap(distance_);
  const std::size_t after = bytes();
  return before > after ? before - after : 0;
}

template <typename Scalar>
void RadialDistanceMapT<Scalar>::lookup_many(const double* pts, std::int64_t n, double* out) const {
  double x[kStencilBlock], y[kStencilBlock], z[kStencilBlock];
  for (std::int64_t b = 0; b < n; b += kStencilBlock) {
    const int m = static_cast<int>(std::min<std::int64_t>(kStencilBlock, n - b));
    for (int j = 0; j < m; ++j) x[j] = pts[3 * (b + j)], y[j] = pts[3 * (b + j) + 1], z[j] = pts[3 * (b + j) + 2];
    lookup_soa<false>(x, y, z, m, out + b);
  }
}

template <typename Scalar>
template <bool kMarked>
void RadialDistanceMapT<Scalar>::lookup_soa(const double* x, const double* y, const double* z, std::int64_t n,
                                        double* out) const {
  alignas(64) std::int32_t nd[4 * kStencilBlock];
  alignas(64) double w[4 * kStencilBlock];
  const Scalar* dense = tiles_.empty() ? distance_.data() : nullptr;
  const std::uint32_t* tiles = tiles_.empty() ? nullptr : tiles_.data();
  for (std::int64_t b = 0; b < n; b += kStencilBlock) {
    const int m = static_cast<int>(std::min<std::int64_t>(kStencilBlock, n - b));
    scheme_->stencils_soa(x + b, y + b, z + b, m, nd, w);
    combine<kMarked>(dense, stored_.data(), tiles, nd, w, m, out + b);
  }
}

template class RadialDistanceMapT<float>;
template class RadialDistanceMapT<double>;
template void RadialDistanceMapT<float>::lookup_soa<false>(const double*, const double*, const double*, std::int64_t,
                                                       double*) const;
template void RadialDistanceMapT<float>::lookup_soa<true>(const double*, const double*, const double*, std::int64_t,
                                                      double*) const;
template void RadialDistanceMapT<double>::lookup_soa<false>(const double*, const double*, const double*, std::int64_t,
                                                        double*) const;
template void RadialDistanceMapT<double>::lookup_soa<true>(const double*, const double*, const double*, std::int64_t,
                                                       double*) const;
}  // namespace impinge
