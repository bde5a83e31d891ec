#pragma once
/// @file generated_models.hpp
/// Procedural hip-like models at chosen triangle counts, standing in for the thesis' generic
/// TurboSquid models (300 to 12k triangles per model, thesis sec. 3.4) and for test shapes.

#include <Eigen/Core>
#include <functional>

#include "impinge/core/mesh.hpp"
#include "impinge/core/range.hpp"

namespace impinge {

/// Closed UV sphere: `n_theta` segments, `n_phi` >= 2 ring intervals, poles along `axis`
/// (unit, any direction) through `centre`; 2 n_theta (n_phi - 1) triangles, outward-facing.
TriangleMesh make_uv_sphere(double radius_mm, const Eigen::Vector3d& centre, int n_theta, int n_phi,
                            const Eigen::Vector3d& axis = Eigen::Vector3d::UnitZ());

/// Closed star-shaped surface r(u) about `centre`: a UV sphere (poles along `axis`) whose
/// vertex in unit direction u sits at distance radius(u) (mm, > 0).
TriangleMesh make_radial_surface(const std::function<double(const Eigen::Vector3d&)>& radius,
                                 const Eigen::Vector3d& centre, int n_theta, int n_phi,
                                 const Eigen::Vector3d& axis = Eigen::Vector3d::UnitZ());

/// Closed spherical cup (a thick shell segment): inner radius `inner_mm`, outer `outer_mm`,
/// covering polar angles [0, coverage_deg] about `axis` (its pole, the deepest point), with a
/// flat rim joining inner and outer edges. `n_beta` segments around, `n_alpha` rings.
TriangleMesh make_cup(double inner_mm, double outer_mm, double coverage_deg, const Eigen::Vector3d& centre,
                      const Eigen::Vector3d& axis, int n_beta, int n_alpha);

/// Closed staircase sphere as a segmentation of CT slices gives (thesis sec. 3.5.2): slices of
/// thickness `slice_mm` with boundaries at z = centre.z + i slice_mm (the middle plane is a
/// boundary); each slice is a cylinder of the sphere's cross-section radius at the slice's mid
/// height (slices whose mid height is outside the sphere are empty), joined by flat steps and
/// capped by disks; `segments` around. Star-shaped about `centre`.
TriangleMesh make_sliced_sphere(double radius_mm, double slice_mm, const Eigen::Vector3d& centre, int segments);

/// Closed surface of revolution of Menschik's conchoid r(phi) = a + b cos(phi) about `axis`
/// through `origin` (the conchoid's origin; thesis sec. 5.1, Fig. 54), as a radial surface.
TriangleMesh make_conchoid_surface(double a_mm, double b_mm, const Eigen::Vector3d& origin, int n_theta, int n_phi,
                                   const Eigen::Vector3d& axis = Eigen::Vector3d::UnitZ());

/// Options of a generated hip (right side, anatomical RAS frame).
struct HipModelOptions {
  int target_triangles = 3000;       ///< per model (thesis levels 300, 1k, 3k, 12k)
  static constexpr Range kTargetTrianglesRange{50, 2e7};  ///< of target_triangles (2e7: about 2 GB of mesh)
  double head_radius_mm = 22;        ///< femoral head (44 mm diameter, thesis sec. 3.5)
  double cartilage_gap_mm = 2.5;     ///< cup inner radius minus head radius
  double neck_radius_mm = 15;        ///< femoral neck (a cylinder)
  double neck_length_mm = 50;        ///< COR to the neck's cut end
  double cup_wall_mm = 6;            ///< cup thickness
  double cup_coverage_deg = 100;     ///< rim angle from the cup pole; > 90 over-covers (pincer)
  static constexpr Range kCupCoverageRange{30, 170};  ///< of cup_coverage_deg, deg
  double cam_height_mm = 0;          ///< cam bump at the antero-superior head-neck junction
  static constexpr Range kCamHeightRange{0, 15};      ///< of cam_height_mm, mm
  Eigen::Vector3d cor{60, -20, 30};  ///< where the model is placed, mm
};

/// A generated joint and its true COR.
struct HipModel {
  TriangleMesh ball;    ///< femoral head and neck, star-shaped about the COR
  TriangleMesh socket;  ///< acetabular cup
  Eigen::Vector3d cor;  ///< exact centre of the head and of the cup
};

/// Hip-like model: a spherical head with a cylindrical neck (lateral, anterior, inferior) and
/// optional cam bump, in a concentric cup opening laterally and inferiorly. Poles of the
/// meshes are kept off the z axis so that the generic (non-pole) rasterisation path is used.
HipModel make_hip_model(const HipModelOptions& options);

}  // namespace impinge
