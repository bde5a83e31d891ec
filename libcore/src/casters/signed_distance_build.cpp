// SignedDistanceQuery's constructor: the kept triangles, their normals and edge twins, and the point query's
// hierarchy (Embree's groups of detail::kGroup triangles, or CGAL's AABB tree).
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <string>
#include <utility>

#include "casters/signed_distance_impl.hpp"
#include "impinge/casters/embree_ray_caster.hpp"
#include "core/box_order.hpp"
#include "impinge/core/error.hpp"

namespace impinge {

#ifdef IMPINGE_HAVE_EMBREE
using detail::kBoxMarginMm;
using detail::kGroup;
#endif

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
  build(mesh, nullptr);
}

namespace {
// The cell of coordinate x on axis `axis` (clamped to the grid); monotone in x, so a point inside a box
// lies in a cell of the box's range.
int cell_of(const SignedDistanceQuery::Impl::Crop& g, double x, int axis) {
  const double u = std::floor((x - g.origin[axis]) / g.cell);
  return static_cast<int>(std::clamp(u, 0.0, static_cast<double>(g.dims[static_cast<std::size_t>(axis)] - 1)));
}
// A query ball's box is widened by this (mm, and relative to the coordinates) against rounding; the region's
// balls are marked widened by more, so that a query about a region ball's own centre and radius is covered.
double check_slack(const Eigen::Vector3d& q, double radius) { return 1e-9 * (1 + q.cwiseAbs().maxCoeff() + radius); }
}  // namespace

void SignedDistanceQuery::Impl::Crop::range(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                                            std::array<int, 3>& first, std::array<int, 3>& last) const {
  for (int d = 0; d < 3; ++d)
    first[static_cast<std::size_t>(d)] = cell_of(*this, lo[d], d), last[static_cast<std::size_t>(d)] = cell_of(*this, hi[d], d);
}

namespace {
// Calls f(index) for every cell of the range [first, last] (per axis) until f returns false; whether none did.
template <class F>
bool every_cell(const SignedDistanceQuery::Impl::Crop& g, const std::array<int, 3>& first,
                const std::array<int, 3>& last, F&& f) {
  const auto nx = static_cast<std::size_t>(g.dims[0]), ny = static_cast<std::size_t>(g.dims[1]);
  for (int z = first[2]; z <= last[2]; ++z)
    for (int y = first[1]; y <= last[1]; ++y)
      for (int x = first[0]; x <= last[0]; ++x)
        if (!f((static_cast<std::size_t>(z) * ny + static_cast<std::size_t>(y)) * nx + static_cast<std::size_t>(x)))
          return false;
  return true;
}
}  // namespace

bool SignedDistanceQuery::Impl::Crop::any_marked(const std::array<int, 3>& first, const std::array<int, 3>& last) const {
  return !every_cell(*this, first, last, [&](std::size_t i) { return !marked[i]; });
}

bool SignedDistanceQuery::Impl::Crop::all_marked(const std::array<int, 3>& first, const std::array<int, 3>& last) const {
  return every_cell(*this, first, last, [&](std::size_t i) { return marked[i] != 0; });
}

bool SignedDistanceQuery::Impl::Crop::covers(const Eigen::Vector3d& q, double radius) const {
  // Outside the grid (the mesh's box) there is no triangle: clamping to it loses nothing, and a ball off it
  // holds none.
  if (!(radius < std::numeric_limits<double>::infinity()) || !q.allFinite()) return false;
  const double r = radius + check_slack(q, radius);
  if ((q.array() + r < origin.array()).any() || (q.array() - r > upper.array()).any()) return true;
  std::array<int, 3> first{}, last{};
  range(q.array() - r, q.array() + r, first, last);
  return all_marked(first, last);
}

