#pragma once
/// @file helix_arc_length.hpp
/// Arc length ("traveled distance", thesis sec. 4.3) of the k-turn spherical helix
/// theta = 2 k phi on the unit sphere (thesis Eq. 9, Nishio et al. 2006).

#include <vector>

namespace impinge {

/// Exact arc length s(phi) = int_0^phi sqrt(1 + 4 k^2 sin^2 t) dt of the helix theta = 2 k phi,
/// an incomplete elliptic integral of the second kind with parameter -m, m = 4 k^2, evaluated in
/// Carlson's symmetric form with GSL (gsl_sf_ellint_RF, gsl_sf_ellint_RD; DLMF 19.25.9).
/// `operator()` is the fast form used by queries: s tabulated at 8193 angles with its exact
/// derivative and interpolated by cubic Hermite (error <= h^4 max|s^(4)| / 384 ~ 5e-13 for
/// k = 4584, no trigonometry), and the exact integral within 20/k rad of the poles, where s
/// varies on the scale 1/(2k); agrees with `exact` to better than 1e-7 of a node spacing (tested).
class HelixArcLength {
 public:
  /// k > 0 turns. Throws impinge::Error otherwise.
  explicit HelixArcLength(double turns);
  double turns() const { return k_; }
  /// s(phi), phi in [0, pi] radians; fast.
  double operator()(double phi) const {
    if (phi < cap_ || phi > kPiHelix - cap_) return exact(phi < 0 ? 0 : (phi > kPiHelix ? kPiHelix : phi));
    const double f = phi * inv_h_;
    int j = static_cast<int>(f);
    if (j >= intervals_) j = intervals_ - 1;
    const double t = f - j, t2 = t * t, t3 = t2 * t;
    return (2 * t3 - 3 * t2 + 1) * s_[j] + (t3 - 2 * t2 + t) * h_ * ds_[j] + (-2 * t3 + 3 * t2) * s_[j + 1] +
           (t3 - t2) * h_ * ds_[j + 1];
  }
  /// s(phi) and ds/dphi together (fast outside the polar caps).
  void value_and_derivative(double phi, double& s, double& ds) const {
    if (in_cap(phi)) {
      s = (*this)(phi);
      ds = derivative(phi);
      return;
    }
    const double f = phi * inv_h_;
    int j = static_cast<int>(f);
    if (j >= intervals_) j = intervals_ - 1;
    const double t = f - j, t2 = t * t, t3 = t2 * t;
    const double s0 = s_[j], s1 = s_[j + 1], d0 = ds_[j], d1 = ds_[j + 1];
    s = (2 * t3 - 3 * t2 + 1) * s0 + (t3 - 2 * t2 + t) * h_ * d0 + (-2 * t3 + 3 * t2) * s1 + (t3 - t2) * h_ * d1;
    ds = (6 * t2 - 6 * t) * inv_h_ * (s0 - s1) + (3 * t2 - 4 * t + 1) * d0 + (3 * t2 - 2 * t) * d1;
  }
  /// s at n angles (phi: n values in [0, pi], radians) into s_out: the table's cubic Hermite in a
  /// vectorised pass, then the exact integral for the few angles inside the polar caps. Same
  /// values as operator().
  void evaluate_many(const double* phi, int n, double* s_out) const;
  /// True where the fast form uses the exact integral (within 20/k of a pole).
  bool in_cap(double phi) const { return phi < cap_ || phi > kPiHelix - cap_; }
  /// s(phi) by the elliptic integral (slow reference, ~0.3 us).
  double exact(double phi) const;
  /// ds/dphi = sqrt(1 + 4 k^2 sin^2 phi).
  double derivative(double phi) const;
  /// Total length s(pi).
  double total() const { return total_; }
  /// phi with s(phi) = s (0 <= s <= total), by Newton iteration from `guess` (radians).
  double inverse(double s, double guess) const;

 private:
  static constexpr double kPiHelix = 3.14159265358979323846;
  double quarter(double phi) const;  ///< s(phi) for phi in [0, pi/2]
  double k_, m_, total_;
  double cap_;  ///< below cap_ (and above pi - cap_) s is computed exactly
  int intervals_;
  double h_, inv_h_;
  std::vector<double> s_, ds_;  ///< s(phi) and s'(phi) at phi = j h
};

/// The thesis' fitted traveled distance (Eq. 10): T(phi) = (4k + 1)(1 - cos phi) / 2.
inline double traveled_distance_eq10(double turns, double cos_phi) { return (4 * turns + 1) * (1 - cos_phi) / 2; }

}  // namespace impinge
