#include "impinge/sampling/raster_plan.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "impinge/core/error.hpp"
#include "impinge/sampling/naive_sampling.hpp"
#include "core/z_order.hpp"

namespace impinge {

namespace {
/// Kept triangles (all when culling is disabled) in Z-curve order of their centroid direction.
void order_triangles(const TriangleMesh& mesh, const Eigen::Vector3d& cor, RasterPlan& fc, bool with_cones) {
  std::vector<std::pair<std::uint64_t, std::int32_t>> key;
  key.reserve(static_cast<std::size_t>(mesh.F.rows()));
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)).transpose() - cor,
                          b = mesh.V.row(mesh.F(f, 1)).transpose() - cor,
                          c = mesh.V.row(mesh.F(f, 2)).transpose() - cor;
    if (fc.enabled && (a.dot(b.cross(c)) > 0 ? 1 : -1) != fc.keep_sign) continue;
    const Eigen::Vector3d m = a + b + c;
    key.emplace_back(detail::direction_z_order(m.x(), m.y(), m.z()), static_cast<std::int32_t>(f));
  }
  std::sort(key.begin(), key.end());
  fc.triangle_order.resize(key.size());
  for (std::size_t k = 0; k < key.size(); ++k) fc.triangle_order[k] = key[k].second;
  fc.with_cones = with_cones;
  if (with_cones) fc.cones = triangle_cones(mesh, cor, fc.triangle_order, &fc.cones_edge_on);
  fc.cor = cor;
  fc.mesh_fingerprint = mesh_fingerprint(mesh);
}

/// Mix of 64-bit words: position-weighted sum of the words and of their rotations (a
/// multiply-rotate hash whose loop vectorises).
template <typename T>
void mix_words(const T* data, std::size_t n, std::uint64_t& h) {
  static_assert(sizeof(T) == 8 || sizeof(T) == 4);
  std::uint64_t a = 0, b = 0;
  for (std::size_t i = 0; i < n; ++i) {
    std::uint64_t w = 0;
    std::memcpy(&w, data + i, sizeof(T));
    a += w * (2 * i + 1);
    b += ((w << 29) | (w >> 35)) * 0x9E3779B97F4A7C15ull;
  }
  h = (h ^ a) * 0xff51afd7ed558ccdull;
  h = (h ^ b ^ n) * 0xc4ceb9fe1a85ec53ull;
  h ^= h >> 33;
}
}  // namespace

std::uint64_t mesh_fingerprint(const TriangleMesh& mesh) {
  std::uint64_t h = 0x243F6A8885A308D3ull;
  mix_words(mesh.V.data(), static_cast<std::size_t>(mesh.V.size()), h);
  mix_words(mesh.F.data(), static_cast<std::size_t>(mesh.F.size()), h);
  return h ^ static_cast<std::uint64_t>(mesh.V.rows()) * 31 ^ static_cast<std::uint64_t>(mesh.F.rows());
}

RasterPlan plan_rasterization(const TriangleMesh& mesh, const Eigen::Vector3d& cor, int rays, bool with_cones) {
  validate_mesh(mesh);
  require(cor.allFinite(), mesh.source + ": centre of rotation is not finite");
  require(rays >= 1, "face culling: at least one ray is needed");
  RasterPlan fc;
  // Closed and consistently oriented: every directed edge (i, j) has exactly one (j, i).
  fc.boundary_edges = count_unpaired_directed_edges(mesh);
  if (fc.boundary_edges > 0) {
    fc.reason = std::to_string(fc.boundary_edges) +
                " directed edges without exactly one reverse (open or inconsistently "
                "oriented mesh)";
    order_triangles(mesh, cor, fc, with_cones);
    return fc;
  }
  // Orientation of the nearest hit along rays towards triangle centroids spread over the mesh (all rays in one
  // pass over the triangles).
  std::vector<Eigen::Vector3d> dirs;
  for (int k = 0; k < rays; ++k) {
    const Eigen::Index f = (mesh.F.rows() - 1) * k / std::max(1, rays - 1);
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)).transpose() - cor,
                          b = mesh.V.row(mesh.F(f, 1)).transpose() - cor,
                          c = mesh.V.row(mesh.F(f, 2)).transpose() - cor;
    const Eigen::Vector3d u = (a + b + c).normalized();
    if (u.allFinite()) dirs.push_back(u);
  }
  for (const auto& hit : cast_rays_naive(mesh, cor, dirs)) {
    if (!hit) continue;
    const Eigen::Index h = hit->second;
    const Eigen::Vector3d p = mesh.V.row(mesh.F(h, 0)).transpose() - cor,
                          q = mesh.V.row(mesh.F(h, 1)).transpose() - cor,
                          r = mesh.V.row(mesh.F(h, 2)).transpose() - cor;
    const double det = p.dot(q.cross(r));
    if (det == 0) continue;
    const int sign = det > 0 ? 1 : -1;
    ++fc.rays_checked;
    if (fc.keep_sign == 0) fc.keep_sign = sign;
    fc.rays_agreeing += sign == fc.keep_sign;
  }
  if (fc.rays_checked == 0) {
    fc.reason = "no ray from the COR hit the mesh";
    fc.keep_sign = 0;
  } else if (fc.rays_agreeing != fc.rays_checked) {
    fc.reason = "nearest hits of different orientation (nested or self-intersecting shells)";
    fc.keep_sign = 0;
  } else {
    fc.enabled = true;
  }
  order_triangles(mesh, cor, fc, with_cones);
  return fc;
}

}  // namespace impinge
