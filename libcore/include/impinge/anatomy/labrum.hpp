#pragma once
/// @file labrum.hpp
/// The acetabular labrum as a soft-tissue body: a ring of triangular cross-section along the acetabular rim,
/// its base on the rim's bone and its apex (the free margin) continuing the socket's articular surface past the
/// bony rim. The labrum is a fibrocartilaginous ring attached to the bony rim and, across the acetabular notch,
/// to the transverse acetabular ligament; its cut surfaces are mostly triangles (Won et al. 2003, Yonsei Med J
/// 44:855: 432 cut surfaces of 54 cadaveric labra; Abe et al. 2000, Radiology 216:576: triangular in 80 % of 382
/// MR segments of asymptomatic hips). Adding it to a bone-only collision model lowered the simulated internal
/// rotation of the flexion-adduction-internal rotation examination by a median 18 deg (IQR 15-25) in 19 CT
/// arthrograms (PMC7754612).

#include <string>

#include "impinge/anatomy/clock_face.hpp"
#include "impinge/core/mesh.hpp"
#include "impinge/core/range.hpp"

namespace impinge {

/// The labrum's base width on the rim, mm: the average width of the adult acetabular labrum in 55 embalmed
/// hips, 5.3 mm (SD 2.6; Tan et al. 2001, Am J Orthop 30:809, PubMed 11757858 abstract).
inline constexpr double kLabrumWidthMm = 5.3;
/// The labrum's height (base to free margin), mm: the average height of the anterior labrum's cut surfaces,
/// 7.0 and 7.4 mm at the two anterior sites of 54 cadaveric labra, 4.0-6.8 mm at the other six (Won et al.
/// 2003, Yonsei Med J 44:855, abstract); the anterior value is taken because the contacts of flexion with
/// internal rotation lie anterosuperiorly (PMC7754612).
inline constexpr double kLabrumHeightMm = 7.0;

/// The labrum asked for (the session's --labrum, --labrum-width and --labrum-height).
struct LabrumOptions {
  bool enabled = false;                  ///< build the labrum and report labral limits beside the bony ones
  double width_mm = kLabrumWidthMm;      ///< base width on the rim, mm
  double height_mm = kLabrumHeightMm;    ///< apex height above the base, mm
  static constexpr Range kWidthRange{0, 15, true};   ///< of width_mm: (0, 15] mm
  static constexpr Range kHeightRange{0, 15, true};  ///< of height_mm: (0, 15] mm
};

/// The labrum of `acetabulum` (its sphere centre c and radius R, rim points, opening n; any one frame, mm) as a
/// closed, consistently outward-oriented triangle mesh (a ring, genus 1) of 3 m vertices and 6 m triangles for
/// m rim points. Each rim point p (in the order of its azimuth about n through the rim centre) gives one
/// cross-section in the plane through c spanned by u = (p - c) / |p - c| and n:
/// - inner base corner I = c + R u: on the acetabular sphere, where the lunate surface meets the rim;
/// - outer base corner O = c + (R + width) u: the base I-O lies across the rim's bone along the ray from c
///   through the rim point, `width_mm` long;
/// - apex A = I + height t, with t the unit tangent of the sphere at I in that plane pointing out of the
///   acetabulum (t = (n - (n.u) u) normalised): the inner face I-A continues the socket's articular surface
///   tangentially past the bony rim (beyond a hemisphere it turns towards the axis, embracing the head), and
///   lies outside the sphere (|A - c| = sqrt(R^2 + height^2)), so the labrum is never nearer the head than the
///   lunate surface; the cross-section is a right triangle of base `width_mm` and height `height_mm`.
/// The ring runs across the acetabular notch too (the labrum and the transverse acetabular ligament form one
/// ring). Throws impinge::Error naming `source` when a dimension lies outside LabrumOptions' ranges, the sphere
/// is not finite, or fewer than 8 rim points are given. Source: impinge (issue 81).
TriangleMesh make_labrum(const Acetabulum& acetabulum, double width_mm, double height_mm, const std::string& source);

}  // namespace impinge
