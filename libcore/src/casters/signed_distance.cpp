#include "impinge/casters/signed_distance.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <string>
#include <utility>

#include "core/box_order.hpp"
#include "core/simd_clones.hpp"
#include "impinge/core/error.hpp"

#ifdef IMPINGE_HAVE_EMBREE
#include <embree3/rtcore.h>
#elif defined(IMPINGE_HAVE_CGAL)
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>
#endif

namespace impinge {

namespace {

/// Closest point of triangle (a, b, c) to p (Ericson 2005, Real-Time Collision Detection, sec. 5.1.5),
/// and its feature: 0 the face, 1 + k the edge k (0: ab, 1: bc, 2: ca), 4 + k the corner k (a, b, c).
Eigen::Vector3d closest_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
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

constexpr double kBoxMarginMm = 1e-3;  // the float hierarchy's boxes against the double triangles
constexpr double kNearbySlackMm = 2;   // a NearbyTriangles' ball: the search's own radius plus this
constexpr double kBoxReachMm = 2 * kBoxMarginMm;  // a group's box within the best distance plus this may hold it

#ifdef IMPINGE_HAVE_EMBREE
constexpr int kGroup = 16;  // triangles per group of the point query's hierarchy (8 and 32 were slower)
typedef float GroupLanes __attribute__((vector_size(4 * kGroup)));

/// The squared lower bounds of the distance from q (float, about the query's shift) to the triangles of a
/// group (Impl::Group's rows: plane, then the three edges' lines), lane by lane: h^2 + max(0, s_0, s_1,
/// s_2)^2, with h the distance to the triangle's plane and s_e the distance of q's foot point in that plane
/// beyond edge e's line (negative inside). The in-plane distance to the triangle is at least the largest
/// s_e (the triangle is the intersection of the three half-planes), and equal to it where the closest point
/// lies on the face or an edge; below it only in a corner's region. Compiled for AVX-512, AVX2 and the
/// baseline (clones), kGroup lanes. Returns the lanes whose bound is at most limit2 (bit l: lane l).
IMPINGE_SIMD_CLONES
std::uint32_t group_lower_bounds(const float (*v)[kGroup], float x, float y, float z, float limit2, float* lb2) {
  GroupLanes row[16];
  for (int r = 0; r < 16; ++r) std::memcpy(&row[r], v[r], sizeof(GroupLanes));
  const GroupLanes h = row[0] * x + row[1] * y + row[2] * z - row[3];
  const GroupLanes s0 = row[4] * x + row[5] * y + row[6] * z - row[7];
  const GroupLanes s1 = row[8] * x + row[9] * y + row[10] * z - row[11];
  const GroupLanes s2 = row[12] * x + row[13] * y + row[14] * z - row[15];
  GroupLanes s = s0 > s1 ? s0 : s1;
  s = s > s2 ? s : s2;
  s = s > 0 ? s : GroupLanes{};
  const GroupLanes out = h * h + s * s;
  std::memcpy(lb2, &out, sizeof(GroupLanes));
  const auto within = out <= limit2;  // -1 where within, lane by lane
  std::uint32_t bits = 0;
  for (int l = 0; l < kGroup; ++l) bits |= static_cast<std::uint32_t>(within[l] & 1) << l;
  return bits;
}

#endif

}  // namespace

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
    point = closest_on_triangle(q, a[k], b[k], c[k], feature);
    return (q - point).norm();
  }

