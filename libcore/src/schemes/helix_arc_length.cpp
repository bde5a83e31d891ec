#include "impinge/schemes/helix_arc_length.hpp"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_mode.h>
#include <gsl/gsl_sf_ellint.h>

#include <algorithm>
#include <cmath>

#include "impinge/core/error.hpp"
#include "impinge/core/spherical_frame.hpp"
#include "core/simd_clones.hpp"

namespace impinge {

namespace {
constexpr int kTableIntervals = 8192;
}

HelixArcLength::HelixArcLength(double turns) : k_(turns) {
  require(std::isfinite(turns) && turns > 0, "helix: turns must be > 0");
  gsl_set_error_handler_off();
  m_ = 4 * k_ * k_;
  total_ = 2 * quarter(kPi / 2);
  cap_ = std::min(kPi / 2, 20.0 / k_);
  intervals_ = kTableIntervals;
  h_ = kPi / kTableIntervals;
  inv_h_ = 1 / h_;
  s_.resize(kTableIntervals + 1);
  ds_.resize(kTableIntervals + 1);
  for (int j = 0; j <= kTableIntervals; ++j) {
    s_[j] = exact(j * h_);
    ds_[j] = derivative(j * h_);
  }
}

double HelixArcLength::quarter(double phi) const {
  // Incomplete elliptic integral of the second kind with negative parameter -m in Carlson's
  // symmetric form (DLMF 19.25.9): E(phi | -m) = s R_F(c^2, 1 + m s^2, 1) + (m/3) s^3
  // R_D(c^2, 1 + m s^2, 1), s = sin phi, c = cos phi. Both terms are positive: no cancellation,
  // unlike the complementary form sqrt(1 + m) [E(pi/2, kappa) - E(pi/2 - phi, kappa)], which
  // loses up to 1e-4 relative near the poles and 2e-8 absolute at k = 4584 in GSL.
  const double s = std::sin(phi), c = std::cos(phi);
  const double y = 1 + m_ * s * s;
  return s * gsl_sf_ellint_RF(c * c, y, 1, GSL_PREC_DOUBLE) +
         m_ / 3 * s * s * s * gsl_sf_ellint_RD(c * c, y, 1, GSL_PREC_DOUBLE);
}

double HelixArcLength::exact(double phi) const {
  if (phi <= 0) return 0;
  if (phi >= kPi) return total_;
  return phi <= kPi / 2 ? quarter(phi) : total_ - quarter(kPi - phi);  // symmetric about pi/2
}

double HelixArcLength::derivative(double phi) const {
  const double s = std::sin(phi);
  return std::sqrt(1 + m_ * s * s);
}

double HelixArcLength::inverse(double s, double guess) const {
  double phi = std::clamp(guess, 0.0, kPi);
  for (int it = 0; it < 60; ++it) {
    double v, dv;
    value_and_derivative(phi, v, dv);
    const double step = (v - s) / dv;
    phi = std::clamp(phi - step, 0.0, kPi);
    if (std::abs(step) < 1e-15) break;
  }
  return phi;
}

namespace {
/// Cubic Hermite of the tabulated s and s' (the body of operator() outside the caps).
IMPINGE_SIMD_CLONES
void hermite_many(const double* __restrict phi, int n, const double* __restrict s, const double* __restrict ds,
                  double h, double inv_h, int intervals, double* __restrict out) {
  for (int k = 0; k < n; ++k) {
    const double f = std::max(phi[k], 0.0) * inv_h;
    int j = static_cast<int>(f);
    j = j >= intervals ? intervals - 1 : j;
    const double t = f - j, t2 = t * t, t3 = t2 * t;
    out[k] = (2 * t3 - 3 * t2 + 1) * s[j] + (t3 - 2 * t2 + t) * h * ds[j] + (-2 * t3 + 3 * t2) * s[j + 1] +
             (t3 - t2) * h * ds[j + 1];
  }
}
}  // namespace

void HelixArcLength::evaluate_many(const double* phi, int n, double* s_out) const {
  hermite_many(phi, n, s_.data(), ds_.data(), h_, inv_h_, intervals_, s_out);
  for (int k = 0; k < n; ++k)
    if (in_cap(phi[k])) s_out[k] = (*this)(phi[k]);
}

}  // namespace impinge
