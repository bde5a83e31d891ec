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
//     query_ns_per_vertex, query_ns_q25, query_ns_q75, timing_runs: both scans, median and quartiles over the
//       repetitions (timing_runs), per vertex (CGAL too: every repetition, no longer half);
//     sampling_ms: filling both maps (sample_surface, exact mode with face culling), median of the repetitions
//       after a warm-up at p >= 0.5 deg; one run without a warm-up at finer p (sampling_runs = 1: a fill, sparse
//       conversion or marking of seconds, whose spread is small beside the orders the figures read; issue 82
//       item 7 cut the 69 minutes the full run spent mostly on repeating these fills and markings);
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
//     sampling_runs: the runs sampling_ms is the median of (1: one run, see sampling_ms)
// Poses: rest (scan pose) and pushed_3mm (femur 3 mm into the acetabulum, as in 03).
// Cuts of the full run (issue 82 item 7; what each measures unchanged): the exact look-ups at depth
// discontinuities (exact_refined rows) at every resolution on the first subject only (the Pareto figures' and the
// every-configuration table's subject) and at 0.1 deg on every subject (the refined table's resolution); the generated
// hip, when real subjects are given, at 0.1 deg only (the peers' and the headline rows; no table or figure reads its
// sweep, which repeated the real hips' trend).
// --quick: p = 2, 1, 0.5 deg on the first subject, 0.5 deg alone on the others (CI's budget, issue 82 item 7).
// Command: build/experiments/exp_10_error_vs_runtime --out results --data ../shared/data/hips [--quick]
// Resolutions: largest node spacings p = 2, 1, 0.5 (quick: only these), 0.35, 0.25, 0.16, 0.1, 0.05 deg; every registered
// scheme at the coarsest resolution that reaches p (resolution_for_spacing, issue 12), so a new
// scheme joins with no change here.
#include <algorithm>
#include <cstring>
#include <functional>
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
// The library's default tolerance (JointOptions, its one place).
double discontinuity_tolerance_mm() {
  static const double t = JointOptions{}.discontinuity_tolerance_mm;
  return t;
}

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

// The experiment's two tables.
struct Outputs {
  explicit Outputs(const std::string& dir)
      : csv(dir + "/error_runtime.csv",
            {"subject",     "generated",     "pose",         "scheme",           "mode",
             "resolution",  "precision_deg", "vertices",     "compared",         "mismatched",
             "max_abs_mm",  "p99_abs_mm",    "p95_abs_mm",   "median_abs_mm",    "query_ns_per_vertex", "query_ns_q25",
             "query_ns_q75", "timing_runs",
             "sampling_ms", "bytes",         "large_errors", "at_discontinuity", "near_pole",
             "near_seam",   "resample_precision_deg", "storage", "sampling_runs"}),
        vcsv(dir + "/vertex_errors.csv",
             {"subject", "scan", "x_mm", "y_mm", "z_mm", "phi_deg", "theta_deg", "stencil_spread_mm", "error_mm"}) {}
  CsvWriter csv, vcsv;
};