#ifdef IMPINGE_HAVE_EMBREE
  // The point query's primitives: groups of kGroup kept triangles close in space (detail::box_order), each with
  // its rows of group_lower_bounds' lower bounds (float, about `shift`): the unit normal and the plane's
  // offset (rows 0-3), then per edge e the in-plane unit normal pointing away from the triangle and its
  // line's offset (rows 4 + 4e .. 7 + 4e). A lane past the kept triangles has triangle -1 and a plane
  // 1e18 mm away.
  struct Group {
    alignas(4 * kGroup) float v[16][kGroup];
    std::int32_t triangle[kGroup];
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

std::int32_t SignedDistanceQuery::Impl::build_node(std::int32_t begin, std::int32_t end) {
  const auto id = static_cast<std::int32_t>(nodes.size());
  nodes.emplace_back();
  Node n;
  n.begin = begin, n.end = end;
  double total = 0;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (std::int32_t k = begin; k < end; ++k) {
    const auto t = static_cast<std::size_t>(order[static_cast<std::size_t>(k)]);
    const Eigen::Vector3d& av = area_vector[t];
    const Eigen::Vector3d& g = centroid[t];
    n.area += av;
    n.centre += av.norm() * g;
    total += av.norm();
    lo = lo.cwiseMin(g), hi = hi.cwiseMax(g);
  }
  n.centre /= total;
  double moment[3][3] = {};  // summed in plain accumulators (an Eigen temporary per term went through memory)
  for (std::int32_t k = begin; k < end; ++k) {
    const auto t = static_cast<std::size_t>(order[static_cast<std::size_t>(k)]);
    n.radius = std::max({n.radius, (a[t] - n.centre).squaredNorm(), (b[t] - n.centre).squaredNorm(),
                         (c[t] - n.centre).squaredNorm()});
    const Eigen::Vector3d d = centroid[t] - n.centre;
    const Eigen::Vector3d& av = area_vector[t];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) moment[i][j] += d[i] * av[j];
  }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) n.moment(i, j) = moment[i][j];
  n.radius = std::sqrt(n.radius);
  if (end - begin > 8) {
    int axis = 0;
    (hi - lo).maxCoeff(&axis);
    const std::int32_t mid = begin + (end - begin) / 2;
    std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end, [&](std::int32_t x, std::int32_t y) {
      const auto i = static_cast<std::size_t>(x), j = static_cast<std::size_t>(y);
      return centroid[i][axis] < centroid[j][axis];
    });
    n.left = build_node(begin, mid);
    n.right = build_node(mid, end);
  }
  nodes[static_cast<std::size_t>(id)] = n;
  return id;
}

void SignedDistanceQuery::Impl::build_hierarchy() {
  const std::size_t k = a.size();
  order.resize(k);
  area_vector.resize(k), centroid.resize(k);
  for (std::size_t t = 0; t < k; ++t) {
    order[t] = static_cast<std::int32_t>(t);
    area_vector[t] = (b[t] - a[t]).cross(c[t] - a[t]) / 2;
    centroid[t] = (a[t] + b[t] + c[t]) / 3;
  }
  nodes.reserve(k / 2);
  build_node(0, static_cast<std::int32_t>(k));
  std::vector<Eigen::Vector3d>().swap(area_vector), std::vector<Eigen::Vector3d>().swap(centroid);
}

bool SignedDistanceQuery::available() {
#if defined(IMPINGE_HAVE_EMBREE) || defined(IMPINGE_HAVE_CGAL)
  return true;
#else
  return false;
#endif
}

#ifdef IMPINGE_HAVE_EMBREE
namespace {
// The point query's groups to Embree: a group's box; no ray queries (only point queries reach them).
void group_bounds(const RTCBoundsFunctionArguments* args) {
  const auto& b = static_cast<const SignedDistanceQuery::Impl*>(args->geometryUserPtr)->group_box[args->primID];
  *args->bounds_o = RTCBounds{b[0], b[1], b[2], 0.f, b[3], b[4], b[5], 0.f};
}
void no_ray_queries(const RTCIntersectFunctionNArguments*) {}
void no_ray_queries(const RTCOccludedFunctionNArguments*) {}
}  // namespace
#endif

