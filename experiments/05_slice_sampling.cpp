// 05_slice_sampling -- thesis sec. 3.5.2, Fig. 45-46: the slice (Shannon) analysis, reproduced
// for any head size and slice thickness, then tested: a sphere segmented on 1.25 mm CT slices
// (a staircase surface) is sampled at p = 5 .. 0.05 deg and its gaps compared with the smooth
// sphere. Does refining beyond ~1.5 deg stop helping?
//
// Outputs: OUT/05_slice_sampling/
//   slices.csv      per head radius x slice thickness x slice index: phi_i and delta phi_i
//   nyquist.csv     per head radius x slice thickness: smallest delta phi and the Nyquist precision
//   staircase.csv   per precision: radial error of the map of the staircase sphere against the
//                   smooth sphere and against the staircase itself (exact ray cast), and the
//                   socket-scan gap error of a smooth concentric cup against the smooth truth
//   meta.json
// Command: build/experiments/exp_05_slice_sampling --out results [--quick]
#include <random>

#include "experiment_support.hpp"
#include "impinge/core/spherical_frame.hpp"
#include "impinge/detection/joint.hpp"
#include "impinge/io/generated_models.hpp"
#include "impinge/sampling/naive_sampling.hpp"
#include "impinge/sampling/sampling_error.hpp"

using namespace impinge;
using namespace impinge::experiment;

int main(int argc, char** argv) {
  const Args args = parse_args(argc, argv, "05_slice_sampling: thesis sec. 3.5.2 slice analysis, tested");
  const std::string dir = experiment_dir(args, "05_slice_sampling");
  {
    CsvWriter sl(dir + "/slices.csv", {"radius_mm", "slice_mm", "slice", "phi_deg", "dphi_deg"});
    CsvWriter ny(dir + "/nyquist.csv", {"radius_mm", "slice_mm", "slices_per_side", "min_dphi_deg",
                                        "nyquist_precision_deg", "thesis_min_dphi_deg", "thesis_precision_deg"});
    for (double r : {18.0, 20.0, 22.0, 24.0, 26.0})
      for (double t : {0.5, 0.625, 1.0, 1.25, 2.0, 3.0}) {
        const SliceAnalysis a = slice_sampling(r, t);
        for (std::size_t i = 0; i < a.phi_deg.size(); ++i)
          sl.row(r, t, int(i), a.phi_deg[i], i < a.dphi_deg.size() ? a.dphi_deg[i] : std::nan(""));
        const bool thesis = r == 22.0 && t == 1.25;
        ny.row(r, t, int(a.dphi_deg.size()), a.min_dphi_deg, a.nyquist_precision_deg, thesis ? 3.0 : std::nan(""),
               thesis ? 1.5 : std::nan(""));
      }
  }
  // The staircase sphere: r = 22, 1.25 mm slices; reference smooth sphere of r = 22.
  const Eigen::Vector3d cor(0, 0, 0);
  const double R = 22, T = 1.25;
  const TriangleMesh stairs = make_sliced_sphere(R, T, cor, 720);
  const TriangleMesh cup = make_cup(R + 2.5, R + 8, 100, cor, Eigen::Vector3d(0, 0.3, 1).normalized(), 720, 200);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> U(0, 1);
  const int n_dirs = args.quick ? 1000 : 4000;
  std::vector<Eigen::Vector3d> dirs;
  for (int j = 0; j < n_dirs; ++j) dirs.push_back(direction(std::acos(2 * U(rng) - 1), 2 * kPi * U(rng)));
  std::vector<double> stair_exact(dirs.size());
  for (std::size_t j = 0; j < dirs.size(); ++j) stair_exact[j] = cast_ray_naive(stairs, cor, dirs[j])->first;
  CsvWriter st(dir + "/staircase.csv", {"precision_deg", "directions", "vs_sphere_rms_mm", "vs_sphere_max_mm",
                                        "vs_staircase_rms_mm", "vs_staircase_max_mm", "staircase_vs_sphere_rms_mm",
                                        "gap_vs_smooth_rms_mm", "gap_vs_smooth_max_mm", "nyquist_precision_deg"});
  const double nyquist = slice_sampling(R, T).nyquist_precision_deg;
  std::vector<double> precisions{5, 3, 2, 1.5, 1, 0.5, 0.25, 0.1};
  if (!args.quick) precisions.push_back(0.05);
  double stair_rms = 0;
  for (std::size_t j = 0; j < dirs.size(); ++j) stair_rms += (stair_exact[j] - R) * (stair_exact[j] - R);
  stair_rms = std::sqrt(stair_rms / double(dirs.size()));
  int step = 0;
  for (double p : precisions) {
    progress("05_slice_sampling", ++step, int(precisions.size()), "p=" + std::to_string(p));
    JointOptions o;
    o.scheme = make_scheme("equiangular", p);
    const Joint joint(stairs, cup, cor, o);
    double s2 = 0, smax = 0, t2 = 0, tmax = 0;
    for (std::size_t j = 0; j < dirs.size(); ++j) {
      const double v = joint.ball().map.lookup(dirs[j]);
      s2 += (v - R) * (v - R), smax = std::max(smax, std::abs(v - R));
      t2 += (v - stair_exact[j]) * (v - stair_exact[j]), tmax = std::max(tmax, std::abs(v - stair_exact[j]));
    }
    // socket scan: the smooth cup's vertices against the staircase ball's map; the smooth truth
    // is (R + 2.5) - R = 2.5 mm along every ray
    const PoseResult res = joint.detect(Eigen::Matrix3d::Identity());
    double g2 = 0, gmax = 0;
    std::int64_t gn = 0;
    for (std::size_t i = 0; i < res.socket_gaps.gap_mm.size(); ++i) {
      if (res.socket_gaps.status[i] != ScanGaps::tested) continue;
      const double e = res.socket_gaps.gap_mm[i] - 2.5;
      g2 += e * e, gmax = std::max(gmax, std::abs(e)), ++gn;
    }
    const double nd = double(dirs.size());
    st.row(p, n_dirs, std::sqrt(s2 / nd), smax, std::sqrt(t2 / nd), tmax, stair_rms,
           gn > 0 ? std::sqrt(g2 / double(gn)) : std::nan(""), gmax, nyquist);
  }
  write_meta(dir, args,
             {{"radius_mm", R},
              {"slice_mm", T},
              {"staircase_segments", 720},
              {"directions", n_dirs},
              {"precisions_deg", precisions},
              {"thesis_source", "thesis sec. 3.5.2, Fig. 45-46"},
              {"staircase", "slices [k t, (k+1) t] with the sphere's cross-section radius at mid height"}});
  return 0;
}
