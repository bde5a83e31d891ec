#include "impinge/casters/first_hit_caster.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <limits>
#include <optional>

#include "impinge/casters/embree_ray_caster.hpp"
#include "impinge/casters/exact_reference.hpp"
#include "impinge/core/error.hpp"

namespace impinge {

struct FirstHitCaster::Impl {
  Eigen::Vector3d origin;
  std::vector<Eigen::Matrix3d> edge_on;  ///< columns: the corners relative to the origin
  std::optional<EmbreeRayCaster> embree;
  std::optional<ExactReference> cgal;
  std::vector<Eigen::Vector3f> normals;  ///< unit normal of each triangle given to Embree (crossings)
};

bool FirstHitCaster::available() { return have_embree() || have_exact_reference(); }

const Eigen::Vector3d& FirstHitCaster::origin() const { return impl_->origin; }

namespace {
// Welds the vertices of `mesh` (V: n x 3, mm) that coincide to 1e-6 mm: each face corner (F) goes to the first
// vertex (lowest index) of its 1e-6 mm cell. The cells sit in an open-addressing table (twice as many slots as
// vertices, linear probing), filled in index order, so that a cell's slot holds its first vertex (a sort by
// (cell, index) gave the same map at some 4x the time: issue 52). V is left as it is.
void weld_coincident_vertices(TriangleMesh& mesh) {
  const auto n = static_cast<std::size_t>(mesh.V.rows());
  std::vector<std::array<std::int64_t, 3>> cell(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    cell[i] = {std::llround(mesh.V(r, 0) * 1e6), std::llround(mesh.V(r, 1) * 1e6), std::llround(mesh.V(r, 2) * 1e6)};
  }
  std::size_t slots = 16;
  while (slots < 2 * n) slots *= 2;
  std::vector<std::int32_t> slot(slots, -1);  // a vertex index, or -1: empty
  std::vector<int> to(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto& c = cell[i];
    std::uint64_t h = static_cast<std::uint64_t>(c[0]) * 0x9E3779B97F4A7C15ull;
    h = (h ^ (h >> 29) ^ static_cast<std::uint64_t>(c[1])) * 0xBF58476D1CE4E5B9ull;
    h = (h ^ (h >> 31) ^ static_cast<std::uint64_t>(c[2])) * 0x94D049BB133111EBull;
    h ^= h >> 32;
    for (std::size_t k = h & (slots - 1);; k = (k + 1) & (slots - 1)) {
      if (slot[k] < 0) {
        slot[k] = static_cast<std::int32_t>(i);
        to[i] = static_cast<int>(i);
        break;
      }
      if (cell[static_cast<std::size_t>(slot[k])] == c) {
        to[i] = slot[k];
        break;
      }
    }
  }
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) mesh.F(f, k) = to[static_cast<std::size_t>(mesh.F(f, k))];
}

// Drops from mesh.F the triangles edge-on to `origin` (mm: their plane through it, within 1e-6 of their corners'
// largest distance from it), each kept in edge_on (columns: its corners relative to the origin, mm). Returns how
// many were dropped.
Eigen::Index drop_edge_on_triangles(TriangleMesh& mesh, const Eigen::Vector3d& origin,
                                    std::vector<Eigen::Matrix3d>& edge_on) {
  std::vector<Eigen::Index> keep;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)).transpose() - origin,
                          b = mesh.V.row(mesh.F(f, 1)).transpose() - origin,
                          c = mesh.V.row(mesh.F(f, 2)).transpose() - origin;
    const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
    const double scale = std::max({a.norm(), b.norm(), c.norm()});
    if (std::abs(n.dot(a)) > 1e-6 * scale)
      keep.push_back(f);
    else {
      Eigen::Matrix3d T;
      T << a, b, c;
      edge_on.push_back(T);
    }
  }
  const Eigen::Index dropped = mesh.F.rows() - static_cast<Eigen::Index>(keep.size());
  Faces F(static_cast<Eigen::Index>(keep.size()), 3);
  for (std::size_t k = 0; k < keep.size(); ++k) F.row(static_cast<Eigen::Index>(k)) = mesh.F.row(keep[k]);
  mesh.F = std::move(F);
  return dropped;
}

// The orientation of `mesh`'s triangles about `origin` (mm): 1 when their signed volume is >= 0, else -1; normals
// gets each triangle's unit normal (float, in F's order).
int orientation_and_normals(const TriangleMesh& mesh, const Eigen::Vector3d& origin,
                            std::vector<Eigen::Vector3f>& normals) {
  double volume = 0;
  normals.reserve(static_cast<std::size_t>(mesh.F.rows()));
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)).transpose() - origin,
                          b = mesh.V.row(mesh.F(f, 1)).transpose() - origin,
                          c = mesh.V.row(mesh.F(f, 2)).transpose() - origin;
    volume += a.dot(b.cross(c)) / 6;
    normals.push_back((b - a).cross(c - a).normalized().cast<float>());
  }
  return volume >= 0 ? 1 : -1;
}
}  // namespace

