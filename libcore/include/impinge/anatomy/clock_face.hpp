#pragma once
/// @file clock_face.hpp
/// Clock faces of the hip: the acetabular clock (rim plane, 6 o'clock at the acetabular notch /
/// transverse acetabular ligament, 12 superior, 3 anterior on both sides; Blankenbaker et al.
/// 2007, Skeletal Radiol 36:391; Philippon et al. 2007, thesis Fig. 43) found on the pelvis, and
/// the femoral head-neck clock (viewed along the neck axis: 12 superior, 3 anterior on both sides,
/// as cam lesions are located, e.g. Noetzli et al. 2002).

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "impinge/anatomy/anatomical_frame.hpp"
#include "impinge/anatomy/pose.hpp"
#include "impinge/anatomy/sphere_fit.hpp"
#include "impinge/core/mesh.hpp"

namespace impinge {

/// A clock face: a plane through `centre` with normal `axis`, 12 o'clock along `twelve` and 3
/// o'clock along `three` (unit, in the plane, orthogonal). Frame of the bone it belongs to, mm.
struct ClockFace {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();    ///< out of the acetabulum / along the neck towards the head
  Eigen::Vector3d twelve = Eigen::Vector3d::UnitY();  ///< 12 o'clock
  Eigen::Vector3d three = Eigen::Vector3d::UnitX();   ///< 3 o'clock (anterior)

