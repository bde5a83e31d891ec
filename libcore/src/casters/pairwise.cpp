#include "impinge/casters/pairwise.hpp"

#include <vector>

#include "impinge/core/error.hpp"

#ifdef IMPINGE_HAVE_CGAL
#include <CGAL/Simple_cartesian.h>
#include <CGAL/intersections.h>
#endif

namespace impinge {

namespace {
Eigen::Matrix<double, Eigen::Dynamic, 9, Eigen::RowMajor> region_triangles(const TriangleMesh& m,
                                                                           const Eigen::Vector3d& cor, double radius) {
  validate_mesh(m);
  std::vector<Eigen::Index> keep;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      if ((m.V.row(m.F(f, k)).transpose() - cor).norm() <= radius) {
        keep.push_back(f);
        break;
      }
  Eigen::Matrix<double, Eigen::Dynamic, 9, Eigen::RowMajor> T(static_cast<Eigen::Index>(keep.size()), 9);
  for (std::size_t i = 0; i < keep.size(); ++i)
    for (int k = 0; k < 3; ++k)
      T.block<1, 3>(static_cast<Eigen::Index>(i), 3 * k) = m.V.row(m.F(keep[i], k)) - cor.transpose();
  return T;
}
}  // namespace

PairwiseJoint::PairwiseJoint(const TriangleMesh& ball, const TriangleMesh& socket, const Eigen::Vector3d& cor,
                             double region_radius_mm) {
#ifndef IMPINGE_HAVE_CGAL
  require(false, "pairwise: this build has no CGAL (install libcgal-dev and reconfigure); mesh " + ball.source);
#endif
  require(cor.allFinite(), "pairwise: centre of rotation is not finite");
  require(region_radius_mm > 0, "pairwise: region radius must be > 0 mm");
  ball_ = region_triangles(ball, cor, region_radius_mm);
  socket_ = region_triangles(socket, cor, region_radius_mm);
}

PairwiseResult PairwiseJoint::intersect(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) const {
  PairwiseResult r;
  r.ball_triangles = ball_.rows();
  r.socket_triangles = socket_.rows();
#ifdef IMPINGE_HAVE_CGAL
  using K = CGAL::Simple_cartesian<double>;
  auto tri = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    return K::Triangle_3(K::Point_3(a.x(), a.y(), a.z()), K::Point_3(b.x(), b.y(), b.z()),
                         K::Point_3(c.x(), c.y(), c.z()));
  };
  std::vector<K::Triangle_3> socket;
  socket.reserve(static_cast<std::size_t>(socket_.rows()));
  for (Eigen::Index j = 0; j < socket_.rows(); ++j)
    socket.push_back(tri(socket_.block<1, 3>(j, 0).transpose(), socket_.block<1, 3>(j, 3).transpose(),
                         socket_.block<1, 3>(j, 6).transpose()));
  for (Eigen::Index i = 0; i < ball_.rows(); ++i) {
    const K::Triangle_3 a =
        tri(R * ball_.block<1, 3>(i, 0).transpose() + t, R * ball_.block<1, 3>(i, 3).transpose() + t,
            R * ball_.block<1, 3>(i, 6).transpose() + t);
    for (const K::Triangle_3& b : socket) r.intersecting_pairs += CGAL::do_intersect(a, b) ? 1 : 0;
  }
  r.pairs_tested = r.ball_triangles * r.socket_triangles;
#else
  (void)R, (void)t;
#endif
  return r;
}

}  // namespace impinge
