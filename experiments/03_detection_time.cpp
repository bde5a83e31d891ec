// 03_detection_time -- thesis Tables 4 and 9: time of one pose's detection (both scans), by
// method, on the generated models at the thesis' triangle levels and on every real subject.
//
// Inputs: generated hips of 300, 1k, 3k and 12k triangles per model, every subject under --data.
// Outputs: OUT/03_detection_time/
//   detection.csv   one row per subject x pose x method:
//     pose: rest (the scan pose) or pushed_3mm (the femur translated 3 mm from the COR towards
//           the centroid of the pelvis vertices within 45 mm: into the acetabulum)
//     method: rsid (equiangular map, exact mode, fast scan), usid (helix at the matched turns),
//             every other registered scheme by its name (at resolution_for_spacing of each precision),
//             embree_radial (rtcIntersect1 per vertex), embree_radial_packet8 (rtcIntersect8),
//             cgal_radial (CGAL AABB tree first intersection per vertex: the exact reference),
//             fcl_collide (FCL OBBRSS trees, every contact), fcl_first_contact (the same, stopping at the first
//             intersecting pair), fcl_distance (FCL minimum distance),
//             pairwise (the thesis' exhaustive triangle-pair test over the hip-region triangles)
//     vertices: the scanned vertices of both bodies (first surface, within 45 mm of the COR);
//     time_ms, time_q25_ms, time_q75_ms, runs: median and quartiles of both scans (or the whole query) of one pose
//       over `runs` rounds, every method of a pose timed alternately (one run of each per round; pair-wise: once);
//       ball_ms, socket_ms: per scan (medians);
//     ns_per_vertex = time / vertices; result: min gap (mm) for the radial methods, contacts,
//     distance (mm) or intersecting pairs for the others; thesis_ms: Table 4 / 9; spacing_deg: the
//     equiangular precision a scheme's resolution is matched to (empty for the peers)
//   detection_runs.csv  every round's time of every method (subject, pose, method, resolution, round, time_ms):
//                   ratios paired round by round
//   throughput.csv  poses per second for every scheme's maps over 256 random poses (rotations up to
//                   20 deg about the COR), with 1 and 2 threads (each thread its own poses), alternated; the
//                   median and quartiles of the 256 poses' time
//   meta.json
// Command: build/experiments/exp_03_detection_time --out results --data ../shared/data/hips [--quick]
// Quick mode: fewer repetitions; the pairwise test only where it has <= 20 million pairs; the registered schemes
// beyond the thesis' pair (RSID, USID) on the first subject alone (CI's budget, issue 82 item 7: their maps at
// 0.1 deg, timed at both poses and over the random poses, were most of the quick run's time).
#include <memory>
#include <random>
#include <thread>

#include "experiment_support.hpp"
#include "impinge/casters/embree_ray_caster.hpp"
#include "impinge/casters/exact_reference.hpp"
#include "impinge/casters/fcl_collision.hpp"
#include "impinge/casters/pairwise.hpp"
#include "impinge/core/error.hpp"
#include "impinge/detection/detection.hpp"
#include "impinge/sampling/raster_plan.hpp"
#include "impinge/sampling/sampling.hpp"
#include "impinge/schemes/helix_scheme.hpp"

using namespace impinge;
using namespace impinge::experiment;

