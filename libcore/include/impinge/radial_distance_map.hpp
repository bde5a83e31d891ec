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

#include "impinge/equiangular_grid.hpp"
#include "impinge/huge_page_allocator.hpp"
#include "impinge/sampling_scheme.hpp"

namespace impinge {

/// Radial distance map over any SamplingScheme. `Scalar` is float (default, 4 bytes a node)
/// or double (the thesis' Tables 2 and 7 count 8 bytes a node). Nodes with no surface hold
/// +infinity (`has_surface(i)` is false).
template <typename Scalar>
class RadialDistanceMapT {
 public:
  /// A map of `scheme` with every node at "no surface".
  explicit RadialDistanceMapT(std::shared_ptr<const SamplingScheme> scheme)
      : scheme_(std::move(scheme)), distance_(static_cast<std::size_t>(scheme_->num_nodes()), no_surface()) {}
  /// Convenience: a map of a copy of a concrete scheme (e.g. EquiangularGrid(0.5)).
  template <typename S, typename = std::enable_if_t<std::is_base_of_v<SamplingScheme, S>>>
  explicit RadialDistanceMapT(const S& scheme) : RadialDistanceMapT(std::make_shared<S>(scheme)) {}

  static constexpr Scalar no_surface() { return std::numeric_limits<Scalar>::infinity(); }

  const SamplingScheme& scheme() const { return *scheme_; }
  const std::shared_ptr<const SamplingScheme>& scheme_ptr() const { return scheme_; }
  /// The scheme as an equiangular grid; throws impinge::Error when it is another scheme.
  const EquiangularGrid& grid() const;
  std::int64_t num_nodes() const { return static_cast<std::int64_t>(distance_.size()); }
  /// Distance (mm) at node i, or +inf for no surface.
  Scalar at(std::int64_t i) const { return distance_[static_cast<std::size_t>(i)]; }
  bool has_surface(std::int64_t i) const { return at(i) != no_surface(); }
  Scalar* data() { return distance_.data(); }
  const Scalar* data() const { return distance_.data(); }
  /// Bytes actually allocated for the node values.
  std::size_t bytes() const { return distance_.capacity() * sizeof(Scalar); }
  /// Number of nodes with a surface.
  std::int64_t nodes_covered() const {
    return std::count_if(distance_.begin(), distance_.end(), [](Scalar d) { return d != no_surface(); });
  }
  /// Interpolated radial distance (mm) of the surface in the direction of `p` (any nonzero
  /// vector relative to the COR), by the scheme's stencil (thesis Algorithms 2 and 3). NaN when
  /// a node with nonzero weight has no surface. One virtual call: for many points use
  /// sample_many.
  double sample(const Eigen::Vector3d& p) const {
    double out;
    scheme_->interpolate_many(distance_.data(), p.data(), 1, &out);
    return out;
  }
  /// sample() at n points (pts: n x 3 row-major), one dispatch for the whole batch.
  void sample_many(const double* pts, std::int64_t n, double* out) const {
    scheme_->interpolate_many(distance_.data(), pts, n, out);
  }
  /// sample_many with the points in structure-of-arrays form (x, y, z: n values each, mm).
  void sample_many_soa(const double* x, const double* y, const double* z, std::int64_t n, double* out) const {
    scheme_->interpolate_many_soa(distance_.data(), x, y, z, n, out);
  }
  /// sample_many_soa, except that a point whose stencil holds a node with the depth-discontinuity
  /// mark (mark_depth_discontinuities) gets -infinity: the caller resolves it exactly.
  void sample_many_soa_marked(const double* x, const double* y, const double* z, std::int64_t n, double* out) const {
    scheme_->interpolate_many_soa_marked(distance_.data(), x, y, z, n, out);
  }

 private:
  std::shared_ptr<const SamplingScheme> scheme_;
  std::vector<Scalar, HugePageAllocator<Scalar>> distance_;  ///< 2 MiB pages for large maps
};

using RadialDistanceMap = RadialDistanceMapT<float>;         ///< float32 map (default)
using RadialDistanceMapDouble = RadialDistanceMapT<double>;  ///< float64 map (thesis Table 2)

/// Memory of a map of `nodes` nodes at `bytes_per_node` bytes (thesis Table 2's formula).
inline std::int64_t map_bytes_formula(std::int64_t nodes, int bytes_per_node) { return nodes * bytes_per_node; }

}  // namespace impinge
