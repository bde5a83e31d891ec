#pragma once
/// @file ray_crossing.hpp
/// One crossing of a ray with a bone's surface: what a layered map (layered_map.hpp) stores per node
/// and what a ray caster (casters/first_hit_caster.hpp) reports.

namespace impinge {

/// Where a ray from the origin crosses a mesh's surface: distance (mm) and whether it enters the
/// solid there (the surface faces the ray) or leaves it. Source: impinge (layered maps; not in the thesis).
struct RayCrossing {
  double distance_mm = 0;
  bool entering = false;
};

}  // namespace impinge
