#pragma once
/// @file sampling_error.hpp
/// The thesis' sampling-error formulas (sec. 3.5: Eq. 7-8, Table 5; slice analysis, Fig. 46)
/// and the interpolation bound that does bound the radial gap error (section 04 of the paper).

#include <vector>

namespace impinge {

/// Thesis Eq. 7: maximum sampling error sqrt(2) pi r / N (mm) of a map with N nodes around the
/// equator on a sphere of radius r (mm): half the diagonal of an equatorial cell.
double eq7_max_sampling_error(double radius_mm, double equator_nodes);

/// Thesis Eq. 8: relative error sqrt(2) pi / N (a fraction of r).
double eq8_relative_error(double equator_nodes);

/// Slice analysis of thesis sec. 3.5.2 (Fig. 45-46): a sphere of radius r cut by slices of
/// thickness t at z_i = i t (i = 0, 1, ...; the middle plane is slice 0) is sampled in
/// phi_i = arccos(i t / r); the smallest step is between the middle plane and the first slice.
struct SliceAnalysis {
  std::vector<double> phi_deg;       ///< phi_i for i = 0..floor(r / t), degrees
  std::vector<double> dphi_deg;      ///< phi_i - phi_{i+1}, degrees (one fewer entry)
  double min_dphi_deg = 0;           ///< smallest step (the first one), degrees
  double nyquist_precision_deg = 0;  ///< half of it (Shannon: twice the sampling rate), degrees
};

/// Slice analysis for head radius `radius_mm` and slice thickness `slice_mm` (both > 0).
/// Throws impinge::Error on bad input. Thesis: r = 22, t = 1.25 gives about 3 deg, p <= 1.5 deg.
SliceAnalysis slice_sampling(double radius_mm, double slice_mm);

/// Second derivative (mm / rad^2) of the radial distance r along a great circle through a
/// surface point where the ray meets the surface at angle alpha to the normal (tan_alpha =
/// r'/r) and the surface's normal curvature in that direction is kappa (1/mm, > 0 convex as seen
/// from the COR): r'' = r (1 + 2 tan^2 alpha) - kappa r^2 / cos^3 alpha. Zero for a sphere about
/// the COR; r (1 + 2 tan^2 alpha) for a plane. From the polar-curve curvature formula.
double radial_second_derivative(double r_mm, double tan_alpha, double kappa_per_mm);

/// Bound on the bilinear interpolation error of a radial map (mm): (h_phi^2 |r_phiphi| +
/// h_theta^2 |r_thetatheta|) / 8 with h in radians and the second partial derivatives' largest
/// magnitudes over the cell (tensor-product linear interpolation bound).
double bilinear_error_bound(double h_phi, double h_theta, double max_r_phiphi, double max_r_thetatheta);

}  // namespace impinge