  /// Clock position of point p (mm, same frame) in hours, (0, 12]: 12 at `twelve`, 3 at `three`,
  /// continuous (1.5 = half past one). NaN when p projects onto the centre.
  double hour(const Eigen::Vector3d& p) const;
  /// The sector (0..11) of an hour: sector k covers hours (k, k + 1], sector 11 is (11, 12].
  static int sector(double hour);
  /// The same clock face in another frame: points x -> R x + t (R: 3 x 3 rotation, t: mm).
  ClockFace transformed(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) const;
};

/// The acetabulum of a pelvis: its sphere, rim and clock face.
struct Acetabulum {
  SphereFitResult sphere;                 ///< the lunate surface's sphere (fit_sphere_to_surface), mm
                                          ///< (iterations: its reweighting steps; rms: weighted)
  double joint_space_mode_mm = 0;         ///< the commonest distance of the socket from the head sphere at the scan pose
  double lunate_area_mm2 = 0;             ///< area of the lunate surface the sphere is fitted on
  std::int64_t lunate_triangles = 0;      ///< its triangles
  Eigen::Vector3d rim_centre;             ///< centroid of the rim points, mm
  Eigen::Vector3d opening;                ///< unit normal of the rim plane, out of the acetabulum
  double rim_radius_mm = 0;               ///< mean distance of the rim points from the rim centre
  double rim_plane_rms_mm = 0;            ///< rms distance of the rim points from their plane
  std::vector<Eigen::Vector3d> rim;       ///< rim points, one per azimuth bin with cup vertices
  double notch_coverage_deg = 0;          ///< the cup's extent from its pole at the notch
  double median_coverage_deg = 0;         ///< and its median over the rim
  std::int64_t cup_vertices = 0;          ///< pelvis vertices taken as the cup (within the sphere's radius + margin)
  ClockFace clock;                        ///< 12 superior, 3 anterior, 6 at the notch
};

/// A triangle belongs to the lunate surface when its outward normal faces the acetabular centre within
/// acos(kLunateFacing) = 45.6 deg and its centroid lies within kLunateBandMm of the acetabular sphere.
inline constexpr double kLunateFacing = 0.7;
/// Half-width of the band about the acetabular sphere that holds the lunate surface, mm: wider than an MRI
/// socket's roughness about its sphere (0.5-0.9 mm rms on the shared hips), narrower than the fossa's depth
/// below it (3-5 mm).
inline constexpr double kLunateBandMm = 1.5;

/// Find the acetabulum of `pelvis` (working frame, mm) around the femoral head (centre
/// `head_centre`, radius `head_radius_mm`) of a hip on `side`, with the pelvic frame `pelvis_frame`
/// (for superior and anterior):
/// 1. joint space: the mode of the head-facing triangles' distance from the head sphere (area-weighted,
///    within [-3, 12] mm; 2-6 mm on the shared hips' CT and MRI);
/// 2. sphere: from the head-centred sphere at that distance, the sphere of the surface facing its centre
///    within kLunateBandMm (Tukey's biweight, kLunateFacing; reweighted to its fixed point): the lunate surface whole, whatever the joint space, without the deeper fossa or the
///    rim's flare; the acetabular centre onto which Puls et al. 2010's equidistant method seats the head.
///    (Until 2026-11 the fit took the vertices within the head radius + 4 mm, which left out 40-97 % of
///    an MRI socket whose joint space is 3.5-6 mm.) The surface, not its vertices or triangles
///    (fit_sphere_to_surface, concave, band kLunateBandMm, facing kLunateFacing): a file that renumbers,
///    duplicates or splits them gives the same sphere;
/// 3. cup: pelvis vertices within the sphere's radius + `cup_margin_mm` of its centre;
/// 4. rim: in each 5-degree azimuth bin about the cup's axis, the cup vertex farthest from the
///    cup's pole (the edge where the bone leaves the head); the rim plane by least squares;
/// 5. notch: the azimuth, in the inferior half, where the cup's extent (smoothed over 45 deg) is least:
///    6 o'clock; 12 opposite; 3 anterior.
/// Throws impinge::Error naming the mesh when no surface faces the head, fewer than 20 triangles lie on
/// the sphere, fewer than 50 cup vertices or 36 rim points are found (is the head in the acetabulum?).
Acetabulum find_acetabulum(const TriangleMesh& pelvis, const Eigen::Vector3d& head_centre, double head_radius_mm,
                           const AnatomicalFrame& pelvis_frame, double cup_margin_mm = 6.0);

/// Radiographic orientation of the acetabulum (Murray 1993, J Bone Joint Surg Br 75:228): the
/// angles of its opening (the rim plane's normal, out of the acetabulum), degrees.
struct AcetabularOrientation {
  double inclination_deg = 0;  ///< between the longitudinal axis and the opening, in the coronal plane (normal ~40-50)
  double anteversion_deg = 0;  ///< between the opening and the coronal plane (normal ~10-25)
};

/// The radiographic inclination and anteversion of `acetabulum` (working frame) in the pelvic frame
/// `pelvis_frame` (ISB: X anterior, Y superior, Z right), mirrored for a left `side` so that both
/// sides read the same: with n the opening in pelvic axes and m = +1 right, -1 left,
/// inclination = atan2(m n_Z, -n_Y), anteversion = asin(n_X). Never throws.
AcetabularOrientation radiographic_orientation(const Acetabulum& acetabulum, const AnatomicalFrame& pelvis_frame,
                                               Side side);

/// The femoral neck axis (unit, from the neck towards the head; same frame as `femur`, mm): the line through the head
/// centre `c` and the centre of the neck's narrowest cross-section (Reikeras et al. 1983, Acta Orthop Scand 54:18):
/// the femur cut by planes normal to the axis, 8 mm inside the head radius `r` to 16 mm beyond it every 0.5 mm, the
/// closed loop nearest the axis in each, the least perimeter's loop centroid (by length) taken as the neck's centre,
/// the axis through it, repeated until it moves less than 1e-7 (at most 20 times) from `seed` (unit, the same
/// direction roughly). The seed back when no section is found or the result turns more than 30 deg from it (a short
/// or cut femur). Throws impinge::Error when c, r or seed is not finite.
Eigen::Vector3d femoral_neck_axis(const TriangleMesh& femur, const Eigen::Vector3d& c, double r,
                                  const Eigen::Vector3d& seed);

/// The femoral head-neck clock face (femur frame, working coordinates, mm): centre at the head
/// centre, axis the femoral neck axis (femoral_neck_axis, seeded by the direction from the area-weighted centroid
/// of the femur's surface 4 to 12 mm outside the head sphere to the head centre: triangles in the shell by their
/// centroids, weighted by area, so that the tessellation does not move it), 12 o'clock towards the femoral frame's
/// +y (superior) and 3 towards +x (anterior), both projected onto the plane normal to the axis. Throws
/// impinge::Error naming the mesh when no neck triangles are found.
ClockFace femoral_clock_face(const TriangleMesh& femur, const Eigen::Vector3d& head_centre, double head_radius_mm,
                             const AnatomicalFrame& femur_frame);

}  // namespace impinge
