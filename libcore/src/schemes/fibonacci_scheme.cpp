#include "impinge/schemes/fibonacci_scheme.hpp"

#include <algorithm>
#include <limits>
#include <sstream>

#include "impinge/core/error.hpp"
#include "impinge/core/fast_angles.hpp"
#include "core/cpu_dispatch.hpp"
#include "core/simd_clones.hpp"

#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>
#endif

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
  // Padded for the block look-up: it reads kZoneWindow zones from any zone a direction can have.
  for (auto* v : {&zones_.f0, &zones_.f1, &zones_.m00, &zones_.m01, &zones_.m10, &zones_.m11, &zones_.a0a1,
                  &zones_.z0z1})
    v->resize(kMaxZones + kZoneWindow, 0.0);
  zones_.start.resize(kMaxZones + kZoneWindow, std::numeric_limits<double>::infinity());
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
/// Cosine of the polar angle cz, sin^2 of it s2 and azimuth az of a block of directions: the first
/// pass of the AVX-512 block look-up (vectorised clones).
IMPINGE_SIMD_CLONES
void fibonacci_angles(const double* __restrict x, const double* __restrict y, const double* __restrict z, int n,
                      double* __restrict cz, double* __restrict s2, double* __restrict az) {
  for (int j = 0; j < n; ++j) {
    const double len = std::sqrt(x[j] * x[j] + y[j] * y[j] + z[j] * z[j]);
    const double c = z[j] / len;
    cz[j] = c, s2[j] = std::max(0.0, (1 - c) * (1 + c));
    az[j] = fast_azimuth(y[j], x[j]);  // [0, 2 pi): the lattice repeats every 2 pi
  }
}

#if defined(__GNUC__) && defined(__x86_64__)
// GCC 12's AVX-512 intrinsics pass _mm512_undefined_pd() as the unused source, which it then
// reports as uninitialised (GCC bug 105593, fixed in GCC 13).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
/// min(max(c, 0), last) by lane; max with 0 gives 0 for a NaN c.
__attribute__((target("avx512f,avx512vl,avx512dq"), always_inline)) inline __m512d clamp_pd(__m512d c, __m512d last) {
  return _mm512_min_pd(_mm512_max_pd(c, _mm512_setzero_pd()), last);
}

/// Lane i of the result: lane d_i of window.
__attribute__((target("avx512f,avx512vl,avx512dq"), always_inline)) inline __m512d pick(__m512i d, __m512d window) {
  return _mm512_permutexvar_pd(d, window);
}

