#pragma once
/// @file sphere_fit.hpp
/// Centre of rotation by least-squares sphere fit of the femoral head (thesis sec. 3.4, Fig. 38).

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "impinge/core/mesh.hpp"

namespace impinge {

/// Result of a sphere fit.
struct SphereFitResult {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  ///< mm, frame of the input points
  double radius = 0;                                 ///< mm
  double rms_residual = 0;       ///< sqrt(mean (|p - centre| - radius)^2) over the fitted points, mm
  std::int64_t points_used = 0;  ///< points in the final fit (the inliers for a robust fit)
  int iterations = 0;            ///< solver iterations (geometric fit) or refinement rounds
  bool converged = false;        ///< solver reached its tolerance
};

/// Algebraic sphere fit: linear least squares of |p|^2 = 2 c.p + (r^2 - |c|^2).
/// P: k x 3 points, mm, k >= 4 and not coplanar. Throws impinge::Error when k < 4 or the
/// system is singular (coplanar points). Fast, biased on partial spheres: use it to start
/// the geometric fit.
SphereFitResult fit_sphere_algebraic(PointsRef P);

/// Geometric sphere fit minimising E(c, r) = sum (|p_i - c| - r)^2 (Eberly 1999, the fit of
/// thesis sec. 3.4), solved by GSL's Levenberg-Marquardt trust region (gsl_multifit_nlinear,
/// steps by Cholesky of the normal equations) from the algebraic fit. P: k x 3 points, mm, k >= 4.
/// Throws impinge::Error on too few or coplanar points.
SphereFitResult fit_sphere_geometric(PointsRef P);
/// The same with a weight per point (k weights >= 0, e.g. the area each vertex stands for: the fit of a
/// surface rather than of its vertices; GSL's weighted least squares); rms_residual is then the weighted
/// rms. Throws impinge::Error on a weight count other than k, a negative or non-finite weight.
SphereFitResult fit_sphere_geometric(PointsRef P, const std::vector<double>& weights);

/// Options of the automatic femoral-head fit.
struct HeadFitOptions {
  double proximal_extent_mm = 70;  ///< candidates: vertices within this height of the most
                                   ///< superior vertex (+z of the working frame, RAS)
  double min_radius_mm = 12;       ///< plausible head radius range for RANSAC spheres
  double max_radius_mm = 40;
  double inlier_threshold_mm = 1.0;  ///< |distance - r| below this counts as an inlier
  int ransac_iterations = 3000;
  int refinement_rounds = 4;   ///< geometric refit on re-selected inliers
  std::uint64_t seed = 12345;  ///< RNG seed: results are reproducible
};

/// Automatic centre of rotation of a femur: RANSAC sphere detection on the proximal femur
/// (4-point minimal spheres with radius in range, most inliers wins), then geometric fits on
/// the re-selected inliers. `femur`: vertices in the working frame (RAS, +z superior), mm.
/// Throws impinge::Error naming the mesh when no plausible sphere is found.
SphereFitResult fit_femoral_head(const TriangleMesh& femur, const HeadFitOptions& options = {});

/// fit_femoral_head, whose last stage (refits until the inliers no longer change, so that the sphere depends on
/// the surface and not on the RANSAC draws) runs only when `to_fixed_point(sphere)` holds for the sphere of the
/// refinement rounds (mm, the femur's frame); otherwise that sphere is returned (iterations =
/// refinement_rounds). An empty function: always, as fit_femoral_head. locate_femoral_head's use: an end of the
/// femur far from the acetabulum is not the head, and its fixed point (11 to 50 refits at a distal end of the
/// shared hips) would not change that. Throws as fit_femoral_head, and what `to_fixed_point` throws.
SphereFitResult fit_femoral_head(const TriangleMesh& femur, const HeadFitOptions& options,
                                 const std::function<bool(const SphereFitResult&)>& to_fixed_point);

/// Geometric fit of the femur's vertices within `region_radius_mm` of `region_centre` (a
/// user-given selection region, as the planes of thesis Fig. 38a). Throws if fewer than 4.
SphereFitResult fit_sphere_in_region(const TriangleMesh& femur, const Eigen::Vector3d& region_centre,
                                     double region_radius_mm);

}  // namespace impinge