SignedDistanceQuery::SignedDistanceQuery(const TriangleMesh& mesh, const std::vector<Eigen::Vector4d>& region)
    : impl_(std::make_unique<Impl>()) {
  validate_mesh(mesh);
  require(available(), "signed distance: needs Embree or CGAL, and this build has neither (" + mesh.source + ")");
  auto crop = std::make_unique<Impl::Crop>();
  Impl::Crop& g = *crop;
  double smallest = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < region.size(); ++i) {
    const Eigen::Vector4d& ball = region[i];
    require(ball.allFinite() && ball[3] >= 0, [&] {
      return "signed distance (cropped, " + mesh.source + "): region ball " + std::to_string(i) + " (" +
             std::to_string(ball[0]) + ", " + std::to_string(ball[1]) + ", " + std::to_string(ball[2]) + "; radius " +
             std::to_string(ball[3]) + " mm) must be finite with radius >= 0";
    });
    if (ball[3] > 0) smallest = std::min(smallest, ball[3]);
  }
  // The grid over the mesh's box: cells about half as wide as the smallest ball, at most 128 per axis.
  const Eigen::Vector3d lo = mesh.V.colwise().minCoeff().transpose(), hi = mesh.V.colwise().maxCoeff().transpose();
  const double extent = (hi - lo).maxCoeff();
  g.cell = std::max({std::isfinite(smallest) ? smallest / 2 : extent, extent / 128, 1e-6});
  g.origin = lo, g.upper = hi;
  for (int d = 0; d < 3; ++d)
    g.dims[static_cast<std::size_t>(d)] = std::clamp(static_cast<int>(std::floor((hi[d] - lo[d]) / g.cell)) + 1, 1, 129);
  g.marked.assign(static_cast<std::size_t>(g.dims[0]) * static_cast<std::size_t>(g.dims[1]) *
                      static_cast<std::size_t>(g.dims[2]), 0);
  for (const Eigen::Vector4d& ball : region) {
    const Eigen::Vector3d c = ball.head<3>();
    const double r = ball[3] + 1e-3 * g.cell + 1e3 * check_slack(c, ball[3]);  // more than covers() widens by
    if ((c.array() + r < lo.array()).any() || (c.array() - r > hi.array()).any()) continue;  // off the mesh's box
    std::array<int, 3> first{}, last{};
    g.range(c.array() - r, c.array() + r, first, last);
    every_cell(g, first, last, [&](std::size_t i) { return g.marked[i] = 1; });
  }
  // A triangle is kept when its box meets a marked cell: every point of a covered query's ball lies in one. Its
  // box's cells run from the least to the greatest of its corners' cells (cell_of is monotone).
  std::vector<std::array<int, 3>> vertex_cell(static_cast<std::size_t>(mesh.V.rows()));
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i)
    for (int d = 0; d < 3; ++d)
      vertex_cell[static_cast<std::size_t>(i)][static_cast<std::size_t>(d)] = cell_of(g, mesh.V(i, d), d);
  std::vector<std::uint8_t> keep(static_cast<std::size_t>(mesh.F.rows()), 0);
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const auto& a = vertex_cell[static_cast<std::size_t>(mesh.F(f, 0))];
    const auto& b = vertex_cell[static_cast<std::size_t>(mesh.F(f, 1))];
    const auto& c = vertex_cell[static_cast<std::size_t>(mesh.F(f, 2))];
    std::array<int, 3> first{}, last{};
    for (std::size_t d = 0; d < 3; ++d) first[d] = std::min({a[d], b[d], c[d]}), last[d] = std::max({a[d], b[d], c[d]});
    keep[static_cast<std::size_t>(f)] = g.any_marked(first, last);
  }
  g.whole_mesh = mesh;
  impl_->crop = std::move(crop);
  build(mesh, &keep);
}

namespace {
// The number of triangles build keeps: all of the mesh's F (keep null), or those with keep[f] != 0.
std::size_t kept_count(const TriangleMesh& mesh, const std::vector<std::uint8_t>* keep) {
  if (keep == nullptr) return static_cast<std::size_t>(mesh.F.rows());
  return static_cast<std::size_t>(std::count_if(keep->begin(), keep->end(), [](std::uint8_t x) { return x != 0; }));
}

// The kept triangles (of nonzero area, and keep[f] != 0 when keep is given) into m: corners a, b, c (mm), their
// face (index in F), corner vertex indices and unit normals (in the triangles' own winding). Returns the signed
// volume of every triangle of nonzero area, kept or not (mm^3); any_area: whether there is one.
double keep_triangles(const TriangleMesh& mesh, const std::vector<std::uint8_t>* keep, SignedDistanceQuery::Impl& m,
                      bool& any_area) {
  double volume = 0;  // of every triangle, kept or not
  any_area = false;
  // Room for the kept triangles only: a crop keeps some 5-10% of a bone's (a one-pose run), and room reserved for
  // all of them would be faulted in (and zeroed) a huge page at a time once written.
  const std::size_t faces = kept_count(mesh, keep);
  m.a.reserve(faces), m.b.reserve(faces), m.c.reserve(faces), m.face.reserve(faces), m.corner.reserve(faces);
  m.face_normal.reserve(faces);
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)).transpose(), b = mesh.V.row(mesh.F(f, 1)).transpose(),
                          c = mesh.V.row(mesh.F(f, 2)).transpose();
    const Eigen::Vector3d n = (b - a).cross(c - a);
    if (!(n.norm() > 0)) continue;
    volume += a.dot(b.cross(c)) / 6;
    any_area = true;
    if (keep != nullptr && !(*keep)[static_cast<std::size_t>(f)]) continue;
    m.a.push_back(a), m.b.push_back(b), m.c.push_back(c), m.face.push_back(f);
    m.corner.push_back({static_cast<std::int32_t>(mesh.F(f, 0)), static_cast<std::int32_t>(mesh.F(f, 1)),
                        static_cast<std::int32_t>(mesh.F(f, 2))});
    m.face_normal.push_back(n.normalized());
  }
  return volume;
}

