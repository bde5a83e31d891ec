#include "sampling/raster_linear_kernels.hpp"

#include <algorithm>

#include "core/simd_clones.hpp"

namespace impinge::detail {

WrappedBox make_box(const Box& bx, int cols, const TriangleCone& t) {
  const int r0 = bx.r0, r1 = bx.r1, c0 = bx.c0, c1 = bx.c1;
  WrappedBox b;
  b.r0 = r0, b.r1 = r1, b.nseg = 0;
  auto add = [&](int lo, int hi, int offset) {
    b.seg[b.nseg][0] = lo, b.seg[b.nseg][1] = hi, b.seg_offset[b.nseg] = offset, ++b.nseg;
  };
  if (c0 < 0) add(c0 + cols, cols - 1, -cols);
  add(std::max(c0, 0), std::min(c1, cols - 1), 0);
  if (c1 >= cols) add(0, c1 - cols, cols);
  std::copy(t.e, t.e + 9, b.e);
  std::copy(t.bias, t.bias + 3, b.bias);
  b.adet = t.adet;
  return b;
}

namespace {

/// The three edge functions of one row (coefficients folded with sin and cos of its phi), each
/// raised by its tolerance `bias` (kEdgeAngleTolerance).
struct RowEdges {
  double a0, b0, c0, a1, b1, c1, a2, b2, c2;
  RowEdges(const double* e, const double* bias, double sp, double cp)
      : a0(sp * e[0]),
        b0(sp * e[1]),
        c0(cp * e[2] + bias[0]),
        a1(sp * e[3]),
        b1(sp * e[4]),
        c1(cp * e[5] + bias[1]),
        a2(sp * e[6]),
        b2(sp * e[7]),
        c2(cp * e[8] + bias[2]) {}
  /// Inside the cone (all three >= 0, each within its tolerance); `sum` = f0 + f1 + f2.
  bool inside(double ct, double st, double& sum) const {
    const double f0 = a0 * ct + b0 * st + c0, f1 = a1 * ct + b1 * st + c1, f2 = a2 * ct + b2 * st + c2;
    sum = f0 + f1 + f2;
    return std::min(std::min(f0, f1), f2) >= 0;
  }
};

template <typename Scalar>
inline std::int64_t linear_rows_body(Scalar* __restrict map, int cols, const LinearBox& L,
                                     const double* __restrict sin_phi, const double* __restrict cos_phi,
                                     const double* __restrict cos_theta, const double* __restrict sin_theta) {
  const WrappedBox& box = L.box;
  std::int64_t newly = 0;
  for (int r = box.r0; r <= box.r1; ++r) {
    const RowEdges edges(box.e, box.bias, sin_phi[r], cos_phi[r]);
    const double phi = r * L.h;
    Scalar* __restrict row = map + std::int64_t(r) * cols;
    for (int g = 0; g < box.nseg; ++g)
      for (int j = box.seg[g][0]; j <= box.seg[g][1]; ++j) {
        double sum;
        const bool inside = edges.inside(cos_theta[j], sin_theta[j], sum);
        const double tn = (j + box.seg_offset[g]) * L.h;
        double lb = ((tn - L.ta) * (L.pc - L.pa) - (L.tc - L.ta) * (phi - L.pa)) * L.inv_area2;
        double lc = ((L.tb - L.ta) * (phi - L.pa) - (tn - L.ta) * (L.pb - L.pa)) * L.inv_area2;
        double la = 1 - lb - lc;
        la = std::max(la, 0.0), lb = std::max(lb, 0.0), lc = std::max(lc, 0.0);
        keep_nearer(row[j], inside, static_cast<Scalar>((la * L.da + lb * L.db + lc * L.dc) / (la + lb + lc)), newly);
      }
  }
  return newly;
}
IMPINGE_SIMD_CLONES
std::int64_t linear_rows_float(float* map, int cols, const LinearBox& L, const double* sin_phi, const double* cos_phi,
                         const double* cos_theta, const double* sin_theta) {
  return linear_rows_body(map, cols, L, sin_phi, cos_phi, cos_theta, sin_theta);
}
IMPINGE_SIMD_CLONES
std::int64_t linear_rows_double(double* map, int cols, const LinearBox& L, const double* sin_phi, const double* cos_phi,
                         const double* cos_theta, const double* sin_theta) {
  return linear_rows_body(map, cols, L, sin_phi, cos_phi, cos_theta, sin_theta);
}


}  // namespace

std::int64_t linear_rows(float* map, int cols, const LinearBox& L, const double* sin_phi, const double* cos_phi,
                         const double* cos_theta, const double* sin_theta) {
  return linear_rows_float(map, cols, L, sin_phi, cos_phi, cos_theta, sin_theta);
}
std::int64_t linear_rows(double* map, int cols, const LinearBox& L, const double* sin_phi, const double* cos_phi,
                         const double* cos_theta, const double* sin_theta) {
  return linear_rows_double(map, cols, L, sin_phi, cos_phi, cos_theta, sin_theta);
}

}  // namespace impinge::detail
