#pragma once
/// @file pairwise.hpp
/// The thesis' exhaustive pair-wise impingement test (sec. 2.2 and Tables 4 and 9, "pair-wise
/// testing O(n^2)"): every ball triangle against every socket triangle. The baseline every
/// other detection method is compared with; its own sampling counterpart is sample_naive
/// (naive_sampling.hpp). Triangle-triangle test: CGAL::do_intersect on
/// Simple_cartesian<double> (built only with CGAL; `have_exact_reference()` says which).

#include <Eigen/Core>
#include <cstdint>
#include <limits>

#include "impinge/core/mesh.hpp"

namespace impinge {

/// Result of one exhaustive pair-wise test.
struct PairwiseResult {
  std::int64_t ball_triangles = 0, socket_triangles = 0;  ///< triangles in the region
  std::int64_t pairs_tested = 0;                          ///< ball_triangles x socket_triangles
  std::int64_t intersecting_pairs = 0;                    ///< pairs whose triangles intersect
};

/// Ball and socket triangles restricted once to a region about the COR, for repeated poses.
class PairwiseJoint {
 public:
  /// Keep the triangles with a vertex within `region_radius_mm` of `cor` (all by default).
  /// Throws impinge::Error without CGAL in this build, for invalid meshes or a non-finite COR.
  PairwiseJoint(const TriangleMesh& ball, const TriangleMesh& socket, const Eigen::Vector3d& cor,
                double region_radius_mm = std::numeric_limits<double>::infinity());
  /// Test every pair with the ball rotated by R about the COR and translated by t (mm).
  /// O(m n): seconds for 12k x 12k triangles.
  PairwiseResult intersect(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) const;
  /// Triangles kept in the region, per body.
  std::int64_t ball_triangles() const { return ball_.rows(); }
  std::int64_t socket_triangles() const { return socket_.rows(); }

 private:
  Eigen::Matrix<double, Eigen::Dynamic, 9, Eigen::RowMajor> ball_, socket_;  ///< corners relative to the COR
};

}  // namespace impinge