SignedDistanceQuery::SignedDistanceQuery(const TriangleMesh& mesh) : impl_(std::make_unique<Impl>()) {
  validate_mesh(mesh);
  require(available(), "signed distance: needs Embree or CGAL, and this build has neither (" + mesh.source + ")");
  Impl& m = *impl_;
  static std::atomic<std::uint64_t> built{0};
  m.serial = ++built;
  double volume = 0;
  const auto faces = static_cast<std::size_t>(mesh.F.rows());
  m.a.reserve(faces), m.b.reserve(faces), m.c.reserve(faces), m.face.reserve(faces), m.corner.reserve(faces);
  m.face_normal.reserve(faces);
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)).transpose(), b = mesh.V.row(mesh.F(f, 1)).transpose(),
                          c = mesh.V.row(mesh.F(f, 2)).transpose();
    const Eigen::Vector3d n = (b - a).cross(c - a);
    if (!(n.norm() > 0)) continue;
    m.a.push_back(a), m.b.push_back(b), m.c.push_back(c), m.face.push_back(f);
    m.corner.push_back({static_cast<std::int32_t>(mesh.F(f, 0)), static_cast<std::int32_t>(mesh.F(f, 1)),
                        static_cast<std::int32_t>(mesh.F(f, 2))});
    m.face_normal.push_back(n.normalized());
    volume += a.dot(b.cross(c)) / 6;
  }
  require(!m.a.empty(), "signed distance: " + mesh.source + " has no triangle of nonzero area");
  m.kept.assign(static_cast<std::size_t>(mesh.F.rows()), -1);
  for (std::size_t t = 0; t < m.face.size(); ++t) m.kept[static_cast<std::size_t>(m.face[t])] = static_cast<std::int64_t>(t);
  orientation_ = m.orientation = volume >= 0 ? 1 : -1;
  const std::size_t k = m.a.size();
  for (auto& n : m.face_normal) n *= m.orientation;

  // Edges: directed (from, to) of each kept triangle's edge k (0: ab, 1: bc, 2: ca), grouped undirected:
  // bucketed by their lower vertex (counting sort), each bucket ordered by the higher vertex, then by
  // 3 * tri + k (the half-edges are placed in that order and the bucket sort is stable).
  const std::size_t nv = static_cast<std::size_t>(mesh.V.rows());
  std::vector<std::int64_t> start(nv + 1, 0);
  auto ends = [&](std::size_t h) {
    const std::int32_t u = m.corner[h / 3][h % 3], v = m.corner[h / 3][(h % 3 + 1) % 3];
    return std::pair{std::min(u, v), std::max(u, v)};
  };
  for (std::size_t h = 0; h < 3 * k; ++h) ++start[static_cast<std::size_t>(ends(h).first) + 1];
  for (std::size_t w = 0; w < nv; ++w) start[w + 1] += start[w];
  std::vector<std::pair<std::int32_t, std::int64_t>> bucket(3 * k);  // (higher vertex, 3 * tri + k)
  {
    std::vector<std::int64_t> next(start.begin(), start.end() - 1);
    for (std::size_t h = 0; h < 3 * k; ++h) {
      const auto [lo, hi] = ends(h);
      bucket[static_cast<std::size_t>(next[static_cast<std::size_t>(lo)]++)] = {hi, static_cast<std::int64_t>(h)};
    }
  }
  m.edge_twin.assign(3 * k, -1);
  m.vertex_normal.assign(nv, Eigen::Vector3d::Zero());
  m.vertex_irregular.assign(nv, 0);
  std::int64_t irregular = 0;
  for (std::size_t w = 0; w < nv; ++w) {
    const auto first = bucket.begin() + start[w], last = bucket.begin() + start[w + 1];
    std::stable_sort(first, last, [](const auto& x, const auto& y) { return x.first < y.first; });
    for (auto i = first; i != last;) {
      auto j = i;
      while (j != last && j->first == i->first) ++j;
      bool regular = false;
      if (j - i == 2) {
        const auto e0 = i->second, e1 = (i + 1)->second;
        const auto t0 = static_cast<std::size_t>(e0 / 3), t1 = static_cast<std::size_t>(e1 / 3);
        const std::int32_t from0 = m.corner[t0][e0 % 3], from1 = m.corner[t1][e1 % 3];
        regular = from0 != from1;  // opposite directions: consistently wound
        if (regular) {
          m.edge_twin[static_cast<std::size_t>(e0)] = static_cast<std::int32_t>(t1);
          m.edge_twin[static_cast<std::size_t>(e1)] = static_cast<std::int32_t>(t0);
        }
      }
      if (!regular) {
        ++irregular;
        m.vertex_irregular[w] = 1;
        m.vertex_irregular[static_cast<std::size_t>(i->first)] = 1;
      }
      i = j;
    }
  }
  irregular_edges_ = irregular;
  // Corners: normals weighted by the triangle's angle there.
  for (std::size_t t = 0; t < k; ++t) {
    const std::array<const Eigen::Vector3d*, 3> p{&m.a[t], &m.b[t], &m.c[t]};
    for (int e = 0; e < 3; ++e) {
      const Eigen::Vector3d u = (*p[(e + 1) % 3] - *p[e]).normalized(), v = (*p[(e + 2) % 3] - *p[e]).normalized();
      const double angle = std::acos(std::clamp(u.dot(v), -1.0, 1.0));
      m.vertex_normal[static_cast<std::size_t>(m.corner[t][e])] += angle * m.face_normal[t];
    }
  }

