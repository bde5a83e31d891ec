#include "impinge/sampling/naive_sampling.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "impinge/core/error.hpp"

namespace impinge {

namespace {

/// Moller-Trumbore in double precision, edges inclusive: the distance t > 0 along the unit u from the origin at
/// which the ray meets the triangle p0 + s e1 + t e2 (corners relative to the ray's origin), or nothing.
inline std::optional<double> ray_triangle(const Eigen::Vector3d& p0, const Eigen::Vector3d& e1,
                                          const Eigen::Vector3d& e2, const Eigen::Vector3d& u) {
  const Eigen::Vector3d pv = u.cross(e2);
  const double det = e1.dot(pv);
  if (std::abs(det) < 1e-300) return std::nullopt;
  const double inv = 1.0 / det;
  const Eigen::Vector3d tv = -p0;
  const double bu = tv.dot(pv) * inv;
  if (bu < 0 || bu > 1) return std::nullopt;
  const Eigen::Vector3d qv = tv.cross(e1);
  const double bv = u.dot(qv) * inv;
  if (bv < 0 || bu + bv > 1) return std::nullopt;
  const double t = e2.dot(qv) * inv;
  if (!(t > 0)) return std::nullopt;
  return t;
}

/// Face f's corners relative to `cor` (p0, the edges e1 = p1 - p0 and e2 = p2 - p0), after checking its indices:
/// a bad index is an error, never an out-of-bounds read (one compare per corner; a ray is O(m) anyway).
inline void face_relative(const TriangleMesh& mesh, Eigen::Index f, const Eigen::Vector3d& cor, Eigen::Vector3d& p0,
                          Eigen::Vector3d& e1, Eigen::Vector3d& e2) {
  const Eigen::Index n = mesh.V.rows();
  for (int c = 0; c < 3; ++c)
    if (mesh.F(f, c) < 0 || mesh.F(f, c) >= n)
      throw Error(mesh.source + ": face " + std::to_string(f) + " has vertex index " + std::to_string(mesh.F(f, c)) +
                  " outside [0, " + std::to_string(n) + ")");
  p0 = mesh.V.row(mesh.F(f, 0)).transpose() - cor;
  e1 = mesh.V.row(mesh.F(f, 1)).transpose() - cor - p0;
  e2 = mesh.V.row(mesh.F(f, 2)).transpose() - cor - p0;
}

}  // namespace

std::optional<std::pair<double, std::int64_t>> cast_ray_naive(const TriangleMesh& mesh, const Eigen::Vector3d& cor,
                                                              const Eigen::Vector3d& u) {
  double best = std::numeric_limits<double>::infinity();
  std::int64_t best_f = -1;
  Eigen::Vector3d p0, e1, e2;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    face_relative(mesh, f, cor, p0, e1, e2);
    const std::optional<double> t = ray_triangle(p0, e1, e2, u);
    if (t && *t < best) {
      best = *t;
      best_f = f;
    }
  }
  if (best_f < 0) return std::nullopt;
  return std::make_pair(best, best_f);
}

std::vector<std::optional<std::pair<double, std::int64_t>>> cast_rays_naive(const TriangleMesh& mesh,
                                                                            const Eigen::Vector3d& cor,
                                                                            const std::vector<Eigen::Vector3d>& u) {
  const std::size_t k = u.size();
  std::vector<double> best(k, std::numeric_limits<double>::infinity());
  std::vector<std::int64_t> best_f(k, -1);
  Eigen::Vector3d p0, e1, e2;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    face_relative(mesh, f, cor, p0, e1, e2);
    for (std::size_t r = 0; r < k; ++r) {
      const std::optional<double> t = ray_triangle(p0, e1, e2, u[r]);
      if (t && *t < best[r]) {
        best[r] = *t;
        best_f[r] = f;
      }
    }
  }
  std::vector<std::optional<std::pair<double, std::int64_t>>> out(k);
  for (std::size_t r = 0; r < k; ++r)
    if (best_f[r] >= 0) out[r] = std::make_pair(best[r], best_f[r]);
  return out;
}

template <typename Scalar>
void sample_naive(const TriangleMesh& mesh, const Eigen::Vector3d& cor, RadialDistanceMapT<Scalar>& map,
                  std::vector<std::int64_t>* triangle_of_node) {
  validate_mesh(mesh);
  const std::int64_t n = map.num_nodes();
  if (triangle_of_node != nullptr) triangle_of_node->assign(static_cast<std::size_t>(n), -1);
  for (std::int64_t i = 0; i < n; ++i) {
    const auto hit = cast_ray_naive(mesh, cor, map.scheme().node_direction(i));
    if (!hit) continue;
    const Scalar v = static_cast<Scalar>(hit->first);
    if (v < map.data()[i]) map.data()[i] = v;
    if (triangle_of_node != nullptr) (*triangle_of_node)[static_cast<std::size_t>(i)] = hit->second;
  }
}

template void sample_naive<float>(const TriangleMesh&, const Eigen::Vector3d&, RadialDistanceMapT<float>&,
                                  std::vector<std::int64_t>*);
template void sample_naive<double>(const TriangleMesh&, const Eigen::Vector3d&, RadialDistanceMapT<double>&,
                                   std::vector<std::int64_t>*);

}  // namespace impinge