FirstHitCaster::FirstHitCaster(const TriangleMesh& mesh, const Eigen::Vector3d& origin, HierarchyBuild build)
    : impl_(std::make_unique<Impl>()) {
  require(available(), "first-hit ray caster: this build has neither Embree nor CGAL (" + mesh.source + ")");
  require(origin.allFinite(), "first-hit ray caster: origin is not finite (" + mesh.source + ")");
  impl_->origin = origin;
  // Triangles edge-on to the origin (their plane through it, to float precision) are met by a ray
  // from the origin only inside their plane, where Embree's float intersection returns distances
  // of no meaning (radial rims of generated cups: hits at 2 mm on a cup of radius 24.5). Every
  // such ray meets the neighbouring triangles at the same points, so they are left out, as are
  // zero-area triangles.
  TriangleMesh clean = mesh;
  // Vertices that coincide to 1e-6 mm but are distinct (the seam of a generated surface, a crack
  // of a segmentation) are welded: Embree's watertightness holds for identical corners only, and a
  // ray along such a seam would otherwise slip through it.
  weld_coincident_vertices(clean);
  remove_degenerate_faces(clean);
  edge_on_ = drop_edge_on_triangles(clean, origin, impl_->edge_on);
  // Orientation by the signed volume of the triangles kept (a closed mesh's edge-on triangles
  // add no volume about the origin, which lies in their plane).
  orientation_ = orientation_and_normals(clean, origin, impl_->normals);
  if (have_embree()) {
    impl_->embree.emplace(clean, origin, /*robust=*/true, build);
  } else {
    impl_->cgal.emplace(clean);
  }
  // Whether the origin lies inside the solid: the majority over 13 rays of whether the first crossing
  // leaves it (a ray that misses says outside).
  {
    int inside = 0;
    std::vector<RayCrossing> c;
    for (int k = 0; k < 13; ++k) {
      const double z = 1 - (2 * k + 1) / 13.0, rho = std::sqrt(1 - z * z), az = 2.399963229728653 * k + 0.1;
      raw_crossings(Eigen::Vector3d(rho * std::cos(az), rho * std::sin(az), z), c);
      inside += !c.empty() && !c.front().entering;
    }
    origin_inside_ = 2 * inside > 13;
  }
}

FirstHitCaster::~FirstHitCaster() = default;
FirstHitCaster::FirstHitCaster(FirstHitCaster&&) noexcept = default;
FirstHitCaster& FirstHitCaster::operator=(FirstHitCaster&&) noexcept = default;

namespace {
/// Nearest t >= 0 at which the ray t u (|u| = 1) meets triangle T (corners as columns, relative
/// to the ray's origin) in double: Moller-Trumbore, and for a ray in the triangle's plane (an
/// edge-on triangle seen along itself) the first crossing of its edges. +inf when it misses.
double edge_on_hit(const Eigen::Matrix3d& T, const Eigen::Vector3d& u) {
  const Eigen::Vector3d a = T.col(0), e1 = T.col(1) - a, e2 = T.col(2) - a;
  const Eigen::Vector3d pv = u.cross(e2);
  const double det = e1.dot(pv);
  const double inf = std::numeric_limits<double>::infinity();
  if (std::abs(det) > 1e-12 * e1.norm() * e2.norm()) {
    const Eigen::Vector3d tv = -a;
    const double bu = tv.dot(pv) / det;
    const Eigen::Vector3d qv = tv.cross(e1);
    const double bv = u.dot(qv) / det, t = e2.dot(qv) / det;
    return (bu >= 0 && bv >= 0 && bu + bv <= 1 && t >= 0) ? t : inf;
  }
  const Eigen::Vector3d n = e1.cross(e2).normalized();
  if (std::abs(n.dot(u)) > 1e-9) return inf;  // not in the plane: meets it only at the origin
  double best = inf;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d p = T.col(k), d = T.col((k + 1) % 3) - p;
    // t u = p + s d in the plane: least squares of the 3 x 2 system [u, -d] (t, s) = p.
    Eigen::Matrix<double, 3, 2> A;
    A << u, -d;
    const Eigen::Matrix2d N = A.transpose() * A;
    if (std::abs(N.determinant()) < 1e-18 * N.norm() * N.norm()) continue;  // parallel edge
    const Eigen::Vector2d ts = N.ldlt().solve(A.transpose() * p);
    if (ts[0] >= 0 && ts[1] >= -1e-12 && ts[1] <= 1 + 1e-12) best = std::min(best, ts[0]);
  }
  return best;
}
}  // namespace

double FirstHitCaster::first_hit(const Eigen::Vector3d& direction) const {
  return first_hit(direction, std::numeric_limits<double>::infinity());
}

