#pragma once
/// @file octahedral_scheme.hpp
/// Equal-area octahedral sampling (Clarberg 2008, "Fast equal-area mapping of the (hemi)sphere
/// using SIMD", J. Graphics Tools 13(3)): the unit sphere is mapped onto the square [-1, 1]^2 with
/// the upper hemisphere (z >= 0) in the diamond |u| + |v| <= 1 and the lower hemisphere folded
/// into the four corner triangles. The map preserves area, so the N x N cells of the square have
/// equal solid angle 4 pi / N^2 (an equiangular grid spends pi / 2 times more nodes near the
/// poles). Nodes sit at the cell centres; a look-up is bilinear in (u, v), with the neighbours
/// beyond the square's edges folded back across them (the edge v = 1 is glued to itself with u
/// mirrored, so the virtual row N of column c is row N - 1 of column N - 1 - c), which keeps the
/// look-up continuous across every seam. No libm trigonometry on the look-up path.
///
/// Source: impinge (new sampling schemes; not in the thesis); mapping and inverse as in Clarberg 2008, sec. 3.

#include <cmath>
#include <cstdint>
#include <string>

#include "impinge/core/fast_angles.hpp"
#include "impinge/schemes/sampling_scheme.hpp"

namespace impinge {

/// Square coordinates (u, v) in [-1, 1]^2 of the direction of (x, y, z) (any nonzero length) under
/// the equal-area octahedral map. (0, 0, 1) -> (0, 0); (0, 0, -1) -> the corners.
inline void octahedral_from_direction(double x, double y, double z, double& u, double& v) {
  constexpr double kTwoOverPi = 0.63661977236758134308;
  const double rho2 = x * x + y * y, len = std::sqrt(rho2 + z * z), az = std::abs(z);
  // r = sqrt(1 - |z| / len), written without the cancellation of 1 - |z| near the poles.
  const double r = len > 0 ? std::sqrt(rho2 / (len * (len + az))) : 0.0;
  const double phi = fast_angles_detail::atan2_first_quadrant(std::abs(y), std::abs(x));  // [0, pi/2]
  double b = r * phi * kTwoOverPi, a = r - b;
  if (z < 0) {
    const double a0 = a;
    a = 1 - b, b = 1 - a0;
  }
  u = std::copysign(a, x), v = std::copysign(b, y);
}

/// Unit direction of the square point (u, v) in [-1, 1]^2 (the inverse of octahedral_from_direction).
Eigen::Vector3d octahedral_to_direction(double u, double v);

/// Equal-area octahedral scheme of N x N cells (see the file comment). Node index = row * N +
/// column, row along v, column along u, centres at -1 + (2 i + 1) / N.
class OctahedralScheme : public SchemeImpl<OctahedralScheme> {
 public:
  /// N in [2, 46340] integral cells per side of the square (N^2 nodes fit a map). Throws impinge::Error
  /// otherwise.
  explicit OctahedralScheme(double cells_per_side);

  std::string name() const override { return "octahedral"; }
  std::string resolution_name() const override { return "cells_per_side"; }
  double resolution() const override { return double(n_); }
  std::int64_t num_nodes() const override { return std::int64_t(n_) * n_; }
  Eigen::Vector3d node_direction(std::int64_t i) const override;
  /// Angles straight from the inverse map (no direction round trip): the resampling fast path.
  void node_angles(std::int64_t first, std::int64_t count, double* phi, double* theta) const override;
  /// The node whose cell holds u.
  std::int64_t node(const Eigen::Vector3d& u) const override;
  /// Largest great-circle distance between two nodes that are neighbours in the square (seams
  /// included), radians: measured over all neighbour pairs of one quadrant (the map is symmetric
  /// under u -> -u and v -> -v).
  double max_node_spacing() const override { return max_spacing_; }

  /// Bilinear stencil in the square with folded neighbours (see the file comment).
  void stencil_at(double x, double y, double z, std::int64_t nodes[4], double w[4]) const {
    double u, v;
    octahedral_from_direction(x, y, z, u, v);
    const double su = (u + 1) * half_n_ - 0.5, sv = (v + 1) * half_n_ - 0.5;
    const double fu0 = std::floor(su), fv0 = std::floor(sv);
    const double s = su - fu0, t = sv - fv0;
    const int c0 = static_cast<int>(fu0), r0 = static_cast<int>(fv0);
    nodes[0] = folded(c0, r0), nodes[1] = folded(c0 + 1, r0);
    nodes[2] = folded(c0, r0 + 1), nodes[3] = folded(c0 + 1, r0 + 1);
    w[0] = (1 - s) * (1 - t), w[1] = s * (1 - t), w[2] = (1 - s) * t, w[3] = s * t;
  }

 private:
  /// Index of cell (c, r) with c, r in [-1, N], folded back into the square across its edges.
  std::int64_t folded(int c, int r) const {
    if (c < 0) c = 0, r = n_ - 1 - r;
    else if (c >= n_) c = n_ - 1, r = n_ - 1 - r;
    if (r < 0) r = 0, c = n_ - 1 - c;
    else if (r >= n_) r = n_ - 1, c = n_ - 1 - c;
    return std::int64_t(r) * n_ + c;
  }
  int n_;
  double half_n_;
  double max_spacing_;
};

}  // namespace impinge