#ifdef IMPINGE_HAVE_EMBREE
  for (std::size_t t = 0; t < k; ++t) m.shift += (m.a[t] + m.b[t] + m.c[t]) / 3.0;
  m.shift /= static_cast<double>(k);
  m.device = rtcNewDevice(nullptr);  // the build on every core; each query runs on its caller's thread
  require(m.device != nullptr, "signed distance: rtcNewDevice failed (" + mesh.source + ")");
  m.scene = rtcNewScene(m.device);
  for (std::size_t t = 0; t < k; ++t)
    for (const Eigen::Vector3d* p : {&m.a[t], &m.b[t], &m.c[t]}) m.extent = std::max(m.extent, (*p - m.shift).cwiseAbs().maxCoeff());
  {
    std::vector<Eigen::Vector3d> centroid(k);
    for (std::size_t t = 0; t < k; ++t) centroid[t] = (m.a[t] + m.b[t] + m.c[t]) / 3.0;
    // Groups compact in space: the centroids in boxes of kGroup (every group but the last full).
    const std::vector<std::int32_t> order = detail::box_order(
        k, {kGroup}, [&](std::int32_t t, int axis) { return centroid[static_cast<std::size_t>(t)][axis]; });
    const std::size_t groups = (k + kGroup - 1) / kGroup;
    m.groups.resize(groups);
    m.group_box.resize(groups);
    const double widen = kBoxMarginMm + 1e-6 * m.extent;  // the boxes' and rows' float rounding, and more
    for (std::size_t g = 0; g < groups; ++g) {
      Impl::Group& G = m.groups[g];
      Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
      for (int l = 0; l < kGroup; ++l) {
        const std::size_t j = g * kGroup + static_cast<std::size_t>(l);
        if (j >= k) {  // past the kept triangles: a plane far away, never a candidate
          for (auto& row : G.v) row[l] = 0.f;
          G.v[3][l] = -1e18f;
          G.triangle[l] = -1;
          continue;
        }
        const auto t = static_cast<std::size_t>(order[j]);
        G.triangle[l] = static_cast<std::int32_t>(t);
        const std::array<Eigen::Vector3d, 3> p{m.a[t] - m.shift, m.b[t] - m.shift, m.c[t] - m.shift};
        const Eigen::Vector3d n = (p[1] - p[0]).cross(p[2] - p[0]).normalized();
        for (int d = 0; d < 3; ++d) G.v[d][l] = static_cast<float>(n[d]);
        G.v[3][l] = static_cast<float>(n.dot(p[0]));
        for (int e = 0; e < 3; ++e) {  // edge e from corner e to corner e + 1; the in-plane normal away from the third
          const Eigen::Vector3d& u = p[static_cast<std::size_t>(e)];
          Eigen::Vector3d w = (p[static_cast<std::size_t>((e + 1) % 3)] - u).cross(n).normalized();
          if (w.dot(p[static_cast<std::size_t>((e + 2) % 3)] - u) > 0) w = -w;
          for (int d = 0; d < 3; ++d) G.v[4 + 4 * e + d][l] = static_cast<float>(w[d]);
          G.v[7 + 4 * e][l] = static_cast<float>(w.dot(u));
        }
        for (const Eigen::Vector3d& x : p) lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
      }
      for (int d = 0; d < 3; ++d) {
        m.group_box[g][static_cast<std::size_t>(d)] = static_cast<float>(lo[d] - widen);
        m.group_box[g][static_cast<std::size_t>(d) + 3] = static_cast<float>(hi[d] + widen);
      }
    }
  }
  RTCGeometry g = rtcNewGeometry(m.device, RTC_GEOMETRY_TYPE_USER);
  rtcSetGeometryUserPrimitiveCount(g, static_cast<unsigned>(m.groups.size()));
  rtcSetGeometryUserData(g, &m);
  rtcSetGeometryBoundsFunction(g, group_bounds, &m);
  rtcSetGeometryIntersectFunction(g, no_ray_queries);
  rtcSetGeometryOccludedFunction(g, no_ray_queries);
  rtcCommitGeometry(g);
  rtcAttachGeometry(m.scene, g);
  rtcReleaseGeometry(g);
  rtcSetSceneBuildQuality(m.scene, RTC_BUILD_QUALITY_MEDIUM);
  rtcCommitScene(m.scene);
  require(rtcGetDeviceError(m.device) == RTC_ERROR_NONE,
          "signed distance: building the hierarchy of " + mesh.source + " failed");
