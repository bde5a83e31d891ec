#include "impinge/fibonacci_scheme.hpp"

#include <algorithm>
#include <limits>
#include <sstream>

#include "impinge/error.hpp"
#include "impinge/fast_angles.hpp"
#include "simd_clones.hpp"

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
/// The zone of cosine-of-polar-angle z: k = max(2, floor(log_{Phi^2}(n pi sqrt(5) (1 - z^2)))).
int zone_at(double z, double n) {
  return static_cast<int>(std::max(2.0, std::floor(std::log(n * kPi * std::sqrt(5.0) * std::max(1e-300, 1 - z * z)) /
                                                   std::log(kPhi * kPhi))));
}
Basis basis_of(int k, double n) {
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
Basis basis_at(double z, double n) { return basis_of(zone_at(z, n), n); }

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
  // Zones k = 2 .. k_max, k_max that of the equator (1 - z^2 = 1), the largest there is.
  const int k_max = zone_at(0, double(n_));
  for (int k = 2; k <= k_max; ++k) {
    const Basis b = basis_of(k, double(n_));
    const double det = b.a0 * b.z1 - b.a1 * b.z0;
    Zones& t = zones_;
    t.f0.push_back(b.f0), t.f1.push_back(b.f1);
    t.m00.push_back(b.z1 / det), t.m01.push_back(-b.a1 / det), t.m10.push_back(-b.z0 / det), t.m11.push_back(b.a0 / det);
    t.a0a1.push_back(b.a0 * b.a1), t.z0z1.push_back(b.z0 * b.z1);
    t.start.push_back(std::pow(kPhi, 2 * k));
  }
  require(zones_.start.size() <= std::size_t(kMaxZones), os.str());
  zones_.start.resize(kMaxZones, std::numeric_limits<double>::infinity());
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

namespace {
/// The zone index (k - 2) of v = n pi sqrt(5) (1 - z^2): the last of the kMaxZones starts v
/// reaches (0 when none), by a branch-free binary search, so that the block look-up vectorises.
inline int zone_index(double v, const double* start) {
  int zi = v >= start[16] ? 16 : 0;
  zi += v >= start[zi + 8] ? 8 : 0;
  zi += v >= start[zi + 4] ? 4 : 0;
  zi += v >= start[zi + 2] ? 2 : 0;
  return zi + (v >= start[zi + 1] ? 1 : 0);
}
static_assert(FibonacciScheme::kMaxZones == 32, "zone_index searches 32 starts");

/// The block look-up (issue 12), branch-free so that it vectorises; cloned for AVX-512 and AVX2 and
/// chosen at run time. For each direction: its zone (the last zone start Phi^(2k) that
/// n pi sqrt(5) (1 - z^2) reaches: the table holds kMaxZones starts, +inf past the last zone), its
/// lattice coordinates in that zone's basis, the cell and the triangle of the cell's shorter
/// diagonal, clamped corners and barycentric weights.
IMPINGE_SIMD_CLONES
void fibonacci_stencils_kernel(const double* __restrict x, const double* __restrict y, const double* __restrict z,
                               int n, const double* __restrict f0t, const double* __restrict f1t,
                               const double* __restrict m00, const double* __restrict m01,
                               const double* __restrict m10, const double* __restrict m11,
                               const double* __restrict a0a1, const double* __restrict z0z1,
                               const double* __restrict start, double n_nodes, std::int32_t* __restrict i0,
                               std::int32_t* __restrict i1, std::int32_t* __restrict i2, std::int32_t* __restrict i3,
                               double* __restrict w0, double* __restrict w1, double* __restrict w2,
                               double* __restrict w3) {
  const double nc = n_nodes * kPi * 2.2360679774997896964, z_first = 1 - 1 / n_nodes, last = n_nodes - 1;
  for (int j = 0; j < n; ++j) {
    const double len = std::sqrt(x[j] * x[j] + y[j] * y[j] + z[j] * z[j]);
    const double cz = z[j] / len, a = fast_azimuth(y[j], x[j]);  // [0, 2 pi): the lattice repeats every 2 pi
    const double s2 = std::max(0.0, (1 - cz) * (1 + cz)), v = nc * s2;
    const int zi = zone_index(v, start);
    const double rz = cz - z_first;
    const double f0 = m00[zi] * a + m01[zi] * rz, f1 = m10[zi] * a + m11[zi] * rz;
    const double c0 = std::floor(f0), c1 = std::floor(f1);
    const double s = f0 - c0, t = f1 - c1;
    const double F0 = f0t[zi], F1 = f1t[zi], base = F0 * c0 + F1 * c1;
    const double c00 = std::min(std::max(base, 0.0), last), c10 = std::min(std::max(base + F0, 0.0), last);
    const double c01 = std::min(std::max(base + F1, 0.0), last), c11 = std::min(std::max(base + F0 + F1, 0.0), last);
    // The shorter diagonal on the sphere: 0 -- 3 when s2^2 a0 a1 + z0 z1 <= 0 (metric2 of both).
    const bool main = s2 * s2 * a0a1[zi] + z0z1[zi] <= 0;
    const bool upper = main ? s < t : s + t > 1;
    // The corner outside the triangle (weight 0) repeats one inside it, so that the look-up reads
    // three places, not four, and no mark or missing surface of that corner counts.
    // (Selected as doubles by nested conditionals, the form the loop vectorises in.)
    i0[j] = static_cast<std::int32_t>(main ? c00 : (upper ? c11 : c00));
    i1[j] = static_cast<std::int32_t>(main ? (upper ? c00 : c10) : c10);
    i2[j] = static_cast<std::int32_t>(main ? (upper ? c01 : c00) : c01);
    i3[j] = static_cast<std::int32_t>(main ? c11 : (upper ? c11 : c00));
    // Corners 0 = (0,0), 1 = (1,0), 2 = (0,1), 3 = (1,1).
    w0[j] = main ? (upper ? 1 - t : 1 - s) : (upper ? 0 : 1 - s - t);
    w1[j] = main ? (upper ? 0 : s - t) : (upper ? 1 - t : s);
    w2[j] = main ? (upper ? t - s : 0) : (upper ? 1 - s : t);
    w3[j] = main ? (upper ? s : t) : (upper ? s + t - 1 : 0);
  }
}
void fibonacci_stencils(const double* x, const double* y, const double* z, int n, const FibonacciScheme::Zones& t,
                        double n_nodes, std::int32_t* nodes, double* w) {
  fibonacci_stencils_kernel(x, y, z, n, t.f0.data(), t.f1.data(), t.m00.data(), t.m01.data(), t.m10.data(),
                            t.m11.data(), t.a0a1.data(), t.z0z1.data(), t.start.data(), n_nodes, nodes, nodes + n,
                            nodes + 2 * n, nodes + 3 * n, w, w + n, w + 2 * n, w + 3 * n);
}
}  // namespace

void FibonacciScheme::stencils_soa(const double* x, const double* y, const double* z, int n, std::int32_t* nodes,
                                   double* w) const {
  fibonacci_stencils(x, y, z, n, zones_, double(n_), nodes, w);
}

void FibonacciScheme::cell(double x, double y, double z, std::int64_t i[4]) const {
  const double len = std::sqrt(x * x + y * y + z * z);
  const double cz = z / len, a = fast_azimuth(y, x);
  const auto zi = static_cast<std::size_t>(
      zone_index(double(n_) * kPi * 2.2360679774997896964 * std::max(0.0, (1 - cz) * (1 + cz)), zones_.start.data()));
  const double rz = cz - (1 - inv_n_);
  const double f0 = zones_.m00[zi] * a + zones_.m01[zi] * rz, f1 = zones_.m10[zi] * a + zones_.m11[zi] * rz;
  const double F0 = zones_.f0[zi], F1 = zones_.f1[zi], base = F0 * std::floor(f0) + F1 * std::floor(f1);
  i[0] = std::llround(base), i[1] = std::llround(base + F0), i[2] = std::llround(base + F1),
  i[3] = std::llround(base + F0 + F1);
}

void FibonacciScheme::stencil_at(double x, double y, double z, std::int64_t nodes[4], double w[4]) const {
  std::int32_t nd[4];
  fibonacci_stencils(&x, &y, &z, 1, zones_, double(n_), nd, w);
  for (int k = 0; k < 4; ++k) nodes[k] = nd[k];
}

std::int64_t FibonacciScheme::node(const Eigen::Vector3d& u) const {
  std::int64_t i[4];
  cell(u.x(), u.y(), u.z(), i);
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
