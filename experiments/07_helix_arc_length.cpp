// 07_helix_arc_length -- thesis Eq. 10 (the fitted "traveled distance") against the exact arc
// length of the k-turn spherical helix (an elliptic integral of the second kind).
//
// Inputs: none. Outputs: OUT/07_helix_arc_length/
//   arc_length.csv    per k and phi (0.1-deg steps): exact s, Eq. 10's T, their absolute and
//                     relative difference, and the difference in node steps used for locating
//   index_errors.csv  per k: how often locating with Eq. 10 picks other stencil nodes than the
//                     exact arc length, over random directions, and by how many nodes at most; the cost of
//                     one locate-and-interpolate (ns) of each locator, median and quartiles over `runs`
//                     alternated rounds
//   self_consistent.csv  per k: a helix whose nodes are placed by Eq. 10 itself (node i at T = i steps, so
//                     phi_i = acos(1 - 2 i / (w - 1))), located by Eq. 10 without error by construction: its node
//                     spacing along the curve against the exact helix's equal spacing (smallest and largest
//                     ratio, where the largest lies, and the share of intervals within 10 % of it) -- the
//                     sensitivity check of a self-consistent Eq. 10 helix (issue 51)
//   helix_nodes.csv   thesis Fig. 47: every node of the k = 10, 20 and 40 helices (w = k^2 nodes), as the scheme
//                     places them (node_angles, node_direction)
//   helix_locate.csv  thesis Fig. 48: one direction v on the k = 10 helix, the points P_a and P_b where its
//                     meridian crosses the turns above and below, the four nodes of its stencil (both locators),
//                     each with its traveled distance (exact arc length from the start, unit sphere) in node steps
//   meta.json
// Command: build/experiments/exp_07_helix_arc_length --out results [--quick]
#include <algorithm>
#include <cmath>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "experiment_support.hpp"
#include "impinge/core/spherical_frame.hpp"
#include "impinge/schemes/helix_scheme.hpp"

using namespace impinge;
using namespace impinge::experiment;

