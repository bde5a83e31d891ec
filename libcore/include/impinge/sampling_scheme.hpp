#pragma once
/// @file sampling_scheme.hpp
/// The sampling-scheme interface (DESIGN.md "Style", after HEALPix's healpix_base.h): a set of
/// sampling directions on the unit sphere with O(1) location of the interpolation stencil of
/// any direction. Maps, sampling, detection, the CLI and the experiments use only this
/// interface; a new scheme is one header/source pair deriving from SchemeImpl plus one line in
/// scheme_registry.cpp.

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdint>
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
};

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
  Stencil interpolate(const Eigen::Vector3d& u) const override {
    Stencil s;
    static_cast<const Derived*>(this)->stencil_at(u.x(), u.y(), u.z(), s.nodes.data(), s.weights.data());
    return s;
  }

 private:
  template <typename Scalar>
  void run(const Scalar* values, const double* pts, std::int64_t n, double* out) const {
    const Derived& self = *static_cast<const Derived*>(this);
    for (std::int64_t j = 0; j < n; ++j) {
      std::int64_t nd[4];
      double w[4];
      self.stencil_at(pts[3 * j], pts[3 * j + 1], pts[3 * j + 2], nd, w);
      const double v = w[0] * values[nd[0]] + w[1] * values[nd[1]] + w[2] * values[nd[2]] + w[3] * values[nd[3]];
      out[j] = std::isfinite(v) ? v : slow_path(values, nd, w);
    }
  }
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

}  // namespace impinge
