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

ConvexHull convex_hull(PointsRef P) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Point = K::Point_3;
  require(P.rows() >= 4, "convex hull: needs at least 4 points, got " + std::to_string(P.rows()));
  require(P.allFinite(), "convex hull: a point has a non-finite coordinate");
  using Mesh = CGAL::Surface_mesh<Point>;
  // Points strictly inside the hull of a few extreme points (along the 26 directions of a cube's
  // faces, edges and corners) are on no face of the whole hull: left out before the quickhull (Akl and
  // Toussaint 1978), by a margin far above the planes' rounding. The others keep their order.
  std::vector<Point> pts;
  pts.reserve(static_cast<std::size_t>(P.rows()));
  std::vector<Eigen::Index> kept;  // pts[k] is input point kept[k]
  {
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
      for (auto f : inner.faces()) {
        std::array<Eigen::Vector3d, 3> q;
        int k = 0;
        for (auto v : CGAL::vertices_around_face(inner.halfedge(f), inner)) {
          const Point& p = inner.point(v);
          if (k < 3) q[static_cast<std::size_t>(k)] = Eigen::Vector3d(p.x(), p.y(), p.z());
          ++k;
        }
        const Eigen::Vector3d n = (q[1] - q[0]).cross(q[2] - q[0]);
        if (k == 3 && n.norm() > 0) planes.emplace_back(n.normalized(), n.normalized().dot(q[0]));
      }
    const double scale = (P.colwise().maxCoeff() - P.colwise().minCoeff()).norm();
    const double margin = 1e-6 * scale;
    for (Eigen::Index i = 0; i < P.rows(); ++i) {
      const Eigen::Vector3d p = P.row(i).transpose();
      bool inside = !planes.empty();
      for (const auto& [n, offset] : planes)
        if (!(n.dot(p) - offset < -margin)) {
          inside = false;
          break;
        }
      if (inside) continue;
      pts.emplace_back(p.x(), p.y(), p.z());
      kept.push_back(i);
    }
  }
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
