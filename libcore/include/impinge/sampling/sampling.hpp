#pragma once
/// @file sampling.hpp
/// Filling a radial distance map of any scheme from a mesh: rasterisation (equiangular),
/// resampling of a rasterised equiangular map (thesis sec. 4.2.2, accelerated USID sampling),
/// or casting every node's ray (thesis sec. 4.2.1, the O(m n) reference).

#include <Eigen/Core>
#include <string>

#include "impinge/core/mesh.hpp"
#include "impinge/maps/radial_distance_map.hpp"
#include "impinge/sampling/rasterize.hpp"
#include "impinge/core/enum_names.hpp"

namespace impinge {

/// How a map is filled.
enum class SamplingMethod {
  automatic,  ///< rasterize for equiangular maps, resample for every other scheme
  rasterize,  ///< equiangular maps only (thesis Algorithm 1)
  resample,   ///< rasterise a temporary equiangular map, interpolate it at every node, release it
  ray_cast,   ///< every node's ray against every triangle (naive, O(nodes x triangles))
  /// Every node's ray through a BVH (FirstHitCaster: Embree, else CGAL), on all cores: the exact
  /// first hit at every node of any scheme, without the bilinear error that `resample` adds.
  /// O(nodes log triangles). Throws impinge::Error when the build has no ray caster. Source: impinge (not in the thesis).
  ray_cast_bvh,
};
/// The names of the sampling methods (the option table's choices of --sampling; summary.json).
inline constexpr EnumNames<SamplingMethod, 5> kSamplingMethodNames{{{SamplingMethod::automatic, "auto"},
                                                                   {SamplingMethod::rasterize, "rasterize"},
                                                                   {SamplingMethod::resample, "resample"},
                                                                   {SamplingMethod::ray_cast, "ray-cast"},
                                                                   {SamplingMethod::ray_cast_bvh, "ray-cast-bvh"}}};

/// Parse "auto", "rasterize", "resample", "ray-cast", "ray-cast-bvh"; throws impinge::Error otherwise.
SamplingMethod parse_sampling_method(const std::string& name, const std::string& context = "sampling method");
const char* to_string(SamplingMethod method);

/// Options of sample_surface.
struct SamplingOptions {
  DistanceMode mode = DistanceMode::exact;  ///< rasterisation distance mode
  SamplingMethod method = SamplingMethod::automatic;
  double resample_precision_deg = 0;  ///< temporary equiangular precision for `resample`; 0 picks
                                      ///< 180 / round(180 / node spacing in degrees), the precision
                                      ///< whose equator count matches the scheme's (thesis Table 6)
  /// `resample` with resample_precision_deg = 0: the temporary equiangular precision is the matched
  /// one divided by this (>= 1). 1 is the thesis' accelerated sampling (sec. 4.2.2); its bilinear
  /// error adds to the scheme's own, so comparisons of schemes at equal error use 2 (a quarter of
  /// that error, at four times the rasterisation). Source: impinge (not in the thesis).
  int resample_oversampling = 1;
  /// Exact mode: skip the triangles that can never be the nearest hit (raster_plan.hpp).
  /// With `plan` null, the plan is made here (O(m), counted in planning_ms); culling turns itself
  /// off, and says why, on meshes where it would not be exact.
  bool cull_faces = true;
  const RasterPlan* plan = nullptr;  ///< a plan made once by plan_rasterization for this mesh and COR, or null
};

/// What a sampling run did.
struct SamplingReport {
  SamplingMethod method = SamplingMethod::automatic;          ///< the method actually used
  SamplingStats raster;                                       ///< counts of the rasterisation (equiangular part)
  double resample_precision_deg = 0;                          ///< temporary map precision (resample), else 0
  std::int64_t nodes_covered = 0;                             ///< nodes with a surface in the filled map
  double rasterize_ms = 0, resample_ms = 0, ray_cast_ms = 0;  ///< wall times of the stages
  double planning_ms = 0;                                     ///< rasterisation plan (face culling) made here
  bool faces_culled = false;                                  ///< rasterised with culling
};

/// Fill `map` (any scheme) from `mesh` (mm) about `cor` (mm): nearest hit per node, +inf where
/// no surface. Throws impinge::Error for `rasterize` on a non-equiangular map or a non-finite COR.
template <typename Scalar>
SamplingReport sample_surface(const TriangleMesh& mesh, const Eigen::Vector3d& cor, const SamplingOptions& options,
                              RadialDistanceMapT<Scalar>& map);

/// Resample `source` (equiangular) at every node of `target`: target[i] = bilinear value of
/// `source` in node i's direction (+inf where any weighted source node has no surface).
template <typename Scalar>
void resample(const RadialDistanceMap& source, RadialDistanceMapT<Scalar>& target);

}  // namespace impinge
