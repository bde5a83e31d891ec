#pragma once
/// @file naive_sampling.hpp
/// The thesis' pairwise O(m*n) sampling baseline: every node's ray against every triangle.

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "impinge/core/mesh.hpp"
#include "impinge/maps/radial_distance_map.hpp"

namespace impinge {

/// Nearest intersection of the ray cor + t u (t > 0, u unit) with the mesh by testing every
/// triangle (Moller-Trumbore in double precision, edges inclusive). Returns t in mm and the
/// triangle index, or nullopt when the ray misses. O(m). Throws impinge::Error naming the mesh
/// and face on a vertex index outside [0, n).
std::optional<std::pair<double, std::int64_t>> cast_ray_naive(const TriangleMesh& mesh, const Eigen::Vector3d& cor,
                                                              const Eigen::Vector3d& u);

/// cast_ray_naive for several rays from one `cor` in one pass over the triangles (each triangle's corners read
/// once for every ray): `u[k]` unit directions, result k the same value cast_ray_naive(mesh, cor, u[k]) gives
/// (the same arithmetic, triangles in the same order). O(rays x m). Throws as cast_ray_naive.
std::vector<std::optional<std::pair<double, std::int64_t>>> cast_rays_naive(const TriangleMesh& mesh,
                                                                            const Eigen::Vector3d& cor,
                                                                            const std::vector<Eigen::Vector3d>& u);

/// Fill `map` node by node with the nearest hit of the node's ray on every triangle (thesis
/// sec. 3.2 "naive O(m*n)" and sec. 4.2.1). Exact distances; the test oracle for
/// `rasterize` on small meshes. If `triangle_of_node` is given it receives, per node, the
/// index of the triangle hit (-1 for none). Cost O(nodes x triangles). Throws impinge::Error on
/// an invalid mesh (validate_mesh).
template <typename Scalar>
void sample_naive(const TriangleMesh& mesh, const Eigen::Vector3d& cor, RadialDistanceMapT<Scalar>& map,
                  std::vector<std::int64_t>* triangle_of_node = nullptr);

}  // namespace impinge
