#pragma once
/// @file equiangular_grid.hpp
/// The equiangular (phi, theta) sampling scheme of RSID (thesis sec. 3.1, Table 2).

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "impinge/core/fast_angles.hpp"
#include "impinge/schemes/sampling_scheme.hpp"

namespace impinge {

/// Equiangular grid at precision p degrees: rows phi_i = i p for i = 0..180/p (both poles
/// included), columns theta_j = j p for j = 0..360/p - 1 (theta periodic), node index
/// i * columns + j. Node count (180/p + 1) x (360/p) (thesis Table 2: 65,160 at 1 deg).
/// Every node of row 0 (and of the last row) has the same direction, the pole.
/// Interpolation: bilinear in (phi, theta) over the four surrounding nodes (thesis Alg. 2).
/// The valid precision (degrees, 180/p integral) nearest to a node spacing of `spacing_rad`
/// radians: 180 / round(180 / spacing_deg), at most 180. Used to rasterise the equiangular map
/// that other schemes are resampled from (thesis Table 6's matching) and to image them.
double matched_equiangular_precision(double spacing_rad);

class EquiangularGrid : public SchemeImpl<EquiangularGrid> {
 public:
  /// Grid of precision `precision_deg` (degrees). Throws impinge::Error unless
  /// 0 < p <= 90 and 180 / p is an integer (to 1e-9 relative).
  explicit EquiangularGrid(double precision_deg);

  std::string name() const override { return "equiangular"; }
  std::string resolution_name() const override { return "precision_deg"; }
  double resolution() const override { return precision_deg_; }
  double precision_deg() const { return precision_deg_; }  ///< resolution parameter p, degrees
  double step() const { return step_; }                    ///< p in radians
  int rows() const { return rows_; }                       ///< 180/p + 1
  int columns() const { return cols_; }                    ///< 360/p
  std::int64_t num_nodes() const override { return std::int64_t(rows_) * cols_; }

  /// Direction (unit vector) of node i, 0 <= i < num_nodes().
  Eigen::Vector3d node_direction(std::int64_t i) const override;
  void node_angles(std::int64_t first, std::int64_t count, double* phi, double* theta) const override;
  /// Nearest node to a unit direction `u` (ties toward the lower index).
  std::int64_t node(const Eigen::Vector3d& u) const override;
  /// Largest great-circle distance between neighbouring nodes in radians: p (along a
  /// meridian and along the equator). Feeds the error bounds (thesis Eq. 7).
  double max_node_spacing() const override { return step_; }

  /// Bilinear stencil of the direction of (x, y, z) (nonzero), the hot path of detection:
  /// one sqrt, no libm trigonometry (fast_angles.hpp: angles within 1e-13 rad), no allocation.
  /// Theta wraps at 360 deg.
  void stencil_at(double x, double y, double z, std::int64_t nodes[4], double w[4]) const {
    const double phi = fast_polar_angle(std::sqrt(x * x + y * y), z);
    const double theta = fast_azimuth(y, x);
    stencil_angles(phi, theta, nodes, w);
  }

  /// As stencil_at from phi in [0, pi] and theta in [0, 2 pi) radians.
  void stencil_angles(double phi, double theta, std::int64_t nodes[4], double w[4]) const {
    const double fr = phi * inv_step_;
    int r0 = static_cast<int>(fr);
    if (r0 > rows_ - 2) r0 = rows_ - 2;
    const double t = fr - r0;
    const double fc = theta * inv_step_;
    int c0 = static_cast<int>(fc);
    const double s = fc - c0;
    if (c0 >= cols_) c0 -= cols_;
    const int c1 = (c0 + 1 == cols_) ? 0 : c0 + 1;
    const std::int64_t b0 = std::int64_t(r0) * cols_, b1 = b0 + cols_;
    nodes[0] = b0 + c0;
    nodes[1] = b0 + c1;
    nodes[2] = b1 + c0;
    nodes[3] = b1 + c1;
    w[0] = (1 - t) * (1 - s);
    w[1] = (1 - t) * s;
    w[2] = t * (1 - s);
    w[3] = t * s;
  }

  /// Block stencils (SamplingScheme::stencils_soa): the fast angles, the cell and its weights in
  /// one branch-free pass (cloned for AVX-512 and AVX2, chosen at run time), then the node indices.
  /// The same stencils as stencil_at up to the rounding of the angles (one division for both).
  void stencils_soa(const double* x, const double* y, const double* z, int n, std::int32_t* nodes,
                    double* w) const override;
  /// The row neighbours (r -+ 1, same column; across a pole, row 1 half a turn round) and column
  /// neighbours (c -+ 1, wrapping at the seam) of each node, one node of weight 1 each: the nodes
  /// that the bilinear stencils join (SamplingScheme::neighbour_stencils).
  void neighbour_stencils(std::int64_t first, std::int64_t count, Stencil* out) const override;
  /// Those four neighbours of node i (0 <= i < num_nodes()) as node indices, in the stencils' order (row
  /// before, row after, column before, column after).
  std::array<std::int64_t, 4> neighbour_nodes(std::int64_t i) const {
    return neighbour_nodes(static_cast<int>(i / cols_), static_cast<int>(i % cols_));
  }
  /// The same for the node at row r, column c (no division: for callers that walk the rows).
  std::array<std::int64_t, 4> neighbour_nodes(int r, int c) const {
    const int cl = c == 0 ? cols_ - 1 : c - 1, cr = c + 1 == cols_ ? 0 : c + 1;
    const int co = r == 0 || r == rows_ - 1 ? (c + cols_ / 2) % cols_ : c;  // across the pole (first, last rows)
    auto at = [this](int rr, int cc) { return std::int64_t(rr) * cols_ + cc; };
    return {r == 0 ? at(1, co) : at(r - 1, c), r == rows_ - 1 ? at(rows_ - 2, co) : at(r + 1, c), at(r, cl), at(r, cr)};
  }
  /// The rows within the cap's polar range, and in each the columns within the azimuth half-width
  /// where the cap's boundary crosses the row (whole rows around a pole), each node confirmed by the
  /// same distance test as the default (SamplingScheme::nodes_in_cap): O(nodes in the cap + rows).
  void nodes_in_cap(const Eigen::Vector3d& direction, double radius_rad, std::vector<std::int64_t>& out) const override;

 private:
  double precision_deg_;
  double step_;
  double inv_step_;
  int rows_;
  int cols_;
};

/// The equiangular grid whose node indexing a map of `scheme` shares (SamplingScheme::conformable
/// with the grid of the scheme's node spacing), or nothing. For the operations that run over an
/// equiangular grid's rows and columns (rasterising straight into a map, ROM bound pyramids, map
/// images); any other scheme takes their general path. Never throws.
std::optional<EquiangularGrid> conformable_equiangular_grid(const SamplingScheme& scheme);

/// `scheme` as an equiangular grid, for the operations that need one (rasterisation, the
/// resampling source). Throws impinge::Error naming the scheme when it is another.
const EquiangularGrid& equiangular_grid_of(const SamplingScheme& scheme);

}  // namespace impinge
