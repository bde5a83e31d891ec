#include "impinge/schemes/conchoid.hpp"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_integration.h>
#include <gsl/gsl_roots.h>

#include <cmath>
#include <sstream>

#include "impinge/core/error.hpp"
#include "impinge/core/spherical_frame.hpp"

namespace impinge {

Conchoid::Conchoid(double a_mm, double b_mm) : a_(a_mm), b_(b_mm) {
  std::ostringstream os;
  os << "conchoid: need a > b >= 0 (mm), got a = " << a_mm << ", b = " << b_mm;
  require(std::isfinite(a_mm) && std::isfinite(b_mm) && b_mm >= 0 && a_mm > b_mm, os.str());
}

double Conchoid::radius(double phi) const { return a_ + b_ * std::cos(phi); }

namespace {
struct Params {
  double a, b;
};
double integrand(double t, void* p) {
  const auto* q = static_cast<Params*>(p);
  return std::sqrt(q->a * q->a + q->b * q->b + 2 * q->a * q->b * std::cos(t));
}
}  // namespace

double Conchoid::arc_length(double phi) const {
  if (phi == 0) return 0;
  gsl_set_error_handler_off();
  Params p{a_, b_};
  gsl_function f{integrand, &p};
  gsl_integration_workspace* w = gsl_integration_workspace_alloc(1000);
  double result = 0, err = 0;
  const int status = gsl_integration_qags(&f, 0, phi, 0, 1e-12, 1000, w, &result, &err);
  gsl_integration_workspace_free(w);
  require(status == GSL_SUCCESS, "conchoid: quadrature failed (" + std::string(gsl_strerror(status)) + ")");
  return result;
}

namespace {
// The root of f in [lo, hi] (f(lo) and f(hi) of opposite signs) by GSL's Brent solver to 1e-13.
template <class F>
double brent_root(F f, double lo, double hi) {
  gsl_set_error_handler_off();
  gsl_function g;
  g.function = [](double x, void* p) { return (*static_cast<F*>(p))(x); };
  g.params = &f;
  gsl_root_fsolver* solver = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
  const int status = gsl_root_fsolver_set(solver, &g, lo, hi);
  double root = 0;
  for (int it = 0; status == GSL_SUCCESS && it < 200; ++it) {
    gsl_root_fsolver_iterate(solver);
    root = gsl_root_fsolver_root(solver);
    if (gsl_root_test_interval(gsl_root_fsolver_x_lower(solver), gsl_root_fsolver_x_upper(solver), 1e-13, 0) ==
        GSL_SUCCESS)
      break;
  }
  gsl_root_fsolver_free(solver);
  require(status == GSL_SUCCESS, "conchoid: no root in the interval (" + std::string(gsl_strerror(status)) + ")");
  return root;
}
}  // namespace

double Conchoid::angle_at_length(double s, double phi_max) const {
  if (s <= 0) return 0;
  const double total = arc_length(phi_max);
  if (s >= total) return phi_max;
  return brent_root([&](double phi) { return arc_length(phi) - s; }, 0, phi_max);
}

double Conchoid::angle_seen_from(double origin_x_mm, double psi, double phi_max) const {
  require(origin_x_mm >= 0 && origin_x_mm <= b_, "conchoid: the origin must lie on the axis within [0, b]");
  const auto seen = [&](double phi) {
    const double r = radius(phi);
    return std::atan2(r * std::sin(phi), r * std::cos(phi) - origin_x_mm) - psi;
  };
  if (seen(0) == 0) return 0;
  if (seen(phi_max) == 0) return phi_max;
  return brent_root(seen, 0, phi_max);
}

std::vector<double> Conchoid::equal_length_angles(int n, double phi_max) const {
  require(n >= 2, "conchoid: need at least 2 rays");
  const double total = arc_length(phi_max);
  std::vector<double> out(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) out[static_cast<std::size_t>(i)] = angle_at_length(total * i / (n - 1), phi_max);
  out.back() = phi_max;
  return out;
}

double conchoid_length_thesis(double b_mm) { return std::sqrt(4.6) * b_mm * 2 * std::sin(kPi / 4); }

std::vector<double> conchoid_angles_eq16(int n) {
  require(n >= 2, "conchoid: need at least 2 rays");
  std::vector<double> out(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double x = 3.03 * i / ((n - 1) * 4.29);
    out[static_cast<std::size_t>(i)] = 2 * std::asin(std::min(1.0, x));
  }
  return out;
}

}  // namespace impinge