/// The block look-up with AVX-512 when the block's directions lie in fewer than kZoneWindow
/// consecutive zones (usually: a block is a run of a scan set, whose vertices are in Z order of
/// direction): each direction's zone parameters are picked from registers holding the window's
/// zones by one permute each, where fibonacci_stencils_kernel gathers them from memory, and the
/// zone is counted with at most kZoneWindow - 1 compares, not a binary search of gathers. The same
/// computation otherwise (the same corners and weights, up to the rounding of fused multiply-adds).
/// Returns false, having written nothing, when the zones span kZoneWindow or more.
__attribute__((target("avx512f,avx512vl,avx512dq"))) bool fibonacci_stencils_avx512(
    const double* x, const double* y, const double* z, int n, const FibonacciScheme::Zones& t, double n_nodes,
    std::int32_t* nodes, double* w) {
  constexpr int kW = FibonacciScheme::kZoneWindow;
  static_assert(kW == 8, "one 8-lane register per zone parameter");
  alignas(64) double cz[kStencilBlock], s2v[kStencilBlock], az[kStencilBlock];
  fibonacci_angles(x, y, z, n, cz, s2v, az);
  const double nc = n_nodes * kPi * 2.2360679774997896964, z_first = 1 - 1 / n_nodes, last = n_nodes - 1;
  // The least and largest n pi sqrt(5) (1 - z^2) of the block (NaN ignored), and their zones.
  __m512d lo = _mm512_set1_pd(std::numeric_limits<double>::infinity()), hi = _mm512_set1_pd(-1.0);
  for (int j = 0; j < n; j += 8) {
    const __mmask8 k = n - j >= 8 ? __mmask8(0xFF) : __mmask8((1u << (n - j)) - 1);
    const __m512d s2 = _mm512_maskz_loadu_pd(k, s2v + j);
    lo = _mm512_mask_min_pd(lo, k, s2, lo), hi = _mm512_mask_max_pd(hi, k, s2, hi);
  }
  const double* start = t.start.data();
  alignas(64) double lo8[8], hi8[8];
  _mm512_store_pd(lo8, lo), _mm512_store_pd(hi8, hi);
  const int zlo = zone_index(nc * *std::min_element(lo8, lo8 + 8), start);
  const int zhi = zone_index(nc * *std::max_element(hi8, hi8 + 8), start);
  if (zhi - zlo >= kW) return false;
  const __m512d F0w = _mm512_loadu_pd(t.f0.data() + zlo), F1w = _mm512_loadu_pd(t.f1.data() + zlo);
  const __m512d m00w = _mm512_loadu_pd(t.m00.data() + zlo), m01w = _mm512_loadu_pd(t.m01.data() + zlo);
  const __m512d m10w = _mm512_loadu_pd(t.m10.data() + zlo), m11w = _mm512_loadu_pd(t.m11.data() + zlo);
  const __m512d a0a1w = _mm512_loadu_pd(t.a0a1.data() + zlo), z0z1w = _mm512_loadu_pd(t.z0z1.data() + zlo);
  const __m512d zero = _mm512_setzero_pd(), one = _mm512_set1_pd(1.0), vlast = _mm512_set1_pd(last);
  const __m512d vnc = _mm512_set1_pd(nc), vz_first = _mm512_set1_pd(z_first);
  const __m512i one_i = _mm512_set1_epi64(1);
  for (int j = 0; j < n; j += 8) {
    const __mmask8 k = n - j >= 8 ? __mmask8(0xFF) : __mmask8((1u << (n - j)) - 1);
    const __m512d a = _mm512_maskz_loadu_pd(k, az + j), s2 = _mm512_maskz_loadu_pd(k, s2v + j);
    const __m512d rz = _mm512_sub_pd(_mm512_maskz_loadu_pd(k, cz + j), vz_first);
    // The zone within the window: how many of the window's later zone starts v reaches.
    const __m512d v = _mm512_mul_pd(vnc, s2);
    __m512i d = _mm512_setzero_si512();
    for (int q = 1; q <= zhi - zlo; ++q)
      d = _mm512_mask_add_epi64(d, _mm512_cmp_pd_mask(v, _mm512_set1_pd(start[zlo + q]), _CMP_GE_OQ), d, one_i);
    const __m512d F0 = pick(d, F0w), F1 = pick(d, F1w);
    const __m512d f0 = _mm512_add_pd(_mm512_mul_pd(pick(d, m00w), a),
                                     _mm512_mul_pd(pick(d, m01w), rz));
    const __m512d f1 = _mm512_add_pd(_mm512_mul_pd(pick(d, m10w), a),
                                     _mm512_mul_pd(pick(d, m11w), rz));
    const __m512d c0 = _mm512_roundscale_pd(f0, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
    const __m512d c1 = _mm512_roundscale_pd(f1, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
    const __m512d s = _mm512_sub_pd(f0, c0), tt = _mm512_sub_pd(f1, c1);
    const __m512d base = _mm512_add_pd(_mm512_mul_pd(F0, c0), _mm512_mul_pd(F1, c1));
    // Clamped corners; max(x, 0) gives 0 for a NaN x, so a degenerate direction reads node 0.
    const __m512d c00 = clamp_pd(base, vlast), c10 = clamp_pd(_mm512_add_pd(base, F0), vlast);
    const __m512d c01 = clamp_pd(_mm512_add_pd(base, F1), vlast);
    const __m512d c11 = clamp_pd(_mm512_add_pd(_mm512_add_pd(base, F0), F1), vlast);
    // The shorter diagonal on the sphere: 0 -- 3 when s2^2 a0 a1 + z0 z1 <= 0.
    const __m512d diag = _mm512_add_pd(_mm512_mul_pd(_mm512_mul_pd(s2, s2), pick(d, a0a1w)),
                                       pick(d, z0z1w));
    const __mmask8 main = _mm512_cmp_pd_mask(diag, zero, _CMP_LE_OQ);
    const __mmask8 upper = (main & _mm512_cmp_pd_mask(s, tt, _CMP_LT_OQ)) |
                           (~main & _mm512_cmp_pd_mask(_mm512_add_pd(s, tt), one, _CMP_GT_OQ));
    const __mmask8 mu = main & upper, ml = main & ~upper, au = ~main & upper, al = ~main & ~upper;
    // Corners as in fibonacci_stencils_kernel: the one outside the triangle repeats one inside it.
    const __m512d i0 = _mm512_mask_blend_pd(au, c00, c11), i1 = _mm512_mask_blend_pd(mu, c10, c00);
    const __m512d i2 = _mm512_mask_blend_pd(ml, c01, c00), i3 = _mm512_mask_blend_pd(al, c11, c00);
    const __m512d one_s = _mm512_sub_pd(one, s), one_t = _mm512_sub_pd(one, tt);
    // w0 = main ? (upper ? 1 - t : 1 - s) : (upper ? 0 : 1 - s - t), and so on.
    __m512d w0 = _mm512_mask_blend_pd(al, _mm512_mask_blend_pd(mu, one_s, one_t), _mm512_sub_pd(one_s, tt));
    w0 = _mm512_mask_blend_pd(au, w0, zero);
    __m512d w1 = _mm512_mask_blend_pd(ml, _mm512_mask_blend_pd(au, s, one_t), _mm512_sub_pd(s, tt));
    w1 = _mm512_mask_blend_pd(mu, w1, zero);
    __m512d w2 = _mm512_mask_blend_pd(mu, _mm512_mask_blend_pd(au, tt, one_s), _mm512_sub_pd(tt, s));
    w2 = _mm512_mask_blend_pd(ml, w2, zero);
    __m512d w3 = _mm512_mask_blend_pd(au, _mm512_mask_blend_pd(mu, tt, s), _mm512_sub_pd(_mm512_add_pd(s, tt), one));
    w3 = _mm512_mask_blend_pd(al, w3, zero);
    _mm256_mask_storeu_epi32(nodes + j, k, _mm512_cvttpd_epi32(i0));
    _mm256_mask_storeu_epi32(nodes + n + j, k, _mm512_cvttpd_epi32(i1));
    _mm256_mask_storeu_epi32(nodes + 2 * n + j, k, _mm512_cvttpd_epi32(i2));
    _mm256_mask_storeu_epi32(nodes + 3 * n + j, k, _mm512_cvttpd_epi32(i3));
    _mm512_mask_storeu_pd(w + j, k, w0), _mm512_mask_storeu_pd(w + n + j, k, w1);
    _mm512_mask_storeu_pd(w + 2 * n + j, k, w2), _mm512_mask_storeu_pd(w + 3 * n + j, k, w3);
  }
  return true;
}
#pragma GCC diagnostic pop
#endif

void fibonacci_stencils(const double* x, const double* y, const double* z, int n, const FibonacciScheme::Zones& t,
                        double n_nodes, std::int32_t* nodes, double* w) {
#if defined(__GNUC__) && defined(__x86_64__)
  if (n <= kStencilBlock && detail::use_avx512() && fibonacci_stencils_avx512(x, y, z, n, t, n_nodes, nodes, w)) return;
#endif
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
