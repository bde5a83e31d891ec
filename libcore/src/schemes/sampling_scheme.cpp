#include "impinge/schemes/sampling_scheme.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "impinge/core/error.hpp"
#include "impinge/core/spherical_frame.hpp"
#include "schemes/cap_query.hpp"

namespace impinge {

void SamplingScheme::node_angles(std::int64_t first, std::int64_t count, double* phi, double* theta) const {
  for (std::int64_t j = 0; j < count; ++j) {
    const SphericalCoordinates s = to_spherical(node_direction(first + j));
    phi[j] = s.phi;
    theta[j] = s.theta;
  }
}

void SamplingScheme::neighbour_stencils(std::int64_t first, std::int64_t count, Stencil* out) const {
  const double h = max_node_spacing(), ch = std::cos(h), sh = std::sin(h);
  constexpr int kNodes = kStencilBlock / 4;  // four points per node: one stencils_soa call per block
  double phi[kNodes], theta[kNodes], x[kStencilBlock], y[kStencilBlock], z[kStencilBlock], w[4 * kStencilBlock];
  std::int32_t nd[4 * kStencilBlock];
  for (std::int64_t b = 0; b < count; b += kNodes) {
    const int m = static_cast<int>(std::min<std::int64_t>(kNodes, count - b));
    node_angles(first + b, m, phi, theta);
    for (int j = 0; j < m; ++j) {
      const double sp = std::sin(phi[j]), cp = std::cos(phi[j]), st = std::sin(theta[j]), ct = std::cos(theta[j]);
      const Eigen::Vector3d u(sp * ct, sp * st, cp), ep(cp * ct, cp * st, -sp), et(-st, ct, 0);
      const Eigen::Vector3d q[4] = {u * ch - ep * sh, u * ch + ep * sh, u * ch - et * sh, u * ch + et * sh};
      for (int k = 0; k < 4; ++k) x[4 * j + k] = q[k].x(), y[4 * j + k] = q[k].y(), z[4 * j + k] = q[k].z();
    }
    const int n = 4 * m;
    stencils_soa(x, y, z, n, nd, w);
    for (int p = 0; p < n; ++p) {
      Stencil& s = out[4 * b + p];
      for (int k = 0; k < 4; ++k) s.nodes[k] = nd[k * n + p], s.weights[k] = w[k * n + p];
    }
  }
}

void SamplingScheme::neighbours(std::int64_t i, std::vector<std::int64_t>& out) const {
  require(i >= 0 && i < num_nodes(), [&] {
    return "sampling scheme '" + name() + "': node " + std::to_string(i) + " outside [0, " +
           std::to_string(num_nodes()) + ")";
  });
  Stencil s[4];
  neighbour_stencils(i, 1, s);
  out.clear();
  for (const Stencil& st : s)
    for (int k = 0; k < 4; ++k)
      if (st.weights[k] > 0 && st.nodes[k] != i) out.push_back(st.nodes[k]);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
}

void SamplingScheme::nodes_in_cap(const Eigen::Vector3d& direction, double radius_rad,
                                  std::vector<std::int64_t>& out) const {
  const Eigen::Vector3d u = checked_cap_axis(name(), direction, radius_rad);
  const double c = std::cos(std::min(radius_rad, kPi));
  out.clear();
  const std::int64_t n = num_nodes();
  for (std::int64_t i = 0; i < n; ++i)
    if (node_direction(i).dot(u) >= c) out.push_back(i);
}

bool SamplingScheme::conformable(const SamplingScheme& other) const {
  // Resolutions equal to rounding (a precision of 180 / n degrees computed two ways).
  return &other == this || (name() == other.name() && num_nodes() == other.num_nodes() &&
                            std::abs(resolution() - other.resolution()) <= 1e-12 * std::abs(resolution()));
}

}  // namespace impinge
