#include "impinge/core/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <utility>
#include <tuple>
#include <vector>
#include <sstream>

#include "impinge/core/error.hpp"

namespace impinge {

void validate_mesh(const TriangleMesh& mesh) {
  const std::string& src = mesh.source.empty() ? std::string("<mesh>") : mesh.source;
  require(mesh.V.rows() > 0, src + ": mesh has no vertices");
  require(mesh.F.rows() > 0, src + ": mesh has no triangles");
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i) {
    for (int k = 0; k < 3; ++k) {
      if (!std::isfinite(mesh.V(i, k))) {
        std::ostringstream os;
        os << src << ": vertex " << i << " has a non-finite coordinate (" << mesh.V(i, 0) << ", " << mesh.V(i, 1)
           << ", " << mesh.V(i, 2) << ")";
        throw Error(os.str());
      }
    }
  }
  const Eigen::Index n = mesh.V.rows();
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int idx = mesh.F(f, k);
      if (idx < 0 || idx >= n) {
        std::ostringstream os;
        os << src << ": face " << f << " has vertex index " << idx << " outside [0, " << n << ")";
        throw Error(os.str());
      }
    }
  }
}

int remove_degenerate_faces(TriangleMesh& mesh, double min_area_mm2) {
  validate_mesh(mesh);
  // Kept triangles moved up in place (row k <= f), so that a mesh without degenerate triangles (the usual case)
  // is neither copied nor reallocated.
  Eigen::Index k = 0;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const int a = mesh.F(f, 0), b = mesh.F(f, 1), c = mesh.F(f, 2);
    if (a == b || b == c || a == c) continue;
    const Eigen::Vector3d pa = mesh.V.row(a), pb = mesh.V.row(b), pc = mesh.V.row(c);
    const double area = 0.5 * (pb - pa).cross(pc - pa).norm();
    if (!(area > min_area_mm2)) continue;
    if (k != f) mesh.F.row(k) = mesh.F.row(f);
    ++k;
  }
  const int removed = static_cast<int>(mesh.F.rows() - k);
  if (k < mesh.F.rows()) mesh.F = mesh.F.topRows(k).eval();
  mesh.degenerate_faces_skipped += removed;
  return removed;
}

Eigen::VectorXd vertex_areas(const TriangleMesh& mesh) {
  validate_mesh(mesh);
  Eigen::VectorXd area = Eigen::VectorXd::Zero(mesh.V.rows());
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const Eigen::Vector3d pa = mesh.V.row(mesh.F(f, 0)), pb = mesh.V.row(mesh.F(f, 1)), pc = mesh.V.row(mesh.F(f, 2));
    const double third = (pb - pa).cross(pc - pa).norm() / 6.0;
    for (int k = 0; k < 3; ++k) area[mesh.F(f, k)] += third;
  }
  return area;
}

TriangleMesh submesh(const TriangleMesh& mesh, const std::vector<std::uint8_t>& keep_vertex,
                     std::vector<Eigen::Index>* kept) {
  validate_mesh(mesh);
  require(keep_vertex.size() == static_cast<std::size_t>(mesh.V.rows()),
          mesh.source + ": submesh: the vertex selection has " + std::to_string(keep_vertex.size()) +
              " entries for " + std::to_string(mesh.V.rows()) + " vertices");
  std::vector<int> index(keep_vertex.size(), -1);
  std::vector<Eigen::Index> used;
  std::vector<Eigen::Vector3i> faces;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    bool in = true;
    for (int c = 0; c < 3; ++c) in = in && keep_vertex[static_cast<std::size_t>(mesh.F(f, c))] != 0;
    if (!in) continue;
    Eigen::Vector3i idx;
    for (int c = 0; c < 3; ++c) {
      int& k = index[static_cast<std::size_t>(mesh.F(f, c))];
      if (k < 0) k = static_cast<int>(used.size()), used.push_back(mesh.F(f, c));
      idx[c] = k;
    }
    faces.push_back(idx);
  }
  TriangleMesh out;
  out.source = mesh.source;
  out.V.resize(static_cast<Eigen::Index>(used.size()), 3);
  for (std::size_t k = 0; k < used.size(); ++k) out.V.row(static_cast<Eigen::Index>(k)) = mesh.V.row(used[k]);
  out.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (std::size_t k = 0; k < faces.size(); ++k) out.F.row(static_cast<Eigen::Index>(k)) = faces[k].transpose();
  if (kept != nullptr) *kept = std::move(used);
  return out;
}

