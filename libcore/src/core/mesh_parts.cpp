// The connected parts of a bone's mesh and which of them are the bone (mesh_parts.hpp).
#include "core/mesh_parts.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <numeric>
#include <unordered_map>

namespace impinge::detail {

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

namespace {
// Cells of a fixed size over the used vertices, each cell's vertices grouped by part: [part, begin, end) runs.
struct PartCells {
  double size;
  std::vector<int> vertex_part;
  struct Cell {
    std::vector<int> v;                       // vertices, by part
    std::vector<std::array<int, 3>> runs;     // part, begin, end into v
  };
  std::unordered_map<std::int64_t, Cell> cells;
  std::array<std::int64_t, 3> cell_of(const Eigen::Vector3d& x) const {
    return {static_cast<std::int64_t>(std::floor(x.x() / size)), static_cast<std::int64_t>(std::floor(x.y() / size)),
            static_cast<std::int64_t>(std::floor(x.z() / size))};
  }
  static std::int64_t key(std::int64_t i, std::int64_t j, std::int64_t k) {
    return ((i & 0x1fffff) << 42) | ((j & 0x1fffff) << 21) | (k & 0x1fffff);
  }
  PartCells(const TriangleMesh& mesh, const std::vector<Part>& p, double cell) : size(cell) {
    vertex_part.assign(static_cast<std::size_t>(mesh.V.rows()), -1);
    for (std::size_t i = 0; i < p.size(); ++i)
      for (int v : p[i].vertices) {
        vertex_part[static_cast<std::size_t>(v)] = static_cast<int>(i);
        const auto c = cell_of(mesh.V.row(v).transpose());
        cells[key(c[0], c[1], c[2])].v.push_back(v);
      }
    for (auto& [k, c] : cells) {
      std::sort(c.v.begin(), c.v.end(), [&](int a, int b) {
        const int pa = vertex_part[static_cast<std::size_t>(a)], pb = vertex_part[static_cast<std::size_t>(b)];
        return pa != pb ? pa < pb : a < b;
      });
      for (std::size_t i = 0; i < c.v.size();) {
        std::size_t j = i;
        const int part = vertex_part[static_cast<std::size_t>(c.v[i])];
        while (j < c.v.size() && vertex_part[static_cast<std::size_t>(c.v[j])] == part) ++j;
        c.runs.push_back({part, static_cast<int>(i), static_cast<int>(j)});
        i = j;
      }
    }
  }
};
}  // namespace

void keep_bone_parts(const TriangleMesh& mesh, std::vector<Part>& p, double gap_mm) {
  const PartCells grid(mesh, p, gap_mm);
  std::deque<int> frontier;  // kept vertices whose neighbourhood is still to be looked at
  auto take = [&](std::size_t i) {
    p[i].kept = true;
    frontier.insert(frontier.end(), p[i].vertices.begin(), p[i].vertices.end());
  };
  take(largest_part(p));
  while (!frontier.empty()) {
    const int v = frontier.front();
    frontier.pop_front();
    const Eigen::Vector3d x = mesh.V.row(v).transpose();
    const auto c = grid.cell_of(x);
    for (std::int64_t di = -1; di <= 1; ++di)
      for (std::int64_t dj = -1; dj <= 1; ++dj)
        for (std::int64_t dk = -1; dk <= 1; ++dk) {
          const auto it = grid.cells.find(PartCells::key(c[0] + di, c[1] + dj, c[2] + dk));
          if (it == grid.cells.end()) continue;
          for (const auto& [part, b, e] : it->second.runs) {
            if (p[static_cast<std::size_t>(part)].kept) continue;
            for (int k = b; k < e; ++k)
              if ((mesh.V.row(it->second.v[static_cast<std::size_t>(k)]).transpose() - x).squaredNorm() <=
                  gap_mm * gap_mm) {
                take(static_cast<std::size_t>(part));
                break;
              }
          }
        }
  }
}

double distance_to_kept(const TriangleMesh& mesh, const std::vector<Part>& p, const Part& q) {
  std::size_t kept = 0;
  for (const Part& k : p)
    if (k.kept) kept += k.vertices.size();
  const std::size_t stride = std::max<std::size_t>(1, q.vertices.size() * kept / 40000000 + 1);
  double best = INFINITY;
  std::size_t at = 0;
  for (const Part& k : p) {
    if (!k.kept) continue;
    for (int w : k.vertices)
      if (at++ % stride == 0)
        for (int v : q.vertices) best = std::min(best, (mesh.V.row(v) - mesh.V.row(w)).squaredNorm());
  }
  return std::sqrt(best);
}

std::int64_t mark_enclosed_parts(const TriangleMesh& mesh, const std::vector<int>& part, std::vector<Part>& p,
                                 const std::vector<std::uint8_t>& closed, std::size_t max_tested) {
  const std::size_t largest = largest_part(p);
  std::vector<std::size_t> candidates;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (i != largest) candidates.push_back(i);
  std::sort(candidates.begin(), candidates.end(), [&](std::size_t a, std::size_t b) { return p[a].area > p[b].area; });
  if (candidates.size() > max_tested) candidates.resize(max_tested);
  std::vector<std::size_t> inside;
  std::vector<double> sum(p.size());
  for (std::size_t i : candidates) {
    // Each other kept part's winding number at one of this part's vertices (solid angles, van Oosterom & Strackee).
    const Eigen::Vector3d q = mesh.V.row(p[i].vertices.front()).transpose();
    std::fill(sum.begin(), sum.end(), 0.0);
    for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
      const auto j = static_cast<std::size_t>(part[static_cast<std::size_t>(f)]);
      if (j == i || !p[j].kept || closed[j] == 0) continue;
      const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)).transpose() - q, b = mesh.V.row(mesh.F(f, 1)).transpose() - q,
                            c = mesh.V.row(mesh.F(f, 2)).transpose() - q;
      const double la = a.norm(), lb = b.norm(), lc = c.norm();
      sum[j] += 2 * std::atan2(a.dot(b.cross(c)), la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb);
    }
    for (double s : sum)
      if (std::abs(s) / (4 * M_PI) >= 0.5) {
        inside.push_back(i);
        break;
      }
  }
  for (std::size_t i : inside) p[i].kept = false, p[i].inside = true;
  return static_cast<std::int64_t>(inside.size());
}

}  // namespace impinge::detail