namespace {
constexpr double kRegionMm = 45;

/// Thesis Tables 4 and 9 by triangle level (the 12k row was a real CT model), ms.
double thesis_ms(const std::string& subject, const std::string& method) {
  const double nan = std::nan("");
  const int i = subject == "generated-300"   ? 0
                : subject == "generated-1k"  ? 1
                : subject == "generated-3k"  ? 2
                : subject == "generated-12k" ? 3
                                             : -1;
  if (i < 0) return nan;
  const double pairwise[] = {30.7, 522, 2831, nan}, rapid[] = {1.41, 1.41, 1.43, 1.5}, rsid[] = {0.06, 0.18, 0.48, 5.7},
               usid[] = {0.07, 0.65, 1.8, 12};
  if (method == "pairwise") return pairwise[i];
  if (method == "fcl_collide") return rapid[i];
  if (method == "rsid") return rsid[i];
  if (method == "usid") return usid[i];
  return nan;
}

struct Body {
  RadialDistanceMap map;
  ScanSet set;
};

/// A body's map (exact mode, culled) and its hip-region scan set.
Body build(const TriangleMesh& mesh, const Eigen::Vector3d& cor, const std::shared_ptr<const SamplingScheme>& scheme) {
  Body b{RadialDistanceMap(scheme), {}};
  sample_surface(mesh, cor, SamplingOptions{}, b.map);
  const Vertices rel = mesh.V.rowwise() - cor.transpose();
  b.set = make_scan_set(rel, first_surface_mask(rel, b.map, 1.0, kRegionMm));
  return b;
}

double min_of(const std::vector<float>& a, const std::vector<float>& b) {
  double m = std::numeric_limits<double>::infinity();
  for (float g : a)
    if (std::isfinite(g)) m = std::min<double>(m, g);
  for (float g : b)
    if (std::isfinite(g)) m = std::min<double>(m, g);
  return m;
}
// Maps: equiangular at each precision (RSID), the helix at the matched turns (USID), and every other
// registered scheme at the coarsest resolution whose node spacing is at most p (issue 12: a new scheme
// is timed here without touching this driver; method = its name).
struct Scheme {
  std::string method;
  double res;
  std::shared_ptr<const SamplingScheme> scheme;
  double spacing;  ///< the equiangular precision (deg) it is matched to
};
std::vector<Scheme> schemes_at(const std::vector<double>& precisions) {
  std::vector<Scheme> schemes;
  for (double p : precisions) {
    schemes.push_back({"rsid", p, make_scheme("equiangular", p), p});
    schemes.push_back({"usid", matched_helix_turns(p), make_scheme("helix", matched_helix_turns(p)), p});
  }
  for (const auto& [name, unit] : scheme_names()) {
    (void)unit;
    if (name == "equiangular" || name == "helix") continue;  // above, as the thesis' RSID and USID
    for (double p : precisions) {
      try {
        const double r = resolution_for_spacing(name, p);
        schemes.push_back({name, r, make_scheme(name, r), p});
      } catch (const Error&) {
        // a resolution this scheme does not take at this spacing (e.g. conchoid needs 90/p integral)
      }
    }
  }
  return schemes;
}

// The peers available in this build, on one subject.
struct Peers {
  Peers(const Subject& s, const Eigen::Vector3d& cor) {
    if (have_embree())
      emb_f = std::make_unique<EmbreeRayCaster>(s.femur, cor), emb_p = std::make_unique<EmbreeRayCaster>(s.pelvis, cor);
    if (have_exact_reference())
      cg_f = std::make_unique<ExactReference>(s.femur), cg_p = std::make_unique<ExactReference>(s.pelvis);
    if (have_fcl()) fcl = std::make_unique<FclJoint>(s.femur, s.pelvis, cor);
    if (have_exact_reference()) pairwise = std::make_unique<PairwiseJoint>(s.femur, s.pelvis, cor, kRegionMm);
  }
  std::unique_ptr<EmbreeRayCaster> emb_f, emb_p;
  std::unique_ptr<ExactReference> cg_f, cg_p;
  std::unique_ptr<FclJoint> fcl;
  std::unique_ptr<PairwiseJoint> pairwise;
};

// One subject: its COR, the push, its maps per scheme and the peers' vertex sets.
struct SubjectRun {
  SubjectRun(const Subject& subject, const std::vector<Scheme>& sc)
      : s(subject), cor(subject_cor(s)), push(3.0 * push_direction(s.pelvis, cor, kRegionMm)), schemes(sc),
        peers(s, cor) {
    for (const Scheme& k : schemes) built.emplace_back(build(s.femur, cor, k.scheme), build(s.pelvis, cor, k.scheme));
  }
  // The peers' vertex sets: the first-surface hip-region vertices of the finest equiangular map.
  const ScanSet& fset() const { return built[2].first.set; }
  const ScanSet& pset() const { return built[2].second.set; }
  const Subject& s;
  const Eigen::Vector3d cor, push;
  const std::vector<Scheme>& schemes;
  std::vector<std::pair<Body, Body>> built;
  Peers peers;
};

// One row of detection.csv: `t` the spread of the pose's time (both scans), ball_ms and socket_ms their medians.
void row(CsvWriter& csv, const SubjectRun& r, const std::string& pose, const std::string& method, double res,
         std::int64_t vertices, const Timing& t, double ball_ms, double socket_ms, double result,
         const std::string& kind, double spacing = std::nan("")) {
  const Subject& s = r.s;
  const double ms = t.median_ms;
  csv.row(s.name, int(s.generated), static_cast<std::int64_t>(s.femur.F.rows()),
          static_cast<std::int64_t>(s.pelvis.F.rows()), pose, method, res, vertices, ms, t.q25_ms, t.q75_ms, t.runs,
          ball_ms, socket_ms, vertices > 0 ? ms * 1e6 / double(vertices) : std::nan(""), result, kind,
          thesis_ms(s.name, method), spacing);
}

// Every method at one pose, timed alternately (run_alternated: one warm-up each, then `reps` rounds in which each
// runs once), so that their ratios are paired round by round: both scans of every scheme's maps (ball against the
// pelvis map, pelvis against the femur map), Embree (single rays, packets of 8) and CGAL radial scans on the same
// vertices, FCL collide and distance. The raw rounds go to detection_runs.csv. Pair-wise triangle intersection
// (seconds) runs once, apart.
void time_pose(const SubjectRun& r, const std::string& pname, const Eigen::Vector3d& t, int reps, bool quick,
               CsvWriter& csv, CsvWriter& runs_csv) {
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const ScanSet &fset = r.fset(), &pset = r.pset();
  const std::int64_t nv = fset.size() + pset.size();
  const Peers& P = r.peers;
  const double nan = std::nan("");
  struct Job {
    std::string method;
    double res, spacing;
    std::int64_t vertices;
    std::vector<std::size_t> fns;  // indices into `fns`: the ball's and the socket's scan, or one call
    std::function<double()> result;
    std::string kind;
  };
  std::vector<std::function<void()>> fns;
  std::vector<Job> jobs;
  // Every job's outputs live as long as the timing (the lambdas write into them).
  std::vector<std::unique_ptr<std::vector<float>>> outs;
  auto buffer = [&](std::int64_t n) {
    outs.push_back(std::make_unique<std::vector<float>>(std::size_t(n)));
    return outs.back().get();
  };
  for (std::size_t k = 0; k < r.schemes.size(); ++k) {
    const Body &fb = r.built[k].first, &pb = r.built[k].second;
    std::vector<float>* g1 = buffer(fb.set.size());
    std::vector<float>* g2 = buffer(pb.set.size());
    fns.push_back([&fb, &pb, &I, t, g1] { scan_gaps_compact(fb.set, I, t, pb.map, ScanSide::inside, g1->data()); });
    fns.push_back([&fb, &pb, &I, t, g2] {
      scan_gaps_compact(pb.set, I, Eigen::Vector3d(-t), fb.map, ScanSide::outside, g2->data());
    });
    jobs.push_back({r.schemes[k].method, r.schemes[k].res, r.schemes[k].spacing, fb.set.size() + pb.set.size(),
                    {fns.size() - 2, fns.size() - 1}, [g1, g2] { return min_of(*g1, *g2); }, "min_gap_mm"});
  }
  if (P.emb_f)
    for (int packet = 0; packet < 2; ++packet) {
      std::vector<float>* g1 = buffer(fset.size());
      std::vector<float>* g2 = buffer(pset.size());
      fns.push_back([&, g1, packet] { scan_gaps_embree(*P.emb_p, fset, I, t, ScanSide::inside, g1->data(), packet); });
      fns.push_back([&, g2, packet] {
        scan_gaps_embree(*P.emb_f, pset, I, Eigen::Vector3d(-t), ScanSide::outside, g2->data(), packet);
      });
      jobs.push_back({packet ? "embree_radial_packet8" : "embree_radial", 0, nan, nv, {fns.size() - 2, fns.size() - 1},
                      [g1, g2] { return min_of(*g1, *g2); }, "min_gap_mm"});
    }
  if (P.cg_f) {
    auto cgal_scan = [&r](const ScanSet& set, const ExactReference& other, const Eigen::Vector3d& tt, double side,
                          std::vector<float>& out) {
      for (std::int64_t j = 0; j < set.size(); ++j) {
        const Eigen::Vector3d q = Eigen::Vector3d(set.x[j], set.y[j], set.z[j]) + tt;
        const auto h = other.first_hit(r.cor, q.normalized());
        out[std::size_t(j)] = h ? float(side * (*h - q.norm())) : std::numeric_limits<float>::quiet_NaN();
      }
    };
    std::vector<float>* g1 = buffer(fset.size());
    std::vector<float>* g2 = buffer(pset.size());
    fns.push_back([&, g1, cgal_scan] { cgal_scan(fset, *P.cg_p, t, 1, *g1); });
    fns.push_back([&, g2, cgal_scan] { cgal_scan(pset, *P.cg_f, Eigen::Vector3d(-t), -1, *g2); });
    jobs.push_back({"cgal_radial", 0, nan, nv, {fns.size() - 2, fns.size() - 1},
                    [g1, g2] { return min_of(*g1, *g2); }, "min_gap_mm"});
  }
  auto contacts = std::make_shared<FclContacts>();
  auto distance = std::make_shared<double>(0);
  if (P.fcl) {
    fns.push_back([&, contacts] { *contacts = P.fcl->collide(I, t); });
    jobs.push_back({"fcl_collide", 0, nan, 0, {fns.size() - 1}, [contacts] { return double(contacts->contacts); },
                    "contacts"});
    // RAPID's RAPID_FIRST_CONTACT mode, the sensitivity check a referee asks for (issue 51): the query stops at the
    // first intersecting triangle pair, which is all a yes/no impingement test needs.
    auto first = std::make_shared<FclContacts>();
    fns.push_back([&, first] { *first = P.fcl->collide(I, t, 1); });
    jobs.push_back({"fcl_first_contact", 0, nan, 0, {fns.size() - 1}, [first] { return double(first->contacts); },
                    "contacts"});
    fns.push_back([&, distance] { *distance = P.fcl->distance(I, t); });
    jobs.push_back({"fcl_distance", 0, nan, 0, {fns.size() - 1}, [distance] { return *distance; }, "distance_mm"});
  }
  const std::vector<std::vector<double>> runs = run_alternated(fns, reps);
  for (const Job& j : jobs) {
    const std::vector<double> total = round_sums(runs, j.fns);
    const bool two = j.fns.size() == 2;
    row(csv, r, pname, j.method, j.res, j.vertices, summarize(total),
        two ? summarize(runs[j.fns[0]]).median_ms : nan, two ? summarize(runs[j.fns[1]]).median_ms : nan,
        j.result(), j.kind, j.spacing);
    for (std::size_t k = 0; k < total.size(); ++k) runs_csv.row(r.s.name, pname, j.method, j.res, int(k), total[k]);
  }
  if (P.pairwise &&
      (!quick || double(P.pairwise->ball_triangles()) * double(P.pairwise->socket_triangles()) <= 2e7)) {
    PairwiseResult pr;
    const Timing tp = summarize(run_alternated({[&] { pr = P.pairwise->intersect(I, t); }}, 1)[0]);
    row(csv, r, pname, "pairwise", 0, 0, tp, nan, nan, double(pr.intersecting_pairs), "intersecting_pairs");
  }
}

// Throughput: 256 random poses, one thread against two (each thread its own half).
void throughput(const SubjectRun& r, int reps, CsvWriter& thr) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> ang(-20, 20);
  std::vector<Eigen::Matrix3d> poses;
  for (int i = 0; i < 256; ++i) poses.push_back(pose_rotation({ang(rng), ang(rng), ang(rng)}, r.s.side));
  for (std::size_t k = 0; k < r.schemes.size(); ++k) {
    const Body &fb = r.built[k].first, &pb = r.built[k].second;
    auto run = [&](std::size_t lo, std::size_t hi) {
      std::vector<float> a(std::size_t(fb.set.size())), b(std::size_t(pb.set.size()));
      for (std::size_t i = lo; i < hi; ++i) {
        scan_gaps_compact(fb.set, poses[i], Eigen::Vector3d::Zero(), pb.map, ScanSide::inside, a.data());
        scan_gaps_compact(pb.set, Eigen::Matrix3d(poses[i].transpose()), Eigen::Vector3d::Zero(), fb.map,
                          ScanSide::outside, b.data());
      }
    };
    // One thread and two, alternated (run_alternated), so that their ratio is paired round by round.
    const std::vector<std::vector<double>> runs = run_alternated(
        {[&] { run(0, poses.size()); },
         [&] {
           std::thread other([&] { run(poses.size() / 2, poses.size()); });
           run(0, poses.size() / 2);
           other.join();
         }},
        reps);
    for (int threads : {1, 2}) {
      const Timing tt = summarize(runs[std::size_t(threads - 1)]);
      thr.row(r.s.name, r.schemes[k].method, r.schemes[k].res, threads, static_cast<int>(poses.size()), tt.median_ms,
              tt.q25_ms, tt.q75_ms, tt.runs, 1000.0 * double(poses.size()) / tt.median_ms, r.schemes[k].spacing);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  const Args args = parse_args(argc, argv, "03_detection_time: thesis Tables 4 and 9, detection time by method");
  const std::string dir = experiment_dir(args, "03_detection_time");
  const std::vector<Subject> subjects = load_subjects(args, {300, 1000, 3000, 12000});
  const int reps = args.repetitions;
  const double kPrecision = 0.5;  // RSID / USID maps of the detection table (the thesis does not say)
  const std::vector<double> precisions{0.5, 0.1};
  const std::vector<Scheme> schemes = schemes_at(precisions);
  // schemes_at puts the thesis' pair at each precision first.
  const std::vector<Scheme> thesis_pair(schemes.begin(), schemes.begin() + 2 * std::ptrdiff_t(precisions.size()));

  CsvWriter csv(dir + "/detection.csv",
                {"subject", "generated", "femur_triangles", "pelvis_triangles", "pose", "method", "resolution",
                 "vertices", "time_ms", "time_q25_ms", "time_q75_ms", "runs", "ball_ms", "socket_ms", "ns_per_vertex",
                 "result", "result_kind", "thesis_ms", "spacing_deg"});
  CsvWriter runs_csv(dir + "/detection_runs.csv", {"subject", "pose", "method", "resolution", "round", "time_ms"});
  CsvWriter thr(dir + "/throughput.csv", {"subject", "method", "resolution", "threads", "poses", "time_ms",
                                          "time_q25_ms", "time_q75_ms", "runs", "poses_per_s", "spacing_deg"});
  int done = 0;
  for (const Subject& s : subjects) {
    progress("03_detection_time", ++done, static_cast<int>(subjects.size()), s.name);
    const SubjectRun r(s, args.quick && done > 1 ? thesis_pair : schemes);
    for (int pose = 0; pose < 2; ++pose) {
      const std::string pname = pose == 0 ? "rest" : "pushed_3mm";
      const Eigen::Vector3d t = pose == 0 ? Eigen::Vector3d::Zero() : r.push;
      time_pose(r, pname, t, reps, args.quick, csv, runs_csv);
    }
    throughput(r, reps, thr);
  }
  write_meta(dir, args,
             {{"region_radius_mm", kRegionMm},
              {"detection_table_precision_deg", kPrecision},
              {"precisions_deg", precisions},
              {"push_mm", 3.0},
              {"embree", have_embree()},
              {"fcl", have_fcl()},
              {"cgal", have_exact_reference()},
              {"note", "single thread unless throughput.csv says threads = 2"}});
  return 0;
}
