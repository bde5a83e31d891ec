#pragma once
/// @file mesh.hpp
/// Triangle mesh: vertex positions and triangle indices, plus validation and per-vertex areas.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace impinge {

/// Row-major matrices so that one vertex / one face is contiguous in memory.
using Vertices = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;  ///< V: n x 3, mm
using Faces = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;        ///< F: m x 3, 0-based

/// The array convention at the API: a point set is a read-only reference to a row-major n x 3
/// double matrix (mm). A Vertices binds to it without a copy, and so does an Eigen::Map of a
/// C-contiguous float64 (n, 3) numpy array (the Python module's layout); any other layout (a
/// column-major matrix, a block) is copied into a temporary by Eigen.
using PointsRef = Eigen::Ref<const Vertices>;

/// A triangle mesh. Invariants after `validate_mesh`: n >= 3 vertices, every coordinate
/// finite, every index in [0, n), m >= 1 triangles.
struct TriangleMesh {
  Vertices V;                        ///< n x 3 vertex positions, mm, in the frame of the file it came from
  Faces F;                           ///< m x 3 vertex indices (counter-clockwise not required)
  std::string source;                ///< file name (or generator name) used in error messages
  int degenerate_faces_skipped = 0;  ///< zero-area triangles removed while loading
};

/// Check the invariants of `mesh` and throw impinge::Error naming `mesh.source` and the first
/// offending element (vertex with a non-finite coordinate, face with an out-of-range index,
/// empty mesh).
void validate_mesh(const TriangleMesh& mesh);

/// Remove triangles whose area is below `min_area_mm2` or which repeat a vertex index;
/// returns how many were removed and adds that to `mesh.degenerate_faces_skipped`. Validates the
/// mesh first (validate_mesh throws impinge::Error on a bad index or coordinate).
int remove_degenerate_faces(TriangleMesh& mesh, double min_area_mm2 = 1e-12);

/// The part of `mesh` made of the triangles whose three corners have keep_vertex[i] != 0,
/// with its vertices renumbered in order of first use. `kept` (optional) receives, for each new
/// vertex, its index in `mesh`. Throws impinge::Error when keep_vertex.size() != n or the mesh is
/// invalid (validate_mesh).
TriangleMesh submesh(const TriangleMesh& mesh, const std::vector<std::uint8_t>& keep_vertex,
                     std::vector<Eigen::Index>* kept = nullptr);

/// The number of directed edges (a, b) of `mesh`'s triangles (3 m in all) that do not occur exactly once with
/// exactly one reverse (b, a): 0 for a closed, consistently wound surface (each edge shared by two triangles
/// that run it opposite ways), more for an open, inconsistently wound or non-manifold one. Stops counting
/// once `stop_after` are found (the default counts all). Outgoing edges per vertex in compressed rows: O(m)
/// for bounded valence. Throws impinge::Error when a corner index is outside 0..n-1.
std::int64_t count_unpaired_directed_edges(const TriangleMesh& mesh,
                                           std::int64_t stop_after = std::numeric_limits<std::int64_t>::max());

/// Make the triangles' winding consistent across the edges they share: within each edge-connected part
/// (across edges of exactly two triangles), the triangles wound against the majority of their part are
/// flipped (two corners swapped), so a file whose triangles face in and out at random reads as one surface
/// (the signed distance's sign comes from the winding). Vertices and the triangles' order are kept. Returns
/// the number of triangles flipped (0 for a consistent mesh); `conflicts` (optional) receives the number of
/// shared edges no flip can make consistent (a non-orientable part such as a Moebius strip). O(m log m).
std::int64_t orient_consistently(TriangleMesh& mesh, std::int64_t* conflicts = nullptr);

/// Per-vertex area (mm^2): one third of the area of every incident triangle (barycentric dual
/// area), so the sum over vertices equals the surface area. Returns n values. Validates the mesh
/// first (impinge::Error on a bad index or coordinate).
Eigen::VectorXd vertex_areas(const TriangleMesh& mesh);

/// Every triangle of `m` (n x 3 vertices, m x 3 faces, mm) split in four at its edges' midpoints, a midpoint shared
/// between the triangles on either side of its edge: the same surface with 4 m triangles and n + (edges) vertices.
/// Face f becomes faces 4f..4f+3 (the three corners' triangles, then the middle one), wound as f; `source` is kept.
/// Does not validate (an out-of-range index is the caller's to check). Source: impinge (issue 81: the tessellation
/// tests; the plan's finer labrum).
TriangleMesh split_in_four(const TriangleMesh& m);

}  // namespace impinge
