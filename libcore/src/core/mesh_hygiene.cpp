// A bone's mesh cleaned at load: welded corners, double walls, fragments, holes (mesh_hygiene.hpp).
#include "impinge/core/mesh_hygiene.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <unordered_map>

#include "core/mesh_parts.hpp"
#include "impinge/core/error.hpp"

namespace impinge {
namespace {
using detail::Part;
}  // namespace
using detail::find_root;
namespace {

std::string fixed(double v, int digits) {
  char b[64];
  std::snprintf(b, sizeof b, "%.*f", digits, v);
  return b;
}

// Step 1: every corner onto the lowest-index vertex at its exact position. Returns the corners moved.
std::int64_t weld_corners(TriangleMesh& mesh) {
  const Eigen::Index n = mesh.V.rows();
  std::vector<Eigen::Index> order(static_cast<std::size_t>(n));
  std::iota(order.begin(), order.end(), Eigen::Index{0});
  auto less = [&](Eigen::Index a, Eigen::Index b) {
    for (int k = 0; k < 3; ++k)
      if (mesh.V(a, k) != mesh.V(b, k)) return mesh.V(a, k) < mesh.V(b, k);
    return a < b;
  };
  std::sort(order.begin(), order.end(), less);
  std::vector<int> to(static_cast<std::size_t>(n));
  for (std::size_t i = 0; i < order.size(); ++i) {
    const bool same = i > 0 && mesh.V.row(order[i]) == mesh.V.row(order[i - 1]);
    to[static_cast<std::size_t>(order[i])] = same ? to[static_cast<std::size_t>(order[i - 1])] : int(order[i]);
  }
  std::int64_t moved = 0;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int t = to[static_cast<std::size_t>(mesh.F(f, k))];
      moved += t != mesh.F(f, k);
      mesh.F(f, k) = t;
    }
  return moved;
}

// Keep the faces with keep[f] != 0, in order.
void keep_faces(TriangleMesh& mesh, const std::vector<std::uint8_t>& keep) {
  Eigen::Index m = 0;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
    if (keep[static_cast<std::size_t>(f)] != 0) mesh.F.row(m++) = mesh.F.row(f);
  mesh.F.conservativeResize(m, 3);
}

// Step 2: a face whose corner set an earlier face has (either winding) removed. Returns the faces removed.
std::int64_t remove_duplicate_faces(TriangleMesh& mesh) {
  const auto m = static_cast<std::size_t>(mesh.F.rows());
  std::vector<std::array<int, 4>> key(m);
  for (std::size_t f = 0; f < m; ++f) {
    std::array<int, 3> c{mesh.F(Eigen::Index(f), 0), mesh.F(Eigen::Index(f), 1), mesh.F(Eigen::Index(f), 2)};
    std::sort(c.begin(), c.end());
    key[f] = {c[0], c[1], c[2], static_cast<int>(f)};
  }
  std::sort(key.begin(), key.end());
  std::vector<std::uint8_t> keep(m, 1);
  std::int64_t removed = 0;
  for (std::size_t i = 1; i < m; ++i)
    if (key[i][0] == key[i - 1][0] && key[i][1] == key[i - 1][1] && key[i][2] == key[i - 1][2])
      keep[static_cast<std::size_t>(key[i][3])] = 0, ++removed;
  if (removed > 0) keep_faces(mesh, keep);
  return removed;
}

// Step 2 within a tolerance: a face (its longest edge at least 10 kNearFaceMm: a speck's slivers are not judged)
// whose centroid lies within kNearFaceMm of an earlier such face's of another connected part (a copy; a flat
// speck's two sides share corners and stay), in a parallel plane
// (|cos| > 0.99) and of nearly the same area (1 %), is the same wall stored twice with its corners moved a little
// (a copy written with rounding, or reversed and offset by a micrometre). Removed. Centroids in cells of
// kNearFaceMm (O(m)). Returns the faces removed.
constexpr double kNearFaceMm = 0.01;  // mm
std::int64_t remove_near_duplicate_faces(TriangleMesh& mesh) {
  const auto m = static_cast<std::size_t>(mesh.F.rows());
  int parts = 0;
  const std::vector<int> part = detail::face_parts(mesh, parts);
  std::vector<Eigen::Vector3d> centre(m), normal(m);
  std::vector<double> area(m);
  std::unordered_map<std::int64_t, std::vector<int>> cells;
  auto key = [](const Eigen::Vector3d& x, int di, int dj, int dk) {
    const auto c = [](double v, int d) { return (static_cast<std::int64_t>(std::floor(v / kNearFaceMm)) + d) & 0x1fffff; };
    return (c(x.x(), di) << 42) | (c(x.y(), dj) << 21) | c(x.z(), dk);
  };
  std::vector<std::uint8_t> keep(m, 1);
  std::int64_t removed = 0;
  for (std::size_t f = 0; f < m; ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(Eigen::Index(f), 0)), b = mesh.V.row(mesh.F(Eigen::Index(f), 1)),
                          c = mesh.V.row(mesh.F(Eigen::Index(f), 2));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    centre[f] = (a + b + c) / 3, area[f] = n.norm(), normal[f] = n / std::max(area[f], 1e-300);
    if (std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()}) < 10 * kNearFaceMm) continue;  // a speck's
    bool repeat = false;
    for (int di = -1; di <= 1 && !repeat; ++di)
      for (int dj = -1; dj <= 1 && !repeat; ++dj)
        for (int dk = -1; dk <= 1 && !repeat; ++dk) {
          const auto it = cells.find(key(centre[f], di, dj, dk));
          if (it == cells.end()) continue;
          for (int g : it->second) {
            const auto k = static_cast<std::size_t>(g);
            if (part[k] != part[f] && (centre[k] - centre[f]).norm() <= kNearFaceMm &&
                std::abs(normal[k].dot(normal[f])) > 0.99 &&
                std::abs(area[k] - area[f]) <= 0.01 * std::max(area[k], area[f])) {
              repeat = true;
              break;
            }
          }
        }
    if (repeat) {
      keep[f] = 0, ++removed;
    } else {
      cells[key(centre[f], 0, 0, 0)].push_back(static_cast<int>(f));
    }
  }
  if (removed > 0) keep_faces(mesh, keep);
  return removed;
}

