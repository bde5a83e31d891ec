#include "impinge/sampling/layered_sampling.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <vector>

#include "impinge/core/interrupt.hpp"
#include "impinge/core/timing.hpp"

namespace impinge {

LayeredSamplingReport sample_layered_map(LayeredMap& map, const FirstHitCaster& caster) {
  const auto t0 = std::chrono::steady_clock::now();
  LayeredSamplingReport rep;
  const std::int64_t nodes = map.num_nodes();
  const int layers = map.layers();
  rep.nodes = nodes;
  std::int64_t covered = 0, truncated = 0, not_alternating = 0;
  int most = 0;
#pragma omp parallel reduction(+ : covered, truncated, not_alternating) reduction(max : most)
  {
    std::vector<RayCrossing> c;
    bool stop = false;  // a front end's stop (asked every 1024 nodes): the rest skipped, thrown below
#pragma omp for schedule(dynamic, 4096)
    for (std::int64_t i = 0; i < nodes; ++i) {
      if ((i & 1023) == 0) stop = interruption_requested();
      if (stop) continue;
      caster.crossings(map.scheme().node_direction(i), c);
      covered += !c.empty();
      truncated += static_cast<int>(c.size()) > layers;
      most = std::max(most, static_cast<int>(c.size()));
      for (std::size_t k = 1; k < c.size(); ++k)
        if (c[k].entering == c[k - 1].entering) {
          ++not_alternating;
          break;
        }
      map.set(i, c);
    }
  }
  interruption_point();  // a front end's stop (Ctrl-C in Python): the map is incomplete
  rep.nodes_covered = covered;
  rep.nodes_truncated = truncated;
  rep.nodes_not_alternating = not_alternating;
  rep.max_crossings = most;
  rep.sampling_ms = ms_since(t0);
  return rep;
}

double signed_radial_distance_exact(const FirstHitCaster& caster, const Eigen::Vector3d& q) {
  const double r = q.norm();
  if (!(r > 0)) return std::numeric_limits<double>::quiet_NaN();
  thread_local std::vector<RayCrossing> c;
  caster.crossings(q, c);
  return signed_radial_distance(c.data(), static_cast<int>(c.size()), true, r);
}

}  // namespace impinge
