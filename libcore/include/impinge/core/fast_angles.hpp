#pragma once
/// @file fast_angles.hpp
/// Spherical angles of a direction without libm trigonometry: the hot path of every map look-up
/// (fast query path). Branch-free (selects only), so loops over them vectorise.
///
/// Method: fold (y, x) into the first octant (0 <= mn <= mx), reduce once more with
/// atan(t) = pi/4 + atan((t - 1) / (t + 1)) when t = mn / mx > tan(pi/8), so the argument u lies
/// in [-tan(pi/8), tan(pi/8)], and evaluate an odd degree-17 polynomial u * q(u^2) fitted
/// (iteratively reweighted least squares on Chebyshev nodes, near-minimax) to atan on that
/// interval. Fit error 5.2e-15 rad; with rounding, every result is within
/// `kFastAngleMaxError` = 1e-13 rad of the exact angle (tested against long-double atan2 on
/// 4 million random and all edge-case directions in tests/fast_angles_test.cpp).
///
/// Effect on a look-up: a direction error of e radians moves the bilinear weights of a grid of
/// spacing h by at most e / h, so the interpolated distance by at most (e / h) * (largest
/// difference between neighbouring node values). At h = 0.05 deg and a 300 mm jump at a depth
/// discontinuity that is 3.4e-8 mm, far below the 1e-4 mm we allow.

#include <algorithm>
#include <cmath>

namespace impinge {

/// Largest error (radians) of fast_polar_angle and fast_azimuth against the exact angles.
inline constexpr double kFastAngleMaxError = 1e-13;

namespace fast_angles_detail {
inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kTanPi8 = 0.41421356237309504880;  // tan(pi/8) = sqrt(2) - 1

/// atan(u) for |u| <= tan(pi/8): u * q(u^2), near-minimax, |error| <= 5.2e-15.
inline double atan_reduced(double u) {
  const double s = u * u;
  double q = 0.02963552492242751;
  q = q * s - 0.05799456218771525;
  q = q * s + 0.07541112038780916;
  q = q * s - 0.09074782228087129;
  q = q * s + 0.1111005637975972;
  q = q * s - 0.1428567343829258;
  q = q * s + 0.199999991390151;
  q = q * s - 0.3333333332505993;
  q = q * s + 0.9999999999997656;
  return u * q;
}

/// The reduction of atan2(b, a), a, b >= 0: atan2(b, a) = finish(b, a, big, num / den).
struct Reduced {
  double num, den;
  bool big;
};
inline Reduced reduce(double b, double a) {
  const double mn = std::min(a, b), mx = std::max(a, b);
  const bool big = mn > kTanPi8 * mx;
  return {big ? mn - mx : mn, std::max(big ? mn + mx : mx, 1e-150), big};
}
inline double finish(double b, double a, bool big, double u) {
  const double r = (big ? kPi / 4 : 0.0) + atan_reduced(u);
  return b > a ? kPi / 2 - r : r;
}

/// atan2(b, a) for a, b >= 0, in [0, pi/2]; 0 when both are 0.
inline double atan2_first_quadrant(double b, double a) {
  const Reduced q = reduce(b, a);
  return finish(b, a, q.big, q.num / q.den);
}
}  // namespace fast_angles_detail

/// Polar angle phi = atan2(rho, z) in [0, pi] radians of a direction with rho = sqrt(x^2 + y^2)
/// >= 0 (thesis Eq. 5, phi from +z). Error <= kFastAngleMaxError. (0, 0) gives 0.
inline double fast_polar_angle(double rho, double z) {
  const double a = fast_angles_detail::atan2_first_quadrant(rho, std::abs(z));
  return z < 0 ? fast_angles_detail::kPi - a : a;
}

/// Both angles of (x, y, z) with one division for the two reductions (num1 / den1 and
/// num2 / den2 from one reciprocal of den1 * den2: two more roundings, within the same bound
/// for |x|, |y|, |z| in [1e-100, 1e100]). phi in [0, pi], theta in [0, 2 pi].
inline void fast_spherical_angles(double x, double y, double z, double& phi, double& theta) {
  using namespace fast_angles_detail;
  const double rho = std::sqrt(x * x + y * y), az = std::abs(z), ax = std::abs(x), ay = std::abs(y);
  const Reduced p = reduce(rho, az), t = reduce(ay, ax);
  const double inv = 1.0 / (p.den * t.den);
  const double a = finish(rho, az, p.big, p.num * t.den * inv);
  phi = z < 0 ? fast_angles_detail::kPi - a : a;
  double b = finish(ay, ax, t.big, t.num * p.den * inv);
  b = x < 0 ? fast_angles_detail::kPi - b : b;
  theta = y < 0 ? 2 * fast_angles_detail::kPi - b : b;
}

/// Azimuth theta = atan2(y, x) mapped to [0, 2 pi] radians (thesis Eq. 6; 2 pi only when y is a
/// tiny negative number and rounding reaches it: callers wrap). Error <= kFastAngleMaxError.
/// (0, 0) gives 0.
inline double fast_azimuth(double y, double x) {
  double a = fast_angles_detail::atan2_first_quadrant(std::abs(y), std::abs(x));
  a = x < 0 ? fast_angles_detail::kPi - a : a;
  return y < 0 ? 2 * fast_angles_detail::kPi - a : a;
}

/// Largest error (radians) of fast_acos_coarse, fit plus double rounding (tested).
inline constexpr double kFastAcosCoarseMaxError = 3e-8;

/// The degree-7 polynomial of fast_acos_coarse, highest degree first (Abramowitz and Stegun,
/// eq. 4.4.46); vectorised copies of fast_acos_coarse use the same coefficients.
inline constexpr double kFastAcosCoarseCoefficients[8] = {-0.0012624911, 0.0066700901, -0.0170881256, 0.0308918810,
                                                          -0.0501743046, 0.0889789874, -0.2145988016, 1.5707963050};

/// acos(x) in radians for x in [-1, 1] without a division: sqrt(1 - |x|) times a degree-7
/// polynomial in |x| (Abramowitz and Stegun, Handbook of Mathematical Functions, eq. 4.4.46,
/// fit error <= 2e-8), reflected as pi - acos(|x|) for x < 0. Error <= kFastAcosCoarseMaxError
/// (tests/fast_angles_test.cpp). For bounds that are padded by more than that (the
/// rasteriser's row spans), not for look-ups.
inline double fast_acos_coarse(double x) {
  const double a = std::abs(x);
  double p = kFastAcosCoarseCoefficients[0];
  for (int i = 1; i < 8; ++i) p = p * a + kFastAcosCoarseCoefficients[i];
  const double r = std::sqrt(std::max(0.0, 1 - a)) * p;
  return x < 0 ? fast_angles_detail::kPi - r : r;
}

}  // namespace impinge
