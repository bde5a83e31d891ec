// 12_sphere_fit -- thesis sec. 3.4, Fig. 38-39: the centre of rotation by sphere fit.
// (1) Synthetic heads with known centre and radius: algebraic fit, geometric (Eberly) fit and
// the automatic head fit (RANSAC on the proximal femur, then geometric), under noise, partial
// coverage and a cam bump. (2) Each real femur: fitted centre, radius, RMS residual, inliers,
// stability of the centre when the proximal extent or the inlier threshold changes, and the
// residual over the head (Fig. 39).
//
// Outputs: OUT/12_sphere_fit/
//   synthetic.csv   per method x noise x coverage x cam x seed: centre and radius errors
//   real.csv        per subject x proximal extent x threshold: centre, radius, RMS, inliers,
//                   shift of the centre from the default fit
//   residuals.csv   per subject: head vertices near the fitted sphere, direction and residual
//   meta.json
// Command: build/experiments/exp_12_sphere_fit --out results --data ../shared/data/hips [--quick]
#include <random>

#include "experiment_support.hpp"
#include "impinge/anatomy/sphere_fit.hpp"
#include "impinge/core/error.hpp"
#include "impinge/core/spherical_frame.hpp"
#include "impinge/io/generated_models.hpp"

using namespace impinge;
using namespace impinge::experiment;
using PointMatrix = Eigen::Matrix<double, Eigen::Dynamic, 3>;

namespace {

// Synthetic heads: a cap of half-angle `coverage` about +z with Gaussian radial noise and a cam bump,
// fitted algebraically, geometrically and by the automatic fit; `seeds` draws each.
void synthetic_table(const std::string& dir, int seeds) {
  CsvWriter syn(dir + "/synthetic.csv", {"method", "noise_mm", "coverage_deg", "cam_mm", "seed", "centre_error_mm",
                                         "radius_error_mm", "rms_mm", "points"});
  const double R = 22;
  int step = 0;
  const std::vector<double> noises{0, 0.1, 0.3, 0.5}, coverages{60, 90, 120, 150}, cams{0, 2, 4};
  for (double noise : noises)
    for (double cov : coverages)
      for (double cam : cams) {
        progress(
            "12_sphere_fit", ++step, int(noises.size() * coverages.size() * cams.size()),
            "noise " + std::to_string(noise) + " coverage " + std::to_string(cov) + " cam " + std::to_string(cam));
        for (int seed = 0; seed < seeds; ++seed) {
          // Head points: a cap of half-angle `cov` about +z (superior) with Gaussian radial noise;
          // the cam bump: a Gaussian bump of height `cam` and width 15 deg at 60 deg from the top.
          std::mt19937_64 rng(1000 + seed);
          std::uniform_real_distribution<double> U(0, 1);
          std::normal_distribution<double> N(0, 1);
          const Eigen::Vector3d c(12, -7, 40);
          const Eigen::Vector3d cam_dir = direction(60 * kDegToRad, 30 * kDegToRad);
          const int n = 4000;
          PointMatrix P(n, 3);
          for (int i = 0; i < n; ++i) {
            const double z = 1 - U(rng) * (1 - std::cos(cov * kDegToRad));
            const Eigen::Vector3d u = direction(std::acos(z), 2 * kPi * U(rng));
            const double g = std::acos(std::clamp(u.dot(cam_dir), -1.0, 1.0)) / (15 * kDegToRad);
            P.row(i) = (c + (R + noise * N(rng) + cam * std::exp(-g * g)) * u).transpose();
          }
          // the automatic fit on a femur-like mesh: the generated head + neck carries the same
          // noise-free geometry; here it runs on the point set as a vertex-only mesh
          TriangleMesh pts;
          pts.V = P;
          pts.F.resize(1, 3);
          pts.F << 0, 1, 2;
          pts.source = "synthetic head";
          struct Fit {
            const char* name;
            SphereFitResult r;
          };
          std::vector<Fit> fits{{"algebraic", fit_sphere_algebraic(P)}, {"geometric", fit_sphere_geometric(P)}};
          try {
            HeadFitOptions o;
            o.seed = 99 + seed;
            o.surface_stage = false;  // a point set: no surface to fit (the vertices' fixed point is the result)
            fits.push_back({"automatic", fit_femoral_head(pts, o)});
          } catch (const Error&) {
          }
          for (const Fit& f : fits)
            syn.row(f.name, noise, cov, cam, seed, (f.r.centre - c).norm(), f.r.radius - R, f.r.rms_residual,
                    f.r.points_used);
        }
      }
}

// Real femurs: the automatic fit's sensitivity to its proximal extent and inlier band, and the
// residuals of the head vertices (Fig. 39).
void real_tables(const Args& args, const std::string& dir) {
  CsvWriter real(dir + "/real.csv", {"subject", "proximal_extent_mm", "inlier_threshold_mm", "cx_mm", "cy_mm", "cz_mm",
                                     "radius_mm", "rms_mm", "inliers", "shift_from_default_mm"});
  CsvWriter res(dir + "/residuals.csv", {"subject", "phi_deg", "theta_deg", "residual_mm"});
  for (const Subject& s : load_subjects(args, {12000})) {
    const SphereFitResult def = fit_femoral_head(s.femur);
    for (double extent : {50.0, 70.0, 90.0})
      for (double thr : {0.5, 1.0, 1.5}) {
        HeadFitOptions o;
        o.proximal_extent_mm = extent;
        o.inlier_threshold_mm = thr;
        try {
          const SphereFitResult f = fit_femoral_head(s.femur, o);
          real.row(s.name, extent, thr, f.centre.x(), f.centre.y(), f.centre.z(), f.radius, f.rms_residual,
                   f.points_used, (f.centre - def.centre).norm());
        } catch (const Error& e) {
          real.row(s.name, extent, thr, std::nan(""), std::nan(""), std::nan(""), std::nan(""), std::nan(""),
                   std::int64_t(0), std::nan(""));
        }
      }
    // Fig. 39: residual |p - c| - r of the vertices within 4 mm of the fitted sphere (the head).
    for (Eigen::Index i = 0; i < s.femur.V.rows(); ++i) {
      const Eigen::Vector3d d = s.femur.V.row(i).transpose() - def.centre;
      const double e = d.norm() - def.radius;
      if (std::abs(e) > 4) continue;
      const SphericalCoordinates sc = to_spherical(d);
      res.row(s.name, sc.phi * kRadToDeg, sc.theta * kRadToDeg, e);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  const Args args = parse_args(argc, argv, "12_sphere_fit: thesis sec. 3.4 centre of rotation by sphere fit");
  const std::string dir = experiment_dir(args, "12_sphere_fit");
  const int seeds = args.quick ? 3 : 10;
  synthetic_table(dir, seeds);
  real_tables(args, dir);
  write_meta(dir, args,
             {{"seeds", seeds},
              {"points", 4000},
              {"radius_mm", 22},
              {"cam_width_deg", 15},
              {"cam_at_deg", 60},
              {"thesis_source", "thesis sec. 3.4, Fig. 38-39; Eberly 1999"},
              {"automatic", "fit_femoral_head defaults (RANSAC 3000 iterations, 1 mm band, 4 geometric refits)"}});
  return 0;
}
