#pragma once
/// @file convex_hull.hpp
/// Convex hull of a point set through CGAL (`CGAL::convex_hull_3`, quickhull with exact
/// predicates), with the hull's vertices and triangles given as indices into the input. The
/// points strictly inside the hull of 26 extreme points are left out first (Akl and Toussaint
/// 1978, Inf. Process. Lett. 7:219): they lie on no face of the whole hull.

#include <Eigen/Core>
#include <vector>

#include "impinge/core/mesh.hpp"

namespace impinge {

/// A convex hull: triangles whose corners index the input points, oriented outwards.
struct ConvexHull {
  std::vector<Eigen::Index> vertices;  ///< indices of the input points on the hull
  Faces triangles;                     ///< h x 3 indices into the input points, counter-clockwise seen from outside
};

/// True when this build has CGAL (convex_hull works); false otherwise.
bool have_convex_hull();

/// Convex hull of the points P (n x 3, mm; any frame). Exact predicates
/// (CGAL::Exact_predicates_inexact_constructions_kernel), so the result does not depend on
/// the order or rigid placement of the points beyond rounding of the input coordinates.
/// Throws impinge::Error when n < 4, the points are coplanar, a coordinate is not finite,
/// or the build has no CGAL.
ConvexHull convex_hull(PointsRef P);

}  // namespace impinge
