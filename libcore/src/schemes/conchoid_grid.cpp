#include "impinge/schemes/conchoid_grid.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "impinge/core/error.hpp"
#include "impinge/core/spherical_frame.hpp"

namespace impinge {

ConchoidGrid::ConchoidGrid(double precision_deg, double a_mm, double b_mm) : precision_deg_(precision_deg) {
  std::ostringstream os;
  os << "conchoid grid: precision " << precision_deg << " deg must be in (0, 90] and divide 90 evenly";
  require(std::isfinite(precision_deg) && precision_deg > 0 && precision_deg <= 90, os.str());
  const double half = 90.0 / precision_deg;
  require(std::abs(half - std::round(half)) <= 1e-9 * half, os.str());
  const int n_half = static_cast<int>(std::lround(half));  // row intervals in [0, 90] deg
  step_ = kPi / (2 * n_half);
  cols_ = 4 * n_half;
  const Conchoid c(a_mm, b_mm);
  row_phi_ = c.equal_length_angles(n_half + 1, kPi / 2);  // rows 0..n_half
  for (int r = 1; r <= n_half; ++r) row_phi_.push_back(kPi / 2 + r * step_);
  row_phi_.back() = kPi;
  max_spacing_ = step_;
  for (std::size_t r = 1; r < row_phi_.size(); ++r)
    max_spacing_ = std::max(max_spacing_, row_phi_[r] - row_phi_[r - 1]);
}

Eigen::Vector3d ConchoidGrid::node_direction(std::int64_t i) const {
  const int r = static_cast<int>(i / cols_);
  if (r == 0) return {0, 0, 1};
  if (r == rows() - 1) return {0, 0, -1};
  return direction(row_phi_[static_cast<std::size_t>(r)], static_cast<double>(i % cols_) * step_);
}

void ConchoidGrid::node_angles(std::int64_t first, std::int64_t count, double* phi, double* theta) const {
  for (std::int64_t j = 0; j < count; ++j) {
    const std::int64_t i = first + j;
    phi[j] = row_phi_[static_cast<std::size_t>(i / cols_)];
    theta[j] = static_cast<double>(i % cols_) * step_;
  }
}

std::int64_t ConchoidGrid::node(const Eigen::Vector3d& u) const {
  const Stencil s = interpolate(u);
  return s.nodes[static_cast<std::size_t>(std::max_element(s.weights.begin(), s.weights.end()) - s.weights.begin())];
}

void ConchoidGrid::stencil_at(double x, double y, double z, std::int64_t nodes[4], double w[4]) const {
  const double r = std::sqrt(x * x + y * y + z * z);
  const double phi = std::acos(std::clamp(z / r, -1.0, 1.0));
  double theta = std::atan2(y, x);
  if (theta < 0) theta += 2 * kPi;
  int r0 = static_cast<int>(std::upper_bound(row_phi_.begin(), row_phi_.end(), phi) - row_phi_.begin()) - 1;
  r0 = std::clamp(r0, 0, rows() - 2);
  const double p0 = row_phi_[static_cast<std::size_t>(r0)], p1 = row_phi_[static_cast<std::size_t>(r0) + 1];
  const double t = std::clamp((phi - p0) / (p1 - p0), 0.0, 1.0);
  const double fc = theta / step_;
  int c0 = static_cast<int>(fc);
  const double s = fc - c0;
  if (c0 >= cols_) c0 -= cols_;
  const int c1 = (c0 + 1 == cols_) ? 0 : c0 + 1;
  const std::int64_t b0 = std::int64_t(r0) * cols_, b1 = b0 + cols_;
  nodes[0] = b0 + c0, nodes[1] = b0 + c1, nodes[2] = b1 + c0, nodes[3] = b1 + c1;
  w[0] = (1 - t) * (1 - s), w[1] = (1 - t) * s, w[2] = t * (1 - s), w[3] = t * s;
}

}  // namespace impinge
