#pragma once
/// @file face_culling.hpp
/// Which triangles of a mesh can be the nearest hit of a ray from the COR (issue 4's faster
/// rasteriser; not in the thesis). Along any ray from a point off a closed, consistently
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
#include <string>
#include <vector>

#include "impinge/mesh.hpp"

namespace impinge {

/// Result of the analysis, with the evidence.
struct FaceCulling {
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
};

/// Decide whether culling is exact for `mesh` about `cor` (mm), and order the triangles for
/// rasterisation. For culling, every directed edge must have
/// exactly one reverse edge (closed and consistently oriented), and the nearest hits of
/// `rays` brute-force rays (towards triangle centroids spread over the mesh) must all have one
/// orientation, which becomes keep_sign. Cost O(m) for the edges plus O(rays x m); a
/// once-per-mesh precomputation like building a BVH. Throws impinge::Error for an invalid
/// mesh or a non-finite COR.
FaceCulling analyse_face_culling(const TriangleMesh& mesh, const Eigen::Vector3d& cor, int rays = 8);

}  // namespace impinge
