#include "impinge/maps/depth_discontinuity.hpp"

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "impinge/core/error.hpp"
#include "impinge/schemes/equiangular_grid.hpp"

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
  const double h = scheme.max_node_spacing();
  const double ch = std::cos(h), sh = std::sin(h);
  std::vector<std::uint8_t> mark(static_cast<std::size_t>(n), 0);
  constexpr std::int64_t kChunk = 1024;
  const Scalar* values = map.data();
  auto is_marked = [tolerance_mm](double d, double a, double b, double c, double e) {
    const double dp = a - 2 * d + b, dt = c - 2 * d + e;  // NaN / inf next to "no surface"
    return !(std::abs(dp) <= tolerance_mm && std::abs(dt) <= tolerance_mm);
  };
  if (const auto* grid = dynamic_cast<const EquiangularGrid*>(&scheme)) {
    // The grid's own neighbours (the nodes its bilinear stencils join): rows r +- 1 and columns
    // c +- 1 (wrapping); at a pole row, the polar neighbours are the next row at c and c + 180 deg.
    const int rows = grid->rows(), cols = grid->columns();
    auto at = [&](int r, int c) { return double(values[std::int64_t(r) * cols + c]); };
#pragma omp parallel for schedule(static)
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        const double d = at(r, c);
        if (!std::isfinite(d)) continue;
        const int cl = c == 0 ? cols - 1 : c - 1, cr = c + 1 == cols ? 0 : c + 1, co = (c + cols / 2) % cols;
        const double up = r == 0 ? at(1, co) : at(r - 1, c);
        const double down = r == rows - 1 ? at(rows - 2, co) : at(r + 1, c);
        if (is_marked(d, up, down, at(r, cl), at(r, cr))) mark[static_cast<std::size_t>(std::int64_t(r) * cols + c)] = 1;
      }
    }
  } else
#pragma omp parallel
  {
    std::vector<double> phi(kChunk), theta(kChunk), pts(4 * 3 * kChunk), nb(4 * kChunk);
#pragma omp for schedule(dynamic, 16)
    for (std::int64_t first = 0; first < n; first += kChunk) {
      const std::int64_t m = std::min(kChunk, n - first);
      scheme.node_angles(first, m, phi.data(), theta.data());
      // The four neighbours of each node at great-circle distance h: u cos h +- e sin h along the
      // polar (e_phi) and azimuthal (e_theta) unit tangents.
      for (std::int64_t j = 0; j < m; ++j) {
        const double sp = std::sin(phi[j]), cp = std::cos(phi[j]), st = std::sin(theta[j]), ct = std::cos(theta[j]);
        const Eigen::Vector3d u(sp * ct, sp * st, cp), ep(cp * ct, cp * st, -sp), et(-st, ct, 0);
        const Eigen::Vector3d q[4] = {u * ch + ep * sh, u * ch - ep * sh, u * ch + et * sh, u * ch - et * sh};
        for (int k = 0; k < 4; ++k)
          for (int c = 0; c < 3; ++c) pts[static_cast<std::size_t>(3 * (4 * j + k) + c)] = q[k][c];
      }
      map.sample_many(pts.data(), 4 * m, nb.data());
      for (std::int64_t j = 0; j < m; ++j) {
        const double d = values[first + j];
        if (!std::isfinite(d)) continue;
        const double* v = nb.data() + 4 * j;
        if (is_marked(d, v[0], v[1], v[2], v[3])) mark[static_cast<std::size_t>(first + j)] = 1;
      }
    }
  }
  std::int64_t count = 0;
  Scalar* out = map.data();
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
