#pragma once
// Private to libcore: the rasteriser's linear-mode kernel (thesis Algorithm 1): over a triangle's
// box away from the poles, the nodes inside the cone get the barycentric interpolation of the
// corners' distances in the (theta, phi) plane. Vectorised clones.

#include <cstdint>

#include "sampling/raster_row_spans.hpp"
#include "sampling/raster_tables.hpp"

namespace impinge::detail {

/// Linear mode's box: rows r0..r1 and the columns as up to three contiguous segments (the box
/// may wrap across theta = 0/360), with the cone's edge normals e and adet.
struct WrappedBox {
  int r0, r1, nseg, seg[3][2];
  int seg_offset[3];  ///< the box's own (unwrapped) column = stored column + offset, per segment
  double e[9], bias[3], adet;
};

/// The box of rows r0..r1 and unwrapped columns c0..c1 (c0 may be negative, c1 may reach past the
/// last column: the box wraps across theta = 0/360) as up to three contiguous segments.
WrappedBox make_box(const Box& bx, int cols, const TriangleCone& t);

/// Linear-mode (thesis Algorithm 1) rows of one triangle's box away from the poles: the same
/// cone test as exact mode, and at covered nodes the barycentric interpolation of the corner
/// distances in the (theta, phi) plane (planar_value's formula, theta unwrapped as the box's own
/// column index), clamped to the triangle. Branch-free; vectorised clones.
struct LinearBox {
  WrappedBox box;
  double h, ta, tb, tc, pa, pb, pc, da, db, dc, inv_area2;
};
/// The linear-mode rows of one box into a float or double map of `cols` columns; returns the nodes
/// newly covered.
std::int64_t linear_rows(float* map, int cols, const LinearBox& L, const double* sin_phi, const double* cos_phi,
                         const double* cos_theta, const double* sin_theta);
std::int64_t linear_rows(double* map, int cols, const LinearBox& L, const double* sin_phi, const double* cos_phi,
                         const double* cos_theta, const double* sin_theta);

}  // namespace impinge::detail
