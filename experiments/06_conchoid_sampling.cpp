// 06_conchoid_sampling -- thesis sec. 5.1, Table 10, Fig. 58-59: the conchoid r = a + b cos(phi)
// of Menschik (a = 20.501, b = 17.843 mm), its curve length (Eq. 12-14) by quadrature beside the
// thesis' closed form 3.03 b, the adjusted ray angles by Eq. 16 beside the exact inversion of arc
// length, the size of the thesis' approximations, and an empirical test: on a conchoid-shaped
// joint, does weighted sampling lower the radial error at equal node count?
//
// Outputs: OUT/06_conchoid_sampling/
//   length.csv       curve length over [0, pi/2] exact and by each approximation
//   table10.csv      30-deg example: original, Eq. 16 and exact adjusted angles
//   angles.csv       0.1 deg (901 rays): original, Eq. 16, exact adjusted angle and adjustment
//   equal_nodes.csv  per scheme at equal node count: radial error over the hip region
//   segments.csv     thesis Fig. 53: equal-angle rays (1 deg) from the conchoid's origin and from the
//                    object's centre (the area centroid of the closed curve, and its extent's middle) cut
//                    the hip curve (phi in [0, 90] deg) into segments: each segment's curve length
//   meta.json
// Command: build/experiments/exp_06_conchoid_sampling --out results [--quick]
#include <cmath>
#include <random>

#include "experiment_support.hpp"
#include "impinge/core/spherical_frame.hpp"
#include "impinge/maps/radial_distance_map.hpp"
#include "impinge/schemes/conchoid.hpp"
#include "impinge/schemes/sampling_scheme.hpp"

using namespace impinge;
using namespace impinge::experiment;

