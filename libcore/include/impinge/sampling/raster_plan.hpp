#pragma once
/// @file raster_plan.hpp
/// A rasterisation plan: what can be prepared once per mesh and COR before rasterising it at any
/// precision (faster rasteriser; not in the thesis): which triangles can be the nearest hit
/// of a ray from the COR (face culling), in what order to draw them, and their cones set up.
///
/// Face culling: which triangles of a mesh can be the nearest hit of a ray from the COR. Along any ray from a point off a closed, consistently
/// oriented surface, hits alternate between entering and leaving the solid, so the first hit
/// always has the same orientation relative to the ray: entering when the COR is outside (the
/// pelvis seen from the hip centre), leaving when it is inside (the femoral head). The other
/// half of the triangles can never be the nearest hit and need not be rasterised.
///
/// The orientation is read off as det = a . (b x c) with a, b, c the corners relative to the
/// COR (six times the signed volume of the tetrahedron COR-a-b-c): culling keeps the triangles
/// whose det has `keep_sign`.

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "impinge/core/mesh.hpp"
#include "impinge/sampling/triangle_cone.hpp"

namespace impinge {

/// The plan for rasterising one mesh about one COR (plan_rasterization), with the evidence for its
/// culling. Formerly FaceCulling.
struct RasterPlan {
  bool enabled = false;             ///< true when culling is exact for this mesh and COR
  int keep_sign = 0;                ///< +1 or -1: keep triangles with sign(det) == keep_sign
  std::int64_t boundary_edges = 0;  ///< directed edges without exactly one reverse edge
  int rays_checked = 0;             ///< rays whose nearest hit was found by brute force
  int rays_agreeing = 0;            ///< of those, rays whose nearest hit has keep_sign
  std::string reason;               ///< why culling is disabled (empty when enabled)
  /// The triangles to rasterise (the kept ones when enabled, else all), in Z-curve order of
  /// their centroid's direction from the COR, so that consecutive triangles write the same
  /// cache lines of the map (a 100 MB map at 0.05 deg does not fit in cache).
  std::vector<std::int32_t> triangle_order;
  /// Exact-mode set-up of each triangle of triangle_order (same order) whose plane misses the
  /// COR, made once here so that rasterize() only turns angles into rows, columns and spans.
  /// Empty when the plan was made without cones (with_cones false): rasterize() then makes them
  /// a few thousand at a time as it draws them (the same map).
  std::vector<TriangleCone> cones;
  std::int64_t cones_edge_on = 0;  ///< triangles of triangle_order left out of cones (edge-on)
  bool with_cones = true;          ///< whether `cones` was made (plan_rasterization's with_cones)
  /// What the plan was made for; rasterize() refuses a plan whose mesh or COR differs.
  Eigen::Vector3d cor = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  std::uint64_t mesh_fingerprint = 0;  ///< mesh_fingerprint() of the mesh analysed
};

/// plan_rasterization's brute-force rays unless told otherwise.
inline constexpr int kPlanRays = 8;

/// A 64-bit fingerprint of a mesh's vertex coordinates (bit patterns), face indices and sizes:
/// any edit of a coordinate or index changes it with overwhelming probability. O(n + m), about
/// 0.1 ms for a 100k-triangle bone. Used to check that a plan belongs to the mesh it is used on.
std::uint64_t mesh_fingerprint(const TriangleMesh& mesh);

/// Decide whether culling is exact for `mesh` about `cor` (mm), and order the triangles for
/// rasterisation. For culling, every directed edge must have
/// exactly one reverse edge (closed and consistently oriented), and the nearest hits of
/// `rays` brute-force rays (towards triangle centroids spread over the mesh) must all have one
/// orientation, which becomes keep_sign. Also makes the triangles' cones (triangle_cone.hpp)
/// when `with_cones`: some 240 bytes a kept triangle (34 MB for a 280k-triangle femur), worth it
/// for a plan drawn many times (several resolutions); a plan drawn once (sample_surface's own)
/// leaves them to rasterize(), which makes them as it draws them, for the same map.
/// Cost O(m) for the edges and cones plus O(rays x m); a once-per-mesh precomputation like
/// building a BVH. Throws impinge::Error for an invalid
/// mesh or a non-finite COR.
RasterPlan plan_rasterization(const TriangleMesh& mesh, const Eigen::Vector3d& cor, int rays = kPlanRays,
                              bool with_cones = true);

}  // namespace impinge
