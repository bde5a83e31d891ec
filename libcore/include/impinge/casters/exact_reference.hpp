#pragma once
/// @file exact_reference.hpp
/// Exact geometric references for error figures: CGAL's AABB tree over a triangle mesh
/// (CGAL 5, Simple_cartesian<double>): first hit of a ray and closest-point distance.
/// Built only when CGAL is found (IMPINGE_HAVE_CGAL); the oracle of record for every error
/// figure on meshes.

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "impinge/core/mesh.hpp"

namespace impinge {

/// True when this build has CGAL (exact references available).
bool have_exact_reference();

/// AABB tree over one mesh. Construction O(m log m); queries O(log m) typical.
class ExactReference {
 public:
  /// Build the tree over `mesh` (mm). Throws impinge::Error if CGAL is not available in this
  /// build or the mesh is invalid.
  explicit ExactReference(const TriangleMesh& mesh);
  ~ExactReference();
  ExactReference(ExactReference&&) noexcept;
  ExactReference& operator=(ExactReference&&) noexcept;

  /// Distance (mm) from `origin` along unit `direction` to the nearest intersection with the
  /// mesh, or nullopt when the ray misses (CGAL AABB_tree::first_intersection).
  std::optional<double> first_hit(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const;
  /// Every crossing of the ray from `origin` along unit `direction` with the mesh, sorted by
  /// distance: (distance mm, cosine of the angle between the triangle's normal (corner order
  /// a, b, c: (b - a) x (c - a), normalised) and the direction), one per triangle met
  /// (AABB_tree::all_intersections); a ray in a triangle's plane gives the nearer end of the segment
  /// and cosine 0. Empty when the ray misses. Source: impinge (layered maps; not in the thesis).
  std::vector<std::pair<double, double>> all_hits(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const;
  /// Distance (mm) from `p` to the closest point of the mesh (AABB_tree::closest_point).
  double closest_distance(const Eigen::Vector3d& p) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Nearest-neighbour index over a point set (CGAL kd-tree, Orthogonal_k_neighbor_search): the
/// exact reference for "distance from a surface point to its nearest sample point" (Eq. 7).
class PointCloudIndex {
 public:
  /// P: k x 3 points (mm). Throws impinge::Error without CGAL or when P is empty.
  explicit PointCloudIndex(const std::vector<Eigen::Vector3d>& points);
  ~PointCloudIndex();
  PointCloudIndex(PointCloudIndex&&) noexcept;
  PointCloudIndex& operator=(PointCloudIndex&&) noexcept;
  /// Distance (mm) from q to the nearest point of the set.
  double nearest_distance(const Eigen::Vector3d& q) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace impinge
