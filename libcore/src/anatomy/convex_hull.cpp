#include "impinge/anatomy/convex_hull.hpp"

#include <string>

#include "impinge/core/error.hpp"

#ifdef IMPINGE_HAVE_CGAL
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/convex_hull_3.h>

#include <array>
#endif

namespace impinge {

#ifdef IMPINGE_HAVE_CGAL
bool have_convex_hull() { return true; }

ConvexHull convex_hull(PointsRef P) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Point = K::Point_3;
  require(P.rows() >= 4, "convex hull: needs at least 4 points, got " + std::to_string(P.rows()));
  require(P.allFinite(), "convex hull: a point has a non-finite coordinate");
  std::vector<Point> pts;
  pts.reserve(static_cast<std::size_t>(P.rows()));
  for (Eigen::Index i = 0; i < P.rows(); ++i) pts.emplace_back(P(i, 0), P(i, 1), P(i, 2));
  // The hull as a Surface_mesh whose vertices carry their input index.
  using Mesh = CGAL::Surface_mesh<Point>;
  Mesh hull;
  CGAL::convex_hull_3(pts.begin(), pts.end(), hull);
  require(hull.number_of_faces() >= 4, "convex hull: the points are coplanar (no 3-D hull)");
  // Map hull points back to input indices (the hull copies input coordinates exactly).
  std::vector<std::pair<Point, Eigen::Index>> sorted;
  sorted.reserve(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) sorted.emplace_back(pts[i], static_cast<Eigen::Index>(i));
  std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  auto index_of = [&](const Point& p) {
    const auto it = std::lower_bound(sorted.begin(), sorted.end(), p,
                                     [](const auto& a, const Point& q) { return a.first < q; });
    require(it != sorted.end() && it->first == p, "convex hull: a hull vertex is not an input point");
    return it->second;
  };
  ConvexHull out;
  for (auto v : hull.vertices()) out.vertices.push_back(index_of(hull.point(v)));
  out.triangles.resize(static_cast<Eigen::Index>(hull.number_of_faces()), 3);
  Eigen::Index f = 0;
  for (auto face : hull.faces()) {
    int k = 0;
    std::array<Eigen::Index, 3> idx{};
    for (auto v : CGAL::vertices_around_face(hull.halfedge(face), hull)) {
      require(k < 3, "convex hull: a hull face is not a triangle");
      idx[static_cast<std::size_t>(k++)] = index_of(hull.point(v));
    }
    for (int c = 0; c < 3; ++c) out.triangles(f, c) = static_cast<int>(idx[static_cast<std::size_t>(c)]);
    ++f;
  }
  return out;
}
#else
bool have_convex_hull() { return false; }
ConvexHull convex_hull(PointsRef) {
  throw Error("convex hull: this build has no CGAL (tools/install-deps installs libcgal-dev)");
}
#endif

}  // namespace impinge
