#include "impinge/equiangular_grid.hpp"

#include <cmath>
#include <sstream>

#include "impinge/error.hpp"
#include "impinge/spherical_frame.hpp"

namespace impinge {

EquiangularGrid::EquiangularGrid(double precision_deg) : precision_deg_(precision_deg) {
  std::ostringstream os;
  os << "precision " << precision_deg << " deg: must be in (0, 90] and divide 180 evenly";
  require(std::isfinite(precision_deg) && precision_deg > 0 && precision_deg <= 90, os.str());
  const double n = 180.0 / precision_deg;
  require(std::abs(n - std::round(n)) <= 1e-9 * n, os.str());
  rows_ = static_cast<int>(std::lround(n)) + 1;
  cols_ = 2 * (rows_ - 1);
  step_ = kPi / (rows_ - 1);
}

Eigen::Vector3d EquiangularGrid::node_direction(std::int64_t i) const {
  const int r = static_cast<int>(i / cols_);
  const int c = static_cast<int>(i % cols_);
  if (r == 0) return {0, 0, 1};
  if (r == rows_ - 1) return {0, 0, -1};
  return direction(r * step_, c * step_);
}

std::int64_t EquiangularGrid::node(const Eigen::Vector3d& u) const {
  const SphericalCoordinates s = to_spherical(u);
  const int r = static_cast<int>(std::lround(s.phi / step_));
  if (r <= 0) return 0;
  if (r >= rows_ - 1) return std::int64_t(rows_ - 1) * cols_;
  int c = static_cast<int>(std::lround(s.theta / step_));
  if (c >= cols_) c -= cols_;
  return std::int64_t(r) * cols_ + c;
}

Stencil EquiangularGrid::interpolate(const Eigen::Vector3d& u) const {
  const SphericalCoordinates s = to_spherical(u);
  const double fr = s.phi / step_;
  int r0 = static_cast<int>(std::floor(fr));
  if (r0 > rows_ - 2) r0 = rows_ - 2;
  if (r0 < 0) r0 = 0;
  const double t = fr - r0;
  const double fc = s.theta / step_;
  int c0 = static_cast<int>(std::floor(fc));
  const double w = fc - c0;
  if (c0 >= cols_) c0 -= cols_;
  const int c1 = (c0 + 1 == cols_) ? 0 : c0 + 1;
  Stencil st;
  const std::int64_t base0 = std::int64_t(r0) * cols_, base1 = base0 + cols_;
  st.nodes = {base0 + c0, base0 + c1, base1 + c0, base1 + c1};
  st.weights = {(1 - t) * (1 - w), (1 - t) * w, t * (1 - w), t * w};
  return st;
}

}  // namespace impinge