// The kept triangles' half-edges grouped undirected: a half-edge h = 3 * tri + k is the directed (from, to) of
// kept triangle tri's edge k (0: ab, 1: bc, 2: ca). They are bucketed by their lower vertex (counting sort over
// the nv vertices: bucket w is [start[w], start[w + 1]), start: nv + 1), each entry (higher vertex, h) in order
// of h (the bucket sort is stable); pair_edges orders each bucket by the higher vertex.
void bucket_half_edges(const SignedDistanceQuery::Impl& m, std::size_t nv, std::vector<std::int64_t>& start,
                       std::vector<std::pair<std::int32_t, std::int64_t>>& bucket) {
  const std::size_t k = m.a.size();
  start.assign(nv + 1, 0);
  auto ends = [&](std::size_t h) {
    const std::int32_t u = m.corner[h / 3][h % 3], v = m.corner[h / 3][(h % 3 + 1) % 3];
    return std::pair{std::min(u, v), std::max(u, v)};
  };
  for (std::size_t h = 0; h < 3 * k; ++h) ++start[static_cast<std::size_t>(ends(h).first) + 1];
  for (std::size_t w = 0; w < nv; ++w) start[w + 1] += start[w];
  bucket.assign(3 * k, {});  // (higher vertex, 3 * tri + k)
  std::vector<std::int64_t> next(start.begin(), start.end() - 1);
  for (std::size_t h = 0; h < 3 * k; ++h) {
    const auto [lo, hi] = ends(h);
    bucket[static_cast<std::size_t>(next[static_cast<std::size_t>(lo)]++)] = {hi, static_cast<std::int64_t>(h)};
  }
}

// The edges' twins from bucket_half_edges' buckets: an edge is regular when exactly two kept triangles share it,
// wound against each other (m.edge_twin: 3 per kept triangle, the triangle across, else -1); the vertices of an
// irregular edge are marked (m.vertex_irregular: nv). Also sizes m.vertex_normal (nv, zero). Returns the number
// of irregular edges.
std::int64_t pair_edges(SignedDistanceQuery::Impl& m, std::size_t nv, const std::vector<std::int64_t>& start,
                        std::vector<std::pair<std::int32_t, std::int64_t>>& bucket) {
  m.edge_twin.assign(3 * m.a.size(), -1);
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
  return irregular;
}

// The corners' pseudo-normals: m.vertex_normal (nv, zeroed by pair_edges) gains each kept triangle's outward unit
// normal weighted by the triangle's angle at that corner (radians).
void add_corner_normals(SignedDistanceQuery::Impl& m) {
  for (std::size_t t = 0; t < m.a.size(); ++t) {
    const std::array<const Eigen::Vector3d*, 3> p{&m.a[t], &m.b[t], &m.c[t]};
    for (int e = 0; e < 3; ++e) {
      const Eigen::Vector3d u = (*p[(e + 1) % 3] - *p[e]).normalized(), v = (*p[(e + 2) % 3] - *p[e]).normalized();
      const double angle = std::acos(std::clamp(u.dot(v), -1.0, 1.0));
      m.vertex_normal[static_cast<std::size_t>(m.corner[t][e])] += angle * m.face_normal[t];
    }
  }
}

#ifdef IMPINGE_HAVE_EMBREE
// One lane l of group G: kept triangle t's rows (Impl::Group: its unit normal and plane offset, then per edge
// the in-plane unit normal away from the triangle and its line's offset; float, about m.shift). Widens the box
// [lo, hi] (mm, about m.shift) by its corners.
void fill_lane(const SignedDistanceQuery::Impl& m, std::size_t t, int l, SignedDistanceQuery::Impl::Group& G,
               Eigen::Vector3d& lo, Eigen::Vector3d& hi) {
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

// The point query's groups (m.groups, m.group_box: (k + kGroup - 1) / kGroup each) over the k kept triangles:
// compact in space (their centroids in boxes of kGroup, every group but the last full), each box widened by
// kBoxMarginMm and the float rounding at m.extent (mm).
void fill_groups(SignedDistanceQuery::Impl& m) {
  const std::size_t k = m.a.size();
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
    SignedDistanceQuery::Impl::Group& G = m.groups[g];
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (int l = 0; l < kGroup; ++l) {
      const std::size_t j = g * kGroup + static_cast<std::size_t>(l);
      if (j >= k) {  // past the kept triangles: a plane far away, never a candidate
        for (auto& row : G.v) row[l] = 0.f;
        G.v[3][l] = -1e18f;
        G.triangle[l] = -1;
        continue;
      }
      fill_lane(m, static_cast<std::size_t>(order[j]), l, G, lo, hi);
    }
    for (int d = 0; d < 3; ++d) {
      m.group_box[g][static_cast<std::size_t>(d)] = static_cast<float>(lo[d] - widen);
      m.group_box[g][static_cast<std::size_t>(d) + 3] = static_cast<float>(hi[d] + widen);
    }
  }
}