namespace {

// Thesis Figs. 47-48 drawn from the scheme's own geometry: the nodes of three helices, and the look-up of one
// direction on the k = 10 helix (the turns bracketing it, its stencil by the exact and the Eq. 10 locator).
void write_figure_geometry(const std::string& dir) {
  CsvWriter nodes(dir + "/helix_nodes.csv", {"turns", "node", "phi_deg", "theta_deg", "x", "y", "z"});
  for (double k : {10.0, 20.0, 40.0}) {
    const HelixScheme h(k);
    std::vector<double> phi(static_cast<std::size_t>(h.num_nodes())), theta(phi.size());
    h.node_angles(0, h.num_nodes(), phi.data(), theta.data());
    for (std::int64_t i = 0; i < h.num_nodes(); ++i) {
      const Eigen::Vector3d u = h.node_direction(i);
      nodes.row(k, i, phi[std::size_t(i)] * kRadToDeg, theta[std::size_t(i)] * kRadToDeg, u.x(), u.y(), u.z());
    }
  }
  CsvWriter loc(dir + "/helix_locate.csv",
                {"turns", "point", "locator", "node", "phi_deg", "theta_deg", "x", "y", "z", "steps", "weight"});
  const double k = 10, phi_v = 64 * kDegToRad, theta_v = 235 * kDegToRad;
  const HelixScheme exact(k), fitted(k, TraveledDistance::fitted);
  const double dx = exact.node_spacing();
  const Eigen::Vector3d v = direction(phi_v, theta_v);
  auto point = [&](const char* name, const char* locator, std::int64_t node, double phi, double theta, double w) {
    const Eigen::Vector3d u = direction(phi, theta);
    loc.row(k, name, locator, node, phi * kRadToDeg, theta * kRadToDeg, u.x(), u.y(), u.z(),
            exact.arc_length()(phi) / dx, w);
  };
  point("v", "--", -1, phi_v, theta_v, 1.0);
  // The turns (theta = 2 k phi, Eq. 9) cross v's meridian at phi_j = (theta_v + 2 pi j) / (2 k): the last such phi
  // before phi_v (the turn above, P_a) and the next (the turn below, P_b).
  const double j = std::floor((2 * k * phi_v - theta_v) / (2 * kPi));
  const double phi_a = (theta_v + 2 * kPi * j) / (2 * k), phi_b = phi_a + kPi / k;
  point("P_a", "--", -1, phi_a, theta_v, 0.0);
  point("P_b", "--", -1, phi_b, theta_v, 0.0);
  for (const HelixScheme* h : {&exact, &fitted}) {
    const Stencil st = h->interpolate(v);
    for (int n = 0; n < 4; ++n) {
      std::vector<double> phi(1), theta(1);
      exact.node_angles(st.nodes[std::size_t(n)], 1, phi.data(), theta.data());
      point(("stencil_" + std::to_string(n)).c_str(), h == &exact ? "exact" : "eq10", st.nodes[std::size_t(n)],
            phi[0], theta[0], st.weights[std::size_t(n)]);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  const Args args = parse_args(argc, argv, "07_helix_arc_length: thesis Eq. 10 against the exact arc length");
  const std::string dir = experiment_dir(args, "07_helix_arc_length");
  const std::vector<double> turns{10, 40, 229, 458, 2292, 4584};
  const int directions = args.quick ? 50000 : 400000;
  CsvWriter arc(dir + "/arc_length.csv", {"turns", "phi_deg", "s_exact", "t_eq10", "abs_error", "rel_error",
                                          "steps_exact", "steps_eq10", "index_error_steps"});
  CsvWriter idx(
      dir + "/index_errors.csv",
      {"turns", "nodes", "node_spacing_deg", "total_length_exact", "total_length_eq10", "directions",
       "stencils_differing", "fraction_differing", "nearest_node_differing", "fraction_nearest_differing",
       "max_node_index_difference", "max_abs_index_error_steps", "exact_ns_per_locate", "exact_ns_q25", "exact_ns_q75",
       "eq10_ns_per_locate", "eq10_ns_q25", "eq10_ns_q75", "runs"});
  CsvWriter self(dir + "/self_consistent.csv", {"turns", "nodes", "exact_spacing_deg", "min_spacing_ratio",
                                                 "max_spacing_ratio", "phi_of_max_deg", "share_within_10pct"});
  write_figure_geometry(dir);
  int step = 0;
  for (double k : turns) {
    progress("07_helix_arc_length", ++step, int(turns.size()), "k=" + std::to_string(int(k)));
    const HelixScheme exact(k), fitted(k, TraveledDistance::fitted);
    const HelixArcLength& s = exact.arc_length();
    double max_steps = 0;
    for (int j = 0; j <= 1800; ++j) {
      const double phi = j * 0.1 * kDegToRad;
      const double se = s.exact(phi), t10 = traveled_distance_eq10(k, std::cos(phi));
      const double steps_e = exact.steps_at(phi), steps_f = fitted.steps_at(phi);
      max_steps = std::max(max_steps, std::abs(steps_f - steps_e));
      arc.row(k, j * 0.1, se, t10, t10 - se, j > 0 ? (t10 - se) / se : std::nan(""), steps_e, steps_f,
              steps_f - steps_e);
    }
    {
      // The self-consistent Eq. 10 helix: node i where Eq. 10's traveled distance is i steps. Its spacing along
      // the curve (exact arc length between consecutive nodes) over the exact helix's equal spacing.
      const std::int64_t w = exact.num_nodes();
      const double dx = exact.node_spacing();
      double lo = 1e300, hi = 0, phi_hi = 0, prev_s = 0;
      std::int64_t within = 0;
      for (std::int64_t i = 1; i < w; ++i) {
        const double phi = std::acos(std::clamp(1 - 2 * double(i) / double(w - 1), -1.0, 1.0));
        const double si = s(phi), ratio = (si - prev_s) / dx;
        prev_s = si;
        if (ratio < lo) lo = ratio;
        if (ratio > hi) hi = ratio, phi_hi = phi;
        within += std::abs(ratio - 1) <= 0.1;
      }
      self.row(k, w, dx * kRadToDeg, lo, hi, phi_hi * kRadToDeg, double(within) / double(w - 1));
    }
    std::mt19937_64 rng(1234);
    std::uniform_real_distribution<double> U(0, 1);
    std::vector<Eigen::Vector3d> dirs(static_cast<std::size_t>(directions));
    for (auto& u : dirs) u = direction(std::acos(2 * U(rng) - 1), 2 * kPi * U(rng));
    std::int64_t differ = 0, nearest_differ = 0, max_diff = 0;
    for (const auto& u : dirs) {
      const Stencil a = exact.interpolate(u), b = fitted.interpolate(u);
      if (a.nodes != b.nodes) ++differ;
      for (int j = 0; j < 4; ++j) max_diff = std::max<std::int64_t>(max_diff, std::abs(a.nodes[j] - b.nodes[j]));
      if (exact.node(u) != fitted.node(u)) ++nearest_differ;
    }
    // Locate cost (the scalar stencil of each locator, thesis Algorithm 3 one direction at a time),
    // medians.
    double sink = 0;
    auto locate_all = [&](const HelixScheme& h) {
      for (const auto& u : dirs) {
        const Stencil st = h.interpolate(u);
        sink += st.weights[0] + double(st.nodes[3]);
      }
    };
    // Both locators timed alternately (one run of each per round): medians and quartiles per locate.
    const std::vector<std::vector<double>> runs =
        run_alternated({[&] { locate_all(exact); }, [&] { locate_all(fitted); }}, args.repetitions);
    const Timing t_exact = summarize(runs[0]), t_fit = summarize(runs[1]);
    const double per = 1e6 / directions;
    if (!(sink > 0)) std::cerr << "07_helix_arc_length: empty stencils\n";
    idx.row(k, exact.num_nodes(), exact.node_spacing() * kRadToDeg, s.total(), traveled_distance_eq10(k, -1.0),
            directions, differ, double(differ) / directions, nearest_differ, double(nearest_differ) / directions,
            max_diff, max_steps, t_exact.median_ms * per, t_exact.q25_ms * per, t_exact.q75_ms * per,
            t_fit.median_ms * per, t_fit.q25_ms * per, t_fit.q75_ms * per, t_exact.runs);
  }
  write_meta(dir, args,
             {{"turns", turns},
              {"directions", directions},
              {"phi_step_deg", 0.1},
              {"exact", "Carlson symmetric form of the incomplete elliptic integral E(phi | -4k^2) (GSL)"},
              {"eq10", "T = (4k + 1)(1 - cos phi) / 2 (thesis Eq. 10); for locating scaled to w - 1 steps"},
              {"directions_distribution", "uniform on the sphere, seed 1234"}});
  return 0;
}
