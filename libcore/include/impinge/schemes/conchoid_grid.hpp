#pragma once
/// @file conchoid_grid.hpp
/// Weighted equiangular grid for a conchoid-shaped joint (thesis sec. 5.1, "weighted
/// spherical sampling"): the rows of phi in [0, 90] deg are placed at equal curve length of
/// Menschik's conchoid r = a + b cos(phi) (the exact inversion behind thesis Eq. 15-16) instead
/// of equal angle; rows in (90, 180] deg and all columns stay equiangular. Same node count as
/// the equiangular grid of the same precision, so the two compare at equal memory.

#include <cstdint>
#include <string>
#include <vector>

#include "impinge/schemes/conchoid.hpp"
#include "impinge/schemes/sampling_scheme.hpp"

namespace impinge {

class ConchoidGrid : public SchemeImpl<ConchoidGrid> {
 public:
  /// Precision p in degrees (180/p integral, 90/p integral) and the conchoid's a > b >= 0 (mm;
  /// only a/b matters). Throws impinge::Error on bad input.
  explicit ConchoidGrid(double precision_deg, double a_mm = kMenschikA, double b_mm = kMenschikB);

  std::string name() const override { return "conchoid"; }
  std::string resolution_name() const override { return "precision_deg"; }
  double resolution() const override { return precision_deg_; }
  std::int64_t num_nodes() const override { return std::int64_t(rows()) * cols_; }
  int rows() const { return static_cast<int>(row_phi_.size()); }
  int columns() const { return cols_; }
  /// Polar angle of row r, radians.
  double row_phi(int r) const { return row_phi_[static_cast<std::size_t>(r)]; }

  Eigen::Vector3d node_direction(std::int64_t i) const override;
  void node_angles(std::int64_t first, std::int64_t count, double* phi, double* theta) const override;
  std::int64_t node(const Eigen::Vector3d& u) const override;
  double max_node_spacing() const override { return max_spacing_; }

  /// Bilinear stencil: the bracketing rows by binary search over the row angles, linear in phi
  /// between them; equiangular in theta.
  void stencil_at(double x, double y, double z, std::int64_t nodes[4], double w[4]) const;

 private:
  double precision_deg_, step_;
  int cols_;
  std::vector<double> row_phi_;
  double max_spacing_;
};

}  // namespace impinge
