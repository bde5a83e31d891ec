// A bone's mesh cleaned at load: welded corners, double walls, fragments, holes (mesh_hygiene.hpp).
#include "impinge/core/mesh_hygiene.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <unordered_map>

#include "impinge/core/error.hpp"

namespace impinge {
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

int find_root(std::vector<int>& parent, int v) {
  while (parent[static_cast<std::size_t>(v)] != v) {
    parent[static_cast<std::size_t>(v)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(v)])];
    v = parent[static_cast<std::size_t>(v)];
  }
  return v;
}

// The mesh's connected parts (across shared corners): each face's part (0..parts-1, numbered by first face).
std::vector<int> face_parts(const TriangleMesh& mesh, int& parts) {
  std::vector<int> parent(static_cast<std::size_t>(mesh.V.rows()));
  std::iota(parent.begin(), parent.end(), 0);
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
    for (int k = 1; k < 3; ++k) {
      const int a = find_root(parent, mesh.F(f, 0)), b = find_root(parent, mesh.F(f, k));
      if (a != b) parent[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
    }
  std::unordered_map<int, int> number;
  std::vector<int> part(static_cast<std::size_t>(mesh.F.rows()));
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const auto [it, added] = number.try_emplace(find_root(parent, mesh.F(f, 0)), static_cast<int>(number.size()));
    part[static_cast<std::size_t>(f)] = it->second;
  }
  parts = static_cast<int>(number.size());
  return part;
}

// The parts' geometry: area, bounding box and vertices.
struct Part {
  double area = 0;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = Eigen::Vector3d::Constant(-INFINITY);
  std::vector<int> vertices;
  std::int64_t triangles = 0;
  bool kept = false;
};

std::vector<Part> describe_parts(const TriangleMesh& mesh, const std::vector<int>& part, int parts) {
  std::vector<Part> p(static_cast<std::size_t>(parts));
  std::vector<int> seen(static_cast<std::size_t>(mesh.V.rows()), -1);
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    Part& q = p[static_cast<std::size_t>(part[static_cast<std::size_t>(f)])];
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    q.area += 0.5 * (b - a).cross(c - a).norm();
    ++q.triangles;
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.F(f, k);
      if (seen[static_cast<std::size_t>(v)] >= 0) continue;
      seen[static_cast<std::size_t>(v)] = 1;
      q.vertices.push_back(v);
      q.lo = q.lo.cwiseMin(mesh.V.row(v).transpose()), q.hi = q.hi.cwiseMax(mesh.V.row(v).transpose());
    }
  }
  return p;
}

// The largest part by area; of equal areas the one whose box's lowest corner comes first (not the file's order).
std::size_t largest_part(const std::vector<Part>& p) {
  std::size_t best = 0;
  for (std::size_t i = 1; i < p.size(); ++i) {
    const bool lower = std::lexicographical_compare(p[i].lo.data(), p[i].lo.data() + 3, p[best].lo.data(),
                                                    p[best].lo.data() + 3);
    if (p[i].area > p[best].area || (p[i].area == p[best].area && lower)) best = i;
  }
  return best;
}

// Cells of kBoneGapMm over the kept parts' vertices, to find the parts within that gap of them.
struct KeptGrid {
  std::unordered_map<std::int64_t, std::vector<int>> cells;
  static std::array<std::int64_t, 3> cell_of(const Eigen::Vector3d& x) {
    return {static_cast<std::int64_t>(std::floor(x.x() / kBoneGapMm)),
            static_cast<std::int64_t>(std::floor(x.y() / kBoneGapMm)),
            static_cast<std::int64_t>(std::floor(x.z() / kBoneGapMm))};
  }
  static std::int64_t key(std::int64_t i, std::int64_t j, std::int64_t k) {
    return ((i & 0x1fffff) << 42) | ((j & 0x1fffff) << 21) | (k & 0x1fffff);
  }
  void add(const TriangleMesh& mesh, const Part& p) {
    for (int v : p.vertices) {
      const auto c = cell_of(mesh.V.row(v).transpose());
      cells[key(c[0], c[1], c[2])].push_back(v);
    }
  }
  // Whether any kept vertex lies within kBoneGapMm of one of p's vertices.
  bool near(const TriangleMesh& mesh, const Part& p) const {
    for (int v : p.vertices) {
      const Eigen::Vector3d x = mesh.V.row(v).transpose();
      const auto c = cell_of(x);
      for (std::int64_t di = -1; di <= 1; ++di)
        for (std::int64_t dj = -1; dj <= 1; ++dj)
          for (std::int64_t dk = -1; dk <= 1; ++dk) {
            const auto it = cells.find(key(c[0] + di, c[1] + dj, c[2] + dk));
            if (it == cells.end()) continue;
            for (int w : it->second)
              if ((mesh.V.row(w).transpose() - x).squaredNorm() <= kBoneGapMm * kBoneGapMm) return true;
          }
    }
    return false;
  }
};

// Step 3: mark the bone's parts kept (the largest, then every part within kBoneGapMm of a kept one, repeatedly).
void keep_bone_parts(const TriangleMesh& mesh, std::vector<Part>& p) {
  KeptGrid grid;
  const std::size_t first = largest_part(p);
  p[first].kept = true;
  grid.add(mesh, p[first]);
  for (bool grew = true; grew;) {
    grew = false;
    for (Part& q : p)
      if (!q.kept && grid.near(mesh, q)) q.kept = true, grid.add(mesh, q), grew = true;
  }
}