constexpr std::size_t kMaxDescribed = 20;       // fragments whose distance is measured and listed
constexpr std::size_t kMaxEnclosureTests = 256;  // parts tested for lying inside another (largest first)

// Step 4: the parts left out as fragments (largest first; the first kMaxDescribed with their distance), or an
// error for another bone's worth of surface.
std::vector<MeshFragment> left_out(const TriangleMesh& mesh, const std::vector<Part>& p, const std::string& source) {
  const double largest = p[detail::largest_part(p)].area;
  std::vector<const Part*> out;
  for (const Part& q : p)
    if (!q.kept && !q.inside) out.push_back(&q);
  std::sort(out.begin(), out.end(), [](const Part* a, const Part* b) {
    return a->area != b->area ? a->area > b->area
                              : std::lexicographical_compare(a->lo.data(), a->lo.data() + 3, b->lo.data(), b->lo.data() + 3);
  });
  std::vector<MeshFragment> frags;
  for (const Part* q : out) {
    MeshFragment f;
    f.triangles = q->triangles, f.area_mm2 = q->area, f.extent_mm = (q->hi - q->lo).maxCoeff();
    f.centre = (q->lo + q->hi) / 2;
    f.distance_mm = frags.size() < kMaxDescribed ? detail::distance_to_kept(mesh, p, *q) : NAN;
    require(q->area < kFragmentAreaFraction * largest, [&] {
      return source + ": two bones in one file? a part of " + fixed(q->area, 0) + " mm^2 lies " +
             fixed(f.distance_mm, 1) + " mm from the largest (" + fixed(largest, 0) +
             " mm^2), more than " + fixed(kBoneGapMm, 0) + " mm apart and over " +
             fixed(100 * kFragmentAreaFraction, 0) + " % of its area; give one bone per file (the parts of one bone lie "
             "within " + fixed(kBoneGapMm, 0) + " mm of each other)";
    });
    frags.push_back(f);
  }
  return frags;
}

// Remove the faces of the parts not kept, then every vertex no face uses (the others keep their order), their
// indices into `removed`. Returns how many.
std::int64_t remove_parts(TriangleMesh& mesh, const std::vector<Part>& p, const std::vector<int>& part,
                          std::vector<std::int64_t>& removed) {
  std::vector<std::uint8_t> keep(static_cast<std::size_t>(mesh.F.rows()));
  for (std::size_t f = 0; f < keep.size(); ++f) keep[f] = p[static_cast<std::size_t>(part[f])].kept ? 1 : 0;
  keep_faces(mesh, keep);
  std::vector<int> to(static_cast<std::size_t>(mesh.V.rows()), -1);
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) to[static_cast<std::size_t>(mesh.F(f, k))] = 0;
  Eigen::Index n = 0;
  for (std::size_t v = 0; v < to.size(); ++v) {
    if (to[v] == 0) {
      mesh.V.row(n) = mesh.V.row(Eigen::Index(v)), to[v] = static_cast<int>(n++);
    } else {
      removed.push_back(static_cast<std::int64_t>(v));
    }
  }
  const std::int64_t count = mesh.V.rows() - n;
  mesh.V.conservativeResize(n, 3);
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) mesh.F(f, k) = to[static_cast<std::size_t>(mesh.F(f, k))];
  return count;
}

