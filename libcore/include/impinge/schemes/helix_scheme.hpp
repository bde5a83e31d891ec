#pragma once
/// @file helix_scheme.hpp
/// The spherical-helix sampling scheme of USID (thesis ch. 4): w = k^2 helix orientation
/// points equally spaced along the k-turn helix theta = 2 k phi (Eq. 9, Nishio et al. 2006),
/// stored as a 1-D map.

#include <cmath>
#include <cstdint>
#include <string>

#include "impinge/core/fast_angles.hpp"
#include "impinge/core/spherical_frame.hpp"
#include "impinge/schemes/helix_arc_length.hpp"
#include "impinge/schemes/sampling_scheme.hpp"

namespace impinge {

/// How a direction's traveled distance is computed when locating its neighbours (thesis
/// sec. 4.3). It never changes which nodes exist: nodes are equally spaced in exact arc length.
enum class TraveledDistance {
  exact,   ///< exact arc length (elliptic integral, HelixArcLength)
  fitted,  ///< the thesis' fitted formula Eq. 10, T = (4k+1)(1 - cos phi)/2, scaled to w - 1 steps
};

/// k-turn spherical helix scheme. Node i lies at arc length s_i = i L / (w - 1) (L the total
/// length), so node 0 is the north pole and node w - 1 the south pole.
/// Stencil of a direction (phi, theta) (thesis Fig. 48, Algorithm 3): the helix crosses the
/// meridian theta at phi_a <= phi < phi_b = phi_a + pi/k (the two bracketing turns); on each
/// crossing the two nodes bracketing its traveled distance, linearly weighted along the curve;
/// then linear in phi between the crossings. In the first (last) turn the north (south) pole
/// node replaces the missing crossing: three neighbours.
/// Turns k whose helix carries as many nodes on the equator as the equiangular grid of precision
/// p degrees (360/p): a helix of spacing ~4/k has ~pi k / 2 equator nodes, so k = round(720 / (pi p))
/// (thesis Table 6: 229, 458, 2292, 4584 for p = 1, 0.5, 0.1, 0.05).
inline double matched_helix_turns(double precision_deg) {
  return std::round(720.0 / (3.14159265358979323846 * precision_deg));
}

/// The two crossings of the meridian of direction (x, y, z) by a k-turn helix that bracket it
/// (thesis Fig. 48): polar angles phi_a <= phi < phi_b = phi_a + pi/k, clamped to 0 in the
/// first turn and to pi in the last (where a pole node replaces the missing crossing), and the
/// weight u of phi_b in the linear interpolation between them (0 when the span is empty).
/// No libm trigonometry (fast_angles.hpp). inv_2k = 1 / (2k), pi_over_k = pi / k. Shared by
/// HelixScheme::stencil_at and the vectorised look-up, branch-free so that loops vectorise.
inline void helix_crossings_of(double x, double y, double z, double k, double inv_2k, double pi_over_k, double& phi_a,
                               double& phi_b, double& u) {
  constexpr double kTwoPi = 2 * kPi;
  double phi, theta;
  fast_spherical_angles(x, y, z, phi, theta);
  theta = theta >= kTwoPi ? theta - kTwoPi : theta;
  const double jf = (2 * k * phi - theta) * (1 / kTwoPi);  // floor without a libm call
  double j = static_cast<double>(static_cast<std::int64_t>(jf));
  j = j > jf ? j - 1 : j;
  const double a = (theta + kTwoPi * j) * inv_2k, b = a + pi_over_k;
  phi_a = a <= 0 ? 0.0 : a;
  phi_b = b >= kPi ? kPi : b;
  const double span = phi_b - phi_a;  // 0 when a crossing falls exactly on the south pole
  double w = span > 0 ? (phi - phi_a) / span : 0.0;
  u = w < 0 ? 0.0 : (w > 1 ? 1.0 : w);
}

class HelixScheme : public SchemeImpl<HelixScheme> {
 public:
  /// k >= 2 integral turns (thesis Table 6: 229, 458, 2292, 4584). Throws impinge::Error.
  explicit HelixScheme(double turns, TraveledDistance locate = TraveledDistance::exact);