// One subject: its COR, the pushed pose, the exact references, the compared vertices of both scans
// and the oracle's gaps at both poses.
struct SubjectData {
  explicit SubjectData(const Subject& subject)
      : s(subject), cor(subject_cor(s)), push(3.0 * push_direction(s.pelvis, cor, kRegionMm)), ref_f(s.femur),
        ref_p(s.pelvis), fset(exact_scan_set(s.femur, ref_f, cor)), pset(exact_scan_set(s.pelvis, ref_p, cor)),
        nv(fset.size() + pset.size()) {
    if (FirstHitCaster::available()) casters.emplace(FirstHitCaster(s.femur, cor), FirstHitCaster(s.pelvis, cor));
    // The oracle per pose: exact radial gaps of both scans.
    for (int pose = 0; pose < 2; ++pose)
      for (int scan = 0; scan < 2; ++scan) {
        const ScanSet& set = scan == 0 ? fset : pset;
        const ExactReference& other = scan == 0 ? ref_p : ref_f;
        const Eigen::Vector3d tt = scan == 0 ? translation(pose) : Eigen::Vector3d(-translation(pose));
        const double side = scan == 0 ? 1 : -1;
        for (std::int64_t j = 0; j < set.size(); ++j) {
          const Eigen::Vector3d q = Eigen::Vector3d(set.x[j], set.y[j], set.z[j]) + tt;
          const auto h = other.first_hit(cor, q.normalized());
          exact[pose][scan].push_back(h ? float(side * (*h - q.norm())) : std::numeric_limits<float>::quiet_NaN());
          dirs[pose][scan].push_back(q);
        }
      }
  }
  Eigen::Vector3d translation(int pose) const { return pose == 0 ? Eigen::Vector3d::Zero() : push; }
  static const char* pose_name(int pose) { return pose == 0 ? "rest" : "pushed_3mm"; }
  // Gaps of both scans (ball against the pelvis map, pelvis against the femur map) at `pose`, and the
  // median and quartiles of `reps` scans' times (ms).
  using Scan = std::function<void(const Eigen::Vector3d& t, std::vector<float> (&g)[2])>;
  Timing scan(int pose, const Scan& fn, std::vector<float> (&g)[2], int reps) const {
    g[0].assign(std::size_t(fset.size()), 0.f);
    g[1].assign(std::size_t(pset.size()), 0.f);
    return summarize(run_alternated({[&] { fn(translation(pose), g); }}, reps)[0]);
  }

  const Subject& s;
  const Eigen::Vector3d cor, push;
  const ExactReference ref_f, ref_p;
  std::optional<std::pair<FirstHitCaster, FirstHitCaster>> casters;
  const ScanSet fset, pset;
  const std::int64_t nv;
  std::vector<float> exact[2][2];
  std::vector<Eigen::Vector3d> dirs[2][2];  // q in the other map's frame
};

