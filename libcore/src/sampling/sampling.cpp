#include "impinge/sampling/sampling.hpp"

#include <chrono>
#include <cmath>
#include <vector>

#include "impinge/casters/first_hit_caster.hpp"
#include "impinge/core/error.hpp"
#include "impinge/core/interrupt.hpp"
#include "impinge/core/spherical_frame.hpp"
#include "impinge/core/timing.hpp"
#include "impinge/sampling/naive_sampling.hpp"

namespace impinge {

SamplingMethod parse_sampling_method(const std::string& name, const std::string& context) {
  return parse_enum(kSamplingMethodNames, name, context);
}

const char* to_string(SamplingMethod method) { return enum_name(kSamplingMethodNames, method); }

template <typename Scalar>
void resample(const RadialDistanceMap& source, RadialDistanceMapT<Scalar>& target) {
  const EquiangularGrid& g = equiangular_grid_of(source.scheme());
  const SamplingScheme& scheme = target.scheme();
  const float* src = source.data();
  Scalar* dst = target.data();
  constexpr std::int64_t kBlock = 4096;
  std::vector<double> phi(kBlock), theta(kBlock);
  const std::int64_t n = target.num_nodes();
  for (std::int64_t first = 0; first < n; first += kBlock) {
    const std::int64_t count = std::min(kBlock, n - first);
    scheme.node_angles(first, count, phi.data(), theta.data());
    for (std::int64_t j = 0; j < count; ++j) {
      std::int64_t nd[4];
      double w[4];
      g.stencil_angles(phi[j], theta[j], nd, w);
      double v = w[0] * src[nd[0]] + w[1] * src[nd[1]] + w[2] * src[nd[2]] + w[3] * src[nd[3]];
      if (!std::isfinite(v)) {  // a neighbour without surface: keep only if its weight is 0
        v = 0;
        for (int k = 0; k < 4; ++k) {
          if (w[k] == 0) continue;
          if (!std::isfinite(src[nd[k]])) {
            v = std::numeric_limits<double>::infinity();
            break;
          }
          v += w[k] * src[nd[k]];
        }
      }
      dst[first + j] = static_cast<Scalar>(v);
    }
  }
}

namespace {
// Every node of `map` by a ray cast (all cores). Throws Interrupted on a front end's stop (core/interrupt.hpp),
// asked every 1024 nodes, the map then incomplete.
template <typename Scalar>
void cast_every_node(const FirstHitCaster& caster, RadialDistanceMapT<Scalar>& map) {
  const SamplingScheme& scheme = map.scheme();
  Scalar* out = map.data();
  const std::int64_t n = map.num_nodes();
#pragma omp parallel
  {
    bool stop = false;
#pragma omp for schedule(dynamic, 4096)
    for (std::int64_t i = 0; i < n; ++i) {
      if ((i & 1023) == 0) stop = interruption_requested();
      if (!stop) out[i] = static_cast<Scalar>(caster.first_hit(scheme.node_direction(i)));
    }
  }
  interruption_point();
}
}  // namespace

template <typename Scalar>
SamplingReport sample_surface(const TriangleMesh& mesh, const Eigen::Vector3d& cor, const SamplingOptions& o,
                              RadialDistanceMapT<Scalar>& map) {
  require(cor.allFinite(), mesh.source + ": centre of rotation is not finite");
  SamplingReport rep;
  rep.method = o.method;
  // The rasteriser fills an equiangular grid: a map conformable with one is rasterised directly,
  // any other is resampled from one (thesis sec. 4.2.2).
  if (rep.method == SamplingMethod::automatic)
    rep.method = conformable_equiangular_grid(map.scheme()) ? SamplingMethod::rasterize : SamplingMethod::resample;
  auto t0 = std::chrono::steady_clock::now();
  // Face culling (exact mode): the caller's plan, or one made here when asked to.
  RasterPlan own;
  const RasterPlan* cull = o.plan;
  if (cull == nullptr && o.cull_faces && o.mode == DistanceMode::exact &&
      (rep.method == SamplingMethod::rasterize || rep.method == SamplingMethod::resample)) {
    // Drawn once: a map that fits in the cache (up to 8 MB, 0.25 deg in float) is drawn as the cones are made,
    // a few thousand at a time, instead of from all of them made first (240 bytes a kept triangle, faulted in
    // fresh: 34 MB for a 280k-triangle femur); a larger one from the plan's cones, in bands of rows
    // (rasterize.hpp). The same map either way.
    constexpr double kStreamedMapBytes = 8.0 * 1024 * 1024;
    const bool streamed = rep.method == SamplingMethod::rasterize &&
                          static_cast<double>(map.num_nodes()) * sizeof(Scalar) <= kStreamedMapBytes;
    own = plan_rasterization(mesh, cor, kPlanRays, /*with_cones=*/!streamed);
    cull = &own;
    rep.planning_ms = ms_since(t0);
    t0 = std::chrono::steady_clock::now();
  }
  rep.faces_culled = cull != nullptr && cull->enabled && o.mode == DistanceMode::exact;
  switch (rep.method) {
    case SamplingMethod::rasterize:
      // A fresh map, as documented (with a plan the reset is fused with the drawing).
      rep.raster = rasterize(mesh, cor, o.mode, map, RasterizeOptions{cull, true, MapStart::reset});  // throws via equiangular_grid_of
                                                                                      // when not equiangular
      rep.rasterize_ms = ms_since(t0);
      break;
    case SamplingMethod::resample: {
      double p = o.resample_precision_deg;
      if (p <= 0) {
        require(o.resample_oversampling >= 1, mesh.source + ": resample oversampling " +
                                                   std::to_string(o.resample_oversampling) + " must be >= 1");
        p = matched_equiangular_precision(map.scheme().max_node_spacing() / o.resample_oversampling);
      }
      rep.resample_precision_deg = p;
      {
        RadialDistanceMap tmp{EquiangularGrid(p)};
        rep.raster = rasterize(mesh, cor, o.mode, tmp, RasterizeOptions{cull});
        rep.rasterize_ms = ms_since(t0);
        t0 = std::chrono::steady_clock::now();
        resample(tmp, map);
        rep.resample_ms = ms_since(t0);
      }  // the temporary map is released here (thesis sec. 4.2.2)
      break;
    }
    case SamplingMethod::ray_cast:
      sample_naive(mesh, cor, map);
      rep.ray_cast_ms = ms_since(t0);
      break;
    case SamplingMethod::ray_cast_bvh: {
      require(FirstHitCaster::available(), mesh.source + ": ray-cast-bvh sampling needs Embree or CGAL in this build");
      cast_every_node(FirstHitCaster(mesh, cor), map);
      rep.ray_cast_ms = ms_since(t0);
      break;
    }
    case SamplingMethod::automatic:
      break;
  }
  rep.nodes_covered = map.nodes_covered();
  return rep;
}

template void resample<float>(const RadialDistanceMap&, RadialDistanceMapT<float>&);
template void resample<double>(const RadialDistanceMap&, RadialDistanceMapT<double>&);
template SamplingReport sample_surface<float>(const TriangleMesh&, const Eigen::Vector3d&, const SamplingOptions&,
                                              RadialDistanceMapT<float>&);
template SamplingReport sample_surface<double>(const TriangleMesh&, const Eigen::Vector3d&, const SamplingOptions&,
                                               RadialDistanceMapT<double>&);

}  // namespace impinge
