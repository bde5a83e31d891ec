#pragma once
/// @file detection.hpp
/// Per-vertex gap by look-up in the other body's radial distance map (thesis sec. 3.3,
/// Algorithm 2), and the statistics of a scan.

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "impinge/casters/embree_ray_caster.hpp"
#include "impinge/casters/first_hit_caster.hpp"
#include "impinge/core/mesh.hpp"
#include "impinge/detection/impingement_levels.hpp"
#include "impinge/maps/layered_map.hpp"
#include "impinge/maps/radial_distance_map.hpp"
#include "impinge/core/enum_names.hpp"

namespace impinge {

/// Which way the gap is measured: the ball lies inside the socket map's surface, the socket
/// outside the ball map's surface. gap = d_map - r for `inside`, r - d_map for `outside`, so
/// that gap > 0 means apart and gap < 0 penetrating for both scans.
enum class ScanSide { inside = 1, outside = -1 };

/// Per-vertex result of one scan. gap_mm[i] is NaN where vertex i was not tested (masked
/// out) or the other map has no surface in its direction; status[i] tells which.
struct ScanGaps {
  /// tested: by the single-layer map (first-surface vertices); tested_layered: a vertex hidden behind its
  /// own body's nearer surface, tested by the other body's layered map (extra-articular).
  enum Status : std::uint8_t { tested = 0, no_surface = 1, beyond_reach = 2, tested_layered = 3 };
  std::vector<float> gap_mm;         ///< n gaps, mm
  std::vector<std::uint8_t> status;  ///< n statuses
  std::int64_t refined = 0;          ///< look-ups at a depth discontinuity resolved by an exact ray cast
  /// Signed Euclidean distance to the other bone's surface (JointOptions::distances), n values,
  /// mm, negative inside the other bone; NaN where proven farther than the reach or not measured. Empty
  /// when distances are off.
  std::vector<float> distance_mm;
  std::int64_t distance_winding = 0;  ///< distances whose sign the winding number decided
  /// n flags (empty when distances are off): 1 where the other mesh cannot decide the sign (a hole's rim:
  /// signed_distance.hpp, rule 3; the distance is written >= 0), else 0.
  std::vector<std::uint8_t> distance_sign_undecided;
  std::int64_t distance_undecided = 0;  ///< how many are 1
};

/// Which per-vertex quantity the impingement levels classify: the thesis' radial gap, or the
/// Euclidean distance (ScanGaps::distance_mm; a vertex without one is farther than the distances' reach,
/// which is at least the largest level threshold, so level 0).
enum class LevelQuantity : std::uint8_t { radial_gap = 0, distance = 1 };
/// The names of LevelQuantity (the option table's choices of --levels-on; summary.json's "levels_on").
inline constexpr EnumNames<LevelQuantity, 2> kLevelQuantityNames{
    {{LevelQuantity::distance, "distance"}, {LevelQuantity::radial_gap, "radial"}}};

/// "radial" or "distance".
const char* to_string(LevelQuantity q);
/// Parse "radial" or "distance"; throws impinge::Error naming `context` otherwise.
LevelQuantity parse_level_quantity(const std::string& text, const std::string& context);

/// Whether vertex i of a scan has no value at all: beyond the radial scan's reach, with neither a gap
/// nor a distance (most vertices of a scan). Such a vertex only counts, and has no level (vertex_level's
/// 255). `g`'s distances are empty (distances off) or one per gap; i < g.gap_mm.size().
inline bool vertex_unmeasured(const ScanGaps& g, std::size_t i) {
  return g.status[i] == ScanGaps::beyond_reach && std::isnan(g.gap_mm[i]) &&
         (g.distance_mm.empty() || std::isnan(g.distance_mm[i]));
}

/// Whether the eight vertices i .. i + 7 of a scan all have no value: each beyond the reach or without
/// surface in its direction (ScanGaps::no_surface), with neither a gap nor a distance, so that none has a
/// level. `no_surface` gets how many are without surface. Tested side by side: most runs of a scan's
/// vertices are so, and the summaries count them eight at a time. i + 8 <= n.
inline bool eight_without_value(const ScanGaps& g, std::size_t i, int& no_surface) {
  static_assert(ScanGaps::no_surface == 1 && ScanGaps::beyond_reach == 2,
                "eight_without_value reads the statuses' bytes as 1 or 2");
  std::uint64_t status = 0;
  std::memcpy(&status, g.status.data() + i, sizeof(status));
  constexpr std::uint64_t kLow = 0x0101010101010101ull;
  // Every byte 1 or 2: no bit above the lowest two, and bit 0 differs from bit 1.
  if ((status & ~(3 * kLow)) != 0 || ((status ^ (status >> 1)) & kLow) != kLow) return false;
  bool none = true;
  for (std::size_t k = i; k < i + 8; ++k) none &= std::isnan(g.gap_mm[k]);
  if (!g.distance_mm.empty())
    for (std::size_t k = i; k < i + 8; ++k) none &= std::isnan(g.distance_mm[k]);
  // The bytes' sum (each 0 or 1, at most 8) gathered in the top byte: a popcount without the POPCNT
  // instruction, which the baseline build may not use (libgcc's __popcountdi2 was 0.4 % of a pose).
  no_surface = static_cast<int>(((status & kLow) * kLow) >> 56);
  return none;
}

/// The level of vertex i of a scan by quantity `q`: 255 where it has no value (untested by the radial
/// scan; for distance, neither tested nor within the distances' reach), else levels.level of the gap or
/// of the distance (a vertex tested by the radial scan and beyond the distances' reach: level 0). With
/// `q` distance and no distances in `g` (distances off), the radial gap's level.
std::uint8_t vertex_level(const ScanGaps& g, std::size_t i, const ImpingementLevels& levels, LevelQuantity q);

/// Statistics of a scan (thesis sec. 3.4 colour levels; counts so nothing is dropped silently).
struct ScanSummary {
  std::int64_t vertices = 0;                                     ///< vertices in the mesh
  std::int64_t vertices_tested = 0;                              ///< looked up and gap computed (either map)
  std::int64_t vertices_tested_layered = 0;                      ///< of them, hidden vertices tested by the other
                                                                 ///< body's layered map (JointOptions::layers)
  std::int64_t vertices_no_surface = 0;                          ///< the other map has no surface in their direction
  std::int64_t vertices_beyond_reach = 0;                        ///< skipped: not on their body's first surface seen
                                                                 ///< from the COR, or beyond the region radius
  double min_gap_mm = std::numeric_limits<double>::quiet_NaN();  ///< NaN when none tested
  double min_gap_layered_mm = std::numeric_limits<double>::quiet_NaN();  ///< over the hidden vertices tested by
                                                                         ///< the layered map; NaN when none
  std::int64_t vertices_refined = 0;                             ///< tested by an exact ray cast instead of the map
                                                                 ///< (their stencil straddles a depth discontinuity)
  std::int64_t vertices_penetrating = 0;                         ///< gap <= 0
  double area_penetrating_mm2 = 0;                               ///< their vertex area
  double min_distance_mm = std::numeric_limits<double>::quiet_NaN();  ///< least Euclidean distance; NaN when
                                                                     ///< none measured or distances off
  std::int64_t vertices_distance = 0;                            ///< vertices with a Euclidean distance
  std::int64_t vertices_inside = 0;                              ///< of them, inside the other bone (< 0)
  double area_inside_mm2 = 0;                                    ///< their vertex area
  std::int64_t distance_winding = 0;                             ///< signs decided by the winding number
  std::int64_t distance_undecided = 0;                           ///< signs the mesh cannot decide (read >= 0)
  LevelQuantity levels_on = LevelQuantity::radial_gap;           ///< what level_vertices classify
  std::vector<std::int64_t> level_vertices;                      ///< count per impingement level
  std::vector<double> level_area_mm2;                            ///< vertex area per impingement level
};

/// One scan of Algorithm 2: for every vertex i with mask[i] != 0, q = R * P.row(i) (P: n x 3,
/// mm, relative to the COR in the vertex body's frame; R: 3 x 3 rotation into the map's frame),
/// gap = side * (map.lookup(q) - |q|). A one-shot convenience: it builds the ScanSet of the mask
/// and runs scan_gaps_compact; for many poses build the set once (make_scan_set, as Joint does)
/// and call scan_gaps_compact. `out` is resized to n. Vertices at the COR itself are reported
/// as no surface.
template <typename Scalar>
void scan_gaps(PointsRef P, const Eigen::Matrix3d& R, const std::vector<std::uint8_t>& mask,
               const RadialDistanceMapT<Scalar>& map, ScanSide side, ScanGaps& out);

/// The vertices of one body that a scan looks up, prepared once (pose-invariant): the indices
/// of the vertices with mask[i] != 0 and their coordinates relative to the COR in structure-of-
/// arrays form, so a scan touches only them, with no per-vertex branch on the mask. They are
/// ordered along a Z curve over their direction, so that consecutive look-ups share cache lines
/// of the other map.
struct ScanSet {
  std::vector<std::int32_t> index;  ///< k indices into the body's vertices (Z-curve order)
  std::vector<double> x, y, z;      ///< k coordinates each, mm, relative to the COR, body frame
  std::int64_t vertices = 0;        ///< n, vertices of the body
  std::int64_t size() const { return static_cast<std::int64_t>(index.size()); }
};

/// ScanSet of the vertices P (n x 3, mm, relative to the COR) with mask[i] != 0. Throws
/// impinge::Error when mask.size() != n or n exceeds 2^31 - 1.
ScanSet make_scan_set(PointsRef P, const std::vector<std::uint8_t>& mask);

/// The fast scan: for every vertex j of `set`, q = R * p_j + t in the map's frame
/// (R: 3 x 3 rotation, t: translation, mm; the identity and 0 when the bodies share the COR),
/// gap_mm[j] = side * (map.lookup(q) - |q|), NaN where the map has no surface in q's direction
/// or q is the COR. `gap_mm` must hold set.size() floats. Allocation-free, single thread; blocks
/// of 256 vertices: transform, then the scheme's two-pass look-up (stencils, then loads).
template <typename Scalar>
void scan_gaps_compact(const ScanSet& set, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                       const RadialDistanceMapT<Scalar>& map, ScanSide side, float* gap_mm);

/// The same scan through Embree (EmbreeRayCaster::scan_gaps, the exact peer of scan_gaps_compact):
/// gap_mm[j] = side * (nearest hit along q - |q|) for vertex j of `set`, q = R p_j + t; NaN on a miss.
/// `caster` is built on the other bone's mesh about the same COR; `packet8`: 8-ray packets.
inline void scan_gaps_embree(const EmbreeRayCaster& caster, const ScanSet& set, const Eigen::Matrix3d& R,
                             const Eigen::Vector3d& t, ScanSide side, float* gap_mm, bool packet8) {
  caster.scan_gaps(set.x.data(), set.y.data(), set.z.data(), set.size(), R, t, static_cast<double>(static_cast<int>(side)),
                   gap_mm, packet8);
}

/// scan_gaps_compact with exact look-ups at depth discontinuities: with `exact` given
/// (the ray caster of the map's mesh about the same COR, in the map's frame) and the map's nodes
/// marked (mark_depth_discontinuities), a vertex whose stencil holds a marked node gets
/// gap_mm[j] = side * (exact->first_hit(q) - |q|) (NaN on a miss) instead of the interpolated
/// gap. Returns the number of vertices so resolved. With `exact` null, the plain scan (returns 0).
template <typename Scalar>
std::int64_t scan_gaps_compact(const ScanSet& set, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                               const RadialDistanceMapT<Scalar>& map, ScanSide side, float* gap_mm,
                               const FirstHitCaster* exact);

/// scan_gaps_compact with exact look-ups over the vertices [first, first + count) of `set` only:
/// gap_mm[j] for j in that range (gap_mm still indexed like the whole set). The ROM searches' scanner
/// looks clusters up this way, so that they see the gaps Joint::detect sees. Throws impinge::Error
/// for a range outside the set.
template <typename Scalar>
std::int64_t scan_gaps_compact(const ScanSet& set, std::int64_t first, std::int64_t count, const Eigen::Matrix3d& R,
                               const Eigen::Vector3d& t, const RadialDistanceMapT<Scalar>& map, ScanSide side,
                               float* gap_mm, const FirstHitCaster* exact);

/// The layered scan: for every vertex j of `set`, q = R p_j + t in the map's frame (as
/// scan_gaps_compact), gap_mm[j] = the layered map's signed radial distance at q (mm; > 0 apart, < 0
/// inside the other bone), NaN where the other bone is nowhere along q's ray or the answer is unknown
/// (a truncated node). With `exact` given (the other mesh's caster about the same COR, in the map's
/// frame), a vertex whose stencil straddles an edge of the bone or a depth jump (exact_needed of
/// LayeredMap::signed_distance_many_soa) gets the exact signed_radial_distance_exact instead. Returns the
/// number so resolved. `gap_mm` must hold set.size() floats.
std::int64_t scan_layered(const ScanSet& set, const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const LayeredMap& map,
                          float* gap_mm, const FirstHitCaster* exact);

/// scan_layered over the vertices [first, first + count) of `set` only: gap_mm[j] for j in that range
/// (gap_mm still indexed like the whole set). Throws impinge::Error for a range outside the set.
std::int64_t scan_layered(const ScanSet& set, std::int64_t first, std::int64_t count, const Eigen::Matrix3d& R,
                          const Eigen::Vector3d& t, const LayeredMap& map, float* gap_mm, const FirstHitCaster* exact);

/// Write a layered scan's gaps into `out` (already expanded by expand_scan for the same body): vertex
/// set.index[j] gets gap_mm[j] with status tested_layered, or no_surface when NaN; +infinity (a vertex
/// scan_layered_near skipped) leaves it as it was (beyond reach).
void expand_layered_scan(const ScanSet& set, const float* gap_mm, ScanGaps& out);

/// Expand a compact scan into per-vertex ScanGaps (n entries): vertices outside the set are
/// beyond reach, NaN gaps of the set are no surface.
void expand_scan(const ScanSet& set, const float* gap_mm, ScanGaps& out);

/// Vertices of a body that lie on its own first surface seen from the COR:
/// mask[i] = 1 when |p_i| <= own_map.lookup(p_i) + tolerance_mm and |p_i| <= max_radius_mm; at
/// the edge of the own map's coverage the nearest covered stencil node is used, and a vertex
/// none of whose stencil nodes is covered is skipped (the map cannot place its first surface).
/// Pose-invariant (the COR is fixed in both bodies), so computed once per body. Vertices hidden
/// behind their own body's nearer surface (the femoral shaft behind the head, the inner pelvic
/// wall behind the acetabulum) are not represented by a radial map and would give a spurious
/// gap against the other map.
template <typename Scalar>
std::vector<std::uint8_t> first_surface_mask(PointsRef P, const RadialDistanceMapT<Scalar>& own_map,
                                             double tolerance_mm, double max_radius_mm);

/// first_surface_mask decided exactly where the map cannot decide it: a vertex whose stencil in
/// `own_map` holds a node with the depth-discontinuity mark or without surface is tested by a ray
/// cast of its own mesh (`own_exact`, about the same COR): on the first surface when the ray's
/// first hit is at least |p| - tolerance_mm away, or the ray misses.
template <typename Scalar>
std::vector<std::uint8_t> first_surface_mask(PointsRef P, const RadialDistanceMapT<Scalar>& own_map,
                                             double tolerance_mm, double max_radius_mm,
                                             const FirstHitCaster& own_exact);

/// Summary of a scan: counts, minimum gap, penetration and levels weighted by vertex area
/// (`vertex_area`: n values, mm^2). Throws impinge::Error unless `gaps` has n statuses (and, when it has
/// distances, n distances) and `vertex_area` n values.
ScanSummary summarize_scan(const ScanGaps& gaps, const Eigen::VectorXd& vertex_area, const ImpingementLevels& levels,
                           LevelQuantity levels_on = LevelQuantity::radial_gap);

/// The same into `out`, reusing its level vectors (no allocation once they have the size).
void summarize_scan(const ScanGaps& gaps, const Eigen::VectorXd& vertex_area, const ImpingementLevels& levels,
                    ScanSummary& out, LevelQuantity levels_on = LevelQuantity::radial_gap);

}  // namespace impinge
