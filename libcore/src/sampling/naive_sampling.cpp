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

namespace {
/// ray_triangle for k rays at once against one triangle (corners relative to the rays' origin), keeping each
/// ray's nearest hit: best[r] and best_f[r] become t and f where ray r meets the triangle at t < best[r]. The
/// same double arithmetic as ray_triangle, operation by operation (Eigen's cross and dot products written out in
/// its order), computed for every lane and then selected, so that the lanes vectorise; built for AVX-512, AVX2 and
/// the baseline, chosen at run time, without contraction into fused multiply-adds (-ffp-contract=off,
/// sampling/CMakeLists.txt): every clone gives ray_triangle's t to the bit (NaiveSampling.RaysInOnePassEqualOneByOne).
__attribute__((target_clones("avx512f", "avx2", "default"))) void nearest_hits_with_triangle(
    const double* ux, const double* uy, const double* uz, std::size_t k, const double* p0, const double* e1,
    const double* e2, std::int64_t f, double* best, std::int64_t* best_f) {
  const double tx = -p0[0], ty = -p0[1], tz = -p0[2];
  for (std::size_t r = 0; r < k; ++r) {
    const double pvx = uy[r] * e2[2] - uz[r] * e2[1];  // pv = u x e2
    const double pvy = uz[r] * e2[0] - ux[r] * e2[2];
    const double pvz = ux[r] * e2[1] - uy[r] * e2[0];
    const double det = e1[0] * pvx + e1[1] * pvy + e1[2] * pvz;
    const double inv = 1.0 / det;
    const double bu = (tx * pvx + ty * pvy + tz * pvz) * inv;
    const double qvx = ty * e1[2] - tz * e1[1];  // qv = tv x e1
    const double qvy = tz * e1[0] - tx * e1[2];
    const double qvz = tx * e1[1] - ty * e1[0];
    const double bv = (ux[r] * qvx + uy[r] * qvy + uz[r] * qvz) * inv;
    const double t = (e2[0] * qvx + e2[1] * qvy + e2[2] * qvz) * inv;
    const bool hit = !(std::abs(det) < 1e-300) && !(bu < 0 || bu > 1) && !(bv < 0 || bu + bv > 1) && t > 0;
    const bool nearer = hit && t < best[r];
    best[r] = nearer ? t : best[r];
    best_f[r] = nearer ? f : best_f[r];
  }
}
}  // namespace

std::vector<std::optional<std::pair<double, std::int64_t>>> cast_rays_naive(const TriangleMesh& mesh,
                                                                            const Eigen::Vector3d& cor,
                                                                            const std::vector<Eigen::Vector3d>& u) {
  const std::size_t k = u.size();
  std::vector<double> best(k, std::numeric_limits<double>::infinity()), ux(k), uy(k), uz(k);
  std::vector<std::int64_t> best_f(k, -1);
  for (std::size_t r = 0; r < k; ++r) ux[r] = u[r].x(), uy[r] = u[r].y(), uz[r] = u[r].z();
  Eigen::Vector3d p0, e1, e2;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    face_relative(mesh, f, cor, p0, e1, e2);
    nearest_hits_with_triangle(ux.data(), uy.data(), uz.data(), k, p0.data(), e1.data(), e2.data(), f, best.data(),
                               best_f.data());
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