namespace {

// The conchoid's arc length over the hip region: exact (GSL) against the thesis' approximations.
void length_table(const std::string& dir, const Conchoid& exact, const Conchoid& approx_a, double b) {
  CsvWriter len(dir + "/length.csv", {"variant", "length_mm", "length_over_b", "rel_error_vs_exact"});
  const double L = exact.arc_length(kPi / 2);
  // a = 1.15 b only
  const double L115 = approx_a.arc_length(kPi / 2);
  // a = 1.15 b and a^2 + b^2 = 2ab = 2.3 b^2: sqrt(2.3) b sqrt(2) int cos(t/2) = thesis closed form
  const double Lth = conchoid_length_thesis(b);
  // the thesis' printed rounding: 3.03 b
  const double L303 = 3.03 * b;
  for (auto [name, v] :
       std::initializer_list<std::pair<const char*, double>>{{"exact (a, b; GSL QAGS)", L},
                                                             {"a = 1.15 b", L115},
                                                             {"a = 1.15 b, 2.3 b^2 (thesis closed form)", Lth},
                                                             {"3.03 b (thesis, printed)", L303}})
    len.row(std::string("\"") + name + "\"", v, v / b, (v - L) / L);
}

// Table 10: four equal-length angles by Eq. 16 and exactly, beside the thesis' adjusted angles.
void table10(const std::string& dir, const Conchoid& exact) {
  CsvWriter t10(dir + "/table10.csv", {"i", "original_deg", "eq16_deg", "exact_deg", "thesis_adjusted_deg",
                                       "eq16_adjustment_deg", "exact_adjustment_deg"});
  const std::vector<double> e16 = conchoid_angles_eq16(4), ex = exact.equal_length_angles(4, kPi / 2);
  const double thesis[] = {0, 27, 56, 90};
  for (int i = 0; i < 4; ++i)
    t10.row(i, 30.0 * i, e16[i] * kRadToDeg, ex[i] * kRadToDeg, thesis[i], e16[i] * kRadToDeg - 30.0 * i,
            ex[i] * kRadToDeg - 30.0 * i);
}

// The same at 0.1 deg over [0, 90] deg.
void angles_table(const std::string& dir, const Conchoid& exact) {
  CsvWriter an(dir + "/angles.csv",
               {"i", "original_deg", "eq16_deg", "exact_deg", "eq16_adjustment_deg", "exact_adjustment_deg"});
  const int n = 901;  // 0.1 deg over [0, 90]
  const std::vector<double> e16 = conchoid_angles_eq16(n), ex = exact.equal_length_angles(n, kPi / 2);
  for (int i = 0; i < n; ++i)
    an.row(i, 0.1 * i, e16[i] * kRadToDeg, ex[i] * kRadToDeg, e16[i] * kRadToDeg - 0.1 * i,
           ex[i] * kRadToDeg - 0.1 * i);
}

// Thesis Fig. 53 (sec. 5.1.1): equal-angle rays, 1 deg apart, from an origin (cx, 0) on the axis cut the hip
// curve (phi in [0, 90] deg about the conchoid's origin) into segments of unequal length. The thesis: up to
// 20 % longer in the middle with the origin at the object's centre, up to 30 % longer at the bottom with
// the origin at the conchoid's. The object's centre, which the thesis does not define, is taken two ways:
// the area centroid of the closed curve, x = (a^2 b + b^3 / 4) / (a^2 + b^2 / 2), and the middle of its
// extent along the axis, x = b.
void segments_table(const std::string& dir, const Conchoid& c) {
  CsvWriter sg(dir + "/segments.csv",
               {"origin", "origin_x_mm", "ray_from_deg", "ray_to_deg", "phi_from_deg", "phi_to_deg", "length_mm"});
  const double a = c.a(), b = c.b();
  const double centroid = (a * a * b + b * b * b / 4) / (a * a + b * b / 2);
  for (auto [name, cx] : std::initializer_list<std::pair<const char*, double>>{
           {"conchoid_origin", 0.0}, {"object_centroid", centroid}, {"object_extent_middle", b}}) {
    const double psi_end = std::atan2(c.radius(kPi / 2), -cx) * kRadToDeg;  // the rim, seen from the origin
    double phi_prev = 0, s_prev = 0;  // the previous ray's angle and curve length
    for (int k = 1; k <= static_cast<int>(std::ceil(psi_end - 1e-9)); ++k) {
      const double psi = std::min(double(k), psi_end);
      const double phi = psi >= psi_end ? kPi / 2 : c.angle_seen_from(cx, psi * kDegToRad, kPi / 2);
      const double s = c.arc_length(phi);
      sg.row(name, cx, k - 1.0, psi, phi_prev * kRadToDeg, phi * kRadToDeg, s - s_prev);
      phi_prev = phi, s_prev = s;
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  const Args args = parse_args(argc, argv, "06_conchoid_sampling: thesis sec. 5.1 conchoid weighted sampling");
  const std::string dir = experiment_dir(args, "06_conchoid_sampling");
  const double a = kMenschikA, b = kMenschikB;
  const Conchoid exact(a, b), approx_a(1.15 * b, b);
  length_table(dir, exact, approx_a, b);
  table10(dir, exact);
  angles_table(dir, exact);
  segments_table(dir, exact);
  // Equal node count on a conchoid joint (origin at the conchoid origin, axis z): maps filled with
  // the exact radius at every node (the sampling itself is exact here), so only the node layout
  // and its interpolation differ. Error over uniformly random directions with phi <= 90 deg.
  CsvWriter eqn(dir + "/equal_nodes.csv", {"scheme", "resolution", "precision_deg", "nodes", "hip_region_nodes",
                                           "directions", "max_mm", "p95_mm", "rms_mm"});
  std::vector<double> precisions{2, 1, 0.5};
  if (!args.quick) precisions.push_back(0.25);
  const int n_dirs = args.quick ? 50000 : 200000;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> U(0, 1);
  std::vector<Eigen::Vector3d> dirs;
  while (static_cast<int>(dirs.size()) < n_dirs) {
    const Eigen::Vector3d u = direction(std::acos(2 * U(rng) - 1), 2 * kPi * U(rng));
    if (u.z() >= 0) dirs.push_back(u);
  }
  int step = 0;
  for (double p : precisions) {
    progress("06_conchoid_sampling", ++step, int(precisions.size()), "p=" + std::to_string(p));
    const std::int64_t eq_nodes = make_scheme("equiangular", p)->num_nodes();
    const double k = std::round(std::sqrt(double(eq_nodes)));
    for (const auto& scheme : {make_scheme("equiangular", p), make_scheme("conchoid", p), make_scheme("helix", k)}) {
      RadialDistanceMapDouble map(scheme);
      std::vector<double> phi(4096), theta(4096);
      std::int64_t hip_nodes = 0;
      for (std::int64_t first = 0; first < map.num_nodes(); first += 4096) {
        const std::int64_t c = std::min<std::int64_t>(4096, map.num_nodes() - first);
        scheme->node_angles(first, c, phi.data(), theta.data());
        for (std::int64_t j = 0; j < c; ++j) {
          map.data()[first + j] = exact.radius(phi[j]);
          if (phi[j] <= kPi / 2) ++hip_nodes;
        }
      }
      std::vector<double> err;
      double s2 = 0;
      for (const auto& u : dirs) {
        const double e = std::abs(map.lookup(u) - exact.radius(std::acos(std::clamp(u.z(), -1.0, 1.0))));
        err.push_back(e);
        s2 += e * e;
      }
      std::sort(err.begin(), err.end());
      eqn.row(scheme->name(), scheme->resolution(), p, scheme->num_nodes(), hip_nodes, n_dirs, err.back(),
              err[static_cast<std::size_t>(0.95 * double(err.size() - 1))], std::sqrt(s2 / double(err.size())));
    }
  }
  write_meta(dir, args,
             {{"a_mm", a},
              {"b_mm", b},
              {"precisions_deg", precisions},
              {"directions", n_dirs},
              {"helix_turns", "round(sqrt(equiangular node count)) (equal node count)"},
              {"segments", "equal-angle rays 1 deg apart over the hip curve from three origins (Fig. 53)"},
              {"thesis_source", "thesis sec. 5.1, Eq. 11-16, Table 10, Fig. 53, 58-59"}});
  return 0;
}
