// The connected parts of a bone's mesh and which of them are the bone (mesh_hygiene.hpp, steps 3-5). Private to the
// core layer.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "impinge/core/mesh.hpp"

namespace impinge::detail {

/// One connected part (across shared corners): its area, box, vertices, and what became of it.
struct Part {
  double area = 0;  ///< mm^2
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = Eigen::Vector3d::Constant(-INFINITY);
  std::vector<int> vertices;
  std::int64_t triangles = 0;
  bool kept = false;    ///< the bone's
  bool inside = false;  ///< enclosed by another kept part (an inner wall, a cyst, a speck inside): removed
};

int find_root(std::vector<int>& parent, int v);

/// Each face's part (0..parts-1, numbered by first face), across shared corners.
std::vector<int> face_parts(const TriangleMesh& mesh, int& parts);

/// The parts' area, box and vertices.
std::vector<Part> describe_parts(const TriangleMesh& mesh, const std::vector<int>& part, int parts);

/// The largest part by area; of equal areas the one whose box's lowest corner comes first (not the file's order).
std::size_t largest_part(const std::vector<Part>& p);

/// Mark the bone's parts kept: the largest, then every part with a vertex within gap_mm of a kept part's vertex,
/// breadth first over cells of gap_mm (each vertex visited once; a cell's parts listed apart). O(n) for bounded
/// cells.
void keep_bone_parts(const TriangleMesh& mesh, std::vector<Part>& p, double gap_mm);

/// The least vertex-to-vertex distance (mm) from part q to the kept parts: exact below 4e7 vertex pairs, else over
/// an even subsample of the kept vertices (an upper bound).
double distance_to_kept(const TriangleMesh& mesh, const std::vector<Part>& p, const Part& q);

/// Mark parts (kept or not: a cyst deep inside is more than the gap from the surface) enclosed by a kept, closed part (closed[j] != 0: no boundary edge; its generalised winding
/// number at one of their vertices at least 1/2 in magnitude) as inside and no longer kept; the largest part is never
/// inside, and an open part encloses nothing (a holed cup's winding number passes 1/2 in front of it). At most
/// `max_tested` parts are tested, largest first (exact winding numbers: O(m) each). Returns the parts so marked.
std::int64_t mark_enclosed_parts(const TriangleMesh& mesh, const std::vector<int>& part, std::vector<Part>& p,
                                 const std::vector<std::uint8_t>& closed, std::size_t max_tested);

}  // namespace impinge::detail
