#pragma once
// Private to libcore: points in boxes of median splits, so that every run of run_sizes[j] points starting
// at a multiple of it is compact in space (the scan sets' clusters, the closest-point query's groups).
#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

namespace impinge::detail {

/// The order of n points (coordinate(k, axis): point k's coordinate along axis 0, 1 or 2, mm) in boxes: a
/// range of more than run_sizes.back() points is split at a multiple of the largest size from its start, a
/// smaller one at a multiple of the largest size below its length, at the median (so rounded) along its
/// bounding box's longest axis, down to ranges of run_sizes.front(). run_sizes: ascending, each a multiple
/// of the one before, the first >= 1 (the callers check). O(n log n).
template <typename Coordinate>
std::vector<std::int32_t> box_order(std::size_t n, const std::vector<std::int64_t>& run_sizes, Coordinate coordinate) {
  // The points' coordinates beside their indices, moved together (the splits read them in place, not through
  // the order); the same comparisons on the same values as through indices, so the same order.
  struct Point {
    double x[3];
    std::int32_t index;
  };
  std::vector<Point> p(n);
  for (std::size_t k = 0; k < n; ++k) {
    const auto i = static_cast<std::int32_t>(k);
    p[k] = Point{{coordinate(i, 0), coordinate(i, 1), coordinate(i, 2)}, i};
  }
  const auto leaf = static_cast<std::size_t>(run_sizes.front());
  std::vector<std::pair<std::size_t, std::size_t>> todo{{0, n}};  // [begin, end) still to split
  while (!todo.empty()) {
    const auto [begin, end] = todo.back();
    todo.pop_back();
    const std::size_t count = end - begin;
    if (count <= leaf) continue;
    std::size_t unit = leaf;  // the largest run size below the range's length
    for (const std::int64_t r : run_sizes)
      if (static_cast<std::size_t>(r) < count) unit = static_cast<std::size_t>(r);
    const std::size_t half = std::clamp((count / 2 + unit / 2) / unit * unit, unit, (count - 1) / unit * unit);
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (std::size_t k = begin; k < end; ++k)
      for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[k].x[a]), hi[a] = std::max(hi[a], p[k].x[a]);
    int axis = 0;
    (hi - lo).maxCoeff(&axis);
    const auto first = p.begin() + static_cast<std::ptrdiff_t>(begin);
    std::nth_element(first, first + static_cast<std::ptrdiff_t>(half), p.begin() + static_cast<std::ptrdiff_t>(end),
                     [axis](const Point& u, const Point& v) { return u.x[axis] < v.x[axis]; });
    todo.emplace_back(begin, begin + half);
    todo.emplace_back(begin + half, end);
  }
  std::vector<std::int32_t> order(n);
  for (std::size_t k = 0; k < n; ++k) order[k] = p[k].index;
  return order;
}

}  // namespace impinge::detail
