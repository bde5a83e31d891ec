#pragma once
/// @file surface_distance.hpp
/// The distance scan: for the vertices of one body at a pose, the signed Euclidean distance to the other
/// body's surface (casters/signed_distance.hpp), beside the radial gap of the thesis (detection.hpp).
/// Source: impinge (not in the thesis).
///
/// Exact, and cheap, by leaving out what cannot be within reach:
/// - Clusters of up to 32 nearby vertices (boxes of median splits, order_in_boxes), each with a bounding
///   ball.
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
#include "impinge/detection/detection.hpp"
#include "impinge/maps/layered_map.hpp"

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
  std::int64_t undecided = 0;       ///< signs the mesh cannot decide (SignRule::undecided; read as outside)
  std::int64_t searches = 0;        ///< closest-point searches of single vertices
  std::int64_t vertices_recalled = 0;  ///< vertices proven beyond the reach by the memory's empty balls
  std::int64_t clusters_recalled = 0;  ///< clusters so proven (counted in clusters_pruned too)
};

/// What a thread's distance scans of one set against one surface have learnt, for the poses after (a
/// motion's frames): facts about the other surface, which does not move in its own frame, so that they hold
/// at any later pose, in any order. scan_distances fills and reads it; a memory about another surface
/// (`query` is not its SignedDistanceQuery::id()) or of another size is reset first.
struct DistanceScanMemory {
  std::uint64_t query = 0;                    ///< the id of the surface the facts are about (0: none yet)
  std::vector<std::int32_t> seed;             ///< k: each vertex's closest triangle at an earlier pose, or -1
  /// k: a ball about which no point of the surface lies (centre in the surface's frame, mm; radius 0: none
  /// known), from a search that found nothing nearer at an earlier pose.
  std::vector<Eigen::Vector3f> empty_centre;
  std::vector<float> empty_radius;
  std::vector<Eigen::Vector3f> cluster_empty_centre;  ///< c: the same about the clusters' centres
  std::vector<float> cluster_empty_radius;
  /// k: each vertex's NearbyTriangles in `nearby`, or -1 (none yet: given at its first search).
  std::vector<std::int32_t> nearby_slot;
  std::vector<NearbyTriangles> nearby;
  /// c: each cluster's centre at the last scan (the surface's frame, mm; NaN: none yet), to tell a step
  /// along a motion from a jump.
  std::vector<Eigen::Vector3f> cluster_last_centre;
};

/// The distance scan at one pose. For every vertex i of `set`: q = cor + R p_i + t (the other body's
/// mesh frame; R: 3 x 3, t: mm), distance_mm[index[i]] = the signed distance from q to `other`'s surface
/// (mm, negative inside), or NaN when it is proven farther than `reach_mm` (> 0). `gap_mm`: the body's
/// radial gaps (n values, NaN where not tested; empty: none), used as bounds and sign hints (the file
/// comment). `distance_mm` is resized to n and NaN outside the set. Single thread, allocation-free once
/// `distance_mm` and `memory` have their sizes (but for `memory`'s nearby triangles, a slot of 224 bytes
/// added at a vertex's first search: at most k of them).
///
/// `sign_undecided` (optional): resized to n, 1 where the vertex's sign the mesh cannot decide
/// (SignRule::undecided: its distance is written >= 0), else 0.
///
/// `memory` (optional): what earlier scans of the set against the same surface learnt (DistanceScanMemory),
/// used and updated. None of these facts changes an answer, only what it costs:
/// - Seeds: each vertex's closest triangle at an earlier pose is tried first in place of the previous
///   vertex's (SignedDistanceQuery::signed_distance's seed, which only narrows the search). Along a motion
///   a vertex's closest triangle is mostly the one of the frame before, or its neighbour.
/// - Empty balls: a vertex whose radial gap is at or beyond the reach (or missing) is first tested for any
///   point of the surface within the reach plus 2 mm, a cluster for any within its ball grown by the reach
///   plus 4 mm; where there is none, that ball about q (or the cluster's centre) is kept as empty. At a
///   later pose, a vertex whose ball of the reach lies inside its empty ball (|q - centre| + reach <
///   radius, less 1e-3 mm and 2^-20 of the coordinates' size for the float storage) is beyond the reach
///   without a search, and a cluster likewise without its test. Along a motion the vertices and clusters
///   beyond the reach are then tested every few frames instead of at each (lhdl-ct's 1,000-frame trial:
///   about 40 % fewer searches).
/// - Nearby triangles: each searched vertex keeps the hierarchy's groups within 2 mm beyond its search's
///   ball (NearbyTriangles); while its later searches' balls stay inside that ball, they read those groups
///   instead of walking the hierarchy (lhdl-ct's trial: about 9 of 10 searches, the distance scans
///   about 15 % cheaper on one thread).
/// - Steps and jumps: the empty balls' pre-tests and the nearby triangles' fills cost walks of their own, and
///   pay back only where the next scan comes within their margins. So a cluster learns them only when its
///   centre moved at most 4 mm (its empty ball) or 2 mm (its vertices' facts) since the scan before: a step
///   along a motion. At a first scan, and after a jump (a motion of scattered poses), it is scanned as
///   without a memory, but for what it already knows (seeds, empty balls it lies in). lhdl-ct at 0.1 deg,
///   1,000 poses at random, one thread: 4.6-5.0 ms a frame learning at every one, 2.8-3.0 ms so; a smooth
///   1,000-frame trial unchanged (2.03-2.07 ms).
DistanceScanStats scan_distances(const DistanceScanSet& set, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                 const Eigen::Vector3d& cor, const SignedDistanceQuery& other, double reach_mm,
                                 const std::vector<float>& gap_mm, std::vector<float>& distance_mm,
                                 DistanceScanMemory* memory = nullptr,
                                 std::vector<std::uint8_t>* sign_undecided = nullptr);

