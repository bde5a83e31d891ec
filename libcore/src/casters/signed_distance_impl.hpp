#pragma once
// SignedDistanceQuery's state, shared by its three sources: signed_distance.cpp (the queries),
// signed_distance_build.cpp (the constructor: triangles, normals, Embree's or CGAL's hierarchy) and
// signed_distance_winding.cpp (the winding number and its hierarchy). Private to the casters layer.
#include <array>
#include <atomic>
#include <cstring>
#include <memory>
#include <mutex>
#include <vector>

#include "core/simd_clones.hpp"
#include "impinge/casters/signed_distance.hpp"

#ifdef IMPINGE_HAVE_EMBREE
#include <embree3/rtcore.h>
#elif defined(IMPINGE_HAVE_CGAL)
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>
#endif

namespace impinge {

namespace detail {

/// Closest point of triangle (a, b, c) to p (Ericson 2005, Real-Time Collision Detection, sec. 5.1.5),
/// and its feature: 0 the face, 1 + k the edge k (0: ab, 1: bc, 2: ca), 4 + k the corner k (a, b, c).
inline Eigen::Vector3d closest_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                    const Eigen::Vector3d& c, int& feature) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return feature = 4, a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return feature = 5, b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return feature = 1, Eigen::Vector3d(a + (d1 / (d1 - d3)) * ab);
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return feature = 6, c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return feature = 3, Eigen::Vector3d(a + (d2 / (d2 - d6)) * ac);
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return feature = 2, Eigen::Vector3d(b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b));
  const double denom = 1.0 / (va + vb + vc);
  feature = 0;
  return a + ab * (vb * denom) + ac * (vc * denom);
}

inline constexpr double kBoxMarginMm = 1e-3;  // the float hierarchy's boxes against the double triangles
inline constexpr double kNearbySlackMm = 2;   // a NearbyTriangles' ball: the search's own radius plus this
inline constexpr double kBoxReachMm = 2 * kBoxMarginMm;  // a group's box within the best distance plus this may hold it

#ifdef IMPINGE_HAVE_EMBREE
inline constexpr int kGroup = 16;  // triangles per group of the point query's hierarchy (8 and 32 were slower)
#endif

}  // namespace detail

struct SignedDistanceQuery::Impl {
  std::uint64_t serial = 0;  // SignedDistanceQuery::id
  std::vector<Eigen::Vector3d> a, b, c;      // the kept triangles' corners, double, mesh frame
  std::vector<std::int64_t> face;            // kept triangle -> index in the mesh's F
  std::vector<std::int64_t> kept;            // index in the mesh's F -> kept triangle, or -1
  std::vector<std::array<std::int32_t, 3>> corner;  // kept triangle -> vertex indices
  std::vector<Eigen::Vector3d> face_normal;  // unit, outward
  // 3 per kept triangle: the kept triangle across the edge when exactly two faces share it, wound against
  // each other (a regular edge: its pseudo-normal is the sum of the two face normals), else -1. 4 bytes
  // where the sum itself took 24 (the pelvis' 95,000 triangles: 6 MB less to fill at every build).
  std::vector<std::int32_t> edge_twin;
  std::vector<Eigen::Vector3d> vertex_normal;
  std::vector<std::uint8_t> vertex_irregular;
  int orientation = 1;
  // A cropped query (the region constructor): the grid of cells that decides which triangles are kept and
  // which queries they answer, and the whole mesh for the others (its query built at the first of them).
  struct Crop {
    Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // the grid's lower corner (the mesh's box's), mm
    Eigen::Vector3d upper = Eigen::Vector3d::Zero();   // the mesh's box's upper corner, mm
    double cell = 1;                                   // mm
    std::array<int, 3> dims{1, 1, 1};
    std::vector<std::uint8_t> marked;                  // x fastest
    // The cells of box [lo, hi] (clamped to the grid), per axis first and last.
    void range(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, std::array<int, 3>& first,
               std::array<int, 3>& last) const;
    bool any_marked(const std::array<int, 3>& first, const std::array<int, 3>& last) const;
    bool all_marked(const std::array<int, 3>& first, const std::array<int, 3>& last) const;
    // Whether a query ball's box (a little widened against rounding) meets only marked cells.
    bool covers(const Eigen::Vector3d& q, double radius) const;
    TriangleMesh whole_mesh;
    std::once_flag whole_built;
    std::unique_ptr<SignedDistanceQuery> whole;
    std::atomic<std::int64_t> fallbacks{0};
  };
  std::unique_ptr<Crop> crop;
  // Cropped, and the query (q, radius) not covered: the whole mesh's query (built at its first use); else null.
  const SignedDistanceQuery* fallback(const Eigen::Vector3d& q, double radius);
  // Cropped: the whole mesh's query (counted as a fallback); else null.
  const SignedDistanceQuery* whole_query();
  // The winding number's hierarchy (Barill et al. 2018): nodes over `order` (kept triangles), each with
  // its area vector (sum of (b - a) x (c - a) / 2 in the triangles' own winding), area-weighted centroid
  // and the radius of a ball about it holding its triangles. Built at its first use (winding_number_fast):
  // most runs never need it (the pseudo-normal decides every sign of lhdl-ct's 1,000-frame trial).
  std::once_flag hierarchy_built;
  struct Node {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero(), area = Eigen::Vector3d::Zero();
    Eigen::Matrix3d moment = Eigen::Matrix3d::Zero();  // sum of (centroid - centre) area_vector^T
    double radius = 0;
    std::int32_t begin = 0, end = 0, left = -1, right = -1;
  };
  std::vector<Node> nodes;
  std::vector<std::int32_t> order;
  std::vector<Eigen::Vector3d> area_vector, centroid;  // per kept triangle, for the hierarchy's build
  std::int32_t build_node(std::int32_t begin, std::int32_t end);
  void build_hierarchy();

  /// The closest point of kept triangle k to q, with its feature.
  double distance_to(std::size_t k, const Eigen::Vector3d& q, Eigen::Vector3d& point, int& feature) const {
    point = detail::closest_on_triangle(q, a[k], b[k], c[k], feature);
    return (q - point).norm();
  }

#ifdef IMPINGE_HAVE_EMBREE
  // The point query's primitives: groups of kGroup kept triangles close in space (detail::box_order), each with
  // its rows of group_lower_bounds' lower bounds (float, about `shift`): the unit normal and the plane's
  // offset (rows 0-3), then per edge e the in-plane unit normal pointing away from the triangle and its
  // line's offset (rows 4 + 4e .. 7 + 4e). A lane past the kept triangles has triangle -1 and a plane
  // 1e18 mm away.
  struct Group {
    alignas(4 * detail::kGroup) float v[16][detail::kGroup];
    std::int32_t triangle[detail::kGroup];
  };
  std::vector<Group> groups;
  std::vector<std::array<float, 6>> group_box;  // lower x, y, z, upper x, y, z: float, about `shift`, widened
  double extent = 0;  // the largest |corner - shift| (any axis), mm: the float rows' rounding grows with it
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();  // float coordinates are about this point
  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
#elif defined(IMPINGE_HAVE_CGAL)
  using K = CGAL::Simple_cartesian<double>;
  using Triangle = K::Triangle_3;
  using Iterator = std::vector<Triangle>::const_iterator;
  using Primitive = CGAL::AABB_triangle_primitive<K, Iterator>;
  using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;
  std::vector<Triangle> triangles;
  Tree tree;
#endif
};

}  // namespace impinge
