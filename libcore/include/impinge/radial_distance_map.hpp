#pragma once
/// @file radial_distance_map.hpp
/// Radial distance map (the thesis' LUT, sec. 3.1): one distance per node of an equiangular
/// grid, the distance from the COR to the nearest surface hit along the node's ray.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "impinge/equiangular_grid.hpp"
#include "impinge/spherical_frame.hpp"

namespace impinge {

/// Radial distance map over an EquiangularGrid. `Scalar` is float (default, 4 bytes a node)
/// or double (the thesis' Tables 2 and 7 count 8 bytes a node). Nodes with no surface hold
/// +infinity (`has_surface(i)` is false).
template <typename Scalar>
class RadialDistanceMapT {
 public:
  /// A map of `grid` with every node at "no surface".
  explicit RadialDistanceMapT(const EquiangularGrid& grid)
      : grid_(grid), distance_(static_cast<std::size_t>(grid.num_nodes()), no_surface()) {}

  static constexpr Scalar no_surface() { return std::numeric_limits<Scalar>::infinity(); }

  const EquiangularGrid& grid() const { return grid_; }
  std::int64_t num_nodes() const { return grid_.num_nodes(); }
  /// Distance (mm) at node i, or +inf for no surface.
  Scalar at(std::int64_t i) const { return distance_[static_cast<std::size_t>(i)]; }
  bool has_surface(std::int64_t i) const { return at(i) != no_surface(); }
  Scalar* data() { return distance_.data(); }
  const Scalar* data() const { return distance_.data(); }
  /// Bytes actually allocated for the node values.
  std::size_t bytes() const { return distance_.capacity() * sizeof(Scalar); }
  /// Number of nodes with a surface.
  std::int64_t nodes_covered() const {
    return std::count_if(distance_.begin(), distance_.end(), [](Scalar d) { return d != no_surface(); });
  }
  /// Largest stored distance (mm) over covered nodes, or 0 when none is covered.
  double max_distance() const {
    double m = 0;
    for (Scalar d : distance_)
      if (d != no_surface()) m = std::max<double>(m, d);
    return m;
  }

  /// Interpolated radial distance (mm) of the surface in the direction of `p` (any nonzero
  /// vector, relative to the COR): bilinear over the four surrounding nodes (thesis
  /// Algorithm 2). Returns NaN when a node with nonzero weight has no surface.
  /// Cost: one sqrt, acos, atan2 and four loads; no allocation.
  double sample(const Eigen::Vector3d& p) const {
    const double r = p.norm();
    double phi = std::acos(std::clamp(p.z() / r, -1.0, 1.0));
    double theta = std::atan2(p.y(), p.x());
    if (theta < 0) theta += 2 * kPi;
    return sample_angles(phi, theta);
  }

  /// As `sample`, from phi in [0, pi] and theta in [0, 2 pi) radians.
  double sample_angles(double phi, double theta) const {
    const double inv = inv_step_();
    const double fr = phi * inv;
    const int rows = grid_.rows(), cols = grid_.columns();
    int r0 = static_cast<int>(fr);
    if (r0 > rows - 2) r0 = rows - 2;
    const double t = fr - r0;
    const double fc = theta * inv;
    int c0 = static_cast<int>(fc);
    const double w = fc - c0;
    if (c0 >= cols) c0 -= cols;
    const int c1 = (c0 + 1 == cols) ? 0 : c0 + 1;
    const Scalar* row0 = distance_.data() + std::int64_t(r0) * cols;
    const Scalar* row1 = row0 + cols;
    const double w00 = (1 - t) * (1 - w), w01 = (1 - t) * w, w10 = t * (1 - w), w11 = t * w;
    const double d00 = row0[c0], d01 = row0[c1], d10 = row1[c0], d11 = row1[c1];
    const double v = w00 * d00 + w01 * d01 + w10 * d10 + w11 * d11;
    if (std::isfinite(v)) return v;
    // A node with no surface: NaN unless its weight is exactly zero.
    const double ws[4] = {w00, w01, w10, w11}, ds[4] = {d00, d01, d10, d11};
    double acc = 0;
    for (int k = 0; k < 4; ++k) {
      if (ws[k] == 0) continue;
      if (!std::isfinite(ds[k])) return std::numeric_limits<double>::quiet_NaN();
      acc += ws[k] * ds[k];
    }
    return acc;
  }

 private:
  double inv_step_() const { return 1.0 / grid_.step(); }
  EquiangularGrid grid_;
  std::vector<Scalar> distance_;
};

using RadialDistanceMap = RadialDistanceMapT<float>;         ///< float32 map (default)
using RadialDistanceMapDouble = RadialDistanceMapT<double>;  ///< float64 map (thesis Table 2)

/// Memory of a map of `nodes` nodes at `bytes_per_node` bytes (thesis Table 2's formula).
inline std::int64_t map_bytes_formula(std::int64_t nodes, int bytes_per_node) {
  return nodes * bytes_per_node;
}

}  // namespace impinge