std::string short_num(double v) {  // three significant digits: 12.9, 0.00064, 200
  char b[64];
  std::snprintf(b, sizeof b, "%.3g", v);
  return b;
}

std::string describe(const MeshFragment& f) {
  return short_num(f.area_mm2) + " mm^2 (" + short_num(f.extent_mm) + " mm across) " +
         (std::isnan(f.distance_mm) ? std::string("far") : fixed(f.distance_mm, 1) + " mm") + " from the bone";
}

}  // namespace

namespace {
// The undirected edges of `mesh` used by one face (boundary) and the count of those used by three or more
// (non-manifold): the edges grouped by their lower corner (a counting sort), each group sorted (a vertex's few
// neighbours). O(m).
std::vector<std::pair<int, int>> boundary_edge_list(const TriangleMesh& mesh, std::int64_t* nonmanifold) {
  const auto n = static_cast<std::size_t>(mesh.V.rows());
  std::vector<int> start(n + 1, 0), other(static_cast<std::size_t>(3 * mesh.F.rows()));
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) ++start[static_cast<std::size_t>(std::min(mesh.F(f, k), mesh.F(f, (k + 1) % 3))) + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = mesh.F(f, k), b = mesh.F(f, (k + 1) % 3);
      other[static_cast<std::size_t>(fill[static_cast<std::size_t>(std::min(a, b))]++)] = std::max(a, b);
    }
  std::vector<std::pair<int, int>> out;
  if (nonmanifold != nullptr) *nonmanifold = 0;
  for (std::size_t v = 0; v < n; ++v) {
    const auto b = other.begin() + start[v], e = other.begin() + start[v + 1];
    std::sort(b, e);
    for (auto i = b; i != e;) {
      auto j = i;
      while (j != e && *j == *i) ++j;
      if (j - i == 1) out.emplace_back(static_cast<int>(v), *i);
      if (j - i >= 3 && nonmanifold != nullptr) ++*nonmanifold;
      i = j;
    }
  }
  return out;
}
}  // namespace

void count_holes(const TriangleMesh& mesh, MeshHygiene& out) {
  const std::vector<std::pair<int, int>> edges = boundary_edge_list(mesh, &out.nonmanifold_edges);
  std::vector<int> parent(static_cast<std::size_t>(mesh.V.rows()));
  std::iota(parent.begin(), parent.end(), 0);
  std::vector<std::uint8_t> on_boundary(parent.size(), 0);
  for (const auto& [a, b] : edges) {
    on_boundary[static_cast<std::size_t>(a)] = on_boundary[static_cast<std::size_t>(b)] = 1;
    const int ra = find_root(parent, a), rb = find_root(parent, b);
    if (ra != rb) parent[static_cast<std::size_t>(std::max(ra, rb))] = std::min(ra, rb);
  }
  out.boundary_edges = static_cast<std::int64_t>(edges.size());
  out.boundary_loops = 0;
  for (std::size_t v = 0; v < parent.size(); ++v)
    out.boundary_loops += on_boundary[v] != 0 && find_root(parent, static_cast<int>(v)) == static_cast<int>(v);
}

std::int64_t boundary_edges_within(const TriangleMesh& mesh, const Eigen::Vector3d& centre, double radius_mm) {
  auto near = [&](int v) { return (mesh.V.row(v).transpose() - centre).norm() <= radius_mm; };
  std::int64_t n = 0;
  for (const auto& [a, b] : boundary_edge_list(mesh, nullptr)) n += near(a) && near(b);
  return n;
}

double central_span(const Vertices& V) {
  Eigen::Vector3d lo, hi;
  for (int k = 0; k < 3; ++k) {
    std::vector<double> x(static_cast<std::size_t>(V.rows()));
    for (Eigen::Index i = 0; i < V.rows(); ++i) x[static_cast<std::size_t>(i)] = V(i, k);
    const auto cut = static_cast<std::ptrdiff_t>(x.size() / 1000);
    std::nth_element(x.begin(), x.begin() + cut, x.end());
    lo[k] = x[static_cast<std::size_t>(cut)];
    std::nth_element(x.begin(), x.end() - 1 - cut, x.end());
    hi[k] = x[x.size() - 1 - static_cast<std::size_t>(cut)];
  }
  return (hi - lo).norm();
}

double winding_number(const TriangleMesh& mesh, const Eigen::Vector3d& q) {
  double sum = 0;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)).transpose() - q, b = mesh.V.row(mesh.F(f, 1)).transpose() - q,
                          c = mesh.V.row(mesh.F(f, 2)).transpose() - q;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    const double den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    sum += 2 * std::atan2(a.dot(b.cross(c)), den);
  }
  return sum / (4 * M_PI);
}

