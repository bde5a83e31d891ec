// Helix arc length against independent quadrature (Gauss-Legendre of sqrt(1 + 4k^2 sin^2 t)), the
// closed forms (k -> 0: a meridian, s = phi; total length -> 4k + O(log k / k)), and the fast
// tabulated form against the elliptic-integral one to 1e-9 of a node spacing.
#include "impinge/schemes/helix_arc_length.hpp"

#include <gsl/gsl_integration.h>
#include <gtest/gtest.h>

#include <random>

#include "impinge/core/error.hpp"
#include "impinge/core/spherical_frame.hpp"

using namespace impinge;

namespace {
// Gauss-Legendre (20 points) on sub-intervals of width <= 1/(4k): the integrand varies on the
// scale 1/(2k) near the poles, so adaptive quadrature over [0, phi] at once is not reliable.
double quadrature(double k, double phi) {
  if (phi <= 0) return 0;
  gsl_integration_glfixed_table* t = gsl_integration_glfixed_table_alloc(20);
  gsl_function f;
  f.function = [](double x, void* p) {
    const double kk = *static_cast<double*>(p);
    return std::sqrt(1 + 4 * kk * kk * std::sin(x) * std::sin(x));
  };
  f.params = &k;
  const int n = std::max(1, static_cast<int>(std::ceil(phi * 4 * k)));
  double sum = 0;
  for (int j = 0; j < n; ++j) sum += gsl_integration_glfixed(&f, phi * j / n, phi * (j + 1) / n, t);
  gsl_integration_glfixed_table_free(t);
  return sum;
}
}  // namespace

TEST(HelixArcLength, EllipticIntegralMatchesQuadrature) {
  for (double k : {1.0, 10.0, 229.0, 4584.0}) {
    const HelixArcLength s(k);
    // s is a difference of two O(1) elliptic integrals scaled by sqrt(1 + 4k^2) ~ 2k: allow a
    // few ulps of that scale plus 1e-13 relative.
    const double tol_abs = 1e-14 * 2 * k;
    for (double phi : {0.0, 1e-9, 1e-6, 1e-4, 0.01, 0.5, 1.0, kPi / 2, 2.0, 3.0, kPi - 1e-4, kPi - 1e-9, kPi}) {
      const double q = quadrature(k, phi);
      EXPECT_NEAR(s.exact(phi), q, tol_abs + 1e-13 * q) << "k=" << k << " phi=" << phi;
    }
    EXPECT_NEAR(s.total(), quadrature(k, kPi), tol_abs + 1e-13 * s.total());
  }
}

TEST(HelixArcLength, ClosedFormLimits) {
  const HelixArcLength meridian(1e-9);  // k -> 0: the helix is a meridian, s = phi
  for (double phi : {0.3, 1.7, kPi}) EXPECT_NEAR(meridian.exact(phi), phi, 1e-12);
  for (double k :
       {229.0,
        4584.0}) {  // s(pi) = 4k + (ln(8k) + 1/2) / (2k) + ... (E near kappa = 1: E ~ 1 + kp^2 (ln(4/kp) - 1/2) / 2)
    const HelixArcLength s(k);
    EXPECT_GT(s.total(), 4 * k);
    EXPECT_NEAR(s.total(), 4 * k + (std::log(8 * k) + 0.5) / (2 * k), 1e-3 / k);
  }
  EXPECT_THROW(HelixArcLength(0), Error);
}

TEST(HelixArcLength, FastFormAgreesWithExact) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> U(0, kPi);
  for (double k : {3.0, 40.0, 229.0, 2292.0, 4584.0}) {
    const HelixArcLength s(k);
    const double spacing = s.total() / (k * k - 1);
    double worst = 0;
    for (int j = 0; j < 20000; ++j) {
      const double phi = j < 200 ? j * 1e-5 : U(rng);  // include the caps near the poles
      worst = std::max(worst, std::abs(s(phi) - s.exact(phi)));
    }
    EXPECT_LT(worst, 1e-7 * spacing) << "k=" << k;
    const double target = 0.37 * s.total();
    EXPECT_NEAR(s(s.inverse(target, 1.0)), target, 1e-7 * spacing);
  }
}