/// The same vertices as `set`, reordered along a Z curve over their positions (the distance scan's
/// order), so that consecutive vertices lie close in space: for the hidden vertices, whose directions
/// repeat at many depths (the neck and trochanter behind the head), so that runs of them have small
/// bounding balls.
ScanSet order_by_position(const ScanSet& set);

/// The same vertices as `set`, reordered by median splits in space so that every run of `run_sizes[j]`
/// vertices starting at a multiple of it is one box of the splits: compact in space whatever gaps the set
/// has (a Z curve jumps, and a subset of a Z-ordered set leaves holes, so that a run of it can span two
/// distant regions). A range of more than run_sizes.back() vertices is split at a multiple of the largest
/// size from its start, a smaller one at a multiple of the largest size below its length, at the median
/// (so rounded) along its bounding box's longest axis. For the bounds of clusters that are runs of the set
/// (the ROM searches' leaves, groups and blocks). run_sizes: ascending, each a multiple of the one before,
/// the first >= 1; throws impinge::Error otherwise. O(k log k).
ScanSet order_in_boxes(const ScanSet& set, const std::vector<std::int64_t>& run_sizes);

/// Consecutive runs of a scan set's vertices (pose-invariant), each with a bounding ball: tight when the
/// set is ordered in boxes of the runs' size (order_in_boxes; runs of a Z curve, order_by_position, can
/// span distant regions). For the layered scan's pruning (scan_layered_near).
struct ScanClusters {
  std::vector<std::int32_t> cluster_begin;  ///< c + 1 offsets into the set (cluster j: [begin[j], begin[j+1]))
  std::vector<Eigen::Vector3d> centre;      ///< c centres, the set's frame (relative to the COR), mm
  std::vector<double> radius;               ///< c radii, mm: every member within it of its centre
  std::int64_t clusters() const { return static_cast<std::int64_t>(centre.size()); }
};

/// ScanClusters of `set` in runs of up to `cluster_size` vertices. Throws impinge::Error when
/// cluster_size < 1.
ScanClusters cluster_scan_set(const ScanSet& set, int cluster_size = 32);

/// Whether every point of the ball (centre: the layered map's frame, relative to the COR; radius_mm) is
/// outside the other bone and farther than reach_mm (>= 0) from its surface: the other surface has no
/// point within radius_mm + reach_mm of cor + centre (`other`'s frame: its mesh's; one pruned hierarchy
/// query), and `map` (the other bone's layered map) places the centre outside (a finite positive look-up,
/// or +inf, whose stencil needs no exact decision). No surface point in the grown ball means every point
/// of the ball is on the centre's side. The radial gap of such a point, at least its distance, is then
/// above reach_mm too. Shared by scan_layered_near and the ROM searches' hidden scan.
bool cluster_apart(const Eigen::Vector3d& centre, double radius_mm, const LayeredMap& map, const Eigen::Vector3d& cor,
                   const SignedDistanceQuery& other, double reach_mm);
/// The same without a layered map (JointOptions::layered_maps off): the centre placed outside by the exact
/// signed radial distance over its ray's crossings (signed_radial_distance_exact on `caster`, the other bone
/// about the COR).
bool cluster_apart(const Eigen::Vector3d& centre, double radius_mm, const FirstHitCaster& caster,
                   const Eigen::Vector3d& cor, const SignedDistanceQuery& other, double reach_mm);

/// Counts of one scan_layered_near.
struct LayeredNearStats {
  std::int64_t refined = 0;            ///< look-ups resolved by an exact ray cast (as scan_layered)
  std::int64_t vertices_scanned = 0;   ///< vertices looked up
  std::int64_t clusters_skipped = 0;   ///< clusters proven outside the other bone and beyond the reach
};

/// scan_layered (detection.hpp) over only the clusters that may come within `reach_mm` (> 0, finite) of the
/// other bone: a cluster (centre c, radius r_c, posed R c + t) for which cluster_apart holds is skipped.
/// Its members get gap_mm = +infinity (which scan_layered never gives: it writes NaN where no surface is
/// along the ray), and expand_layered_scan leaves them beyond reach. The others are scan_layered's gaps,
/// bit for bit, the far members of a cluster that comes near included: which hidden vertices are tested
/// (and so count in a summary's level 0) depends on the clusters, the tighter the fewer. Throws
/// impinge::Error on a bad reach or clusters of another set. Single thread.
LayeredNearStats scan_layered_near(const ScanSet& set, const ScanClusters& clusters, const Eigen::Matrix3d& R,
                                   const Eigen::Vector3d& t, const LayeredMap& map, const Eigen::Vector3d& cor,
                                   const SignedDistanceQuery& other, double reach_mm, float* gap_mm,
                                   const FirstHitCaster* exact);
/// scan_layered_near without a layered map (JointOptions::layered_maps off, a set-up for a few poses): the same
/// clusters pruned (cluster_apart's exact form), each remaining vertex's gap the exact signed radial distance over
/// the crossings of its ray (signed_radial_distance_exact on `exact`, the other bone about the COR), which the
/// map's look-up approximates (they agree where the map resolves its stencil exactly). `refined` counts every
/// vertex so cast. Throws as scan_layered_near.
LayeredNearStats scan_layered_near_exact(const ScanSet& set, const ScanClusters& clusters, const Eigen::Matrix3d& R,
                                         const Eigen::Vector3d& t, const FirstHitCaster& exact,
                                         const Eigen::Vector3d& cor, const SignedDistanceQuery& other, double reach_mm,
                                         float* gap_mm);

}  // namespace impinge
