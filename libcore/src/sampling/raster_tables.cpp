#include "sampling/raster_tables.hpp"

#include <cmath>

namespace impinge::detail {

const GridTables& grid_tables(const EquiangularGrid& grid) {
  thread_local GridTables t;
  if (t.step == grid.step() && !t.sin_phi.empty()) return t;
  const int rows = grid.rows(), cols = grid.columns();
  const double h = grid.step();
  t.step = h;
  t.sin_phi.resize(rows), t.cos_phi.resize(rows), t.cot_phi.resize(rows), t.rsqrt_sin_phi.resize(rows);
  t.inv_sin_phi.resize(rows);
  for (int r = 0; r < rows; ++r) {
    t.sin_phi[r] = std::sin(r * h);
    t.cos_phi[r] = std::cos(r * h);
  }
  t.sin_phi[0] = 0;  // both pole rows are exactly the pole direction
  t.cos_phi[0] = 1;
  t.sin_phi[rows - 1] = 0;
  t.cos_phi[rows - 1] = -1;
  for (int r = 0; r < rows; ++r) {
    const bool pole = t.sin_phi[r] <= 0;  // the pole rows keep the whole box (row_spans)
    t.cot_phi[r] = pole ? 0.0 : t.cos_phi[r] / t.sin_phi[r];
    t.rsqrt_sin_phi[r] = pole ? std::numeric_limits<double>::infinity() : 1 / std::sqrt(t.sin_phi[r]);
    t.inv_sin_phi[r] = pole ? 1.0 : 1 / t.sin_phi[r];  // scales the edge tolerance like the edge functions
  }
  t.cos_theta.resize(cols), t.sin_theta.resize(cols);
  for (int c = 0; c < cols; ++c) {
    t.cos_theta[c] = std::cos(c * h);
    t.sin_theta[c] = std::sin(c * h);
  }
  return t;
}


}  // namespace impinge::detail
