#pragma once
/// @file layered_map.hpp
/// Layered radial map (the thesis' sec. 6 "multiple layers"): for every node of a sampling
/// scheme, the ordered crossings of its ray with a bone's surface (where the ray enters the solid and
/// where it leaves it), so that for any point the map answers whether the point lies inside the bone
/// and how far along the ray the nearest boundary is. The single-layer map (radial_distance_map.hpp)
/// keeps only the first crossing and so cannot place a point behind it: a femoral trochanter behind
/// the head, the ilium above the acetabulum. Extra-articular impingement needs this map.

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "impinge/maps/ray_crossing.hpp"
#include "impinge/schemes/sampling_scheme.hpp"

namespace impinge {

/// Signed radial distance (mm) of the point at distance r_mm (>= 0) along a ray to the nearest of the
/// ray's crossings (nearest first): negative when the point lies inside the solid, positive outside;
/// +infinity when there is no crossing. Inside or outside is read from the nearest crossing before the
/// point (inside after an entering crossing), or, with none before it, from the first one after it
/// (inside before a leaving one: the ray starts inside, as from the centre of the femoral head).
/// `complete` false: the list holds only the nearest crossings, so beyond the last one the answer is
/// unknown (NaN). On a mesh that is not closed this reads "inside" as "behind a surface that faces the
/// ray", nearest surface first; on a self-intersecting mesh a point in the overlap of two shells is
/// inside after the first entering crossing and outside after the first leaving one.
double signed_radial_distance(const RayCrossing* crossings, int count, bool complete, double r_mm);

/// The radial shells [b w, (b + 1) w) (w = bin_mm; shell 63 also holds every radius beyond) that the
/// radii [lo_mm, hi_mm] meet, as bits of a 64-bit mask: the unit of LayeredMap::occupancy.
std::uint64_t radial_shell_bits(double lo_mm, double hi_mm, double bin_mm);

/// Counts of a layered sampling (sampling/layered_sampling.hpp), so nothing is dropped silently.
struct LayeredSamplingReport {
  std::int64_t nodes = 0;                ///< nodes of the scheme
  std::int64_t nodes_covered = 0;        ///< nodes whose ray crosses the surface at least once
  std::int64_t nodes_truncated = 0;      ///< nodes with more crossings than layers (the nearest kept)
  std::int64_t nodes_not_alternating = 0;  ///< nodes whose crossings do not alternate entering/leaving
                                           ///< (a graze read as a crossing, or a mesh not closed)
  int max_crossings = 0;                 ///< most crossings of one node's ray
  double sampling_ms = 0;                ///< wall time, ms
};

/// N crossings per node of any sampling scheme. Memory: num_nodes * (4 N + 1) bytes.
class LayeredMap {
 public:
  static constexpr int kMaxLayers = 16;

  /// A map of `scheme` with `layers` (1..kMaxLayers) crossings per node, every node empty. Throws
  /// impinge::Error on a bad layer count or a scheme larger than kMaxMapNodes.
  LayeredMap(std::shared_ptr<const SamplingScheme> scheme, int layers);

  int layers() const { return layers_; }
  std::int64_t num_nodes() const { return num_nodes_; }
  const SamplingScheme& scheme() const { return *scheme_; }
  const std::shared_ptr<const SamplingScheme>& scheme_ptr() const { return scheme_; }
  /// Crossings stored at node i (0..layers()).
  int count(std::int64_t i) const { return count_[static_cast<std::size_t>(i)] & 0x7f; }
  /// True when node i's ray had more crossings than layers().
  bool truncated(std::int64_t i) const { return (count_[static_cast<std::size_t>(i)] & 0x80) != 0; }
  /// Crossing k (< count(i)) of node i.
  RayCrossing crossing(std::int64_t i, int k) const {
    const float v = value_[static_cast<std::size_t>(i) * static_cast<std::size_t>(layers_) + static_cast<std::size_t>(k)];
    return {std::abs(double(v)), v < 0};
  }
  /// Set node i's crossings (nearest first; more than layers(): the nearest kept, marked truncated).
  void set(std::int64_t i, const std::vector<RayCrossing>& crossings);
  /// Bytes of the node data.
  std::size_t bytes() const { return value_.size() * sizeof(float) + count_.size(); }

  /// signed_radial_distance at node i for radius r_mm.
  double node_signed_distance(std::int64_t i, double r_mm) const;

  /// Interpolated signed radial distance (mm) of each point (x, y, z: n values each, mm relative to the
  /// COR, the map's frame) to the bone's surface: sum_k w_k s_k over the scheme's stencil, s_k the
  /// node's signed_radial_distance at the point's radius. Nodes whose ray misses the surface are left
  /// out and the weights of the others renormalised (at the bone's silhouette); +inf when every node
  /// misses; NaN when a node's answer is unknown (truncated) or the point is the COR.
  /// `exact_needed` (optional, n bytes): 1 where the stencil's nodes disagree in their crossing count or
  /// a crossing's radius spreads by more than `spread_mm` over the stencil, so that the interpolation is
  /// across an edge of the bone or a depth jump and a caller with a ray caster should decide exactly.
  void signed_distance_many_soa(const double* x, const double* y, const double* z, std::int64_t n, double* out,
                                std::uint8_t* exact_needed = nullptr, double spread_mm = 1.0) const;

  /// Bit b of node i's occupancy is set when the solid (inside or on the surface) meets the radial
  /// shell [b w, (b + 1) w) along node i's ray, w = occupancy_bin_mm; the last bit also covers every
  /// radius beyond. For bounds over groups of nodes (ROM searches).
  std::uint64_t occupancy(std::int64_t i, double bin_mm) const;

 private:
  std::shared_ptr<const SamplingScheme> scheme_;
  int layers_ = 1;
  std::int64_t num_nodes_ = 0;
  std::vector<float> value_;         ///< num_nodes * layers: +distance leaving, -distance entering
  std::vector<std::uint8_t> count_;  ///< crossings stored per node; bit 7: truncated
};

}  // namespace impinge
