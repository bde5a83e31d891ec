#pragma once
// Private to libcore: the rasteriser's exact-mode kernels (issue 4): over a cone's row spans, the
// nodes inside the cone get the distance at which their ray meets the triangle's plane, the nearer
// value kept. AVX-512 for float maps when detail::use_avx512(), else vectorised clones.

#include <cstdint>

#include "sampling/raster_tables.hpp"

namespace impinge::detail {

/// One cone's rows r0..r1 with their spans lo[r - r0] .. hi[r - r0] (unwrapped columns), for
/// the exact-mode kernels: e (the three edge normals), n (the face normal) and adet as in
/// TriangleCone; sure (or null): bit i % 8 of sure[i / 8] set when every node of row r0 + i's
/// span is certainly inside the cone (row_spans).
struct SpanRows {
  int r0, r1;
  const int* lo;
  const int* hi;
  const std::uint8_t* sure;
  const double* e;
  const double* bias;  ///< the cone's edge tolerances (kEdgeAngleTolerance |e_k|)
  const double* n;
  double adet;
};

/// The exact-mode rows of one cone (exact_rows_body in raster_exact_kernels.cpp gives the
/// arithmetic) into a float or double map of `cols` columns. Returns the nodes that had no surface
/// before and have one now.
std::int64_t exact_rows(float* map, int cols, const SpanRows& S, const GridTables& T);
std::int64_t exact_rows(double* map, int cols, const SpanRows& S, const GridTables& T);

}  // namespace impinge::detail
