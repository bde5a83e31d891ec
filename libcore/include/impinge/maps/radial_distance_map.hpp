#pragma once
/// @file radial_distance_map.hpp
/// Radial distance map (the thesis' LUT, sec. 3.1 and 4.1): one distance per node of a
/// sampling scheme, the distance from the COR to the nearest surface hit along the node's ray.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <type_traits>
#include <vector>

#include "impinge/core/huge_page_allocator.hpp"
#include "impinge/schemes/sampling_scheme.hpp"

namespace impinge {

/// Radial distance map over any SamplingScheme. `Scalar` is float (default, 4 bytes a node)
/// or double (the thesis' Tables 2 and 7 count 8 bytes a node). Nodes with no surface hold
/// +infinity (`has_surface(i)` is false).
///
/// Look-ups: the scheme computes the stencils of a block of directions (SamplingScheme::stencils_soa),
/// the map loads and combines the node values in one fixed order, sum_k w_k d_k, so that every scheme
/// and both storages give the same value for the same stencil.
///
/// Storage: dense (one value per node, the default) or sparse (make_sparse): the nodes in tiles of
/// kTileNodes consecutive indices, only the tiles that hold a surface within a region of interest
/// allocated, every other tile an alias of one tile of "no surface" (the first of the stored tiles).
/// A look-up reads a node through its tile's number in a table of 32-bit numbers (4 bytes per tile,
/// 1/256 of a float map): no branch on the hot path, and the same bits as the dense map for
/// every look-up whose nodes lie in stored tiles (all look-ups, when the region of interest is the
/// whole map). A sparse map is read-only: data() throws; at(), the look-ups, nodes_covered() and
/// bytes() work on both.
template <typename Scalar>
class RadialDistanceMapT {
 public:
  /// Nodes per tile of a sparse map (1 KiB of float): small enough that a tile straddling the edge
  /// of a bone's coverage wastes little (a row of the equiangular grid at 0.05 deg is 7,200 nodes).
  static constexpr int kTileBits = 8;
  static constexpr std::int64_t kTileNodes = std::int64_t(1) << kTileBits;

  /// A dense map of `scheme` with every node at "no surface". Throws impinge::Error when the scheme
  /// has more than kMaxMapNodes nodes.
  explicit RadialDistanceMapT(std::shared_ptr<const SamplingScheme> scheme);
  /// Convenience: a map of a copy of a concrete scheme (e.g. EquiangularGrid(0.5)).
  template <typename S, typename = std::enable_if_t<std::is_base_of_v<SamplingScheme, S>>>
  explicit RadialDistanceMapT(const S& scheme) : RadialDistanceMapT(std::make_shared<S>(scheme)) {}

  static constexpr Scalar no_surface() { return std::numeric_limits<Scalar>::infinity(); }

  const SamplingScheme& scheme() const { return *scheme_; }
  const std::shared_ptr<const SamplingScheme>& scheme_ptr() const { return scheme_; }
  std::int64_t num_nodes() const { return num_nodes_; }
  /// Distance (mm) at node i, or +inf for no surface.
  Scalar at(std::int64_t i) const {
    return tiles_.empty() ? distance_[static_cast<std::size_t>(i)]
                          : stored_[(std::size_t(tiles_[static_cast<std::size_t>(i >> kTileBits)]) << kTileBits) |
                                    std::size_t(i & (kTileNodes - 1))];
  }
  bool has_surface(std::int64_t i) const { return at(i) != no_surface(); }
  /// The node values of a dense map (num_nodes() of them). Throws impinge::Error on a sparse map.
  Scalar* data();
  const Scalar* data() const;
  /// Bytes actually allocated for the node values (a sparse map: its stored tiles and tile table).
  std::size_t bytes() const;
  /// Number of nodes with a surface.
  std::int64_t nodes_covered() const;

  /// True after make_sparse left a tile out.
  bool sparse() const { return !tiles_.empty(); }
  /// Turn a dense map into a sparse one: a tile is kept when one of its nodes has a surface at most
  /// `region_mm` from the COR (default: any surface, which changes no look-up at all); every other
  /// tile reads as "no surface". Returns the bytes released. Throws impinge::Error when region_mm is
  /// NaN or not positive. A map in which every tile would be kept stays dense. Source: impinge
  /// (sparse maps; not in the thesis).
  std::size_t make_sparse(double region_mm = std::numeric_limits<double>::infinity());
  /// Tiles stored and tiles in all (a dense map: every tile counts as stored).
  std::int64_t tiles_stored() const;
  std::int64_t tiles_total() const { return (num_nodes_ + kTileNodes - 1) >> kTileBits; }

  /// Interpolated radial distance (mm) of the surface in the direction of `p` (any nonzero
  /// vector relative to the COR), by the scheme's stencil (thesis Algorithms 2 and 3). NaN when
  /// a node with nonzero weight has no surface. For many points use the batch forms.
  double lookup(const Eigen::Vector3d& p) const {
    double out;
    lookup_many_soa(&p.x(), &p.y(), &p.z(), 1, &out);
    return out;
  }
  /// lookup() at n points (pts: n x 3 row-major).
  void lookup_many(const double* pts, std::int64_t n, double* out) const;
  /// lookup_many with the points in structure-of-arrays form (x, y, z: n values each, mm).
  void lookup_many_soa(const double* x, const double* y, const double* z, std::int64_t n, double* out) const {
    lookup_soa<false>(x, y, z, n, out);
  }
  /// lookup_many_soa, except that a point whose stencil holds a node with the depth-discontinuity
  /// mark (mark_depth_discontinuities), with any weight, gets -infinity: the caller resolves it
  /// exactly.
  void lookup_many_soa_marked(const double* x, const double* y, const double* z, std::int64_t n, double* out) const {
    lookup_soa<true>(x, y, z, n, out);
  }

 private:
  template <bool kMarked>
  void lookup_soa(const double* x, const double* y, const double* z, std::int64_t n, double* out) const;

  std::shared_ptr<const SamplingScheme> scheme_;
  std::int64_t num_nodes_ = 0;
  std::vector<Scalar, HugePageAllocator<Scalar>> distance_;  ///< dense values (2 MiB pages), empty when sparse
  std::vector<Scalar, HugePageAllocator<Scalar>> stored_;    ///< a sparse map's tiles, back to back; the
                                                             ///< first is the empty tile
  std::vector<std::uint32_t> tiles_;                         ///< a sparse map's tile numbers in stored_,
                                                             ///< 0 for an absent tile; empty when dense
};

using RadialDistanceMap = RadialDistanceMapT<float>;         ///< float32 map (default)
using RadialDistanceMapDouble = RadialDistanceMapT<double>;  ///< float64 map (thesis Table 2)

/// Memory of a map of `nodes` nodes at `bytes_per_node` bytes (thesis Table 2's formula).
inline std::int64_t map_bytes_formula(std::int64_t nodes, int bytes_per_node) { return nodes * bytes_per_node; }

}  // namespace impinge
