#include "impinge/schemes/equiangular_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <sstream>

#include "impinge/core/error.hpp"
#include "impinge/core/spherical_frame.hpp"
#include "core/simd_clones.hpp"
#include "schemes/cap_query.hpp"

namespace impinge {

const EquiangularGrid& equiangular_grid_of(const SamplingScheme& scheme) {
  const auto* g = dynamic_cast<const EquiangularGrid*>(&scheme);
  require(g != nullptr, "this operation needs an equiangular map; the map uses the '" + scheme.name() + "' scheme");
  return *g;
}

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
  require(num_nodes() < std::int64_t(1) << 31, os.str() + " (more than 2^31 nodes)");
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

std::optional<EquiangularGrid> conformable_equiangular_grid(const SamplingScheme& scheme) {
  try {
    EquiangularGrid grid(matched_equiangular_precision(scheme.max_node_spacing()));
    if (scheme.conformable(grid)) return grid;
  } catch (const Error&) {  // no equiangular grid at that spacing (too fine for 32-bit node indices)
  }
  return std::nullopt;
}

void EquiangularGrid::neighbour_stencils(std::int64_t first, std::int64_t count, Stencil* out) const {
  auto one = [](Stencil& s, std::int64_t node) {
    s.nodes = {node, node, node, node};
    s.weights = {1, 0, 0, 0};
  };
  for (std::int64_t k = 0; k < count; ++k) {
    const std::array<std::int64_t, 4> nb = neighbour_nodes(first + k);
    for (int j = 0; j < 4; ++j) one(out[4 * k + j], nb[static_cast<std::size_t>(j)]);
  }
}

void EquiangularGrid::nodes_in_cap(const Eigen::Vector3d& direction, double radius_rad,
                                   std::vector<std::int64_t>& out) const {
  const Eigen::Vector3d u = checked_cap_axis(name(), direction, radius_rad);
  const double r = std::min(radius_rad, kPi), cr = std::cos(r);
  const SphericalCoordinates s = to_spherical(u);
  out.clear();
  // Rows whose polar angle lies within r (and a rounding margin) of the cap centre's.
  constexpr double kMargin = 1e-9;
  const int r0 = std::max(0, static_cast<int>(std::floor((s.phi - r) * inv_step_ - kMargin)));
  const int r1 = std::min(rows_ - 1, static_cast<int>(std::ceil((s.phi + r) * inv_step_ + kMargin)));
  const double sp0 = std::sin(s.phi), cp0 = std::cos(s.phi);
  for (int row = r0; row <= r1; ++row) {
    const double phi = row * step_, sp = std::sin(phi), cp = std::cos(phi);
    const std::int64_t base = std::int64_t(row) * cols_;
    auto take = [&](int c) {
      if (node_direction(base + c).dot(u) >= cr) out.push_back(base + c);
    };
    // cos(d theta) at the cap's boundary on this row; whole rows at a pole or inside the cap.
    const double denom = sp0 * sp;
    const double cdt = denom > 1e-12 ? (cr - cp0 * cp) / denom : -2.0;
    if (cdt <= -1 + 1e-9) {
      for (int c = 0; c < cols_; ++c) take(c);
      continue;
    }
    if (cdt > 1 + 1e-9) continue;  // the row passes outside the cap
    const double half = std::acos(std::min(1.0, cdt)) + kMargin;
    const int c0 = static_cast<int>(std::floor((s.theta - half) * inv_step_)), c1 = static_cast<int>(std::ceil((s.theta + half) * inv_step_));
    if (c1 - c0 + 1 >= cols_) {
      for (int c = 0; c < cols_; ++c) take(c);
      continue;
    }
    const std::size_t before = out.size();
    for (int c = c0; c <= c1; ++c) take(((c % cols_) + cols_) % cols_);
    std::sort(out.begin() + static_cast<std::ptrdiff_t>(before), out.end());  // columns wrapped at the seam
  }
}

namespace {
/// Pass 1 of the look-up: cell (base node index, column step to the next column) and the
/// fractional position (t along phi, s along theta) of n directions. Branch-free so it
/// vectorises; cloned for AVX-512 and AVX2 and chosen at run time.
IMPINGE_SIMD_CLONES
void locate_cells(const double* __restrict x, const double* __restrict y, const double* __restrict z, int n,
                  double inv_step, int rows, int cols, std::int32_t* __restrict base, std::int32_t* __restrict dc,
                  double* __restrict t, double* __restrict s) {
  for (int j = 0; j < n; ++j) {
    double phi, theta;
    fast_spherical_angles(x[j], y[j], z[j], phi, theta);
    const double fr = phi * inv_step;
    const int r0 = std::min(static_cast<int>(fr), rows - 2);
    const double fc = theta * inv_step;
    int c0 = static_cast<int>(fc);
    s[j] = fc - c0;
    t[j] = fr - r0;
    c0 = c0 >= cols ? c0 - cols : c0;
    dc[j] = c0 + 1 == cols ? 1 - cols : 1;
    base[j] = r0 * cols + c0;
  }
}

}  // namespace

void EquiangularGrid::stencils_soa(const double* x, const double* y, const double* z, int n, std::int32_t* nodes,
                                   double* w) const {
  std::int32_t base[kStencilBlock], dc[kStencilBlock];
  double t[kStencilBlock], s[kStencilBlock];
  for (int b = 0; b < n; b += kStencilBlock) {  // callers pass at most one block; any n works
    const int m = std::min(kStencilBlock, n - b);
    locate_cells(x + b, y + b, z + b, m, inv_step_, rows_, cols_, base, dc, t, s);
    for (int j = 0; j < m; ++j) {
      const int q = b + j;
      nodes[q] = base[j], nodes[n + q] = base[j] + dc[j];
      nodes[2 * n + q] = base[j] + cols_, nodes[3 * n + q] = base[j] + cols_ + dc[j];
      w[q] = (1 - t[j]) * (1 - s[j]), w[n + q] = (1 - t[j]) * s[j];
      w[2 * n + q] = t[j] * (1 - s[j]), w[3 * n + q] = t[j] * s[j];
    }
  }
}

}  // namespace impinge