std::vector<std::string> MeshHygiene::warnings(const std::string& source) const {
  std::vector<std::string> w;
  if (!dropped.empty()) {
    std::string s = source + ": " + std::to_string(dropped.size()) + " fragment" + (dropped.size() > 1 ? "s" : "") +
                    " apart from the bone (over " + fixed(kBoneGapMm, 0) + " mm from it) removed: ";
    for (std::size_t i = 0; i < std::min<std::size_t>(dropped.size(), 3); ++i)
      s += (i > 0 ? "; " : "") + describe(dropped[i]);
    if (dropped.size() > 3) s += "; and " + std::to_string(dropped.size() - 3) + " smaller";
    w.push_back(s + " (--strict refuses them)");
  }
  if (parts_inside_removed > 0)
    w.push_back(source + ": " + std::to_string(parts_inside_removed) + " part" + (parts_inside_removed > 1 ? "s" : "") +
                " inside the bone removed (" + short_num(inside_area_mm2) +
                " mm^2: an inner wall, a cyst or a speck within it); the bone's outer surface is what meets the other "
                "bone (--strict refuses them)");
  if (duplicate_faces_removed > 0)
    w.push_back(source + ": " + std::to_string(duplicate_faces_removed) +
                " faces repeat another face (a double wall: the same corners, or within " + short_num(kNearFaceMm) +
                " mm in a parallel plane); the repeats removed");
  if (corners_welded > 0)
    w.push_back(source + ": " + std::to_string(corners_welded) +
                " face corners share a position with another vertex; joined to it");
  if (unused_vertices_removed > 0)
    w.push_back(source + ": " + std::to_string(unused_vertices_removed) +
                " vertices no face uses removed (per-vertex outputs list the vertices kept, in the file's order)");
  return w;
}

namespace {
// Steps 3-4 (mesh_hygiene.hpp): the bone's parts kept, parts inside it and fragments apart from it removed (or
// refused with `strict`), into h.
void keep_the_bone(TriangleMesh& mesh, const std::string& source, bool strict, MeshHygiene& h) {
  int parts = 0;
  const std::vector<int> part = detail::face_parts(mesh, parts);
  std::vector<Part> p = detail::describe_parts(mesh, part, parts);
  detail::keep_bone_parts(mesh, p, kBoneGapMm);
  h.components = parts;
  std::vector<int> vertex_part(static_cast<std::size_t>(mesh.V.rows()), -1);
  for (std::size_t i = 0; i < p.size(); ++i)
    for (int v : p[i].vertices) vertex_part[static_cast<std::size_t>(v)] = static_cast<int>(i);
  std::vector<std::uint8_t> closed(p.size(), 1);
  for (const auto& [a, b] : boundary_edge_list(mesh, nullptr)) closed[static_cast<std::size_t>(vertex_part[a])] = 0;
  h.parts_inside_removed = detail::mark_enclosed_parts(mesh, part, p, closed, kMaxEnclosureTests);
  h.dropped = left_out(mesh, p, source);
  for (const Part& q : p) h.inside_area_mm2 += q.inside ? q.area : 0.0;
  h.components_kept = std::count_if(p.begin(), p.end(), [](const Part& q) { return q.kept; });
  require(!strict || h.dropped.empty(), [&] {
    return source + ": " + std::to_string(h.dropped.size()) + " fragment(s) apart from the bone, the largest " +
           describe(h.dropped.front()) + "; --strict refuses them (without it they are removed)";
  });
  require(!strict || h.parts_inside_removed == 0, [&] {
    return source + ": " + std::to_string(h.parts_inside_removed) +
           " part(s) inside the bone (an inner wall, a cyst); --strict refuses them (without it they are removed)";
  });
  const std::int64_t unused = remove_parts(mesh, p, part, h.removed_vertices);
  std::int64_t fragment_vertices = 0;
  for (const Part& q : p) fragment_vertices += q.kept ? 0 : static_cast<std::int64_t>(q.vertices.size());
  h.unused_vertices_removed = unused - fragment_vertices;
}
}  // namespace

MeshHygiene clean_bone_mesh(TriangleMesh& mesh, const std::string& source, bool strict) {
  validate_mesh(mesh);
  MeshHygiene h;
  h.corners_welded = weld_corners(mesh);
  if (h.corners_welded > 0) remove_degenerate_faces(mesh);  // corners welded together: no area
  h.duplicate_faces_removed = remove_duplicate_faces(mesh);
  h.duplicate_faces_removed += remove_near_duplicate_faces(mesh);
  require(!strict || h.duplicate_faces_removed == 0, [&] {
    return source + ": " + std::to_string(h.duplicate_faces_removed) +
           " faces repeat another face (a double wall); --strict refuses it";
  });
  keep_the_bone(mesh, source, strict, h);
  count_holes(mesh, h);
  return h;
}

}  // namespace impinge