namespace {

/// count_unpaired_directed_edges' count, or, when a corner index is outside 0..n-1, the first such corner
/// (bad_face >= 0) and no count: one pass over the faces serves the check and the count.
struct UnpairedEdges {
  std::int64_t count = 0;
  Eigen::Index bad_face = -1;
  int bad_corner = 0;
};

UnpairedEdges unpaired_directed_edges(const TriangleMesh& mesh, std::int64_t stop_after) {
  const Eigen::Index n = mesh.V.rows(), m = mesh.F.rows();
  UnpairedEdges out;
  std::vector<std::int32_t> start(static_cast<std::size_t>(n) + 1, 0), to(static_cast<std::size_t>(3 * m));
  for (Eigen::Index f = 0; f < m; ++f)
    for (int k = 0; k < 3; ++k) {
      if (mesh.F(f, k) < 0 || mesh.F(f, k) >= n) {
        out.bad_face = f;
        out.bad_corner = k;
        return out;
      }
      ++start[static_cast<std::size_t>(mesh.F(f, k)) + 1];
    }
  for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i) start[i + 1] += start[i];
  std::vector<std::int32_t> fill(start.begin(), start.end() - 1);
  for (Eigen::Index f = 0; f < m; ++f)
    for (int k = 0; k < 3; ++k)
      to[static_cast<std::size_t>(fill[static_cast<std::size_t>(mesh.F(f, k))]++)] = mesh.F(f, (k + 1) % 3);
  for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i)
    for (std::int32_t e = start[i]; e < start[i + 1]; ++e) {
      const auto j = static_cast<std::size_t>(to[static_cast<std::size_t>(e)]);
      int reverse = 0, same = 0;
      for (std::int32_t g = start[j]; g < start[j + 1]; ++g) reverse += to[static_cast<std::size_t>(g)] == std::int32_t(i);
      for (std::int32_t g = start[i]; g < start[i + 1]; ++g) same += to[static_cast<std::size_t>(g)] == std::int32_t(j);
      if ((reverse != 1 || same != 1) && ++out.count >= stop_after) return out;
    }
  return out;
}

/// Whether every directed edge (a, b) of `mesh` occurs once and its reverse (b, a) once: a closed surface wound
/// consistently, which orient_consistently leaves as it is (each shared edge then joins two triangles that run it
/// opposite ways: no flip, no conflict). A corner index out of range is left to the general path (and
/// validate_mesh, whose message names it).
bool wound_consistently(const TriangleMesh& mesh) {
  const UnpairedEdges u = unpaired_directed_edges(mesh, 1);
  return u.bad_face < 0 && u.count == 0;
}

}  // namespace

std::int64_t count_unpaired_directed_edges(const TriangleMesh& mesh, std::int64_t stop_after) {
  const UnpairedEdges u = unpaired_directed_edges(mesh, stop_after);
  require(u.bad_face < 0, [&] {
    return mesh.source + ": triangle " + std::to_string(u.bad_face) + " has corner index " +
           std::to_string(mesh.F(u.bad_face, u.bad_corner)) + "; valid are 0 to " + std::to_string(mesh.V.rows() - 1);
  });
  return u.count;
}

