#pragma once
/// @file mesh_hygiene.hpp
/// What a segmented bone's mesh carries besides the bone, and what impinge does with it at load (issue 80):
/// vertices stored twice, faces stored twice (a double wall: the same triangle again, either way round),
/// fragments apart from the bone (a skin marker, a segmentation speck) and holes. Source: impinge.
///
/// The rule (clean_bone_mesh), in order:
/// 1. Vertices at exactly the same position are one vertex for the faces (their corners move to the vertex of
///    lowest index; the rows stay, so the vertex count and order are kept).
/// 2. A face whose three corners another face already has, in either winding, is a double wall: the later one
///    is removed; so is a face (of edges up to 0.1 mm or longer) whose centroid lies within 0.01 mm of an earlier face's of another
///    connected part, in a parallel plane with the
///    same area to 1 % (a copy whose corners moved a little: reversed 1e-6 mm off, it read -4.0 mm for +0.40) (the winding is then made consistent by orient_consistently, outward by the volume's sign).
/// 3. The bone: the connected part (across shared corners) of largest area, and every part within
///    kBoneGapMm (10 mm, vertex to vertex) of a part already taken, repeatedly. The hemipelves (1.2-2.2 mm
///    apart at the pubic symphysis on the shared hips), a sacrum at its joints, specks on or inside the bone
///    are all within it; a marker or speck 50-400 mm away is not.
/// 4. A part left out with less than kFragmentAreaFraction (10 %) of the largest part's area is a fragment:
///    removed, and said (count, area, size, distance). A part left out with more is another bone (both femurs in
///    one file?): an error, as impinge cannot tell which one is meant. `strict`: a fragment is an error too.
///    4b. A kept part enclosed by another kept part (that part's generalised winding number at one of its vertices
///    at least 1/2 in magnitude: an inner cortical wall, a cyst's wall, a speck inside the bone) is removed and
///    said: the outer surface is what meets the other bone (an inner shell moved the head fit, alpha and version
///    and the equidistant centre by up to 13.7 mm). At most 256 parts are tested, largest first. `strict`: an error.
///    Then every vertex no face uses is removed too (an unused vertex 200 mm away moved the landmarks as a
///    fragment does); the vertices kept keep the file's order.
/// 5. Holes: the boundary edges (of one face) and the loops they form are counted; the distances' signs near
///    them come from the winding number, and where even that cannot tell, the vertex says so
///    (signed_distance.hpp, SignRule::undecided).
/// On the shared hips every pelvis keeps all its parts (lhdl-ct 2; mc22 21 and tlem2-mri 15: the hemipelves and
/// specks of 0-16 mm^2 each within 10 mm of one of them, or of a speck that is); of the femurs only mc22-left's
/// loses two parts, specks of under 0.001 mm^2 12.8 and 15.0 mm from it (its outputs move by 1e-9 relative).

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "impinge/core/mesh.hpp"

namespace impinge {

/// Parts within this distance (mm, vertex to vertex) of the bone belong to it (mesh_hygiene.hpp, step 3).
inline constexpr double kBoneGapMm = 10.0;
/// A part left out of the bone with less than this fraction of the largest part's area is a fragment (step 4).
inline constexpr double kFragmentAreaFraction = 0.1;

/// A connected part of a mesh left out of the bone.
struct MeshFragment {
  std::int64_t triangles = 0;
  double area_mm2 = 0;     ///< surface area, mm^2
  double extent_mm = 0;    ///< its size: the longest side of its bounding box, mm
  double distance_mm = 0;  ///< its least vertex-to-vertex distance from the kept bone, mm
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  ///< its bounding box's centre, mm, the mesh's frame
};

/// What clean_bone_mesh found and did (mesh_hygiene.hpp, the rule).
struct MeshHygiene {
  std::int64_t corners_welded = 0;          ///< face corners moved onto an earlier vertex at the same position
  std::int64_t duplicate_faces_removed = 0; ///< faces another face already had (either winding)
  std::int64_t components = 0;              ///< connected parts read (after 1-2)
  std::int64_t components_kept = 0;         ///< parts kept as the bone
  std::vector<MeshFragment> dropped;        ///< fragments removed, largest area first
  std::int64_t parts_inside_removed = 0;    ///< kept parts enclosed by another (step 4b), removed
  double inside_area_mm2 = 0;               ///< their area, mm^2
  std::int64_t unused_vertices_removed = 0; ///< vertices no face used (besides the removed parts' own)
  /// Every vertex removed (the removed parts' and the unused), as indices into the mesh as read, ascending: the
  /// per-vertex outputs hold the others, in order (np.delete(range(n), removed) maps them back to the file).
  std::vector<std::int64_t> removed_vertices;
  std::int64_t boundary_edges = 0;          ///< edges of exactly one face (after the clean-up)
  std::int64_t nonmanifold_edges = 0;       ///< edges of three or more faces
  std::int64_t boundary_loops = 0;          ///< holes: connected sets of boundary edges
  /// One line per repair (fragments removed, faces removed, corners welded), naming `source`.
  std::vector<std::string> warnings(const std::string& source) const;
};

/// Clean a bone's mesh as mesh_hygiene.hpp's rule says, in place: faces re-pointed (1), removed (2, 4), the
/// vertices only fragments used removed (the others keep their order). `source` names the file in errors.
/// `strict`: a fragment or a double wall is an error instead of a repair. Throws impinge::Error when another
/// bone's worth of surface lies apart from the largest part (naming both areas and the distance), when
/// `strict` finds something to repair, or when the mesh is invalid (validate_mesh). O(m log m).
MeshHygiene clean_bone_mesh(TriangleMesh& mesh, const std::string& source, bool strict = false);

/// The boundary (one face) and non-manifold (three or more faces) edges of `mesh` and the loops the boundary
/// edges form (connected through shared corners), into `out`'s boundary_edges, nonmanifold_edges and
/// boundary_loops. O(m log m).
void count_holes(const TriangleMesh& mesh, MeshHygiene& out);

/// The diagonal (file units) of the box of the central 99.8 % of the vertices V (n x 3) along each axis: a bone's size
/// for a units check that a fragment or stray vertex far away (which clean_bone_mesh removes) does not sway. O(n).
double central_span(const Vertices& V);

/// The boundary edges (of one face) of `mesh` whose two ends lie within `radius_mm` of `centre` (mm, the mesh's
/// frame): a hole there (e.g. in the lunate surface, which the acetabular and equidistant joint centres are fitted
/// to). O(m log m).
std::int64_t boundary_edges_within(const TriangleMesh& mesh, const Eigen::Vector3d& centre, double radius_mm);

/// The generalised winding number of `mesh` at q (mm; Jacobson, Kavan & Sorkine-Hornung 2013, solid angles by van
/// Oosterom & Strackee 1983), exact: the sum over every triangle, O(m). +-1 inside a closed surface (the sign is
/// the winding's), 0 outside; a hole of solid angle W seen from q moves it by W / 4 pi. For a one-off test (is a
/// point inside a bone with holes?); SignedDistanceQuery has the hierarchical one for many points.
double winding_number(const TriangleMesh& mesh, const Eigen::Vector3d& q);

}  // namespace impinge
