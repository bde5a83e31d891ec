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
  /// Interpolated values at n points (pts: n x 3 row-major, any nonzero length; only the
  /// direction matters) of a map whose node values are `values` (+inf = no surface): out[j] is
  /// NaN when a node with nonzero weight has no surface. The batch form is the per-scan
  /// dispatch: one virtual call per block of vertices, the per-point work inlined.
  virtual void interpolate_many(const float* values, const double* pts, std::int64_t n, double* out) const = 0;
  virtual void interpolate_many(const double* values, const double* pts, std::int64_t n, double* out) const = 0;
  /// As interpolate_many with the points in structure-of-arrays form (x, y, z: n values each),
  /// the layout of the fast scan; schemes may override it with a vectorised kernel.
  virtual void interpolate_many_soa(const float* values, const double* x, const double* y, const double* z,
                                    std::int64_t n, double* out) const = 0;
  virtual void interpolate_many_soa(const double* values, const double* x, const double* y, const double* z,
                                    std::int64_t n, double* out) const = 0;
  /// As interpolate_many_soa on a map whose nodes carry depth-discontinuity marks (the least
  /// significant bit of a node's value, depth_discontinuity.hpp): a point whose stencil holds a
  /// marked node, with any weight, gets -infinity instead of its value, so that the caller
  /// resolves it exactly. The other points get exactly what interpolate_many_soa gives.
  virtual void interpolate_many_soa_marked(const float* values, const double* x, const double* y, const double* z,
                                           std::int64_t n, double* out) const = 0;
  virtual void interpolate_many_soa_marked(const double* values, const double* x, const double* y, const double* z,
                                           std::int64_t n, double* out) const = 0;
};

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

/// Base of concrete schemes: implements interpolate_many once, inlining Derived's
///   void stencil_at(double x, double y, double z, std::int64_t nodes[4], double w[4]) const
/// so each scheme writes only its stencil and its node geometry.
template <typename Derived>
class SchemeImpl : public SamplingScheme {
 public:
  void interpolate_many(const float* values, const double* pts, std::int64_t n, double* out) const override {
    run(values, pts, n, out);
  }
  void interpolate_many(const double* values, const double* pts, std::int64_t n, double* out) const override {
    run(values, pts, n, out);
  }
  void interpolate_many_soa(const float* values, const double* x, const double* y, const double* z, std::int64_t n,
                            double* out) const override {
    run_soa(values, x, y, z, n, out);
  }
  void interpolate_many_soa(const double* values, const double* x, const double* y, const double* z, std::int64_t n,
                            double* out) const override {
    run_soa(values, x, y, z, n, out);
  }
  void interpolate_many_soa_marked(const float* values, const double* x, const double* y, const double* z,
                                   std::int64_t n, double* out) const override {
    run_soa<float, true>(values, x, y, z, n, out);
  }
  void interpolate_many_soa_marked(const double* values, const double* x, const double* y, const double* z,
                                   std::int64_t n, double* out) const override {
    run_soa<double, true>(values, x, y, z, n, out);
  }
  Stencil interpolate(const Eigen::Vector3d& u) const override {
    Stencil s;
    static_cast<const Derived*>(this)->stencil_at(u.x(), u.y(), u.z(), s.nodes.data(), s.weights.data());
    return s;
  }

 private:
  /// Two passes per chunk of 64 points: all stencils first (pure arithmetic, no loads), then
  /// the loads, so the cache misses of many points are in flight at once.
  template <typename Scalar, bool kMarked = false>
  void run(const Scalar* values, const double* pts, std::int64_t n, double* out) const {
    const Derived& self = *static_cast<const Derived*>(this);
    constexpr std::int64_t kChunk = 64;
    std::int64_t nd[4 * kChunk];
    double w[4 * kChunk];
    for (std::int64_t b = 0; b < n; b += kChunk) {
      const std::int64_t m = std::min(kChunk, n - b);
      const double* p = pts + 3 * b;
      for (std::int64_t j = 0; j < m; ++j) self.stencil_at(p[3 * j], p[3 * j + 1], p[3 * j + 2], nd + 4 * j, w + 4 * j);
      for (std::int64_t j = 0; j < m; ++j) {
        const std::int64_t* q = nd + 4 * j;
        const double* u = w + 4 * j;
        const double v = u[0] * values[q[0]] + u[1] * values[q[1]] + u[2] * values[q[2]] + u[3] * values[q[3]];
        out[b + j] = std::isfinite(v) ? v : slow_path(values, q, u);
        if constexpr (kMarked) {
          if (has_discontinuity_mark(values[q[0]]) || has_discontinuity_mark(values[q[1]]) ||
              has_discontinuity_mark(values[q[2]]) || has_discontinuity_mark(values[q[3]]))
            out[b + j] = -std::numeric_limits<double>::infinity();
        }
      }
    }
  }
  template <typename Scalar, bool kMarked = false>
  void run_soa(const Scalar* values, const double* x, const double* y, const double* z, std::int64_t n,
               double* out) const {
    constexpr std::int64_t kChunk = 64;
    double p[3 * kChunk];
    for (std::int64_t b = 0; b < n; b += kChunk) {
      const std::int64_t m = std::min(kChunk, n - b);
      for (std::int64_t j = 0; j < m; ++j) p[3 * j] = x[b + j], p[3 * j + 1] = y[b + j], p[3 * j + 2] = z[b + j];
      run<Scalar, kMarked>(values, p, m, out + b);
    }
  }

 protected:
  /// A node with no surface (+inf): NaN unless all such nodes have weight exactly 0.
  template <typename Scalar>
  static double slow_path(const Scalar* values, const std::int64_t* nd, const double* w) {
    double acc = 0;
    for (int k = 0; k < 4; ++k) {
      if (w[k] == 0) continue;
      const double d = values[nd[k]];
      if (!std::isfinite(d)) return std::numeric_limits<double>::quiet_NaN();
      acc += w[k] * d;
    }
    return acc;
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
/// or a spacing outside (0, 90] degrees. Source: issue 12.
double resolution_for_spacing(const std::string& name, double spacing_deg);

}  // namespace impinge
