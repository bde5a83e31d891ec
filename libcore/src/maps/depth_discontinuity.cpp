#include "impinge/maps/depth_discontinuity.hpp"

#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "impinge/core/error.hpp"
#include "impinge/core/interrupt.hpp"
#include "impinge/schemes/equiangular_grid.hpp"
#include "impinge/schemes/sampling_scheme.hpp"

namespace impinge {

namespace {
template <typename Scalar>
Scalar with_mark(Scalar d, bool mark) {
  if (!std::isfinite(d)) return d;
  using Bits = std::conditional_t<sizeof(Scalar) == 4, std::uint32_t, std::uint64_t>;
  Bits b;
  std::memcpy(&b, &d, sizeof b);
  b = (b & ~Bits(1)) | Bits(mark ? 1 : 0);
  std::memcpy(&d, &b, sizeof b);
  return d;
}
}  // namespace

template <typename Scalar>
std::int64_t mark_depth_discontinuities(RadialDistanceMapT<Scalar>& map, double tolerance_mm) {
  require(std::isfinite(tolerance_mm) && tolerance_mm > 0,
          "depth discontinuities: tolerance must be > 0 mm and finite, got " + std::to_string(tolerance_mm));
  const SamplingScheme& scheme = map.scheme();
  const std::int64_t n = map.num_nodes();
  std::vector<std::uint8_t> mark(static_cast<std::size_t>(n), 0);
  constexpr std::int64_t kChunk = 1024;
  const Scalar* values = map.data();
  auto is_marked = [tolerance_mm](double d, double a, double b, double c, double e) {
    const double dp = a - 2 * d + b, dt = c - 2 * d + e;  // NaN / inf next to "no surface"
    return !(std::abs(dp) <= tolerance_mm && std::abs(dt) <= tolerance_mm);
  };
  // A neighbour's value: its stencil's weighted sum over the nodes of nonzero weight, in stencil
  // order (as the map's look-up combines them); +inf when one of them has no surface.
  auto value_of = [values](const Stencil& st) {
    double v = 0;
    for (int k = 0; k < 4; ++k)
      if (st.weights[static_cast<std::size_t>(k)] > 0) {
        const double u = double(values[st.nodes[static_cast<std::size_t>(k)]]);
        if (!std::isfinite(u)) return std::numeric_limits<double>::infinity();
        v += st.weights[static_cast<std::size_t>(k)] * u;
      }
    return v;
  };
  // The second differences along phi and theta over each node's neighbours (the scheme's
  // neighbour_stencils: the equiangular grid's row and column neighbours; for other schemes the
  // map interpolated one node spacing away along the tangents).
  if (const auto* grid = dynamic_cast<const EquiangularGrid*>(&scheme)) {
    // The equiangular grid's stencils are single nodes of weight 1: read by index (1 * u is u), without
    // filling four stencils per node.
    auto value = [values](std::int64_t node) {
      const double u = double(values[node]);
      return std::isfinite(u) ? u : std::numeric_limits<double>::infinity();
    };
    // Row by row (the grid's neighbours by row and column, without two divisions per node).
    const int rows = grid->rows(), cols = grid->columns();
#pragma omp parallel for schedule(dynamic, 16)
    for (int r = 0; r < rows; ++r) {
      if (interruption_requested()) continue;  // a front end's stop: the rest skipped (thrown below)
      const std::int64_t first = std::int64_t(r) * cols;
      for (int c = 0; c < cols; ++c) {
        const double d = values[first + c];
        if (!std::isfinite(d)) continue;
        const std::array<std::int64_t, 4> nb = grid->neighbour_nodes(r, c);
        if (is_marked(d, value(nb[0]), value(nb[1]), value(nb[2]), value(nb[3]))) mark[static_cast<std::size_t>(first + c)] = 1;
      }
    }
  } else
#pragma omp parallel
  {
    std::vector<Stencil> nb(static_cast<std::size_t>(4 * kChunk));
#pragma omp for schedule(dynamic, 16)
    for (std::int64_t first = 0; first < n; first += kChunk) {
      const std::int64_t m = std::min(kChunk, n - first);
      scheme.neighbour_stencils(first, m, nb.data());
      for (std::int64_t j = 0; j < m; ++j) {
        const double d = values[first + j];
        if (!std::isfinite(d)) continue;
        const Stencil* s = nb.data() + 4 * j;
        if (is_marked(d, value_of(s[0]), value_of(s[1]), value_of(s[2]), value_of(s[3])))
          mark[static_cast<std::size_t>(first + j)] = 1;
      }
    }
  }
  interruption_point();  // a front end's stop (Ctrl-C in Python): the marks are incomplete
  std::int64_t count = 0;
  Scalar* out = map.data();
#pragma omp parallel for reduction(+ : count) schedule(static)
  for (std::int64_t i = 0; i < n; ++i) {
    const bool m = mark[static_cast<std::size_t>(i)] != 0;
    out[i] = with_mark(out[i], m);
    count += m;
  }
  return count;
}

template <typename Scalar>
void clear_depth_discontinuities(RadialDistanceMapT<Scalar>& map) {
  Scalar* v = map.data();
  for (std::int64_t i = 0; i < map.num_nodes(); ++i) v[i] = with_mark(v[i], false);
}

template <typename Scalar>
std::int64_t count_depth_discontinuities(const RadialDistanceMapT<Scalar>& map) {
  std::int64_t c = 0;
  for (std::int64_t i = 0; i < map.num_nodes(); ++i) c += std::isfinite(map.at(i)) && has_discontinuity_mark(map.at(i));
  return c;
}

template std::int64_t mark_depth_discontinuities<float>(RadialDistanceMapT<float>&, double);
template std::int64_t mark_depth_discontinuities<double>(RadialDistanceMapT<double>&, double);
template void clear_depth_discontinuities<float>(RadialDistanceMapT<float>&);
template void clear_depth_discontinuities<double>(RadialDistanceMapT<double>&);
template std::int64_t count_depth_discontinuities<float>(const RadialDistanceMapT<float>&);
template std::int64_t count_depth_discontinuities<double>(const RadialDistanceMapT<double>&);

}  // namespace impinge
