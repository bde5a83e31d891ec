#include "impinge/fibonacci_scheme.hpp"

#include <algorithm>
#include <sstream>

#include "impinge/error.hpp"

namespace impinge {

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kPhi = 1.61803398874989484820;         // golden ratio
constexpr double kPhiMinusOne = 0.61803398874989484820;  // frac(Phi) = 1 / Phi

/// frac(i / Phi) for i >= 0, with the rounding of the product compensated (i up to 2^31).
double frac_golden(std::int64_t i) {
  const double a = double(i);
  const double hi = a * kPhiMinusOne, lo = std::fma(a, kPhiMinusOne, -hi);
  double f = (hi - std::floor(hi)) + lo;
  f -= std::floor(f);
  return f;
}

/// The lattice basis at cosine-of-polar-angle z (Keinert et al. 2015, Eq. 7 and Algorithm 1):
/// Fibonacci numbers F0 = F_k, F1 = F_{k+1}, and the azimuth and z steps of each.
struct Basis {
  double f0, f1, a0, a1, z0, z1;
};
Basis basis_at(double z, double n) {
  const double k = std::max(2.0, std::floor(std::log(n * kPi * std::sqrt(5.0) * std::max(1e-300, 1 - z * z)) /
                                            std::log(kPhi * kPhi)));
  const double fk = std::pow(kPhi, k) / std::sqrt(5.0);
  Basis b;
  b.f0 = std::round(fk), b.f1 = std::round(fk * kPhi);
  // 2 pi (frac((F + 1) Phi) - (Phi - 1)): the signed azimuth step of F lattice steps.
  auto step = [](double f) {
    const double p = (f + 1) * kPhiMinusOne;
    return 2 * kPi * ((p - std::floor(p)) - kPhiMinusOne);
  };
  b.a0 = step(b.f0), b.a1 = step(b.f1);
  b.z0 = -2 * b.f0 / n, b.z1 = -2 * b.f1 / n;
  return b;
}

/// Squared length on the sphere (first order) of a step (da, dz) in the (azimuth, z) plane at z.
double metric2(double da, double dz, double z) {
  const double s2 = std::max(1e-300, 1 - z * z);
  return s2 * da * da + dz * dz / s2;
}
}  // namespace

FibonacciScheme::FibonacciScheme(double nodes) {
  std::ostringstream os;
  os << "fibonacci scheme: node count " << nodes << " must be a whole number in [16, 2^31 - 1]";
  require(std::isfinite(nodes) && nodes >= 16 && nodes <= 2147483647.0 && nodes == std::round(nodes), os.str());
  n_ = static_cast<std::int64_t>(nodes);
  inv_n_ = 1.0 / double(n_);
  // Longest triangle edge: both basis steps and the shorter diagonal, at 4,096 latitudes between the
  // outermost nodes.
  max_spacing_ = 0;
  const double zmax = 1 - inv_n_;
  for (int j = 0; j <= 4096; ++j) {
    const double z = -zmax + 2 * zmax * j / 4096.0;
    const Basis b = basis_at(z, double(n_));
    const double e0 = metric2(b.a0, b.z0, z), e1 = metric2(b.a1, b.z1, z);
    const double d = std::min(metric2(b.a0 + b.a1, b.z0 + b.z1, z), metric2(b.a0 - b.a1, b.z0 - b.z1, z));
    max_spacing_ = std::max(max_spacing_, std::sqrt(std::max({e0, e1, d})));
  }
}

double FibonacciScheme::azimuth(std::int64_t i) const { return 2 * kPi * frac_golden(i); }

Eigen::Vector3d FibonacciScheme::node_direction(std::int64_t i) const {
  const double z = 1 - double(2 * i + 1) * inv_n_;
  const double s = std::sqrt(std::max(0.0, (1 - z) * (1 + z))), a = azimuth(i);
  return Eigen::Vector3d(s * std::cos(a), s * std::sin(a), z);
}

void FibonacciScheme::node_angles(std::int64_t first, std::int64_t count, double* phi, double* theta) const {
  for (std::int64_t j = 0; j < count; ++j) {
    const std::int64_t i = first + j;
    const double z = 1 - double(2 * i + 1) * inv_n_;
    phi[j] = std::atan2(std::sqrt(std::max(0.0, (1 - z) * (1 + z))), z);
    theta[j] = azimuth(i);
  }
}

void FibonacciScheme::cell(double x, double y, double z, std::int64_t i[4], double& s, double& t,
                           bool& main_diagonal) const {
  const double len = std::sqrt(x * x + y * y + z * z);
  const double cz = z / len, a = std::atan2(y, x);
  const Basis b = basis_at(cz, double(n_));
  // Lattice coordinates f of (a, cz - z_0) in the basis ((a0, z0), (a1, z1)), z_0 = 1 - 1/n.
  const double det = b.a0 * b.z1 - b.a1 * b.z0;
  const double ra = a, rz = cz - (1 - inv_n_);
  const double f0 = (b.z1 * ra - b.a1 * rz) / det, f1 = (-b.z0 * ra + b.a0 * rz) / det;
  const double c0 = std::floor(f0), c1 = std::floor(f1);
  s = f0 - c0, t = f1 - c1;
  const double base = b.f0 * c0 + b.f1 * c1;
  i[0] = std::llround(base), i[1] = std::llround(base + b.f0), i[2] = std::llround(base + b.f1),
  i[3] = std::llround(base + b.f0 + b.f1);
  main_diagonal = metric2(b.a0 + b.a1, b.z0 + b.z1, cz) <= metric2(b.a0 - b.a1, b.z0 - b.z1, cz);
}

void FibonacciScheme::stencil_at(double x, double y, double z, std::int64_t nodes[4], double w[4]) const {
  std::int64_t i[4];
  double s, t;
  bool main;
  cell(x, y, z, i, s, t, main);
  for (int k = 0; k < 4; ++k) nodes[k] = std::clamp<std::int64_t>(i[k], 0, n_ - 1);
  // Barycentric weights of (s, t) in the triangle of the split cell that holds it; corners
  // 0 = (0,0), 1 = (1,0), 2 = (0,1), 3 = (1,1).
  if (main) {  // split along 0 -- 3
    if (s >= t) w[0] = 1 - s, w[1] = s - t, w[2] = 0, w[3] = t;
    else w[0] = 1 - t, w[1] = 0, w[2] = t - s, w[3] = s;
  } else {  // split along 1 -- 2
    if (s + t <= 1) w[0] = 1 - s - t, w[1] = s, w[2] = t, w[3] = 0;
    else w[0] = 0, w[1] = 1 - t, w[2] = 1 - s, w[3] = s + t - 1;
  }
}

std::int64_t FibonacciScheme::node(const Eigen::Vector3d& u) const {
  std::int64_t i[4];
  double s, t;
  bool main;
  cell(u.x(), u.y(), u.z(), i, s, t, main);
  const Eigen::Vector3d d = u.normalized();
  std::int64_t best = std::clamp<std::int64_t>(i[0], 0, n_ - 1);
  double best_d = (node_direction(best) - d).squaredNorm();
  for (int k = 1; k < 4; ++k) {
    const std::int64_t j = std::clamp<std::int64_t>(i[k], 0, n_ - 1);
    const double e = (node_direction(j) - d).squaredNorm();
    if (e < best_d) best = j, best_d = e;
  }
  return best;
}

}  // namespace impinge