// Embree's point-query hierarchy over the kept triangles: m.shift (their centroids' mean, mm), the device and
// scene, m.extent (mm), the groups (fill_groups) as one user geometry. Throws impinge::Error naming `source`
// when Embree fails.
void build_embree_hierarchy(SignedDistanceQuery::Impl& m, const std::string& source) {
  const std::size_t k = m.a.size();
  for (std::size_t t = 0; t < k; ++t) m.shift += (m.a[t] + m.b[t] + m.c[t]) / 3.0;
  if (k > 0) m.shift /= static_cast<double>(k);  // a crop may keep no triangle (an empty hierarchy)
  m.device = rtcNewDevice(nullptr);  // the build on every core; each query runs on its caller's thread
  if (m.device == nullptr)
    throw_embree_error(int(rtcGetDeviceError(nullptr)), "making the distance hierarchy's device for " + source);
  m.scene = rtcNewScene(m.device);
  for (std::size_t t = 0; t < k; ++t)
    for (const Eigen::Vector3d* p : {&m.a[t], &m.b[t], &m.c[t]}) m.extent = std::max(m.extent, (*p - m.shift).cwiseAbs().maxCoeff());
  fill_groups(m);
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
  if (const RTCError e = rtcGetDeviceError(m.device); e != RTC_ERROR_NONE)
    throw_embree_error(int(e), "building the distance hierarchy of " + source + " (" + std::to_string(k) +
                                   " triangles)");
}
#elif defined(IMPINGE_HAVE_CGAL)
// CGAL's AABB tree over the kept triangles (m.triangles: their corners, mm), with its distance queries' tree.
void build_cgal_tree(SignedDistanceQuery::Impl& m) {
  for (std::size_t t = 0; t < m.a.size(); ++t)
    m.triangles.emplace_back(SignedDistanceQuery::Impl::K::Point_3(m.a[t].x(), m.a[t].y(), m.a[t].z()),
                             SignedDistanceQuery::Impl::K::Point_3(m.b[t].x(), m.b[t].y(), m.b[t].z()),
                             SignedDistanceQuery::Impl::K::Point_3(m.c[t].x(), m.c[t].y(), m.c[t].z()));
  m.tree.insert(m.triangles.begin(), m.triangles.end());
  m.tree.build();
  m.tree.accelerate_distance_queries();
}
#endif
}  // namespace

void SignedDistanceQuery::build(const TriangleMesh& mesh, const std::vector<std::uint8_t>* keep) {
  require(available(), "signed distance: needs Embree or CGAL, and this build has neither (" + mesh.source + ")");
  Impl& m = *impl_;
  static std::atomic<std::uint64_t> built{0};
  m.serial = ++built;
  bool any_area = false;
  const double volume = keep_triangles(mesh, keep, m, any_area);
  require(any_area, "signed distance: " + mesh.source + " has no triangle of nonzero area");
  m.kept.assign(static_cast<std::size_t>(mesh.F.rows()), -1);
  for (std::size_t t = 0; t < m.face.size(); ++t) m.kept[static_cast<std::size_t>(m.face[t])] = static_cast<std::int64_t>(t);
  orientation_ = m.orientation = volume >= 0 ? 1 : -1;
  for (auto& n : m.face_normal) n *= m.orientation;

  // Edges: paired undirected (regular: two kept triangles wound against each other), then the corners' normals.
  const std::size_t nv = static_cast<std::size_t>(mesh.V.rows());
  std::vector<std::int64_t> start;
  std::vector<std::pair<std::int32_t, std::int64_t>> bucket;
  bucket_half_edges(m, nv, start, bucket);
  irregular_edges_ = pair_edges(m, nv, start, bucket);
  add_corner_normals(m);

#ifdef IMPINGE_HAVE_EMBREE
  build_embree_hierarchy(m, mesh.source);
#elif defined(IMPINGE_HAVE_CGAL)
  build_cgal_tree(m);
#endif
}

}  // namespace impinge
