#include "impinge/helix_scheme.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "impinge/error.hpp"
#include "impinge/spherical_frame.hpp"

namespace impinge {

namespace {
double checked_turns(double turns) {
  std::ostringstream os;
  os << "helix: turns k = " << turns << " must be an integer >= 2";
  require(std::isfinite(turns) && turns >= 2 && turns == std::round(turns) && turns < 3e6, os.str());
  return turns;
}
}  // namespace

HelixScheme::HelixScheme(double turns, TraveledDistance locate)
    : k_(checked_turns(turns)),
      locate_(locate),
      w_(static_cast<std::int64_t>(k_) * static_cast<std::int64_t>(k_)),
      arc_(k_) {
  dx_ = arc_.total() / static_cast<double>(w_ - 1);
  inv_dx_ = 1 / dx_;
  inv_2k_ = 1 / (2 * k_);
  kPiOverK_ = kPi / k_;
  half_w1_ = 0.5 * static_cast<double>(w_ - 1);
}

Eigen::Vector3d HelixScheme::node_direction(std::int64_t i) const {
  double phi, theta;
  node_angles(i, 1, &phi, &theta);
  return direction(phi, theta);
}

void HelixScheme::node_angles(std::int64_t first, std::int64_t count, double* phi, double* theta) const {
  // s = 2k (1 - cos phi) + c(phi) with c slowly varying: phi = 2 asin(sqrt((s - c) / 4k)),
  // c taken at the previous node's phi, then one Newton step on the exact-to-table s(phi).
  double prev = -1;
  for (std::int64_t j = 0; j < count; ++j) {
    const std::int64_t i = first + j;
    double p;
    if (i <= 0) {
      p = 0;
    } else if (i >= w_ - 1) {
      p = kPi;
    } else {
      const double s = static_cast<double>(i) * dx_;
      if (prev < 0) prev = arc_.inverse(s, std::acos(std::clamp(1 - 2 * s / arc_.total(), -1.0, 1.0)));
      const double c = arc_(prev) - 2 * k_ * (1 - std::cos(prev));
      const double y = std::clamp((s - c) / (4 * k_), 0.0, 1.0);
      p = 2 * std::asin(std::sqrt(y));
      for (int it = 0; it < 20; ++it) {  // Newton; one step suffices for large k
        const double step = (arc_(p) - s) / arc_.derivative(p);
        p = std::clamp(p - step, 0.0, kPi);
        if (std::abs(step) < 1e-13) break;
      }
    }
    prev = p;
    phi[j] = p;
    double t = 2 * k_ * p;
    t -= kTwoPi * std::floor(t * kInvTwoPi);
    theta[j] = t;
  }
}

std::int64_t HelixScheme::node(const Eigen::Vector3d& u) const {
  const Stencil s = interpolate(u);
  return s.nodes[static_cast<std::size_t>(std::max_element(s.weights.begin(), s.weights.end()) - s.weights.begin())];
}

}  // namespace impinge
