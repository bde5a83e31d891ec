#include "impinge/anatomy/convex_hull.hpp"

#include <string>

#include "impinge/core/error.hpp"

#ifdef IMPINGE_HAVE_CGAL
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/convex_hull_3.h>

#include <algorithm>
#include <array>
#include <limits>
#endif

namespace impinge {

#ifdef IMPINGE_HAVE_CGAL
bool have_convex_hull() { return true; }

namespace {
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;

// The corners of each triangle of a CGAL hull, through `corner` (Point -> T).
template <typename T, typename Corner>
std::vector<std::array<T, 3>> hull_triangles(const Mesh& hull, Corner corner) {
  std::vector<std::array<T, 3>> out;
  for (auto face : hull.faces()) {
    int k = 0;
    std::array<T, 3> t{};
    for (auto v : CGAL::vertices_around_face(hull.halfedge(face), hull)) {
      require(k < 3, "convex hull: a hull face is not a triangle");
      t[static_cast<std::size_t>(k++)] = corner(hull.point(v));
    }
    out.push_back(t);
  }
  return out;
}

// The indices of the points of P not strictly inside the hull of its extreme points along the 26
// directions of a cube's faces, edges and corners (in order): those inside lie on no face of the whole
// hull (Akl and Toussaint 1978). "Strictly" by a margin of 1e-6 x the points' extent, far above the
// planes' rounding.
std::vector<Eigen::Index> beyond_extreme_hull(PointsRef P) {
  std::vector<Eigen::Vector3d> dirs;
  for (int a = -1; a <= 1; ++a)
    for (int b = -1; b <= 1; ++b)
      for (int c = -1; c <= 1; ++c)
        if (a != 0 || b != 0 || c != 0) dirs.emplace_back(a, b, c);
  std::vector<Eigen::Index> extreme(dirs.size(), 0);
  std::vector<double> most(dirs.size(), -std::numeric_limits<double>::infinity());
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    const Eigen::Vector3d p = P.row(i).transpose();
    for (std::size_t k = 0; k < dirs.size(); ++k) {
      const double x = p.dot(dirs[k]);
      if (x > most[k]) most[k] = x, extreme[k] = i;
    }
  }
  std::sort(extreme.begin(), extreme.end());
  extreme.erase(std::unique(extreme.begin(), extreme.end()), extreme.end());
  std::vector<Point> ext;
  for (Eigen::Index i : extreme) ext.emplace_back(P(i, 0), P(i, 1), P(i, 2));
  Mesh inner;
  if (ext.size() >= 4) CGAL::convex_hull_3(ext.begin(), ext.end(), inner);
  std::vector<std::pair<Eigen::Vector3d, double>> planes;  // unit outward normal, offset
  if (inner.number_of_faces() >= 4)
    for (const auto& q : hull_triangles<Eigen::Vector3d>(inner, [](const Point& p) { return Eigen::Vector3d(p.x(), p.y(), p.z()); })) {
      const Eigen::Vector3d n = (q[1] - q[0]).cross(q[2] - q[0]);
      if (n.norm() > 0) planes.emplace_back(n.normalized(), n.normalized().dot(q[0]));
    }
  const double margin = 1e-6 * (P.colwise().maxCoeff() - P.colwise().minCoeff()).norm();
  std::vector<Eigen::Index> kept;
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    const Eigen::Vector3d p = P.row(i).transpose();
    const bool inside = !planes.empty() && std::all_of(planes.begin(), planes.end(), [&](const auto& plane) {
      return plane.first.dot(p) - plane.second < -margin;
    });
    if (!inside) kept.push_back(i);
  }
  return kept;
}
}  // namespace

ConvexHull convex_hull(PointsRef P) {
  require(P.rows() >= 4, "convex hull: needs at least 4 points, got " + std::to_string(P.rows()));
  require(P.allFinite(), "convex hull: a point has a non-finite coordinate");
  const std::vector<Eigen::Index> kept = beyond_extreme_hull(P);  // pts[k] is input point kept[k]
  std::vector<Point> pts;
  pts.reserve(kept.size());
  for (Eigen::Index i : kept) pts.emplace_back(P(i, 0), P(i, 1), P(i, 2));
  // The hull as a Surface_mesh whose vertices carry their input index.
  Mesh hull;
  CGAL::convex_hull_3(pts.begin(), pts.end(), hull);
  require(hull.number_of_faces() >= 4, "convex hull: the points are coplanar (no 3-D hull)");
  // Map hull points back to input indices (the hull copies input coordinates exactly).
  std::vector<std::pair<Point, Eigen::Index>> sorted;
  sorted.reserve(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) sorted.emplace_back(pts[i], kept[i]);
  std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  auto index_of = [&](const Point& p) {
    const auto it = std::lower_bound(sorted.begin(), sorted.end(), p,
                                     [](const auto& a, const Point& q) { return a.first < q; });
    require(it != sorted.end() && it->first == p, "convex hull: a hull vertex is not an input point");
    return it->second;
  };
  ConvexHull out;
  for (auto v : hull.vertices()) out.vertices.push_back(index_of(hull.point(v)));
  const auto triangles = hull_triangles<Eigen::Index>(hull, index_of);
  out.triangles.resize(static_cast<Eigen::Index>(triangles.size()), 3);
  for (std::size_t f = 0; f < triangles.size(); ++f)
    for (int c = 0; c < 3; ++c) out.triangles(static_cast<Eigen::Index>(f), c) = static_cast<int>(triangles[f][static_cast<std::size_t>(c)]);
  return out;
}
#else
bool have_convex_hull() { return false; }
ConvexHull convex_hull(PointsRef) {
  throw Error("convex hull: this build has no CGAL (tools/install-deps installs libcgal-dev)");
}
#endif

}  // namespace impinge
