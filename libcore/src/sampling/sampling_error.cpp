#include "impinge/sampling/sampling_error.hpp"

#include <cmath>

#include "impinge/core/error.hpp"
#include "impinge/core/spherical_frame.hpp"

namespace impinge {

double eq7_max_sampling_error(double radius_mm, double equator_nodes) {
  require(radius_mm > 0 && equator_nodes > 0, "Eq. 7: radius and node count must be > 0");
  return std::sqrt(2.0) * kPi * radius_mm / equator_nodes;
}

double eq8_relative_error(double equator_nodes) {
  require(equator_nodes > 0, "Eq. 8: node count must be > 0");
  return std::sqrt(2.0) * kPi / equator_nodes;
}

SliceAnalysis slice_sampling(double radius_mm, double slice_mm) {
  require(std::isfinite(radius_mm) && std::isfinite(slice_mm) && radius_mm > 0 && slice_mm > 0 && slice_mm <= radius_mm,
          "slice analysis: need 0 < slice thickness <= radius (mm)");
  SliceAnalysis a;
  const int n = static_cast<int>(std::floor(radius_mm / slice_mm + 1e-12));
  for (int i = 0; i <= n; ++i) a.phi_deg.push_back(std::acos(std::min(1.0, i * slice_mm / radius_mm)) * kRadToDeg);
  for (int i = 0; i + 1 < static_cast<int>(a.phi_deg.size()); ++i)
    a.dphi_deg.push_back(a.phi_deg[static_cast<std::size_t>(i)] - a.phi_deg[static_cast<std::size_t>(i) + 1]);
  a.min_dphi_deg = a.dphi_deg.empty() ? 90.0 : a.dphi_deg.front();
  for (double d : a.dphi_deg) a.min_dphi_deg = std::min(a.min_dphi_deg, d);
  a.nyquist_precision_deg = a.min_dphi_deg / 2;
  return a;
}

double radial_second_derivative(double r_mm, double tan_alpha, double kappa_per_mm) {
  const double sec2 = 1 + tan_alpha * tan_alpha;
  return r_mm * (1 + 2 * tan_alpha * tan_alpha) - kappa_per_mm * r_mm * r_mm * sec2 * std::sqrt(sec2);
}

double bilinear_error_bound(double h_phi, double h_theta, double max_r_phiphi, double max_r_thetatheta) {
  return (h_phi * h_phi * std::abs(max_r_phiphi) + h_theta * h_theta * std::abs(max_r_thetatheta)) / 8;
}

}  // namespace impinge
