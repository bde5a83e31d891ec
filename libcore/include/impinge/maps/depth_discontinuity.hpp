#pragma once
/// @file depth_discontinuity.hpp
/// Depth discontinuities of a radial distance map: nodes next to which the map's
/// interpolation cannot be trusted to a tolerance, because the first surface seen from the COR
/// jumps (the acetabular rim in front of the fossa, the femoral head in front of the neck), turns
/// steeply, or ends (the edge of the map's coverage). Look-ups whose stencil holds such a node are
/// resolved exactly by a ray cast (FirstHitCaster) instead of interpolated.

#include <cstdint>

#include "impinge/maps/radial_distance_map.hpp"

namespace impinge {

/// Mark the nodes of `map` where its interpolation may be off by more than `tolerance_mm`, in the
/// least significant bit of their value (has_discontinuity_mark; every other finite value gets
/// that bit cleared, a change of at most one unit in the last place). Returns the number marked.
///
/// Criterion. Let D be the second difference of the map at a node along the polar and along the
/// azimuthal great circle, at the scheme's node spacing h (max_node_spacing): D = d(u + h e) -
/// 2 d(u) + d(u - h e), the neighbours interpolated from the map. On a smooth surface the bilinear
/// interpolation error in a cell is at most (|D_phi| + |D_theta|) / 8 (tensor-product linear
/// interpolation, D ~ h^2 d''); across a jump of height J between two nodes, both get |D| ~ J and
/// the error reaches J. So a cell whose nodes all have |D| <= tolerance is within the tolerance
/// either way, and a node is marked when |D_phi| or |D_theta| exceeds it, or when a neighbour has
/// no surface (the edge of the coverage, where the look-up would report "no surface"). No fixed
/// threshold on the node distances themselves: steep but smooth surfaces (large first, small
/// second differences) are not marked.
///
/// The neighbours: for an equiangular grid its own (rows r +- 1, columns c +- 1: the nodes its
/// stencils join; one pass over the map); for any other scheme the map interpolated at u cos h +-
/// e sin h along the polar and azimuthal tangents e (four interpolations per node). OpenMP over
/// nodes. Throws impinge::Error unless tolerance_mm > 0 and finite.
template <typename Scalar>
std::int64_t mark_depth_discontinuities(RadialDistanceMapT<Scalar>& map, double tolerance_mm);

/// Clear every mark (the least significant bit of every finite value).
template <typename Scalar>
void clear_depth_discontinuities(RadialDistanceMapT<Scalar>& map);

/// Number of nodes of `map` with the mark.
template <typename Scalar>
std::int64_t count_depth_discontinuities(const RadialDistanceMapT<Scalar>& map);

}  // namespace impinge
