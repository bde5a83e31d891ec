#include "impinge/schemes/helix_scheme.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "impinge/core/error.hpp"
#include "impinge/core/spherical_frame.hpp"
#include "core/simd_clones.hpp"

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

double HelixScheme::phi_of_node(std::int64_t i, double guess) const {
  if (i <= 0) return 0;
  if (i >= w_ - 1) return kPi;
  const double s = static_cast<double>(i) * dx_;
  if (!(guess > 0 && guess < kPi)) guess = std::acos(std::clamp(1 - 2 * s / arc_.total(), -1.0, 1.0));
  return arc_.inverse(s, guess);
}

void HelixScheme::node_angles(std::int64_t first, std::int64_t count, double* phi, double* theta) const {
  // Incremental inversion of the arc length along consecutive nodes: predict
  // phi_i = phi_{i-1} + dx / s'(phi_{i-1}) (error ~ dx^2 |s''| / s'^3, ~1e-14 rad for large k),
  // then Newton on the tabulated s (one step for large k, with the previous node's slope: one
  // division per node; no trigonometry). The chain is
  // serial, so kLanes independent chains over consecutive sub-ranges advance in lockstep for
  // instruction-level parallelism. Within 20/k of a pole: Newton on the exact integral.
  constexpr int kLanes = 8;
  const std::int64_t per_lane = (count + kLanes - 1) / kLanes;
  double p[kLanes], ds[kLanes];
  std::int64_t next[kLanes], stop[kLanes];
  for (int l = 0; l < kLanes; ++l) {
    next[l] = first + std::min<std::int64_t>(count, l * per_lane);
    stop[l] = first + std::min<std::int64_t>(count, (l + 1) * per_lane);
    p[l] = -1;
    ds[l] = 0;
  }
  auto emit = [&](std::int64_t i, double value) {
    phi[i - first] = value;
    double t = 2 * k_ * value;  // >= 0: truncation is the floor (no libm call)
    t -= kTwoPi * static_cast<double>(static_cast<std::int64_t>(t * kInvTwoPi));
    theta[i - first] = t;
  };
  for (std::int64_t step = 0; step < per_lane; ++step) {
    for (int l = 0; l < kLanes; ++l) {
      const std::int64_t i = next[l];
      if (i >= stop[l]) continue;
      double q;
      if (p[l] <= 0 || i >= w_ - 1 || arc_.in_cap(p[l])) {  // lane start, poles, polar caps
        q = phi_of_node(i, p[l] > 0 && ds[l] > 0 ? p[l] + dx_ * ds[l] : -1);
        ds[l] = 1 / arc_.derivative(q);
      } else {
        // ds[] holds 1 / s' at the previous node: the predictor and a first Newton step with that
        // slope (s' changes by ~1e-6 relative between nodes, so the step's error is ~1e-6 of an
        // already ~1e-14 rad predictor error); full Newton only when the step is not tiny.
        q = p[l] + dx_ * ds[l];
        double v, dv;
        arc_.value_and_derivative(q, v, dv);
        double step_size = (v - static_cast<double>(i) * dx_) * ds[l];
        q -= step_size;
        for (int it = 0; std::abs(step_size) > 1e-12 && it < 8; ++it) {
          arc_.value_and_derivative(q, v, dv);
          step_size = (v - static_cast<double>(i) * dx_) / dv;
          q -= step_size;
        }
        ds[l] = 1 / dv;
        if (arc_.in_cap(q)) q = phi_of_node(i, q);
      }
      p[l] = q;
      emit(i, q);
      next[l] = i + 1;
    }
  }
}

std::int64_t HelixScheme::node(const Eigen::Vector3d& u) const {
  const Stencil s = interpolate(u);
  return s.nodes[static_cast<std::size_t>(std::max_element(s.weights.begin(), s.weights.end()) - s.weights.begin())];
}

namespace {
/// Pass 1 of the helix look-up: angles of each point and the polar angles of the two crossings
/// of its meridian that bracket it (clamped to the poles in the first and last turn), with the
/// weight u between them. Branch-free; vectorised clones.
IMPINGE_SIMD_CLONES
void helix_crossings(const double* __restrict x, const double* __restrict y, const double* __restrict z, int n,
                     double k, double inv_2k, double pi_over_k, double* __restrict phi_a, double* __restrict phi_b,
                     double* __restrict u) {
  for (int j = 0; j < n; ++j) helix_crossings_of(x[j], y[j], z[j], k, inv_2k, pi_over_k, phi_a[j], phi_b[j], u[j]);
}
/// Pass 3: node and weight along the curve at each crossing (i, t: nodes i and i + 1 with
/// weights 1 - t and t). The pole crossings give node 0 (weight 1) and node w - 1 (weight 1).
IMPINGE_SIMD_CLONES
void helix_along(const double* __restrict s, int n, double inv_dx, double last, std::int32_t* __restrict i_out,
                 double* __restrict t_out) {
  for (int j = 0; j < n; ++j) {
    const double f = s[j] * inv_dx;
    double i = static_cast<double>(static_cast<std::int64_t>(f));
    i = i > last - 1 ? last - 1 : (i < 0 ? 0.0 : i);
    double t = f - i;
    t = t < 0 ? 0.0 : (t > 1 ? 1.0 : t);
    i_out[j] = static_cast<std::int32_t>(i), t_out[j] = t;
  }
}
}  // namespace

void HelixScheme::stencils_soa(const double* x, const double* y, const double* z, int n, std::int32_t* nodes,
                               double* w) const {
  if (locate_ != TraveledDistance::exact) return SchemeImpl<HelixScheme>::stencils_soa(x, y, z, n, nodes, w);
  double pa[kStencilBlock], pb[kStencilBlock], u[kStencilBlock], sa[kStencilBlock], sb[kStencilBlock],
      ta[kStencilBlock], tb[kStencilBlock];
  std::int32_t ia[kStencilBlock], ib[kStencilBlock];
  const double last = static_cast<double>(w_ - 1);
  for (int b = 0; b < n; b += kStencilBlock) {  // callers pass at most one block; any n works
    const int m = std::min(kStencilBlock, n - b);
    helix_crossings(x + b, y + b, z + b, m, k_, inv_2k_, kPiOverK_, pa, pb, u);
    arc_.evaluate_many(pa, m, sa);
    arc_.evaluate_many(pb, m, sb);
    helix_along(sa, m, inv_dx_, last, ia, ta);
    helix_along(sb, m, inv_dx_, last, ib, tb);
    for (int j = 0; j < m; ++j) {
      const int q = b + j;
      nodes[q] = ia[j], nodes[n + q] = ia[j] + 1, nodes[2 * n + q] = ib[j], nodes[3 * n + q] = ib[j] + 1;
      w[q] = (1 - u[j]) * (1 - ta[j]), w[n + q] = (1 - u[j]) * ta[j];
      w[2 * n + q] = u[j] * (1 - tb[j]), w[3 * n + q] = u[j] * tb[j];
    }
  }
}

}  // namespace impinge
