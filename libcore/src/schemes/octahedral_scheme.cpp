#include "impinge/schemes/octahedral_scheme.hpp"

#include <algorithm>
#include <sstream>
#include <vector>

#include "impinge/core/error.hpp"

namespace impinge {

Eigen::Vector3d octahedral_to_direction(double u, double v) {
  constexpr double kPi = 3.14159265358979323846;
  const double au = std::abs(u), av = std::abs(v);
  const double d = 1 - (au + av);
  const double r = 1 - std::abs(d);
  const double phi = (r == 0 ? 1.0 : (av - au) / r + 1) * (kPi / 4);
  const double z = std::copysign(1 - r * r, d);
  const double s = r * std::sqrt(std::max(0.0, 2 - r * r));
  const Eigen::Vector3d p(std::copysign(std::cos(phi) * s, u), std::copysign(std::sin(phi) * s, v), z);
  return p.normalized();
}

namespace {
double arc(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return 2 * std::asin(std::min(1.0, (a - b).norm() / 2));
}
}  // namespace

OctahedralScheme::OctahedralScheme(double cells_per_side) {
  std::ostringstream os;
  os << "octahedral scheme: cells per side " << cells_per_side
     << " must be a whole number in [2, 46340] (a map holds at most 2^31 - 1 nodes)";
  require(std::isfinite(cells_per_side) && cells_per_side >= 2 && cells_per_side <= 46340 &&
              cells_per_side == std::round(cells_per_side),
          os.str());
  n_ = static_cast<int>(cells_per_side);
  half_n_ = 0.5 * n_;
  // Neighbour pairs (right and top neighbour, folded at the edges) of the quadrant u, v >= 0 and
  // the row and column next to it: by the map's symmetry every pair of the square is the mirror
  // image of one of these.
  const int lo = (n_ - 1) / 2;
  max_spacing_ = 0;
  std::vector<Eigen::Vector3d> below(static_cast<std::size_t>(n_)), here(static_cast<std::size_t>(n_));
  for (int r = lo; r < n_; ++r) {
    for (int c = lo; c < n_; ++c) here[std::size_t(c)] = node_direction(std::int64_t(r) * n_ + c);
    for (int c = lo; c < n_; ++c) {
      const Eigen::Vector3d& p = here[std::size_t(c)];
      max_spacing_ = std::max(max_spacing_, arc(p, c + 1 < n_ ? here[std::size_t(c) + 1] : node_direction(folded(c + 1, r))));
      if (r > lo) max_spacing_ = std::max(max_spacing_, arc(p, below[std::size_t(c)]));
      if (r + 1 == n_) max_spacing_ = std::max(max_spacing_, arc(p, node_direction(folded(c, r + 1))));
    }
    std::swap(below, here);
  }
}

Eigen::Vector3d OctahedralScheme::node_direction(std::int64_t i) const {
  const std::int64_t r = i / n_, c = i % n_;
  return octahedral_to_direction(-1 + double(2 * c + 1) / n_, -1 + double(2 * r + 1) / n_);
}

void OctahedralScheme::node_angles(std::int64_t first, std::int64_t count, double* phi, double* theta) const {
  constexpr double kPi = 3.14159265358979323846;
  for (std::int64_t j = 0; j < count; ++j) {
    const std::int64_t i = first + j, r = i / n_, c = i % n_;
    const double u = -1 + double(2 * c + 1) / n_, v = -1 + double(2 * r + 1) / n_;
    const double au = std::abs(u), av = std::abs(v), d = 1 - (au + av), rr = 1 - std::abs(d);
    // Polar angle from (rho, z) = (r sqrt(2 - r^2), sign(d) (1 - r^2)) on the unit sphere; azimuth
    // from the octant angle and the signs of u and v.
    const double rho = rr * std::sqrt(std::max(0.0, 2 - rr * rr)), z = std::copysign(1 - rr * rr, d);
    phi[j] = std::atan2(rho, z);
    const double a = (rr == 0 ? 1.0 : (av - au) / rr + 1) * (kPi / 4);  // in [0, pi/2]
    double t = u < 0 ? kPi - a : a;
    t = v < 0 ? 2 * kPi - t : t;
    theta[j] = t >= 2 * kPi ? t - 2 * kPi : t;
  }
}

std::int64_t OctahedralScheme::node(const Eigen::Vector3d& d) const {
  double u, v;
  octahedral_from_direction(d.x(), d.y(), d.z(), u, v);
  const int c = std::clamp(static_cast<int>(std::floor((u + 1) * half_n_)), 0, n_ - 1);
  const int r = std::clamp(static_cast<int>(std::floor((v + 1) * half_n_)), 0, n_ - 1);
  return std::int64_t(r) * n_ + c;
}

}  // namespace impinge
