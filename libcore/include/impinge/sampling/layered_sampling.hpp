#pragma once
/// @file layered_sampling.hpp
/// Filling a layered map (maps/layered_map.hpp) by ray casting, and its exact counterpart for one
/// point. Source: the thesis' sec. 6 ("multiple layers"), built as layered maps here.

#include <Eigen/Core>

#include "impinge/casters/first_hit_caster.hpp"
#include "impinge/maps/layered_map.hpp"

namespace impinge {

/// Fill `map` from `caster` (the mesh about the COR, in the map's frame): each node's ray cast for all
/// its crossings (FirstHitCaster::crossings), the nearest `map.layers()` kept. Runs on all cores
/// (OpenMP). Returns the counts (nodes covered, truncated, not alternating; wall time, ms).
/// Scheme-independent: any registered scheme. Throws what the caster throws.
LayeredSamplingReport sample_layered_map(LayeredMap& map, const FirstHitCaster& caster);

/// The exact counterpart of LayeredMap::signed_distance_many_soa for one point q (mm, relative to the
/// COR, the caster's frame): signed_radial_distance of |q| over every crossing of q's ray.
double signed_radial_distance_exact(const FirstHitCaster& caster, const Eigen::Vector3d& q);

}  // namespace impinge