std::int64_t orient_consistently(TriangleMesh& mesh, std::int64_t* conflicts) {
  const Eigen::Index m = mesh.F.rows();
  // A closed, consistently wound mesh (every scan's surface) needs no sort: nothing to flip, no conflict.
  if (wound_consistently(mesh)) {
    if (conflicts != nullptr) *conflicts = 0;
    return 0;
  }
  // Every directed edge (a, b) of every triangle under its undirected key, sorted so that the triangles
  // sharing an edge stand together.
  struct HalfEdge {
    std::uint64_t key;
    std::int32_t tri;
    bool forward;  // a < b as the triangle runs
  };
  std::vector<HalfEdge> e;
  e.reserve(static_cast<std::size_t>(3 * m));
  for (Eigen::Index t = 0; t < m; ++t)
    for (int k = 0; k < 3; ++k) {
      const auto a = static_cast<std::uint64_t>(mesh.F(t, k)), b = static_cast<std::uint64_t>(mesh.F(t, (k + 1) % 3));
      e.push_back({std::min(a, b) << 32 | std::max(a, b), static_cast<std::int32_t>(t), a < b});
    }
  std::sort(e.begin(), e.end(), [](const HalfEdge& x, const HalfEdge& y) {
    return std::tie(x.key, x.tri) < std::tie(y.key, y.tri);
  });
  // Neighbours across manifold edges: (other triangle, whether they run the edge the same way).
  std::vector<std::vector<std::pair<std::int32_t, bool>>> next(static_cast<std::size_t>(m));
  for (std::size_t i = 0; i < e.size();) {
    std::size_t j = i;
    while (j < e.size() && e[j].key == e[i].key) ++j;
    if (j - i == 2) {
      const bool same = e[i].forward == e[i + 1].forward;
      next[static_cast<std::size_t>(e[i].tri)].push_back({e[i + 1].tri, same});
      next[static_cast<std::size_t>(e[i + 1].tri)].push_back({e[i].tri, same});
    }
    i = j;
  }
  std::vector<std::int8_t> flip(static_cast<std::size_t>(m), -1);
  std::int64_t flipped = 0, bad = 0;
  std::vector<std::int32_t> part, queue;
  for (Eigen::Index seed = 0; seed < m; ++seed) {
    if (flip[static_cast<std::size_t>(seed)] >= 0) continue;
    part.clear();
    queue.assign(1, static_cast<std::int32_t>(seed));
    flip[static_cast<std::size_t>(seed)] = 0;
    while (!queue.empty()) {
      const std::int32_t t = queue.back();
      queue.pop_back();
      part.push_back(t);
      for (const auto& [n, same] : next[static_cast<std::size_t>(t)]) {
        const std::int8_t want = static_cast<std::int8_t>(flip[static_cast<std::size_t>(t)] ^ (same ? 1 : 0));
        if (flip[static_cast<std::size_t>(n)] < 0) {
          flip[static_cast<std::size_t>(n)] = want;
          queue.push_back(n);
        } else if (flip[static_cast<std::size_t>(n)] != want && t < n) {
          ++bad;
        }
      }
    }
    // The part's majority keeps its winding.
    std::int64_t count = 0;
    for (std::int32_t t : part) count += flip[static_cast<std::size_t>(t)];
    const bool invert = 2 * count > static_cast<std::int64_t>(part.size());
    for (std::int32_t t : part) {
      if ((flip[static_cast<std::size_t>(t)] != 0) != invert) {
        std::swap(mesh.F(t, 1), mesh.F(t, 2));
        ++flipped;
      }
    }
  }
  if (conflicts != nullptr) *conflicts = bad;
  return flipped;
}

TriangleMesh split_in_four(const TriangleMesh& m) {
  std::vector<Eigen::Vector3d> v;
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) v.push_back(m.V.row(i).transpose());
  std::map<std::pair<int, int>, int> mid;
  auto midpoint = [&](int a, int b) {
    const auto key = std::minmax(a, b);
    const auto it = mid.find(key);
    if (it != mid.end()) return it->second;
    v.push_back(0.5 * (v[static_cast<std::size_t>(a)] + v[static_cast<std::size_t>(b)]));
    return mid[key] = static_cast<int>(v.size()) - 1;
  };
  TriangleMesh out;
  out.F.resize(4 * m.F.rows(), 3);
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    const int a = m.F(f, 0), b = m.F(f, 1), c = m.F(f, 2);
    const int ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
    out.F.row(4 * f) << a, ab, ca;
    out.F.row(4 * f + 1) << ab, b, bc;
    out.F.row(4 * f + 2) << ca, bc, c;
    out.F.row(4 * f + 3) << ab, bc, ca;
  }
  out.V.resize(static_cast<Eigen::Index>(v.size()), 3);
  for (std::size_t i = 0; i < v.size(); ++i) out.V.row(static_cast<Eigen::Index>(i)) = v[i].transpose();
  out.source = m.source;
  return out;
}

}  // namespace impinge
