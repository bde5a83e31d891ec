#pragma once
// Private to libcore: what the rasteriser's kernels share (rasterize.cpp, raster_row_spans,
// raster_exact_kernels, raster_linear_kernels): the grid's per-row and per-column trigonometry, the
// pieces of a wrapped span, vector-lane masks, and how a covered node keeps the nearer distance.

#include <cstdint>
#include <limits>
#include <vector>

#include "impinge/schemes/equiangular_grid.hpp"

namespace impinge::detail {

/// The first min(n, 8) of 8 lanes (n >= 1): the mask of a vector step with n items left.
inline std::uint8_t first_lanes(int n) { return n >= 8 ? std::uint8_t(0xff) : std::uint8_t((1u << n) - 1); }

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
const GridTables& grid_tables(const EquiangularGrid& grid);

}  // namespace impinge::detail
