#pragma once
/// @file helix_arc_length.hpp
/// Arc length ("traveled distance", thesis sec. 4.3) of the k-turn spherical helix
/// theta = 2 k phi on the unit sphere (thesis Eq. 9, Nishio et al. 2006).

#include <vector>

namespace impinge {

/// Exact arc length s(phi) = int_0^phi sqrt(1 + 4 k^2 sin^2 t) dt of the helix theta = 2 k phi,
/// an incomplete elliptic integral of the second kind with parameter -m, m = 4 k^2, evaluated in
/// Carlson's symmetric form with GSL (gsl_sf_ellint_RF, gsl_sf_ellint_RD; DLMF 19.25.9).
/// `operator()` is the fast form used by queries: s = 2k (1 - cos phi) + c(phi) with the small
/// correction c tabulated (cubic Hermite with its analytic derivative) and the exact integral
/// within 20/k rad of the poles, where c varies on the scale 1/(2k); agrees with `exact` to
/// better than 1e-7 of a node spacing (tested; double rounding of s ~ 4k is 1e-12 mm-free units).
class HelixArcLength {
 public:
  /// k > 0 turns. Throws impinge::Error otherwise.
  explicit HelixArcLength(double turns);
  double turns() const { return k_; }
  /// s(phi), phi in [0, pi] radians; fast.
  double operator()(double phi) const;
  /// s(phi) by the elliptic integral (slow reference, ~0.3 us).
  double exact(double phi) const;
  /// ds/dphi = sqrt(1 + 4 k^2 sin^2 phi).
  double derivative(double phi) const;
  /// Total length s(pi).
  double total() const { return total_; }
  /// phi with s(phi) = s (0 <= s <= total), by Newton iteration from `guess` (radians).
  double inverse(double s, double guess) const;

 private:
  double quarter(double phi) const;  ///< s(phi) for phi in [0, pi/2]
  double k_, m_, total_;
  double cap_;    ///< below cap_ (and above pi - cap_) s is computed exactly
  double h_, inv_h_;
  std::vector<double> c_, dc_;  ///< c(phi) and c'(phi) at phi = j h
};

/// The thesis' fitted traveled distance (Eq. 10): T(phi) = (4k + 1)(1 - cos phi) / 2.
inline double traveled_distance_eq10(double turns, double cos_phi) { return (4 * turns + 1) * (1 - cos_phi) / 2; }

}  // namespace impinge
