#pragma once
/// @file equiangular_grid.hpp
/// The equiangular (phi, theta) sampling scheme of RSID (thesis sec. 3.1, Table 2).

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

namespace impinge {

/// Interpolation stencil of a direction: up to four node indices and their weights (sum 1).
struct Stencil {
  std::array<std::int64_t, 4> nodes{};  ///< node indices
  std::array<double, 4> weights{};       ///< bilinear weights, >= 0, sum to 1
};

/// Equiangular grid at precision p degrees: rows phi_i = i p for i = 0..180/p (both poles
/// included), columns theta_j = j p for j = 0..360/p - 1 (theta periodic), node index
/// i * columns + j. Node count (180/p + 1) x (360/p) (thesis Table 2: 65,160 at 1 deg).
/// Every node of row 0 (and of the last row) has the same direction, the pole.
class EquiangularGrid {
 public:
  /// Grid of precision `precision_deg` (degrees). Throws impinge::Error unless
  /// 0 < p <= 90 and 180 / p is an integer (to 1e-9 relative).
  explicit EquiangularGrid(double precision_deg);

  double precision_deg() const { return precision_deg_; }  ///< resolution parameter p, degrees
  double step() const { return step_; }                    ///< p in radians
  int rows() const { return rows_; }                       ///< 180/p + 1
  int columns() const { return cols_; }                    ///< 360/p
  std::int64_t num_nodes() const { return std::int64_t(rows_) * cols_; }

  /// Direction (unit vector) of node i, 0 <= i < num_nodes().
  Eigen::Vector3d node_direction(std::int64_t i) const;
  /// Nearest node to a unit direction `u` (ties toward the lower index).
  std::int64_t node(const Eigen::Vector3d& u) const;
  /// Bilinear stencil of a unit direction `u` over the four nodes around (phi, theta),
  /// theta wrapping at 360 deg.
  Stencil interpolate(const Eigen::Vector3d& u) const;
  /// Largest great-circle distance between neighbouring nodes in radians: p (along a
  /// meridian and along the equator). Feeds the error bounds (thesis Eq. 7).
  double max_node_spacing() const { return step_; }

 private:
  double precision_deg_;
  double step_;
  int rows_;
  int cols_;
};

}  // namespace impinge
