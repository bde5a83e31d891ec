// 10_error_vs_runtime -- (new) error of the gap against run time and memory, for every registered
// sampling scheme, both distance modes and a sweep of resolutions, with CGAL's exact radial gap
// as the oracle and Embree and CGAL themselves as peers, on the same vertices.
//
// Inputs: every subject under --data and the generated 3k hip model.
// Outputs: OUT/10_error_vs_runtime/
//   error_runtime.csv  one row per subject x pose x scheme x mode x resolution (and one per peer):
//     vertices: hip-region vertices (within 45 mm of the COR) on their own bone's first surface,
//       decided by CGAL (own first hit along the COR ray at least |p| - 1 mm): the same set for
//       every row; compared: those where both the method and CGAL find a surface; mismatched:
//       one does, the other does not;
//     max / p99 / p95 / median |gap - exact gap| (mm) over the compared vertices;
//     query_ns_per_vertex: both scans, median over the repetitions, per vertex;
//     sampling_ms: filling both maps (sample_surface, exact mode with face culling), median (one
//       run for a ray-cast fill at p <= 0.1 deg: seconds each);
//     bytes: both maps; large_errors: vertices with |error| > 0.05 mm, of which
//     at_discontinuity (the four stencil nodes span > 2 mm: a depth jump such as the
//     acetabular rim), near_pole (phi < 2 or > 178 deg in the map's frame), near_seam (theta
//     within 1 deg of 0/360); resample_precision_deg: the temporary equiangular map of a resampled
//     scheme (half its matched precision; linear mode), 0 when rasterised (equiangular) or ray cast
//     (every other scheme in exact mode: ray-cast-bvh, each node's exact first hit); storage: dense, or sparse (exact mode:
//     the same maps with only the tiles that hold a surface, make_sparse; sampling_ms includes the
//     conversion; the gaps are checked to equal the dense maps' bit for bit)
//   vertex_errors.csv  per-vertex errors of the equiangular map at 0.1 deg, exact mode, rest pose
//     (x, y, z relative to the COR in the map's frame, phi, theta, stencil spread, error)
//   meta.json
// Poses: rest (scan pose) and pushed_3mm (femur 3 mm into the acetabulum, as in 03).
// Command: build/experiments/exp_10_error_vs_runtime --out results --data ../shared/data/hips [--quick]
// Resolutions: largest node spacings p = 2, 1, 0.5 (quick: only these), 0.35, 0.25, 0.16, 0.1, 0.05 deg; every registered
// scheme at the coarsest resolution that reaches p (resolution_for_spacing, issue 12), so a new
// scheme joins with no change here.
#include <algorithm>
#include <cstring>
#include <iostream>
#include <optional>

#include "experiment_support.hpp"
#include "impinge/casters/embree_ray_caster.hpp"
#include "impinge/casters/exact_reference.hpp"
#include "impinge/casters/first_hit_caster.hpp"
#include "impinge/core/error.hpp"
#include "impinge/core/spherical_frame.hpp"
#include "impinge/detection/detection.hpp"
#include "impinge/maps/depth_discontinuity.hpp"
#include "impinge/sampling/sampling.hpp"
#include "impinge/schemes/helix_scheme.hpp"

using namespace impinge;
using namespace impinge::experiment;

namespace {
constexpr double kRegionMm = 45;
constexpr double kDiscontinuityToleranceMm = 0.05;  // JointOptions' default

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const double pos = q * double(v.size() - 1);
  const auto i = static_cast<std::size_t>(pos);
  const double f = pos - double(i);
  return i + 1 < v.size() ? v[i] * (1 - f) + v[i + 1] * f : v[i];
}

/// Hip-region vertices on their own first surface, decided exactly (CGAL).
ScanSet exact_scan_set(const TriangleMesh& mesh, const ExactReference& own, const Eigen::Vector3d& cor) {
  const Vertices rel = mesh.V.rowwise() - cor.transpose();
  std::vector<std::uint8_t> mask(std::size_t(rel.rows()), 0);
  for (Eigen::Index i = 0; i < rel.rows(); ++i) {
    const Eigen::Vector3d p = rel.row(i).transpose();
    const double r = p.norm();
    if (!(r > 0) || r > kRegionMm) continue;
    const auto h = own.first_hit(cor, p / r);
    mask[std::size_t(i)] = (!h || *h >= r - 1.0) ? 1 : 0;
  }
  return make_scan_set(rel, mask);
}

