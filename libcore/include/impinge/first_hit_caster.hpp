#pragma once
/// @file first_hit_caster.hpp
/// The exact first hit along a ray from the centre of rotation: the resolver of look-ups at depth
/// discontinuities (depth_discontinuity.hpp). Embree 3 when the build has it (a BVH in float,
/// hit distances within ~2e-5 mm of the exact ones for meshes within ~200 mm of the COR), CGAL's
/// AABB tree otherwise (double).

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>

#include "impinge/mesh.hpp"

namespace impinge {

/// Rays from a fixed origin (the COR) against one mesh. Queries are const and thread-safe.
class FirstHitCaster {
 public:
  /// True when this build has a ray caster (Embree or CGAL).
  static bool available();
  /// Build the BVH of `mesh` (mm) for rays from `origin` (mm). Throws impinge::Error when no ray
  /// caster is in this build or the mesh is invalid (naming it).
  FirstHitCaster(const TriangleMesh& mesh, const Eigen::Vector3d& origin);
  ~FirstHitCaster();
  FirstHitCaster(FirstHitCaster&&) noexcept;
  FirstHitCaster& operator=(FirstHitCaster&&) noexcept;

  /// Distance (mm) from the origin along `direction` (any nonzero length) to the nearest hit of
  /// the mesh; +infinity when the ray misses.
  double first_hit(const Eigen::Vector3d& direction) const;
  /// "embree" or "cgal".
  const std::string& backend() const;
  /// Triangles whose plane passes through the origin (to 1e-6 of their distance): a ray from the
  /// origin meets them only inside their plane, where Embree's float intersection gives distances
  /// of no meaning (2 mm hits on the radial rim of a 24.5 mm cup). They are kept out of the BVH
  /// and intersected in double, with the in-plane case as the first crossing of their edges.
  std::int64_t edge_on_triangles() const { return edge_on_; }

 private:
  std::int64_t edge_on_ = 0;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace impinge
