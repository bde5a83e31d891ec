#pragma once
/// @file conchoid.hpp
/// The conchoid (limacon of Pascal) r = a + b cos(phi) of Menschik's hip model and the
/// thesis' weighted ray angles (thesis sec. 5.1, Eq. 11-16, Table 10, Fig. 58-59).

#include <vector>

namespace impinge {

/// Menschik's acetabular conchoid (thesis sec. 5.1.2): a = 20.501 mm, b = 17.843 mm.
inline constexpr double kMenschikA = 20.501;
inline constexpr double kMenschikB = 17.843;

/// Conchoid r(phi) = a + b cos(phi) (thesis Eq. 11), a > b >= 0 (mm).
class Conchoid {
 public:
  /// Throws impinge::Error unless a > 0, b >= 0 and a > b (r > 0 everywhere).
  Conchoid(double a_mm, double b_mm);
  double a() const { return a_; }
  double b() const { return b_; }
  /// r(phi) in mm, phi in radians.
  double radius(double phi) const;
  /// Curve length from 0 to phi (thesis Eq. 12): int_0^phi sqrt(r'^2 + r^2) = int_0^phi
  /// sqrt(a^2 + b^2 + 2ab cos t) dt, by GSL adaptive quadrature (QAGS) to 1e-12 relative. mm.
  double arc_length(double phi) const;
  /// phi in [0, phi_max] with arc_length(phi) = s (GSL Brent root finding to 1e-13 rad).
  double angle_at_length(double s, double phi_max) const;
  /// The angle phi in [0, phi_max] (radians) of the point seen from (origin_x_mm, 0) at polar angle psi
  /// (radians, from the +x axis; the curve's axis is x): where a ray from that origin meets the curve.
  /// The origin lies on the axis with 0 <= origin_x_mm <= b, where the angle grows with phi (GSL Brent
  /// root finding to 1e-13 rad). Throws impinge::Error when the ray misses [0, phi_max] or the origin is
  /// outside [0, b]. Source: thesis Fig. 53 (equal-angle rays from the object's centre).
  double angle_seen_from(double origin_x_mm, double psi, double phi_max) const;
  /// Ray angles (radians) cutting [0, phi_max] into n - 1 segments of equal curve length
  /// (the exact counterpart of thesis Eq. 15-16). n >= 2.
  std::vector<double> equal_length_angles(int n, double phi_max) const;

 private:
  double a_, b_;
};

/// The thesis' closed form of the curve length over [0, pi/2] with a = 1.15 b and
/// a^2 + b^2 = 2ab = 2.3 b^2: sqrt(4.6) b * 2 sin(pi/4) (thesis sec. 5.1.2, "3.03 b"). mm.
double conchoid_length_thesis(double b_mm);

/// Thesis Eq. 16: phi_i = 2 asin(3.03 i / ((n - 1) 4.29)), radians, i = 0..n-1.
std::vector<double> conchoid_angles_eq16(int n);

}  // namespace impinge