  std::string name() const override { return locate_ == TraveledDistance::exact ? "helix" : "helix-eq10"; }
  std::string resolution_name() const override { return "turns"; }
  double resolution() const override { return k_; }
  double turns() const { return k_; }
  TraveledDistance locate() const { return locate_; }
  std::int64_t num_nodes() const override { return w_; }
  /// Arc length between consecutive nodes, radians (= the largest node spacing).
  double node_spacing() const { return dx_; }
  double max_node_spacing() const override { return dx_; }
  const HelixArcLength& arc_length() const { return arc_; }

  Eigen::Vector3d node_direction(std::int64_t i) const override;
  /// Incremental inversion of the arc length along consecutive nodes (fast path of resampling).
  void node_angles(std::int64_t first, std::int64_t count, double* phi, double* theta) const override;
  /// The node with the largest stencil weight.
  std::int64_t node(const Eigen::Vector3d& u) const override;
  /// Traveled distance of a point of the helix at polar angle phi, in node steps (so that
  /// node i is at i), by the chosen formula.
  double steps_at(double phi) const {
    if (locate_ == TraveledDistance::fitted) return half_w1_ * (1 - std::cos(phi));
    return arc_(phi) * inv_dx_;
  }

  /// Thesis Algorithm 3's neighbour location and interpolation (see class comment).
  void stencil_at(double x, double y, double z, std::int64_t nodes[4], double w[4]) const {
    double phi_a, phi_b, u;
    helix_crossings_of(x, y, z, k_, inv_2k_, kPiOverK_, phi_a, phi_b, u);
    if (phi_a <= 0) {  // first turn: the north pole node replaces the upper crossing
      nodes[0] = nodes[1] = 0;
      w[0] = 1, w[1] = 0;
    } else {
      along(phi_a, nodes, w);
    }
    if (phi_b >= kPi_) {  // last turn: the south pole node
      nodes[2] = nodes[3] = w_ - 1;
      w[2] = 1, w[3] = 0;
    } else {
      along(phi_b, nodes + 2, w + 2);
    }
    w[0] *= 1 - u, w[1] *= 1 - u, w[2] *= u, w[3] *= u;
  }

  /// Block stencils (exact locator; the Eq. 10 locator uses stencil_at): the angles and both
  /// bracketing crossings of a block in one pass, the arc lengths of the crossings in a second, the
  /// nodes along the curve in a third; vectorised clones. Same stencils as stencil_at up to rounding
  /// (at the south pole the last node is reached as node w - 2 with weight 0 and w - 1 with 1).
  void stencils_soa(const double* x, const double* y, const double* z, int n, std::int32_t* nodes,
                    double* w) const override;

 private:
  /// Polar angle of node i by Newton from `guess` (radians; <= 0 for a closed-form start).
  double phi_of_node(std::int64_t i, double guess) const;
  /// The two nodes bracketing the helix point at phi along the curve, with linear weights.
  void along(double phi, std::int64_t* nodes, double* w) const {
    const double f = steps_at(phi);
    std::int64_t i = static_cast<std::int64_t>(f);
    if (i > w_ - 2) i = w_ - 2;
    if (i < 0) i = 0;
    double t = f - static_cast<double>(i);
    t = t < 0 ? 0 : (t > 1 ? 1 : t);
    nodes[0] = i, nodes[1] = i + 1;
    w[0] = 1 - t, w[1] = t;
  }

  static constexpr double kPi_ = 3.14159265358979323846;
  static constexpr double kTwoPi = 2 * kPi_;
  static constexpr double kInvTwoPi = 1 / kTwoPi;
  double k_;
  TraveledDistance locate_;
  std::int64_t w_;
  HelixArcLength arc_;
  double dx_, inv_dx_, inv_2k_, kPiOverK_, half_w1_;
};

}  // namespace impinge