struct Errors {
  std::int64_t compared = 0, mismatched = 0, large = 0, discontinuity = 0, pole = 0, seam = 0;
  double max = std::nan(""), p99 = std::nan(""), p95 = std::nan(""), median = std::nan("");
};
}  // namespace

int main(int argc, char** argv) {
  const Args args = parse_args(argc, argv, "10_error_vs_runtime: gap error against run time and memory");
  const std::string dir = experiment_dir(args, "10_error_vs_runtime");
  if (!have_exact_reference()) {
    std::cerr << "10_error_vs_runtime: skipped: this build has no CGAL (the exact reference)\n";
    write_meta(dir, args, {{"skipped", "no CGAL in this build"}});
    return 0;
  }
  const std::vector<Subject> subjects = load_subjects(args, {3000});
  // Full runs add 0.35 and 0.16 deg (about the geometric means of their neighbours), so that the
  // equal-error figures (analysis) interpolate across steps of 2x in bytes rather than 4-6x.
  // Quick runs check the pipeline at coarse resolutions only (a minute or two; the analysis writes
  // "--" for the targets these do not reach).
  std::vector<double> precisions = args.quick ? std::vector<double>{2, 1, 0.5}
                                              : std::vector<double>{2, 1, 0.5, 0.35, 0.25, 0.16, 0.1, 0.05};
  const int reps = args.repetitions;

  CsvWriter csv(dir + "/error_runtime.csv",
                {"subject",     "generated",     "pose",         "scheme",           "mode",
                 "resolution",  "precision_deg", "vertices",     "compared",         "mismatched",
                 "max_abs_mm",  "p99_abs_mm",    "p95_abs_mm",   "median_abs_mm",    "query_ns_per_vertex",
                 "sampling_ms", "bytes",         "large_errors", "at_discontinuity", "near_pole",
                 "near_seam",   "resample_precision_deg", "storage"});
  CsvWriter vcsv(dir + "/vertex_errors.csv",
                 {"subject", "scan", "x_mm", "y_mm", "z_mm", "phi_deg", "theta_deg", "stencil_spread_mm", "error_mm"});
  const auto schemes = scheme_names();
  int done = 0;
  const int total = static_cast<int>(subjects.size() * precisions.size());
  for (const Subject& s : subjects) {
    const Eigen::Vector3d cor = subject_cor(s);
    const Eigen::Vector3d push = 3.0 * push_direction(s.pelvis, cor, kRegionMm);
    const ExactReference ref_f(s.femur), ref_p(s.pelvis);
    std::optional<std::pair<FirstHitCaster, FirstHitCaster>> casters;
    if (FirstHitCaster::available()) casters.emplace(FirstHitCaster(s.femur, cor), FirstHitCaster(s.pelvis, cor));
    const ScanSet fset = exact_scan_set(s.femur, ref_f, cor), pset = exact_scan_set(s.pelvis, ref_p, cor);
    const std::int64_t nv = fset.size() + pset.size();
    const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
    // The oracle per pose: exact radial gaps of both scans.
    std::vector<float> exact[2][2];
    std::vector<Eigen::Vector3d> dirs[2][2];  // q in the other map's frame
    for (int pose = 0; pose < 2; ++pose) {
      const Eigen::Vector3d t = pose == 0 ? Eigen::Vector3d::Zero() : push;
      for (int scan = 0; scan < 2; ++scan) {
        const ScanSet& set = scan == 0 ? fset : pset;
        const ExactReference& other = scan == 0 ? ref_p : ref_f;
        const Eigen::Vector3d tt = scan == 0 ? t : Eigen::Vector3d(-t);
        const double side = scan == 0 ? 1 : -1;
        for (std::int64_t j = 0; j < set.size(); ++j) {
          const Eigen::Vector3d q = Eigen::Vector3d(set.x[j], set.y[j], set.z[j]) + tt;
          const auto h = other.first_hit(cor, q.normalized());
          exact[pose][scan].push_back(h ? float(side * (*h - q.norm())) : std::numeric_limits<float>::quiet_NaN());
          dirs[pose][scan].push_back(q);
        }
      }
    }
    auto evaluate = [&](int pose, const std::vector<float>(&g)[2], const RadialDistanceMap* fm,
                        const RadialDistanceMap* pm, bool dump) {
      Errors e;
      std::vector<double> abs;
      for (int scan = 0; scan < 2; ++scan) {
        const RadialDistanceMap* other = scan == 0 ? pm : fm;
        for (std::size_t j = 0; j < g[scan].size(); ++j) {
          const float a = g[scan][j], b = exact[pose][scan][j];
          if (std::isnan(a) != std::isnan(b)) ++e.mismatched;
          if (std::isnan(a) || std::isnan(b)) continue;
          const double err = std::abs(double(a) - double(b));
          abs.push_back(err);
          const Eigen::Vector3d& q = dirs[pose][scan][j];
          double spread = std::nan("");
          if (other != nullptr) {
            const Stencil st = other->scheme().interpolate(q.normalized());
            double lo = 1e300, hi = -1e300;
            for (int k = 0; k < 4; ++k)
              if (st.weights[k] > 0)
                lo = std::min<double>(lo, other->at(st.nodes[k])), hi = std::max<double>(hi, other->at(st.nodes[k]));
            spread = hi - lo;
          }
          const SphericalCoordinates sc = to_spherical(q);
          if (dump)
            vcsv.row(s.name, scan == 0 ? "ball" : "socket", q.x(), q.y(), q.z(), sc.phi * kRadToDeg,
                     sc.theta * kRadToDeg, spread, err);
          if (err > 0.05) {
            ++e.large;
            e.discontinuity += spread > 2.0;
            e.pole += sc.phi * kRadToDeg < 2 || sc.phi * kRadToDeg > 178;
            const double th = sc.theta * kRadToDeg;
            e.seam += th < 1 || th > 359;
          }
        }
      }
      e.compared = static_cast<std::int64_t>(abs.size());
      if (!abs.empty()) {
        e.max = *std::max_element(abs.begin(), abs.end());
        e.p99 = quantile(abs, 0.99), e.p95 = quantile(abs, 0.95), e.median = quantile(abs, 0.5);
      }
      return e;
    };
    auto put = [&](const std::string& pose, const std::string& scheme, const std::string& mode, double res, double p,
                   const Errors& e, double ns, double sampling_ms, double bytes, double resample_p,
                   const char* storage = "dense") {
      csv.row(s.name, int(s.generated), pose, scheme, mode, res, p, nv, e.compared, e.mismatched, e.max, e.p99, e.p95,
              e.median, ns, sampling_ms, bytes, e.large, e.discontinuity, e.pole, e.seam, resample_p, storage);
    };

    for (double p : precisions) {
      progress("10_error_vs_runtime", ++done, total, s.name + " p=" + std::to_string(p));
      for (const auto& [name, resname] : schemes) {
        (void)resname;
        // Every scheme at the coarsest resolution whose largest node spacing is at most p.
        const double res = resolution_for_spacing(name, p);
        for (DistanceMode mode : {DistanceMode::exact, DistanceMode::linear}) {
          std::shared_ptr<const SamplingScheme> scheme;
          try {
            scheme = make_scheme(name, res);
          } catch (const Error&) {
            continue;  // a resolution this scheme does not take (e.g. conchoid needs 90/p integral)
          }
          RadialDistanceMap fm(scheme), pm(scheme);
          SamplingOptions o;
          o.mode = mode;
          // Schemes without a rasteriser: in exact mode, the exact first hit at every node through a
          // BVH (ray-cast-bvh), so that the comparison at equal error is of the schemes' interpolation,
          // not of a fill; in linear mode (the thesis' rasteriser approximation) resampled from an
          // equiangular map at half their matched precision, which adds a quarter of its error, not
          // all of it (issue 12); the thesis' own matched precision is experiment 02's.
          o.resample_oversampling = 2;
          if (mode == DistanceMode::exact && name != "equiangular" && FirstHitCaster::available())
            o.method = SamplingMethod::ray_cast_bvh;
          double resample_p = 0;
          const double ts = median_ms(
              [&] {
                std::fill(fm.data(), fm.data() + fm.num_nodes(), RadialDistanceMap::no_surface());
                std::fill(pm.data(), pm.data() + pm.num_nodes(), RadialDistanceMap::no_surface());
                resample_p = sample_surface(s.femur, cor, o, fm).resample_precision_deg;
                sample_surface(s.pelvis, cor, o, pm);
              },
              // a ray-cast fill of a fine map takes seconds: one timing is enough
              o.method == SamplingMethod::ray_cast_bvh && p <= 0.1 ? 1 : p < 0.1 ? std::min(reps, 3) : reps);
          for (int pose = 0; pose < 2; ++pose) {
            const Eigen::Vector3d t = pose == 0 ? Eigen::Vector3d::Zero() : push;
            std::vector<float> g[2] = {std::vector<float>(std::size_t(fset.size())),
                                       std::vector<float>(std::size_t(pset.size()))};
            const double tq = median_ms(
                [&] {
                  scan_gaps_compact(fset, I, t, pm, ScanSide::inside, g[0].data());
                  scan_gaps_compact(pset, I, Eigen::Vector3d(-t), fm, ScanSide::outside, g[1].data());
                },
                reps);
            const bool dump = pose == 0 && name == "equiangular" && mode == DistanceMode::exact && p == 0.1;
            const Errors e = evaluate(pose, g, &fm, &pm, dump);
            put(pose == 0 ? "rest" : "pushed_3mm", name, to_string(mode), res, p, e, tq * 1e6 / double(nv), ts,
                double(fm.bytes() + pm.bytes()), resample_p);
          }
          // Sparse storage (issue 12): the same maps with only the tiles that hold a surface; the gaps
          // are the dense maps' bit for bit (checked here), the bytes and the query time are not.
          if (mode == DistanceMode::exact) {
            RadialDistanceMap fms = fm, pms = pm;
            const double tsp = median_ms(
                [&] {
                  fms = fm, pms = pm;
                  fms.make_sparse();
                  pms.make_sparse();
                },
                p < 0.1 ? std::min(reps, 3) : reps);
            for (int pose = 0; pose < 2; ++pose) {
              const Eigen::Vector3d t = pose == 0 ? Eigen::Vector3d::Zero() : push;
              std::vector<float> g[2] = {std::vector<float>(std::size_t(fset.size())),
                                         std::vector<float>(std::size_t(pset.size()))};
              std::vector<float> d[2] = {g[0], g[1]};
              const double tq = median_ms(
                  [&] {
                    scan_gaps_compact(fset, I, t, pms, ScanSide::inside, g[0].data());
                    scan_gaps_compact(pset, I, Eigen::Vector3d(-t), fms, ScanSide::outside, g[1].data());
                  },
                  reps);
              scan_gaps_compact(fset, I, t, pm, ScanSide::inside, d[0].data());
              scan_gaps_compact(pset, I, Eigen::Vector3d(-t), fm, ScanSide::outside, d[1].data());
              for (int k = 0; k < 2; ++k)
                require(std::memcmp(g[k].data(), d[k].data(), g[k].size() * sizeof(float)) == 0,
                        "10_error_vs_runtime: " + s.name + " " + name + ": sparse gaps differ from dense");
              put(pose == 0 ? "rest" : "pushed_3mm", name, to_string(mode), res, p, evaluate(pose, g, &fms, &pms, false),
                  tq * 1e6 / double(nv), ts + tsp, double(fms.bytes() + pms.bytes()), resample_p, "sparse");
            }
          }
          // Exact look-ups at depth discontinuities (issue 15): the same maps with their marks, the
          // marked look-ups resolved by ray casts. Sampling time includes the marking.
          if (mode == DistanceMode::exact && casters) {
            RadialDistanceMap fmr = fm, pmr = pm;
            const double tm = median_ms(
                [&] {
                  mark_depth_discontinuities(fmr, kDiscontinuityToleranceMm);
                  mark_depth_discontinuities(pmr, kDiscontinuityToleranceMm);
                },
                p < 0.1 ? std::min(reps, 3) : reps);
            for (int pose = 0; pose < 2; ++pose) {
              const Eigen::Vector3d t = pose == 0 ? Eigen::Vector3d::Zero() : push;
              std::vector<float> g[2] = {std::vector<float>(std::size_t(fset.size())),
                                         std::vector<float>(std::size_t(pset.size()))};
              const double tq = median_ms(
                  [&] {
                    scan_gaps_compact(fset, I, t, pmr, ScanSide::inside, g[0].data(), &casters->second);
                    scan_gaps_compact(pset, I, Eigen::Vector3d(-t), fmr, ScanSide::outside, g[1].data(),
                                      &casters->first);
                  },
                  reps);
              put(pose == 0 ? "rest" : "pushed_3mm", name, "exact_refined", res, p,
                  evaluate(pose, g, &fmr, &pmr, false), tq * 1e6 / double(nv), ts + tm,
                  double(fmr.bytes() + pmr.bytes()), resample_p);
            }
          }
        }
      }
    }
    // Peers on the same vertices: Embree (float ray casting) and CGAL itself.
    for (int pose = 0; pose < 2; ++pose) {
      const Eigen::Vector3d t = pose == 0 ? Eigen::Vector3d::Zero() : push;
      const std::string pname = pose == 0 ? "rest" : "pushed_3mm";
      std::vector<float> g[2] = {std::vector<float>(std::size_t(fset.size())),
                                 std::vector<float>(std::size_t(pset.size()))};
      if (have_embree()) {
        const EmbreeRayCaster ef(s.femur, cor), ep(s.pelvis, cor);
        for (int packet = 0; packet < 2; ++packet) {
          const double tq = median_ms(
              [&] {
                scan_gaps_embree(ep, fset, I, t, ScanSide::inside, g[0].data(), packet);
                scan_gaps_embree(ef, pset, I, Eigen::Vector3d(-t), ScanSide::outside, g[1].data(), packet);
              },
              reps);
          put(pname, packet ? "embree_radial_packet8" : "embree_radial", "exact", 0, 0,
              evaluate(pose, g, nullptr, nullptr, false), tq * 1e6 / double(nv), std::nan(""), std::nan(""), 0);
        }
      }
      const double tq = median_ms(
          [&] {
            for (int scan = 0; scan < 2; ++scan) {
              const ScanSet& set = scan == 0 ? fset : pset;
              const ExactReference& other = scan == 0 ? ref_p : ref_f;
              const Eigen::Vector3d tt = scan == 0 ? t : Eigen::Vector3d(-t);
              for (std::int64_t j = 0; j < set.size(); ++j) {
                const Eigen::Vector3d q = Eigen::Vector3d(set.x[j], set.y[j], set.z[j]) + tt;
                const auto h = other.first_hit(cor, q.normalized());
                g[scan][std::size_t(j)] = h ? float((scan == 0 ? 1 : -1) * (*h - q.norm())) : std::nanf("");
              }
            }
          },
          std::max(1, reps / 2));
      put(pname, "cgal_radial", "exact", 0, 0, evaluate(pose, g, nullptr, nullptr, false), tq * 1e6 / double(nv),
          std::nan(""), std::nan(""), 0);
    }
  }
  write_meta(dir, args,
             {{"precisions_deg", precisions},
              {"region_radius_mm", kRegionMm},
              {"oracle", "CGAL AABB_tree::first_intersection on Simple_cartesian<double>"},
              {"resolutions", "every registered scheme at resolution_for_spacing(scheme, p)"},
              {"resample_oversampling", 2},
              {"exact_mode_fill", "rasterize (equiangular), ray-cast-bvh (every other scheme)"},
              {"large_error_mm", 0.05},
              {"embree", have_embree()}});
  return 0;
}
