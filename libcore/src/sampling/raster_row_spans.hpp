#pragma once
// Private to libcore: the rasteriser's boxes and row spans (issue 4; triangle_cone.hpp explains the
// spans): the rows and columns a cone can cover on the equiangular grid, and on each row the columns
// of the arc each edge allows.

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "impinge/sampling/triangle_cone.hpp"

namespace impinge::detail {

/// Rows r0..r1 and unwrapped columns c0..c1 of a cone's box on a grid of step h (rad), given
/// as inv_h = 1 / h.
struct Box {
  int r0, r1, c0, c1;
};
inline Box box_of(const TriangleCone& t, double inv_h, int rows, int cols) {
  constexpr double pad = 1e-4;  // in steps; acos near +-1 loses ~1e-8 rad
  Box b{std::max(0, static_cast<int>(std::ceil(t.phi_min * inv_h - pad))),
        std::min(rows - 1, static_cast<int>(std::floor(t.phi_max * inv_h + pad))), 0, cols - 1};
  if (!t.full_theta) {
    b.c0 = static_cast<int>(std::ceil(t.theta_min * inv_h - pad));
    b.c1 = static_cast<int>(std::floor(t.theta_max * inv_h + pad));
  }
  return b;
}

/// Per-triangle constants of the row spans in column units (triangle_cone.hpp): edge k allows
/// the columns within W of near[k] (the copy of alpha_k / h nearest the box's middle) when
/// W <= cols / 4, else forbids those strictly within cols / 2 - W of far[k] (the copy of the
/// opposite azimuth nearest the middle). Edges that bound no span get pad = +inf.
struct SpanSetup {
  double c0, c1, inv_h, half, quarter;
  double k[3], pad[3], near[3], far[3];
};
SpanSetup span_setup(const TriangleCone& t, const Box& b, double inv_h, int cols);

/// Row spans lo[i] .. hi[i] (unwrapped columns, empty when lo > hi) of rows r0 + i, i <= r1 - r0,
/// of a cone whose box is narrower than 180 deg, with the sure bits (bit i % 8 of sure[i / 8]: every
/// node of the span certainly inside the cone). AVX-512 when detail::use_avx512(), else scalar (the
/// same spans up to rounding far inside their padding). Returns the number of nodes in the spans.
std::int64_t row_spans(const SpanSetup& P, int r0, int r1, const double* cot_phi, const double* rsqrt_sin_phi, int* lo,
                       int* hi, std::uint8_t* sure);

}  // namespace impinge::detail
