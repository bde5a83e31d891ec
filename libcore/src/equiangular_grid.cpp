#include "impinge/equiangular_grid.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "impinge/error.hpp"
#include "impinge/spherical_frame.hpp"

namespace impinge {

double matched_equiangular_precision(double spacing_rad) {
  return 180.0 / std::max(1.0, std::round(180.0 / (spacing_rad * kRadToDeg)));
}

EquiangularGrid::EquiangularGrid(double precision_deg) : precision_deg_(precision_deg) {
  std::ostringstream os;
  os << "precision " << precision_deg << " deg: must be in (0, 90] and divide 180 evenly";
  require(std::isfinite(precision_deg) && precision_deg > 0 && precision_deg <= 90, os.str());
  const double n = 180.0 / precision_deg;
  require(std::abs(n - std::round(n)) <= 1e-9 * n, os.str());
  rows_ = static_cast<int>(std::lround(n)) + 1;
  cols_ = 2 * (rows_ - 1);
  step_ = kPi / (rows_ - 1);
  inv_step_ = 1.0 / step_;
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

void EquiangularGrid::node_angles(std::int64_t first, std::int64_t count, double* phi, double* theta) const {
  for (std::int64_t j = 0; j < count; ++j) {
    const std::int64_t i = first + j;
    phi[j] = static_cast<double>(i / cols_) * step_;
    theta[j] = static_cast<double>(i % cols_) * step_;
  }
}

}  // namespace impinge
