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
#include <utility>
#include <vector>

#include "impinge/casters/embree_ray_caster.hpp"
#include "impinge/core/mesh.hpp"
#include "impinge/maps/ray_crossing.hpp"

namespace impinge {

/// Crossings from raw ray hits: `hits` (distance mm, cosine of the triangle's winding normal with the
/// ray; any order) merged as FirstHitCaster::crossings does (hits within 1e-4 mm: one crossing by the
/// majority of their facings, none when they cancel), facings multiplied by `orientation` (+1 or -1).
/// For exact references built on ExactReference::all_hits.
std::vector<RayCrossing> crossings_from_hits(std::vector<std::pair<double, double>> hits, int orientation);

/// Rays from a fixed origin (the COR) against one mesh. Queries are const and thread-safe.
class FirstHitCaster {
 public:
  /// True when this build has a ray caster (Embree or CGAL).
  static bool available();
  /// Build the BVH of `mesh` (mm) for rays from `origin` (mm). `build`: Embree's builder (HierarchyBuild:
  /// `fast` for the few rays of one pose; the same hits either way; CGAL's tree ignores it). Throws
  /// impinge::Error when no ray caster is in this build or the mesh is invalid (naming it).
  FirstHitCaster(const TriangleMesh& mesh, const Eigen::Vector3d& origin,
                 HierarchyBuild build = HierarchyBuild::quality);
  ~FirstHitCaster();
  FirstHitCaster(FirstHitCaster&&) noexcept;
  FirstHitCaster& operator=(FirstHitCaster&&) noexcept;

  /// Distance (mm) from the origin along `direction` (any nonzero length) to the nearest hit of
  /// the mesh; +infinity when the ray misses.
  double first_hit(const Eigen::Vector3d& direction) const;
  /// first_hit(direction) when that is nearer than `within_mm` (mm, any value; <= 0: nothing is), and a value
  /// >= within_mm (+infinity) otherwise: the rays end at within_mm, so the traversal visits less of the tree
  /// (the question "is anything in front of this point?" of the first-surface mask). Source: impinge (issue 52).
  double first_hit(const Eigen::Vector3d& direction, double within_mm) const;
  /// Every crossing of the ray from the origin along `direction` (any nonzero length) with the
  /// surface, nearest first, into `out` (cleared first). Hits within 1e-4 mm of each other (a ray
  /// through a shared edge or vertex, or grazing a silhouette) are merged into one crossing whose
  /// side is the majority of their facings, or dropped when the facings cancel (a graze touches the
  /// surface without crossing it). Facing is by the triangles' winding, made outward by the sign of
  /// the mesh's volume (so a mesh wound inward is read the right way round). Triangles edge-on to
  /// the origin are met only in their plane and are left out. A ray whose crossings cannot be those of a
  /// closed surface (not alternating, not ending outside, or starting on the wrong side of the origin:
  /// Embree can lose a crossing where the ray passes exactly through a shared vertex) is replaced by
  /// the first of two rays 1e-6 rad beside it that reads consistently, if any. Thread-safe.
  void crossings(const Eigen::Vector3d& direction, std::vector<RayCrossing>& out) const;
  /// +1 when the mesh is wound outward (signed volume >= 0), -1 when crossings() flips its facings.
  int orientation() const { return orientation_; }
  /// The rays' origin (mm, the mesh's frame).
  const Eigen::Vector3d& origin() const;
  /// Whether the origin lies inside the solid (the majority of 13 rays' first crossings).
  bool origin_inside() const { return origin_inside_; }
  /// Triangles whose plane passes through the origin (to 1e-6 of their distance): a ray from the
  /// origin meets them only inside their plane, where Embree's float intersection gives distances
  /// of no meaning (2 mm hits on the radial rim of a 24.5 mm cup). They are kept out of the BVH
  /// and intersected in double, with the in-plane case as the first crossing of their edges.
  std::int64_t edge_on_triangles() const { return edge_on_; }

 private:
  std::int64_t edge_on_ = 0;
  int orientation_ = 1;
  bool origin_inside_ = false;
  void raw_crossings(const Eigen::Vector3d& unit_direction, std::vector<RayCrossing>& out) const;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace impinge
