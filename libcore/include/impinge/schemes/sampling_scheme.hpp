#pragma once
/// @file sampling_scheme.hpp
/// The sampling-scheme interface (DESIGN.md "Style", after HEALPix's healpix_base.h): a set of
/// sampling directions on the unit sphere with O(1) location of the interpolation stencil of
/// any direction. Maps, sampling, detection, the CLI and the experiments use only this
/// interface; a new scheme is one header/source pair deriving from SchemeImpl plus one line in
/// scheme_registry.cpp.

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace impinge {

/// Interpolation stencil of a direction: up to four node indices and their weights (>= 0,
/// sum 1). Unused entries have weight 0 (and a valid node index).
struct Stencil {
  std::array<std::int64_t, 4> nodes{};
  std::array<double, 4> weights{};
};

/// A sampling scheme. Node indices run over [0, num_nodes()).
class SamplingScheme {
 public:
  virtual ~SamplingScheme() = default;
  /// Registry name ("equiangular", "helix").
  virtual std::string name() const = 0;
  /// Name of the resolution parameter with its unit ("precision_deg", "turns").
  virtual std::string resolution_name() const = 0;
  /// The resolution parameter (p in degrees, k turns, ...).
  virtual double resolution() const = 0;
  /// Number of nodes.
  virtual std::int64_t num_nodes() const = 0;
  /// Unit direction of node i.
  virtual Eigen::Vector3d node_direction(std::int64_t i) const = 0;
  /// Polar angle phi and azimuth theta (radians) of nodes [first, first + count), written to
  /// phi[0..count) and theta[0..count). Default: from node_direction; schemes override it with
  /// a faster incremental form (used to resample maps).
  virtual void node_angles(std::int64_t first, std::int64_t count, double* phi, double* theta) const;
  /// The node nearest (or as near as the scheme's locator finds) to unit direction u.
  virtual std::int64_t node(const Eigen::Vector3d& u) const = 0;
  /// Interpolation stencil of unit direction u.
  virtual Stencil interpolate(const Eigen::Vector3d& u) const = 0;
  /// Largest great-circle distance between neighbouring nodes, radians (feeds error bounds).
  virtual double max_node_spacing() const = 0;
  /// Interpolation stencils of n <= kStencilBlock directions given in structure-of-arrays form (x,
  /// y, z: n values each, any nonzero length; only the direction matters): node k (k = 0..3) of
  /// direction j in nodes[k * n + j] and its weight in w[k * n + j], weights >= 0 summing to 1 (unused
  /// entries weight 0 with a valid node). The one per-block virtual call of a look-up: the scheme
  /// computes where to look, the map (radial_distance_map.hpp) loads and combines the values, so a
  /// scheme knows nothing of the map's value type or storage. May differ from
  /// interpolate() by the rounding of its angle computations (a vectorised kernel may use
  /// fast_angles.hpp). Source: thesis Algorithms 2 and 3 (the look-ups), split for the plug-in.
  virtual void stencils_soa(const double* x, const double* y, const double* z, int n, std::int32_t* nodes,
                            double* w) const = 0;

  // ---- Capabilities (after HEALPix's neighbors, query_disc and conformable, Gorski et al. 2005) ----
  // Defaults that work for any scheme from the members above; a scheme with a cheaper exact form
  // overrides them (the equiangular grid does). tests/schemes/scheme_conformance_test.cpp checks
  // every registered scheme against brute force.

  /// Neighbours of the nodes [first, first + count) as two opposite pairs, for second differences
  /// (maps/depth_discontinuity.hpp): out[4 k] and out[4 k + 1] are the stencils one step away from
  /// node first + k along -phi and +phi, out[4 k + 2] and out[4 k + 3] along -theta and +theta;
  /// `out` holds 4 count stencils. Default: the interpolation stencils (stencils_soa) of the points
  /// at great-circle distance max_node_spacing() along the unit tangents e_phi and e_theta of the
  /// node's (phi, theta) (node_angles). The equiangular grid gives its row and column neighbours
  /// (one node of weight 1 each; across a pole, the next row half a turn round).
  virtual void neighbour_stencils(std::int64_t first, std::int64_t count, Stencil* out) const;

  /// The nodes adjacent to node i (HEALPix's neighbors): the distinct nodes of nonzero weight in
  /// neighbour_stencils(i), without i, ascending. `out` is cleared first. Throws impinge::Error for
  /// i outside [0, num_nodes()).
  void neighbours(std::int64_t i, std::vector<std::int64_t>& out) const;

  /// Every node whose direction lies within great-circle distance `radius_rad` of `direction` (any
  /// nonzero vector), ascending (HEALPix's query_disc, inclusive). `out` is cleared first. Default:
  /// every node tested, O(num_nodes()); the equiangular grid visits only the rows and columns the
  /// cap spans. Throws impinge::Error for a zero or non-finite direction or a negative or NaN radius.
  virtual void nodes_in_cap(const Eigen::Vector3d& direction, double radius_rad, std::vector<std::int64_t>& out) const;

  /// True when a map of `other` holds the same directions at the same node indices, so that its
  /// values can be read with this scheme's indices (HEALPix's conformable): the same registry name,
  /// resolution and node count.
  virtual bool conformable(const SamplingScheme& other) const;
};

/// Largest block of stencils_soa (directions per call).
inline constexpr int kStencilBlock = 128;

/// Largest node count of a scheme usable by a map: block stencils hold 32-bit node indices.
inline constexpr std::int64_t kMaxMapNodes = (std::int64_t(1) << 31) - 1;

/// True when the node value `d` carries the depth-discontinuity mark: its least significant bit
/// (a change of at most one unit in the last place, 2e-6 mm at 30 mm in float). +inf (no surface)
/// is never marked.
inline bool has_discontinuity_mark(float d) {
  std::uint32_t b;
  std::memcpy(&b, &d, sizeof b);
  return (b & 1u) != 0;
}
inline bool has_discontinuity_mark(double d) {
  std::uint64_t b;
  std::memcpy(&b, &d, sizeof b);
  return (b & 1u) != 0;
}

/// Base of concrete schemes: implements interpolate() and stencils_soa() once from Derived's
///   void stencil_at(double x, double y, double z, std::int64_t nodes[4], double w[4]) const
/// (inlined), so each scheme writes only its stencil and its node geometry; a scheme with a faster
/// block form overrides stencils_soa.
template <typename Derived>
class SchemeImpl : public SamplingScheme {
 public:
  Stencil interpolate(const Eigen::Vector3d& u) const override {
    Stencil s;
    static_cast<const Derived*>(this)->stencil_at(u.x(), u.y(), u.z(), s.nodes.data(), s.weights.data());
    return s;
  }
  void stencils_soa(const double* x, const double* y, const double* z, int n, std::int32_t* nodes,
                    double* w) const override {
    const Derived& self = *static_cast<const Derived*>(this);
    for (int j = 0; j < n; ++j) {
      std::int64_t nd[4];
      double wj[4];
      self.stencil_at(x[j], y[j], z[j], nd, wj);
      for (int k = 0; k < 4; ++k) nodes[k * n + j] = static_cast<std::int32_t>(nd[k]), w[k * n + j] = wj[k];
    }
  }
};

/// A scheme made by name and resolution from the registry (scheme_registry.cpp). Throws
/// impinge::Error naming the scheme for an unknown name or an invalid resolution.
std::shared_ptr<const SamplingScheme> make_scheme(const std::string& name, double resolution);

/// Registered scheme names with their resolution parameter names, e.g. {"equiangular",
/// "precision_deg"}.
std::vector<std::pair<std::string, std::string>> scheme_names();

/// The default resolution of the registered scheme `name` (its own unit): the equivalent of an
/// equiangular grid at 0.5 deg. Throws impinge::Error naming the registered schemes when
/// `name` is unknown.
double default_resolution(const std::string& name);

/// The coarsest resolution of the registered scheme `name` (its own unit) whose largest node
/// spacing (max_node_spacing) is at most `spacing_deg` degrees: the way to compare schemes at
/// equal spacing (CLI --spacing). Equiangular-like schemes take p = 180 / n, counted schemes
/// (helix turns) a whole number >= 2. Throws impinge::Error naming the scheme for an unknown name
/// or a spacing outside (0, 90] degrees. Source: impinge (not in the thesis).
double resolution_for_spacing(const std::string& name, double spacing_deg);

}  // namespace impinge