double FirstHitCaster::first_hit(const Eigen::Vector3d& direction, double within_mm) const {
  const double inf = std::numeric_limits<double>::infinity();
  if (!(within_mm > 0)) return inf;  // nothing is nearer than that (a NaN bound asks nothing either)
  double h;
  if (impl_->embree) {
    // Embree intersects in float and is not watertight at a shared vertex: a ray exactly through
    // one (a vertex of the other bone collinear with one of this mesh from the COR, as on meshes
    // built on the same angular grid) can slip between its triangles. The least hit of the ray
    // and two rays 1e-6 rad beside it (2.5e-5 mm at 25 mm) closes such slits.
    const Eigen::Vector3d u = direction.normalized();
    const Eigen::Vector3d a = u.unitOrthogonal(), b = u.cross(a);
    const Eigen::Vector3d d1 = u + 1e-6 * a, d2 = u + 1e-6 * (b * 0.866 - a * 0.5);
    const float dirs[9] = {float(u.x()),  float(u.y()),  float(u.z()),  float(d1.x()), float(d1.y()),
                           float(d1.z()), float(d2.x()), float(d2.y()), float(d2.z())};
    // Embree's rays end at the bound rounded up to float (so a hit nearer than within_mm is still found).
    float within = static_cast<float>(within_mm);
    if (static_cast<double>(within) < within_mm)
      within = std::nextafter(within, std::numeric_limits<float>::infinity());
    h = impl_->embree->least_hit(dirs, 3, within);
  } else {
    const std::optional<double> c = impl_->cgal->first_hit(impl_->origin, direction.normalized());
    h = c ? *c : std::numeric_limits<double>::infinity();
  }
  if (!impl_->edge_on.empty()) {
    const Eigen::Vector3d u = direction.normalized();
    for (const Eigen::Matrix3d& T : impl_->edge_on) h = std::min(h, edge_on_hit(T, u));
  }
  return h;
}

namespace {
void merge_hits(std::vector<std::pair<double, double>>& raw, int orientation, std::vector<RayCrossing>& out);
/// A closed surface seen from a fixed origin: crossings alternate, end leaving the solid, and start
/// entering it exactly when the origin lies outside.
bool consistent(const std::vector<RayCrossing>& c, bool origin_inside) {
  if (c.empty()) return !origin_inside;
  if (c.front().entering == origin_inside || c.back().entering) return false;
  for (std::size_t k = 1; k < c.size(); ++k)
    if (c[k].entering == c[k - 1].entering) return false;
  return true;
}
}  // namespace

void FirstHitCaster::crossings(const Eigen::Vector3d& direction, std::vector<RayCrossing>& out) const {
  const Eigen::Vector3d u = direction.normalized();
  raw_crossings(u, out);
  if (consistent(out, origin_inside_)) return;
  // Embree's float intersection is not watertight at a shared vertex: a ray exactly through one can
  // slip between its triangles and lose a crossing (a closed mesh then reads inconsistently). Two rays
  // 1e-6 rad beside it (2.5e-5 mm at 25 mm) decide; when neither is consistent either (a mesh that is
  // not closed), the ray's own crossings stand.
  const Eigen::Vector3d a = u.unitOrthogonal(), b = u.cross(a);
  thread_local std::vector<RayCrossing> other;
  for (const Eigen::Vector3d& d : {Eigen::Vector3d(u + 1e-6 * a), Eigen::Vector3d(u + 1e-6 * (0.866 * b - 0.5 * a))}) {
    raw_crossings(d.normalized(), other);
    if (consistent(other, origin_inside_)) {
      out.swap(other);
      return;
    }
  }
}

void FirstHitCaster::raw_crossings(const Eigen::Vector3d& u, std::vector<RayCrossing>& out) const {
  out.clear();
  // (distance, facing cosine with the winding's normal), any order.
  thread_local std::vector<std::pair<double, double>> raw;
  raw.clear();
  if (impl_->embree) {
    thread_local std::vector<std::pair<float, unsigned>> hits;
    hits.clear();
    impl_->embree->all_hits(float(u.x()), float(u.y()), float(u.z()), hits);
    for (const auto& [t, f] : hits) raw.emplace_back(double(t), double(impl_->normals[f].cast<double>().dot(u)));
  } else {
    for (const auto& h : impl_->cgal->all_hits(impl_->origin, u)) raw.push_back(h);
  }
  merge_hits(raw, orientation_, out);
}

std::vector<RayCrossing> crossings_from_hits(std::vector<std::pair<double, double>> hits, int orientation) {
  std::vector<RayCrossing> out;
  merge_hits(hits, orientation, out);
  return out;
}

namespace {
void merge_hits(std::vector<std::pair<double, double>>& raw, int orientation, std::vector<RayCrossing>& out) {
  out.clear();
  std::sort(raw.begin(), raw.end());
  for (std::size_t i = 0; i < raw.size();) {
    // A group of hits within 1e-4 mm of its first: one crossing by the majority of the facings.
    std::size_t j = i;
    int facing = 0;
    for (; j < raw.size() && raw[j].first - raw[i].first <= 1e-4; ++j)
      facing += raw[j].second < 0 ? -1 : raw[j].second > 0 ? 1 : 0;
    facing *= orientation;
    if (facing != 0) out.push_back({raw[i].first, facing < 0});
    i = j;
  }
}
}  // namespace


}  // namespace impinge
