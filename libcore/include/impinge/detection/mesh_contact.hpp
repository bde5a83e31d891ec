#pragma once
/// @file mesh_contact.hpp
/// The exact least distance between two triangle meshes, one of them posed rigidly: every pair of
/// triangles within reach, vertex against face AND edge against edge (and a crossing is distance 0), so
/// that the result does not depend on where the vertices lie: the same surface tessellated otherwise
/// gives the same distance (issue 81: a per-vertex test sees a vertex of one bone against the other's
/// surface, but not an edge of one crossing an edge of the other between vertices).
/// Source: impinge; the closest points of Ericson, Real-Time Collision Detection (2005), sec. 5.1.
///
/// Each mesh is held in a tree of axis-aligned boxes (median splits, up to 4 triangles a leaf), built
/// once; a query walks both trees together and prunes a pair of nodes whose bounds (the box of either's
/// counted faces against the other's box) lie farther apart than the reach or the least distance found so
/// far, and a pair of faces whose bounding spheres, or one of which beyond the other's plane, lie so far
/// apart (true lower bounds less 1e-6 mm: no answer changes, only the time).

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

#include "impinge/core/mesh.hpp"

namespace impinge {

/// The closest points of triangles A = (a0, a1, a2) and B = (b0, b1, b2) (mm): their distance, 0 when
/// they touch or cross (then pa = pb is a point of both), with the closest point of each in pa and pb.
/// Degenerate triangles (zero area) are taken as their edges. Source: Ericson 2005, sec. 5.1.2, 5.1.5,
/// 5.1.9 and 5.3.6 (segment against triangle).
double triangle_distance(const Eigen::Vector3d a[3], const Eigen::Vector3d b[3], Eigen::Vector3d& pa,
                         Eigen::Vector3d& pb);

/// Two meshes for exact contact queries: A moves (a point p of A goes to R p + t), B stays. Which
/// triangles count is given per face (1 = counted); a pair of triangles counts when either of its two
/// triangles counts (as a per-vertex test counts a vertex, whatever it meets). A face of A may instead be
/// counted pair by pair (2): such a pair counts when Query::pair_counts says so at its closest points (a
/// class that depends on where on the face the pair comes nearest, e.g. a boundary crossing the face).
class MeshContact {
 public:
  /// Build both trees. a, b: n x 3 vertices (mm); fa, fb: m x 3 faces (0-based). a_counted, b_counted:
  /// per face, empty = every face counted. Throws impinge::Error when a face index is out of range or a
  /// mask's length is not the face count.
  MeshContact(const Vertices& a, const Faces& fa, const Vertices& b, const Faces& fb,
              std::vector<std::uint8_t> a_counted = {}, std::vector<std::uint8_t> b_counted = {});

  /// Replace the counted faces (as in the constructor). Throws impinge::Error on a wrong length.
  void set_counted(std::vector<std::uint8_t> a_counted, std::vector<std::uint8_t> b_counted);

  /// The least distance found and where.
  struct Closest {
    double distance = std::numeric_limits<double>::infinity();  ///< mm; +inf: no counted pair within reach
    std::int64_t face_a = -1, face_b = -1;                       ///< the pair
    Eigen::Vector3d on_a = Eigen::Vector3d::Zero();  ///< closest point on A's face, posed (B's frame), mm
    Eigen::Vector3d on_b = Eigen::Vector3d::Zero();  ///< closest point on B's face, mm
  };
  /// What a query asks.
  struct Query {
    double reach = std::numeric_limits<double>::infinity();  ///< pairs farther apart than this are not seen, mm
    bool first = false;  ///< stop at the first counted pair within reach (only whether there is one)
    /// A further test of B's faces at this pose (e.g. a classification that moves with A): a B face
    /// counts only when it is counted and this returns true for it. Null: none.
    std::function<bool(std::int64_t face_b)> b_counts_now;
    /// For a pair whose A face is counted pair by pair (2): whether it counts, from its closest points (on_a:
    /// posed, B's frame; on_b), mm. Null: such a pair counts.
    std::function<bool(std::int64_t face_a, const Eigen::Vector3d& on_a, const Eigen::Vector3d& on_b)> pair_counts;
  };
  /// The least distance over the counted pairs with A posed by (R, t), or +inf beyond the reach (a pair
  /// counted pair by pair is tested at its closest points: Query::pair_counts). Ties
  /// (several pairs crossing, distance 0) are broken by the closest points' coordinates, so that the
  /// answer does not depend on the order of faces or vertices.
  Closest least(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const Query& query) const;

  /// Every counted pair within `reach` (mm) at the pose (R, t), as (face of A, face of B).
  std::vector<std::pair<std::int64_t, std::int64_t>> pairs_within(const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                                                  double reach, const Query& query) const;

  /// Whether face f of A (of B) is counted (set_counted; for A also pair by pair).
  bool counted_a(std::int64_t f) const { return a_counted_[static_cast<std::size_t>(f)] != 0; }
  bool counted_b(std::int64_t f) const { return b_counted_[static_cast<std::size_t>(f)] != 0; }
  std::int64_t faces_a() const { return static_cast<std::int64_t>(fa_.rows()); }
  std::int64_t faces_b() const { return static_cast<std::int64_t>(fb_.rows()); }

  /// A tree node (public for the implementation's helpers): a box, its bounding sphere, and either two
  /// children or a run of faces.
  struct Node {
    Eigen::Vector3d lo, hi, centre;
    double radius = 0;
    std::int32_t left = -1, right = -1;  ///< children (-1: a leaf)
    std::int32_t first = 0, count = 0;   ///< leaf: faces order[first, first + count)
    bool counted = false;                ///< holds a counted face
    Eigen::Vector3d counted_lo = Eigen::Vector3d::Zero(), counted_hi = Eigen::Vector3d::Zero();  ///< the box of its counted faces (when counted)
  };

 private:
  struct Tree {
    std::vector<Node> nodes;
    std::vector<std::int32_t> order;  ///< faces, leaf by leaf
    /// Per face: a sphere holding it (x, y, z: its centroid; w: the centroid's largest distance to a corner),
    /// so that a pair of faces whose spheres lie farther apart than the bound is passed over untested.
    std::vector<Eigen::Vector4d> spheres;
    /// Per face: its unit normal (zero for a face of no area), for the planes' test of a pair.
    std::vector<Eigen::Vector3d> normals;
  };
  static Tree build(const Vertices& v, const Faces& f);
  static void mark(Tree& tree, const std::vector<std::uint8_t>& counted, const Vertices& v, const Faces& f);
  template <typename Visit>
  void walk(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const Query& q, double& bound, Visit visit) const;
  Vertices a_, b_;
  Faces fa_, fb_;
  std::vector<std::uint8_t> a_counted_, b_counted_;
  Tree ta_, tb_;
};

}  // namespace impinge
