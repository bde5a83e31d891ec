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

/// Which way a surface fitted by fit_sphere_to_surface faces its sphere: its outward normal towards the centre
/// (a socket, the lunate surface) or away from it (a ball, the femoral head).
enum class SurfaceSide { concave, convex };

/// A sphere fitted to a surface (fit_sphere_to_surface).
struct SurfaceSphereFit {
  SphereFitResult sphere;        ///< the sphere (mm); iterations: the reweighting steps; rms: the weighted rms
  double area_in_band_mm2 = 0;   ///< the surface within band_mm of the sphere and facing it (cosine >= facing_cos)
};

/// A sphere fitted to the surface of `mesh` (mm; its triangles' outward normals, by the sign of its volume) rather
/// than to its vertices: an iteratively reweighted geometric fit (Tukey's biweight of each point's distance from
/// the sphere, (1 - (s / band_mm)^2)^2, 0 beyond band_mm; times a smooth step of the cosine between the outward
/// normal and the direction to the centre (concave) or from it (convex), 0 at facing_cos - 0.1, 1 at
/// facing_cos + 0.1; times the area each point stands for), from the sphere (centre, radius), a Gauss-Newton step
/// per reweighting until a step moves the sphere less than 1e-6 mm (at most 2,000), then GSL's weighted geometric
/// fit with the last weights (fit_sphere_geometric) as the result (converged false when the steps ran out). A step
/// is at most band_mm long. The points: each triangle whose centroid lies within band_mm + 3 mm + its longest edge
/// of the sphere, cut into k x k congruent triangles (k the least power of two that makes them at most 0.5 mm long,
/// at most 64), their centroids. The outward side: the sign of the mesh's volume about `centre`. The weights change
/// continuously with the sphere and the points do not depend on the vertices' order, so that one surface gives one
/// sphere: a file with every triangle split in four at its edges' midpoints is cut into the same points where its
/// triangles' longest edges lie in (0.5, 32] mm (elsewhere into nearly the same: a finer or a coarser quadrature of
/// the same surface). Throws impinge::Error (naming mesh.source and `what`) when the start is not finite or its
/// radius or band not > 0, no point weighs anything, a step is not finite, the radius falls to 0 or the last fit
/// fails. Source: impinge (issue 81, item 2); the biweight: Beaton and Tukey 1974.
SurfaceSphereFit fit_sphere_to_surface(const TriangleMesh& mesh, const Eigen::Vector3d& centre, double radius,
                                       double band_mm, double facing_cos, SurfaceSide side, const std::string& what);

/// The head fit's facing cosine (fit_femoral_head's surface stage): the head's surface weighs fully where it faces
/// away from the centre within acos(kHeadFacing + 0.1) = 36.9 deg, half at 45.6 deg, nothing beyond 53.1 deg (the
/// neck's, across the head-neck junction, does not count).
inline constexpr double kHeadFacing = 0.7;

/// Options of the automatic femoral-head fit.
struct HeadFitOptions {
  double proximal_extent_mm = 70;  ///< candidates: vertices within this height of the most
                                   ///< superior vertex (+z of the working frame, RAS)
  double min_radius_mm = 12;       ///< plausible head radius range for RANSAC spheres
  double max_radius_mm = 40;
  double inlier_threshold_mm = 1.0;  ///< |distance - r| below this counts as an inlier
  int ransac_iterations = 3000;
  int refinement_rounds = 4;   ///< geometric refit on re-selected inliers
  /// The last stage, the sphere of the head's surface (fit_sphere_to_surface): needs the femur's triangles; off for a
  /// point set with no surface (experiment 12's vertex clouds).
  bool surface_stage = true;
  std::uint64_t seed = 12345;  ///< RNG seed: results are reproducible
};

/// Automatic centre of rotation of a femur: RANSAC sphere detection on the proximal femur
/// (4-point minimal spheres with radius in range, most inliers wins), then geometric fits on
/// the re-selected inliers until they no longer change, and last the sphere of the head's surface from there
/// (fit_sphere_to_surface, convex, band 4.685 / 3 of the last inlier band, kHeadFacing; points_used: the last
/// inliers, vertices). `femur`: vertices in the working frame (RAS, +z superior), mm.
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
