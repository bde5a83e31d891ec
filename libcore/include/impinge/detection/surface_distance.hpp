#pragma once
/// @file surface_distance.hpp
/// The distance scan: for the vertices of one body at a pose, the signed Euclidean distance to the other
/// body's surface (casters/signed_distance.hpp), beside the radial gap of the thesis (detection.hpp).
/// Source: issue 26.
///
/// Exact, and cheap, by leaving out what cannot be within reach:
/// - Clusters of up to 32 nearby vertices (a Z curve over their positions), each with a bounding ball.
///   A cluster whose ball, grown by the reach, holds no point of the other surface (one pruned
///   hierarchy query that stops at the first triangle found) is proven farther than the reach, vertex
///   by vertex: |p - s| >= |c - s| - r_c > reach for every vertex p and surface point s.
/// - The radial gap bounds the distance from above (the point along the ray at the map's radius lies on
///   the other surface, to the map's interpolation error), so a vertex with a gap g is searched within
///   min(reach, |g| + 0.5 mm) first, which visits few triangles; where that finds nothing, within the
///   reach. A vertex whose gap is below -reach (deep inside the other bone) is searched within
///   |g| + 0.5 mm, so that its depth is measured whatever the reach.
/// - The search itself is exact: the closest point of every triangle the hierarchy cannot prune, in
///   double.
/// The sign: signed_distance.hpp's rule, with the radial gap's sign (where |g| > 0.1 mm, above the maps'
/// interpolation error) as the hint.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "impinge/casters/signed_distance.hpp"
#include "impinge/core/mesh.hpp"

namespace impinge {

/// The vertices of one body for the distance scan, grouped once (pose-invariant).
struct DistanceScanSet {
  std::vector<std::int32_t> index;          ///< k vertex indices, cluster by cluster
  std::vector<Eigen::Vector3d> position;    ///< k positions relative to the COR, body frame, mm
  std::vector<std::int32_t> cluster_begin;  ///< c + 1 offsets into index (cluster j: [begin[j], begin[j+1]))
  std::vector<Eigen::Vector3d> centre;      ///< c cluster centres relative to the COR, body frame, mm
  std::vector<double> radius;               ///< c cluster radii, mm
  std::int64_t vertices = 0;                ///< n, vertices of the body
  std::int64_t clusters() const { return static_cast<std::int64_t>(centre.size()); }
};

/// DistanceScanSet of the vertices P (n x 3, mm, relative to the COR) with |p| <= max_radius_mm, in
/// clusters of at most `cluster_size` (>= 1) vertices. Throws impinge::Error on a bad size or n above
/// 2^31 - 1.
DistanceScanSet make_distance_scan_set(PointsRef P, double max_radius_mm, int cluster_size = 32);

/// Counts of one distance scan.
struct DistanceScanStats {
  std::int64_t measured = 0;        ///< vertices given a distance
  std::int64_t clusters_pruned = 0; ///< clusters proven beyond the reach
  std::int64_t winding = 0;         ///< signs decided by the winding number
};

/// The distance scan at one pose. For every vertex i of `set`: q = cor + R p_i + t (the other body's
/// mesh frame; R: 3 x 3, t: mm), distance_mm[index[i]] = the signed distance from q to `other`'s surface
/// (mm, negative inside), or NaN when it is proven farther than `reach_mm` (> 0). `gap_mm`: the body's
/// radial gaps (n values, NaN where not tested; empty: none), used as bounds and sign hints (the file
/// comment). `distance_mm` is resized to n and NaN outside the set. Single thread, allocation-free once
/// `distance_mm` has its size.
DistanceScanStats scan_distances(const DistanceScanSet& set, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                 const Eigen::Vector3d& cor, const SignedDistanceQuery& other, double reach_mm,
                                 const std::vector<float>& gap_mm, std::vector<float>& distance_mm);

}  // namespace impinge