// The least distance (mm) from a left-out part's vertices to the kept parts' vertices (brute force: fragments
// are small, and only the largest kMaxDescribed are measured).
double distance_to_kept(const TriangleMesh& mesh, const std::vector<Part>& p, const Part& q) {
  double best = INFINITY;
  for (const Part& k : p) {
    if (!k.kept) continue;
    for (int v : q.vertices)
      for (int w : k.vertices) best = std::min(best, (mesh.V.row(v) - mesh.V.row(w)).squaredNorm());
  }
  return std::sqrt(best);
}

constexpr std::size_t kMaxDescribed = 20;  // fragments whose distance is measured and listed

// Step 4: the parts left out as fragments (largest first; the first kMaxDescribed with their distance), or an
// error for another bone's worth of surface.
std::vector<MeshFragment> left_out(const TriangleMesh& mesh, const std::vector<Part>& p, const std::string& source) {
  const double largest = p[largest_part(p)].area;
  std::vector<const Part*> out;
  for (const Part& q : p)
    if (!q.kept) out.push_back(&q);
  std::sort(out.begin(), out.end(), [](const Part* a, const Part* b) {
    return a->area != b->area ? a->area > b->area
                              : std::lexicographical_compare(a->lo.data(), a->lo.data() + 3, b->lo.data(), b->lo.data() + 3);
  });
  std::vector<MeshFragment> frags;
  for (const Part* q : out) {
    MeshFragment f;
    f.triangles = q->triangles, f.area_mm2 = q->area, f.extent_mm = (q->hi - q->lo).maxCoeff();
    f.centre = (q->lo + q->hi) / 2;
    f.distance_mm = frags.size() < kMaxDescribed ? distance_to_kept(mesh, p, *q) : NAN;
    require(q->area < kFragmentAreaFraction * largest, [&] {
      return source + ": two bones in one file? a part of " + fixed(q->area, 0) + " mm^2 lies " +
             fixed(f.distance_mm, 1) + " mm from the largest (" + fixed(largest, 0) +
             " mm^2), more than " + fixed(kBoneGapMm, 0) + " mm apart and over " +
             fixed(100 * kFragmentAreaFraction, 0) + " % of its area; give one bone per file";
    });
    frags.push_back(f);
  }
  return frags;
}

// Remove the fragments' faces and the vertices only they used (the others keep their order).
void remove_parts(TriangleMesh& mesh, const std::vector<Part>& p, const std::vector<int>& part) {
  std::vector<std::uint8_t> keep(static_cast<std::size_t>(mesh.F.rows()));
  for (std::size_t f = 0; f < keep.size(); ++f) keep[f] = p[static_cast<std::size_t>(part[f])].kept ? 1 : 0;
  std::vector<std::uint8_t> drop_vertex(static_cast<std::size_t>(mesh.V.rows()), 0);
  for (const Part& q : p)
    if (!q.kept)
      for (int v : q.vertices) drop_vertex[static_cast<std::size_t>(v)] = 1;
  keep_faces(mesh, keep);
  std::vector<int> to(drop_vertex.size(), -1);
  Eigen::Index n = 0;
  for (std::size_t v = 0; v < drop_vertex.size(); ++v)
    if (drop_vertex[v] == 0) mesh.V.row(n) = mesh.V.row(Eigen::Index(v)), to[v] = static_cast<int>(n++);
  mesh.V.conservativeResize(n, 3);
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) mesh.F(f, k) = to[static_cast<std::size_t>(mesh.F(f, k))];
}

std::string describe(const MeshFragment& f) {
  return fixed(f.area_mm2, 1) + " mm^2 (" + fixed(f.extent_mm, 1) + " mm across) " +
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
  if (duplicate_faces_removed > 0)
    w.push_back(source + ": " + std::to_string(duplicate_faces_removed) +
                " faces repeat another face's corners (a double wall); the repeats removed");
  if (corners_welded > 0)
    w.push_back(source + ": " + std::to_string(corners_welded) +
                " face corners share a position with another vertex; joined to it");
  return w;
}

MeshHygiene clean_bone_mesh(TriangleMesh& mesh, const std::string& source, bool strict) {
  validate_mesh(mesh);
  MeshHygiene h;
  h.corners_welded = weld_corners(mesh);
  if (h.corners_welded > 0) remove_degenerate_faces(mesh);  // corners welded together: no area
  h.duplicate_faces_removed = remove_duplicate_faces(mesh);
  require(!strict || h.duplicate_faces_removed == 0, [&] {
    return source + ": " + std::to_string(h.duplicate_faces_removed) +
           " faces repeat another face's corners (a double wall); --strict refuses it";
  });
  int parts = 0;
  const std::vector<int> part = face_parts(mesh, parts);
  std::vector<Part> p = describe_parts(mesh, part, parts);
  keep_bone_parts(mesh, p);
  h.components = parts;
  h.components_kept = std::count_if(p.begin(), p.end(), [](const Part& q) { return q.kept; });
  h.dropped = left_out(mesh, p, source);
  require(!strict || h.dropped.empty(), [&] {
    return source + ": " + std::to_string(h.dropped.size()) + " fragment(s) apart from the bone, the largest " +
           describe(h.dropped.front()) + "; --strict refuses them (without it they are removed)";
  });
  if (!h.dropped.empty()) remove_parts(mesh, p, part);
  count_holes(mesh, h);
  return h;
}

}  // namespace impinge