#elif defined(IMPINGE_HAVE_CGAL)
  for (std::size_t t = 0; t < k; ++t)
    m.triangles.emplace_back(Impl::K::Point_3(m.a[t].x(), m.a[t].y(), m.a[t].z()),
                             Impl::K::Point_3(m.b[t].x(), m.b[t].y(), m.b[t].z()),
                             Impl::K::Point_3(m.c[t].x(), m.c[t].y(), m.c[t].z()));
  m.tree.insert(m.triangles.begin(), m.triangles.end());
  m.tree.build();
  m.tree.accelerate_distance_queries();
#endif
}

SignedDistanceQuery::~SignedDistanceQuery() = default;
SignedDistanceQuery::SignedDistanceQuery(SignedDistanceQuery&&) noexcept = default;
SignedDistanceQuery& SignedDistanceQuery::operator=(SignedDistanceQuery&&) noexcept = default;

std::int64_t SignedDistanceQuery::triangles() const { return static_cast<std::int64_t>(impl_->a.size()); }

std::uint64_t SignedDistanceQuery::id() const { return impl_->serial; }

namespace {
struct Search {
  const SignedDistanceQuery::Impl* m;
  Eigen::Vector3d q;
  double best;             // mm; the radius until something is found
  std::int64_t kept = -1;  // kept triangle
  Eigen::Vector3d point;
  int feature = 0;
  bool any_only = false;
  double margin = kBoxMarginMm;  // mm: the float lower bounds' rounding at q, and more (run sets it)
  NearbyTriangles* collect = nullptr;  // filling: every group the walk reaches (the radius stays put)
};

// Whether kept triangle t at distance d replaces the best so far: nearer, or as near with a lower index
// (ties: at a shared edge or corner; the answer then does not depend on the order of the tests). With
// nothing found yet, anything within the radius.
bool better(const Search& s, double d, std::int64_t t) {
  return d < s.best || (d == s.best && (s.kept < 0 || t < s.kept));
}

#ifdef IMPINGE_HAVE_EMBREE
// The distance from (x, y, z) to box b (lower x, y, z, upper x, y, z), float, mm.
float box_distance(const std::array<float, 6>& b, float x, float y, float z) {
  const float dx = std::max(std::max(b[0] - x, x - b[3]), 0.f);
  const float dy = std::max(std::max(b[1] - y, y - b[4]), 0.f);
  const float dz = std::max(std::max(b[2] - z, z - b[5]), 0.f);
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

// A group whose box the query's ball reaches (q = (x, y, z), float, about the shift): the triangles whose
// lower bound (group_lower_bounds, widened by the search's margin for float rounding) is within the best
// distance so far get the exact test. Whether one of them became the best.
bool visit_group(Search* s, std::uint32_t group, float x, float y, float z) {
  const SignedDistanceQuery::Impl::Group& g = s->m->groups[group];
  float lb2[kGroup];
  const float first = static_cast<float>(s->best + s->margin);
  std::uint32_t bits = group_lower_bounds(g.v, x, y, z, first * first, lb2);
  bool closer = false;
  for (; bits != 0; bits &= bits - 1) {  // the lanes within the first limit, in order; the limit shrinks
    const int l = __builtin_ctz(bits);
    const float limit = static_cast<float>(s->best + s->margin);
    if (!(lb2[l] <= limit * limit) || g.triangle[l] < 0) continue;
    const auto t = static_cast<std::size_t>(g.triangle[l]);
    if (static_cast<std::int64_t>(t) == s->kept) continue;  // the best so far (a seed): tested already
    Eigen::Vector3d point;
    int feature = 0;
    const double d = s->m->distance_to(t, s->q, point, feature);
    if (!better(*s, d, static_cast<std::int64_t>(t))) continue;
    s->best = d, s->kept = static_cast<std::int64_t>(t), s->point = point, s->feature = feature;
    closer = true;
    if (s->any_only) break;
  }
  return closer;
}

// Embree's callback for a group the walk reaches (visit_group); a walk that fills a NearbyTriangles also
// lists the group, and keeps its radius.
bool visit(RTCPointQueryFunctionArguments* args) {
  auto* s = static_cast<Search*>(args->userPtr);
  if (s->collect != nullptr) {  // filling: list the group; the walk's radius stays that of the list's ball
    NearbyTriangles& n = *s->collect;
    const float d = box_distance(s->m->group_box[args->primID], args->query->x, args->query->y, args->query->z);
    if (n.count < NearbyTriangles::kMax) {  // in order of the box's distance from the centre (insertion)
      int i = n.count;
      for (; i > 0 && n.box_distance[i - 1] > d; --i) n.group[i] = n.group[i - 1], n.box_distance[i] = n.box_distance[i - 1];
      n.group[i] = static_cast<std::int32_t>(args->primID), n.box_distance[i] = d;
    }
    ++n.count;
    // Its triangles only where its box comes within the best distance so far (as a walk that shrinks).
    if (static_cast<double>(d) <= s->best + kBoxReachMm)
      visit_group(s, args->primID, args->query->x, args->query->y, args->query->z);
    return false;
  }
  const bool closer = visit_group(s, args->primID, args->query->x, args->query->y, args->query->z);
  if (closer) args->query->radius = s->any_only ? 0.f : static_cast<float>(s->best + kBoxMarginMm);
  return closer;
}
#endif

bool run(const SignedDistanceQuery::Impl& m, Search& s, double radius, std::int64_t seed = -1,
         NearbyTriangles* nearby = nullptr) {
  require(radius > 0, "signed distance: the query radius must be > 0 mm");
  s.best = radius;
  if (seed >= 0 && seed < static_cast<std::int64_t>(m.kept.size()) && m.kept[static_cast<std::size_t>(seed)] >= 0) {
    const auto t = static_cast<std::size_t>(m.kept[static_cast<std::size_t>(seed)]);
    Eigen::Vector3d point;
    int feature = 0;
    const double d = m.distance_to(t, s.q, point, feature);
    if (better(s, d, static_cast<std::int64_t>(t))) s.best = d, s.kept = static_cast<std::int64_t>(t), s.point = point, s.feature = feature;
  }
#ifdef IMPINGE_HAVE_EMBREE
  s.margin = kBoxMarginMm + 1e-6 * (m.extent + (s.q - m.shift).cwiseAbs().maxCoeff());
  RTCPointQuery query;
  query.x = static_cast<float>(s.q.x() - m.shift.x());
  query.y = static_cast<float>(s.q.y() - m.shift.y());
  query.z = static_cast<float>(s.q.z() - m.shift.z());
  query.time = 0.f;
  query.radius = std::isfinite(s.best) ? static_cast<float>(s.best + kBoxMarginMm) : std::numeric_limits<float>::infinity();
  double listed = 0;  // mm: the ball of a NearbyTriangles this walk refills
  if (nearby != nullptr && std::isfinite(s.best)) {
    const Eigen::Vector3d q(query.x, query.y, query.z);  // about the shift, as the groups' boxes
    const Eigen::Vector3d c(nearby->centre[0], nearby->centre[1], nearby->centre[2]);
    const double off = (q - c).norm();
    if (nearby->query == m.serial && nearby->radius > 0 &&
        off + s.best + kBoxReachMm <= static_cast<double>(nearby->radius)) {
      // This search's ball (and the boxes' margin) lies inside the listed ball: every group it would
      // reach is listed. A group's box lies at least its distance from the centre less `off` from q, so
      // the groups are visited nearest first until that exceeds the best distance so far.
      for (std::int32_t i = 0; i < nearby->count; ++i) {
        if (static_cast<double>(nearby->box_distance[i]) - off > s.best + kBoxReachMm) break;
        visit_group(&s, static_cast<std::uint32_t>(nearby->group[i]), query.x, query.y, query.z);
      }
      return s.kept >= 0;
    }
    // Refill about q: the walk keeps the radius of the list's ball (a little more than this search's own).
    nearby->query = 0, nearby->radius = -1.f, nearby->count = 0;
    listed = s.best + kNearbySlackMm;
    query.radius = static_cast<float>(listed + kBoxMarginMm);
    s.collect = nearby;
  }
  RTCPointQueryContext context;
  rtcInitPointQueryContext(&context);
  rtcPointQuery(m.scene, &query, &context, visit, &s);
  if (s.collect != nullptr) {
    s.collect = nullptr;
    if (nearby->count <= NearbyTriangles::kMax) {
      nearby->query = m.serial;
      nearby->centre[0] = query.x, nearby->centre[1] = query.y, nearby->centre[2] = query.z;
      nearby->radius = static_cast<float>(listed) * (1.f - 0x1p-20f);  // rounded down, below the ball walked
    } else {
      nearby->count = 0;
    }
  }
#elif defined(IMPINGE_HAVE_CGAL)
  using K = SignedDistanceQuery::Impl::K;
  const auto hit = m.tree.closest_point_and_primitive(K::Point_3(s.q.x(), s.q.y(), s.q.z()));
  const auto t = static_cast<std::size_t>(hit.second - m.triangles.begin());
  Eigen::Vector3d point;
  int feature = 0;
  const double d = m.distance_to(t, s.q, point, feature);
  if (better(s, d, static_cast<std::int64_t>(t))) s.best = d, s.kept = static_cast<std::int64_t>(t), s.point = point, s.feature = feature;
#endif
  return s.kept >= 0;
}
}  // namespace

bool SignedDistanceQuery::closest(const Eigen::Vector3d& q, double radius_mm, ClosestSurfacePoint& out) const {
  Search s{impl_.get(), q, 0, -1, {}, 0, false};
  if (!run(*impl_, s, radius_mm)) return false;
  out.distance_mm = s.best;
  out.sign = 1;
  out.triangle = impl_->face[static_cast<std::size_t>(s.kept)];
  out.point = s.point;
  out.rule = SignRule::pseudo_normal;
  return true;
}

bool SignedDistanceQuery::any_within(const Eigen::Vector3d& q, double radius_mm) const {
  Search s{impl_.get(), q, 0, -1, {}, 0, true};
  return run(*impl_, s, radius_mm);
}

bool SignedDistanceQuery::signed_distance(const Eigen::Vector3d& q, double radius_mm, int hint,
                                          ClosestSurfacePoint& out, std::int64_t seed, NearbyTriangles* nearby) const {
  Search s{impl_.get(), q, 0, -1, {}, 0, false};
  if (!run(*impl_, s, radius_mm, seed, nearby)) return false;
  const Impl& m = *impl_;
  const auto t = static_cast<std::size_t>(s.kept);
  bool trusted = true;
  Eigen::Vector3d n;
  if (s.feature == 0) {
    n = m.face_normal[t];
  } else if (s.feature <= 3) {
    // The sum of the two faces' normals (addition commutes: the same bits from either face), zero on an
    // irregular edge.
    const std::int32_t twin = m.edge_twin[3 * t + static_cast<std::size_t>(s.feature - 1)];
    trusted = twin >= 0;
    n = trusted ? Eigen::Vector3d(m.face_normal[t] + m.face_normal[static_cast<std::size_t>(twin)])
                : Eigen::Vector3d::Zero();
  } else {
    const auto v = static_cast<std::size_t>(m.corner[t][s.feature - 4]);
    n = m.vertex_normal[v];
    trusted = !m.vertex_irregular[v];
  }
  const Eigen::Vector3d w = q - s.point;
  const double along = w.dot(n), scale = w.norm() * n.norm();
  int sign = along >= 0 ? 1 : -1;
  if (s.best > 1e-6 && !(std::abs(along) >= 1e-3 * scale)) trusted = false;  // q in the tangent plane
  if (hint != 0 && s.best > 1e-6 && hint != sign) trusted = false;
  out.rule = SignRule::pseudo_normal;
  if (!trusted && s.best > 1e-6) {
    sign = inside_by_winding_number(q) ? -1 : 1;
    out.rule = SignRule::winding_number;
  }
  out.distance_mm = s.best;
  out.sign = sign;
  out.triangle = m.face[t];
  out.point = s.point;
  return true;
}

namespace {
/// Half the solid angle of triangle (A, B, C) seen from q (van Oosterom & Strackee 1983).
double half_solid_angle(const Eigen::Vector3d& q, const Eigen::Vector3d& A, const Eigen::Vector3d& B,
                        const Eigen::Vector3d& C) {
  const Eigen::Vector3d a = A - q, b = B - q, c = C - q;
  const double la = a.norm(), lb = b.norm(), lc = c.norm();
  const double det = a.dot(b.cross(c));
  const double div = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
  return std::atan2(det, div);
}
constexpr double kDipoleBeta = 4;     // a cluster farther than this many of its radii away is a dipole
constexpr double kFastMargin = 0.1;   // the hierarchical sum decides when this far from 1/2
}  // namespace

double SignedDistanceQuery::winding_number(const Eigen::Vector3d& q) const {
  const Impl& m = *impl_;
  double sum = 0;
  for (std::size_t t = 0; t < m.a.size(); ++t) sum += half_solid_angle(q, m.a[t], m.b[t], m.c[t]);
  return m.orientation * sum / (2 * M_PI);
}

double SignedDistanceQuery::winding_number_fast(const Eigen::Vector3d& q) const {
  std::call_once(impl_->hierarchy_built, [this] { impl_->build_hierarchy(); });
  const Impl& m = *impl_;
  double sum = 0;
  std::int32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Impl::Node& n = m.nodes[static_cast<std::size_t>(stack[--top])];
    const Eigen::Vector3d d = n.centre - q;
    const double dist = d.norm();
    if (dist > kDipoleBeta * n.radius) {
      // Half the solid angle of the cluster's dipoles, to second order about its centre: with
      // F(x) = x / |x|^3 and J = dF/dx = I / |d|^3 - 3 d d^T / |d|^5, sum_t a_t . F(d + e_t) ~
      // N . F(d) + tr(J M) (Barill et al. 2018, eq. 11-12).
      const double d2 = dist * dist, d3 = d2 * dist;
      sum += (n.area.dot(d) / d3 + n.moment.trace() / d3 - 3 * d.dot(n.moment * d) / (d3 * d2)) / 2;
    } else if (n.left < 0 || top + 2 > 128) {
      for (std::int32_t k = n.begin; k < n.end; ++k) {
        const auto t = static_cast<std::size_t>(m.order[static_cast<std::size_t>(k)]);
        sum += half_solid_angle(q, m.a[t], m.b[t], m.c[t]);
      }
    } else {
      stack[top++] = n.left;
      stack[top++] = n.right;
    }
  }
  return m.orientation * sum / (2 * M_PI);
}

bool SignedDistanceQuery::inside_by_winding_number(const Eigen::Vector3d& q) const {
  const double fast = winding_number_fast(q);
  if (std::abs(fast - 0.5) > kFastMargin) return fast > 0.5;
  return winding_number(q) >= 0.5;
}

}  // namespace impinge