// Errors of gaps `g` (both scans) against the oracle at `pose`; the maps' stencil spreads classify
// the large ones (nullptr for peers without maps). `dump`: each vertex's error into vertex_errors.csv.
Errors evaluate(const SubjectData& d, int pose, const std::vector<float> (&g)[2], const RadialDistanceMap* fm,
                const RadialDistanceMap* pm, CsvWriter* dump) {
  Errors e;
  std::vector<double> abs;
  for (int scan = 0; scan < 2; ++scan) {
    const RadialDistanceMap* other = scan == 0 ? pm : fm;
    for (std::size_t j = 0; j < g[scan].size(); ++j) {
      const float a = g[scan][j], b = d.exact[pose][scan][j];
      if (std::isnan(a) != std::isnan(b)) ++e.mismatched;
      if (std::isnan(a) || std::isnan(b)) continue;
      const double err = std::abs(double(a) - double(b));
      abs.push_back(err);
      const Eigen::Vector3d& q = d.dirs[pose][scan][j];
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
      if (dump != nullptr)
        dump->row(d.s.name, scan == 0 ? "ball" : "socket", q.x(), q.y(), q.z(), sc.phi * kRadToDeg,
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
}

// One row of error_runtime.csv.
struct Row {
  std::string scheme, mode;
  double resolution = 0, precision = 0, ns = 0, sampling_ms = 0, bytes = 0, resample_p = 0;
  const char* storage = "dense";
  double ns_q25 = std::nan(""), ns_q75 = std::nan("");  // the query time's quartiles, per vertex
  int runs = 0;
  int sampling_runs = 0;  // the runs sampling_ms is the median of
  // The query time per vertex (ns) of a scan's Timing (ms for all vertices).
  void query(const Timing& t, double per_vertex) {
    ns = t.median_ms * per_vertex, ns_q25 = t.q25_ms * per_vertex, ns_q75 = t.q75_ms * per_vertex, runs = t.runs;
  }
};
void put(Outputs& out, const SubjectData& d, int pose, const Row& r, const Errors& e) {
  out.csv.row(d.s.name, int(d.s.generated), SubjectData::pose_name(pose), r.scheme, r.mode, r.resolution, r.precision,
              d.nv, e.compared, e.mismatched, e.max, e.p99, e.p95, e.median, r.ns, r.ns_q25, r.ns_q75, r.runs,
              r.sampling_ms, r.bytes, e.large,
              e.discontinuity, e.pole, e.seam, r.resample_p, r.storage, r.sampling_runs);
}

// The runs a fill, sparse conversion or marking at node spacing p (deg) is timed over: the repetitions (after a
// warm-up) at p >= 0.5 deg, one run (no warm-up) at finer p, where each takes from a second to tens of seconds.
int build_runs(double p, int reps) { return p < 0.5 ? 1 : reps; }

// Median wall time (ms) of `fn` over build_runs(p, reps) runs; one run is timed alone, without a warm-up.
double build_ms(const std::function<void()>& fn, double p, int reps) {
  const int runs = build_runs(p, reps);
  if (runs > 1) return median_ms(fn, runs);
  const auto t0 = std::chrono::steady_clock::now();
  fn();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// Both maps of one scheme, resolution and mode, filled and timed.
struct Maps {
  RadialDistanceMap fm, pm;
  double sampling_ms = 0, resample_p = 0;
};
Maps fill_maps(const SubjectData& d, const std::shared_ptr<const SamplingScheme>& scheme, DistanceMode mode,
               double p, int reps) {
  Maps m{RadialDistanceMap(scheme), RadialDistanceMap(scheme), 0, 0};
  SamplingOptions o;
  o.mode = mode;
  // Schemes without a rasteriser: in exact mode, the exact first hit at every node through a BVH
  // (ray-cast-bvh), so that the comparison at equal error is of the schemes' interpolation, not of a
  // fill; in linear mode (the thesis' rasteriser approximation) resampled from an equiangular map at
  // half their matched precision, which adds a quarter of its error, not all of it (issue 12); the
  // thesis' own matched precision is experiment 02's.
  o.resample_oversampling = 2;
  if (mode == DistanceMode::exact && scheme->name() != "equiangular" && FirstHitCaster::available())
    o.method = SamplingMethod::ray_cast_bvh;
  m.sampling_ms = build_ms(
      [&] {
        std::fill(m.fm.data(), m.fm.data() + m.fm.num_nodes(), RadialDistanceMap::no_surface());
        std::fill(m.pm.data(), m.pm.data() + m.pm.num_nodes(), RadialDistanceMap::no_surface());
        m.resample_p = sample_surface(d.s.femur, d.cor, o, m.fm).resample_precision_deg;
        sample_surface(d.s.pelvis, d.cor, o, m.pm);
      },
      p, reps);
  return m;
}

// The maps' look-ups at both poses: dense, then (exact mode) sparse storage (issue 12; the gaps must
// be the dense maps' bit for bit) and exact look-ups at depth discontinuities (issue 15; sampling time
// includes the marking; `refine` false leaves them out).
void measure_maps(const SubjectData& d, const Maps& m, Row row, DistanceMode mode, int reps, bool refine,
                  Outputs& out) {
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const double per_vertex = 1e6 / double(d.nv);
  std::vector<float> g[2];
  auto lookups = [&](const RadialDistanceMap& fm, const RadialDistanceMap& pm, const FirstHitCaster* cf,
                     const FirstHitCaster* cp) {
    return [&d, &I, f = &fm, p = &pm, cf, cp](const Eigen::Vector3d& t, std::vector<float> (&gg)[2]) {
      scan_gaps_compact(d.fset, I, t, *p, ScanSide::inside, gg[0].data(), cp);
      scan_gaps_compact(d.pset, I, Eigen::Vector3d(-t), *f, ScanSide::outside, gg[1].data(), cf);
    };
  };
  for (int pose = 0; pose < 2; ++pose) {
    row.query(d.scan(pose, lookups(m.fm, m.pm, nullptr, nullptr), g, reps), per_vertex);
    const bool dump = pose == 0 && row.scheme == "equiangular" && mode == DistanceMode::exact && row.precision == 0.1;
    put(out, d, pose, row, evaluate(d, pose, g, &m.fm, &m.pm, dump ? &out.vcsv : nullptr));
  }
  if (mode != DistanceMode::exact) return;
  RadialDistanceMap fms = m.fm, pms = m.pm;
  const double tsp = build_ms(
      [&] {
        fms = m.fm, pms = m.pm;
        fms.make_sparse();
        pms.make_sparse();
      },
      row.precision, reps);
  Row sparse = row;
  sparse.sampling_ms += tsp, sparse.bytes = double(fms.bytes() + pms.bytes()), sparse.storage = "sparse";
  for (int pose = 0; pose < 2; ++pose) {
    sparse.query(d.scan(pose, lookups(fms, pms, nullptr, nullptr), g, reps), per_vertex);
    std::vector<float> dense[2];
    d.scan(pose, lookups(m.fm, m.pm, nullptr, nullptr), dense, 1);
    for (int k = 0; k < 2; ++k)
      require(std::memcmp(g[k].data(), dense[k].data(), g[k].size() * sizeof(float)) == 0,
              "10_error_vs_runtime: " + d.s.name + " " + row.scheme + ": sparse gaps differ from dense");
    put(out, d, pose, sparse, evaluate(d, pose, g, &fms, &pms, nullptr));
  }
  if (!d.casters || !refine) return;
  RadialDistanceMap fmr = m.fm, pmr = m.pm;
  const double tm = build_ms(
      [&] {
        mark_depth_discontinuities(fmr, discontinuity_tolerance_mm());
        mark_depth_discontinuities(pmr, discontinuity_tolerance_mm());
      },
      row.precision, reps);
  Row refined = row;
  refined.mode = "exact_refined", refined.sampling_ms += tm, refined.bytes = double(fmr.bytes() + pmr.bytes());
  for (int pose = 0; pose < 2; ++pose) {
    refined.query(d.scan(pose, lookups(fmr, pmr, &d.casters->first, &d.casters->second), g, reps), per_vertex);
    put(out, d, pose, refined, evaluate(d, pose, g, &fmr, &pmr, nullptr));
  }
}

// Every registered scheme at the coarsest resolution whose largest node spacing is at most p, both modes (the exact
// look-ups at discontinuities too when `refine`).
void measure_schemes(const SubjectData& d, double p, int reps, bool refine, Outputs& out) {
  for (const auto& [name, resname] : scheme_names()) {
    (void)resname;
    const double res = resolution_for_spacing(name, p);
    for (DistanceMode mode : {DistanceMode::exact, DistanceMode::linear}) {
      std::shared_ptr<const SamplingScheme> scheme;
      try {
        scheme = make_scheme(name, res);
      } catch (const Error&) {
        continue;  // a resolution this scheme does not take (e.g. conchoid needs 90/p integral)
      }
      const Maps m = fill_maps(d, scheme, mode, p, reps);
      Row row{name, to_string(mode), res, p, 0, m.sampling_ms, double(m.fm.bytes() + m.pm.bytes()), m.resample_p};
      row.sampling_runs = build_runs(p, reps);
      measure_maps(d, m, row, mode, reps, refine, out);
    }
  }
}

// Peers on the same vertices: Embree (float ray casting, single rays and packets of 8) and CGAL itself.
void measure_peers(const SubjectData& d, int reps, Outputs& out) {
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const double per_vertex = 1e6 / double(d.nv);
  std::vector<float> g[2];
  const double nan = std::nan("");
  for (int pose = 0; pose < 2; ++pose) {
    if (have_embree()) {
      const EmbreeRayCaster ef(d.s.femur, d.cor), ep(d.s.pelvis, d.cor);
      for (int packet = 0; packet < 2; ++packet) {
        const Timing tq = d.scan(
            pose,
            [&](const Eigen::Vector3d& t, std::vector<float> (&gg)[2]) {
              scan_gaps_embree(ep, d.fset, I, t, ScanSide::inside, gg[0].data(), packet);
              scan_gaps_embree(ef, d.pset, I, Eigen::Vector3d(-t), ScanSide::outside, gg[1].data(), packet);
            },
            g, reps);
        Row peer{packet ? "embree_radial_packet8" : "embree_radial", "exact", 0, 0, 0, nan, nan, 0};
        peer.query(tq, per_vertex);
        put(out, d, pose, peer, evaluate(d, pose, g, nullptr, nullptr, nullptr));
      }
    }
    const Timing tq = d.scan(
        pose,
        [&](const Eigen::Vector3d& t, std::vector<float> (&gg)[2]) {
          for (int scan = 0; scan < 2; ++scan) {
            const ScanSet& set = scan == 0 ? d.fset : d.pset;
            const ExactReference& other = scan == 0 ? d.ref_p : d.ref_f;
            const Eigen::Vector3d tt = scan == 0 ? t : Eigen::Vector3d(-t);
            for (std::int64_t j = 0; j < set.size(); ++j) {
              const Eigen::Vector3d q = Eigen::Vector3d(set.x[j], set.y[j], set.z[j]) + tt;
              const auto h = other.first_hit(d.cor, q.normalized());
              gg[scan][std::size_t(j)] = h ? float((scan == 0 ? 1 : -1) * (*h - q.norm())) : std::nanf("");
            }
          }
        },
        g, reps);
    Row cgal{"cgal_radial", "exact", 0, 0, 0, nan, nan, 0};
    cgal.query(tq, per_vertex);
    put(out, d, pose, cgal, evaluate(d, pose, g, nullptr, nullptr, nullptr));
  }
}
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
  const std::vector<double> precisions = args.quick ? std::vector<double>{2, 1, 0.5}
                                                    : std::vector<double>{2, 1, 0.5, 0.35, 0.25, 0.16, 0.1, 0.05};
  // The finest resolution every subject's refined rows and the generated hip's (beside real ones) are measured at.
  const double head_p = args.quick ? precisions.back() : 0.1;
  const bool real = !subjects.empty() && !subjects.front().generated;
  Outputs out(dir);
  int done = 0;
  const int total = static_cast<int>(subjects.size() * precisions.size());
  for (std::size_t k = 0; k < subjects.size(); ++k) {
    const Subject& s = subjects[k];
    const SubjectData d(s);
    for (double p : precisions) {
      progress("10_error_vs_runtime", ++done, total, s.name + " p=" + std::to_string(p));
      // The generated hip beside real ones, and (quick) every subject but the first: the finest resolution alone.
      if (((s.generated && real) || (args.quick && k > 0)) && p != head_p) continue;
      measure_schemes(d, p, args.repetitions, k == 0 || p == head_p, out);
    }
    measure_peers(d, args.repetitions, out);
  }
  write_meta(dir, args,
             {{"precisions_deg", precisions},
              {"region_radius_mm", kRegionMm},
              {"oracle", "CGAL AABB_tree::first_intersection on Simple_cartesian<double>"},
              {"resolutions", "every registered scheme at resolution_for_spacing(scheme, p)"},
              {"resample_oversampling", 2},
              {"build_timing", "fills, sparse conversions and markings: median of the repetitions after a warm-up at "
                               "p >= 0.5 deg, one run without a warm-up at finer p (sampling_runs)"},
              {"refined", "exact look-ups at discontinuities: every resolution on the first subject, 0.1 deg on every "
                          "subject (quick: the finest)"},
              {"generated_beside_real", "0.1 deg only (quick: the finest)"},
              {"exact_mode_fill", "rasterize (equiangular), ray-cast-bvh (every other scheme)"},
              {"large_error_mm", 0.05},
              {"embree", have_embree()}});
  return 0;
}
