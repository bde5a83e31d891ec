// 02_sampling_time -- thesis Tables 3 and 8: time to sample a bone into a radial distance map,
// by method and precision, with std::fill of the same map as the floor.
//
// Inputs: the generated 3k hip model (the thesis' level) and every subject under --data.
// Outputs: OUT/02_sampling_time/
//   sampling_time.csv  one row per subject x body x precision x method:
//     method: fill (std::fill of the map: the floor), rsid_linear (thesis Algorithm 1),
//             rsid_exact (exact mode, every triangle), rsid_exact_culled (exact mode with the
//             face-culling plan made once, raster_plan.hpp: its cones and row spans),
//             usid_accelerated (helix at the
//             matched turns k = round(720 / (pi p)): rasterise the matched equiangular map with
//             culling, resample, release; thesis sec. 4.2.2), embree_node_cast (Embree 3 casts
//             every node's ray, 8-wide packets), pairwise (the thesis' O(m n) ray-triangle sampling,
//             timed on a subset of nodes and scaled to the map: `extrapolated` = 1),
//             culling_analysis (the plan itself, once per mesh; precision 0)
//     thesis_ms: Table 3 / 8 value for the generated 3k rows (pairwise, RSID, USID)
//     node_tests: node-in-cone tests of the rasterisation rows (SamplingStats; 0 otherwise)
//     time_ms, time_q25_ms, time_q75_ms, runs: median and quartiles over `runs` rounds; every method of a
//       precision timed alternately (one run of each per round); pairwise once (runs = 1)
//   sampling_runs.csv  every round's time (subject, body, precision_deg, method, round, time_ms): paired ratios
//   meta.json
// Command: build/experiments/exp_02_sampling_time --out results --data ../shared/data/hips [--quick]
// Quick mode: p = 1, 0.5, 0.1 and 300 pairwise nodes; full: also 0.05 and 500 pairwise nodes (issue 82 item 7: from
// 2,000, which took 4 of the full run's minutes; the time per node of the exhaustive casts does not depend on the
// subset, which is scaled to the map, and 500 nodes take about a second a map).
// Every time is the median (and quartiles) of --repetitions alternated rounds after a warm-up, single thread; the map is
// reset to "no surface" inside each timed run (so each method's row includes one reset: the
// rasterisations use MapStart::reset, which with the plan resets in bands fused with the drawing).
#include <algorithm>
#include <iostream>
#include <random>
#include <tuple>

#include "experiment_support.hpp"
#include "impinge/casters/embree_ray_caster.hpp"
#include "impinge/sampling/naive_sampling.hpp"
#include "impinge/sampling/raster_plan.hpp"
#include "impinge/sampling/rasterize.hpp"
#include "impinge/sampling/sampling.hpp"
#include "impinge/schemes/helix_scheme.hpp"

using namespace impinge;
using namespace impinge::experiment;

namespace {
/// Thesis Tables 3 and 8 (3k generic model), ms; NaN where the thesis has no value.
double thesis_ms(const std::string& method, double p) {
  const double nan = std::nan("");
  const int i = p == 1 ? 0 : p == 0.5 ? 1 : p == 0.1 ? 2 : p == 0.05 ? 3 : -1;
  if (i < 0) return nan;
  const double pairwise[] = {176328, 700844, 17722156, nan}, rsid[] = {15, 16, 62, 187},
               usid[] = {31, 109, 2781, 11172};
  if (method == "pairwise") return pairwise[i];
  if (method == "rsid_linear") return rsid[i];
  if (method == "usid_accelerated") return usid[i];
  return nan;
}
// One body of one subject, what every precision's timing needs.
struct BodyRun {
  const Subject& s;
  const TriangleMesh& mesh;
  std::string bname;
  Eigen::Vector3d cor;
  RasterPlan plan;
  std::unique_ptr<EmbreeRayCaster> embree;
};

// Every method's fill of one body's map at precision p: the thesis' RSID (linear, exact, culled), the
// matched USID, Embree's node casts and the pairwise O(m n) casts (a random subset, scaled).
void time_precision(const BodyRun& r, double p, int reps, int pairwise_nodes, CsvWriter& csv, CsvWriter& runs_csv) {
  const Subject& s = r.s;
  const TriangleMesh& mesh = r.mesh;
  const Eigen::Vector3d& cor = r.cor;
  const RasterPlan& plan = r.plan;
  const std::string& bname = r.bname;
  const auto tri = static_cast<std::int64_t>(mesh.F.rows());
  RadialDistanceMap map{EquiangularGrid(p)};
  const std::int64_t nodes = map.num_nodes();
  auto reset = [&] { std::fill(map.data(), map.data() + nodes, RadialDistanceMap::no_surface()); };
  auto put = [&](const std::string& method, const Timing& t, std::int64_t covered, int extrapolated,
                 std::int64_t timed, std::int64_t rasterised, const std::string& scheme = "equiangular",
                 double res = -1, std::int64_t tests = 0) {
    csv.row(s.name, int(s.generated), bname, tri, p, scheme, res < 0 ? p : res, method,
            scheme == "equiangular" ? nodes : static_cast<std::int64_t>(res * res), covered, t.median_ms, t.q25_ms,
            t.q75_ms, t.runs, extrapolated, timed, s.name == "generated-3k" ? thesis_ms(method, p) : std::nan(""),
            int(plan.enabled), rasterised, tests);
  };
  // The map filled by the exact rasteriser without and with culling must agree node for node (checked once,
  // outside the timing).
  const auto fresh = MapStart::reset;
  rasterize(mesh, cor, DistanceMode::exact, map, RasterizeOptions{nullptr, true, fresh});
  const RadialDistanceMap full = map;
  rasterize(mesh, cor, DistanceMode::exact, map, RasterizeOptions{&plan, true, fresh});
  std::int64_t differing = 0;
  for (std::int64_t i = 0; i < nodes; ++i) differing += map.at(i) != full.at(i);
  if (differing != 0)
    std::cerr << "02_sampling_time: WARNING " << s.name << " " << bname << " p=" << p
              << ": culled map differs at " << differing << " nodes\n";
  // Every fill of this precision timed alternately (run_alternated: one warm-up each, then `reps` rounds in
  // which each runs once), so that their ratios (over the fill, over Embree) are paired round by round.
  const int k = static_cast<int>(matched_helix_turns(p));
  RadialDistanceMap helix(make_scheme("helix", k));
  SamplingOptions o;
  o.plan = &plan;
  SamplingStats st_linear, st_exact, st_culled;
  SamplingReport rep;
  std::int64_t embree_covered = 0;
  std::vector<std::function<void()>> fns{
      reset,
      [&] { st_linear = rasterize(mesh, cor, DistanceMode::linear, map, RasterizeOptions{nullptr, true, fresh}); },
      [&] { st_exact = rasterize(mesh, cor, DistanceMode::exact, map, RasterizeOptions{nullptr, true, fresh}); },
      [&] { st_culled = rasterize(mesh, cor, DistanceMode::exact, map, RasterizeOptions{&plan, true, fresh}); },
      [&] { rep = sample_surface(mesh, cor, o, helix); }};
  if (r.embree) fns.push_back([&] { embree_covered = r.embree->fill_map(map); });
  const std::vector<std::vector<double>> runs = run_alternated(fns, reps);
  put("fill", summarize(runs[0]), 0, 0, nodes, 0);
  for (const auto& [method, st, i] : {std::tuple{"rsid_linear", &st_linear, 1}, std::tuple{"rsid_exact", &st_exact, 2},
                                      std::tuple{"rsid_exact_culled", &st_culled, 3}})
    put(method, summarize(runs[std::size_t(i)]), st->nodes_covered, 0, nodes, st->triangles - st->triangles_culled,
        "equiangular", -1, st->node_tests);
  put("usid_accelerated", summarize(runs[4]), rep.nodes_covered, 0, helix.num_nodes(), rep.raster.triangles, "helix",
      k);
  if (r.embree) put("embree_node_cast", summarize(runs[5]), embree_covered, 0, nodes, tri);
  for (std::size_t i = 0; i < fns.size(); ++i)
    for (std::size_t round = 0; round < runs[i].size(); ++round)
      runs_csv.row(s.name, bname, p, i == 0 ? "fill" : i == 1 ? "rsid_linear" : i == 2 ? "rsid_exact"
                                                     : i == 3 ? "rsid_exact_culled" : i == 4 ? "usid_accelerated"
                                                                                             : "embree_node_cast",
                   int(round), runs[i][round]);
  {  // Pairwise O(m n): a random subset of nodes, scaled to the whole map.
    std::mt19937_64 rng(11);
    std::uniform_int_distribution<std::int64_t> pick(0, nodes - 1);
    std::vector<std::int64_t> sample(static_cast<std::size_t>(std::min<std::int64_t>(pairwise_nodes, nodes)));
    for (auto& i : sample) i = pick(rng);
    volatile double sink = 0;  // keeps the casts from being optimised away
    // Seconds: timed once (runs = 1), its spread unknown; scaled from the subset to the whole map.
    Timing t = summarize(run_alternated({[&] {
                                          for (std::int64_t i : sample) {
                                            const auto h = cast_ray_naive(mesh, cor, map.scheme().node_direction(i));
                                            sink = sink + (h ? h->first : 0);
                                          }
                                        }},
                                        1)[0]);
    const double scale = double(nodes) / double(sample.size());
    t.median_ms *= scale, t.q25_ms *= scale, t.q75_ms *= scale;
    put("pairwise", t, -1, 1, static_cast<std::int64_t>(sample.size()), tri);
  }
}

}  // namespace

int main(int argc, char** argv) {
  const Args args = parse_args(argc, argv, "02_sampling_time: thesis Tables 3 and 8, sampling time by method");
  const std::string dir = experiment_dir(args, "02_sampling_time");
  const std::vector<Subject> subjects = load_subjects(args, {3000});
  std::vector<double> precisions{1, 0.5, 0.1};
  if (!args.quick) precisions.push_back(0.05);
  const int pairwise_nodes = args.quick ? 300 : 500;
  const int reps = args.repetitions;

  CsvWriter csv(dir + "/sampling_time.csv",
                {"subject", "generated", "body", "triangles", "precision_deg", "scheme", "resolution", "method",
                 "nodes", "nodes_covered", "time_ms", "time_q25_ms", "time_q75_ms", "runs", "extrapolated",
                 "nodes_timed", "thesis_ms", "culling_enabled", "triangles_rasterised", "node_tests"});
  CsvWriter runs_csv(dir + "/sampling_runs.csv", {"subject", "body", "precision_deg", "method", "round", "time_ms"});
  const int total = static_cast<int>(subjects.size() * 2 * precisions.size());
  int done = 0;
  for (const Subject& s : subjects) {
    const Eigen::Vector3d cor = subject_cor(s);
    for (int body = 0; body < 2; ++body) {
      BodyRun r{s, body == 0 ? s.femur : s.pelvis, body == 0 ? "femur" : "pelvis", cor, {}, nullptr};
      const auto tri = static_cast<std::int64_t>(r.mesh.F.rows());
      const Timing t_plan = summarize(run_alternated({[&] { r.plan = plan_rasterization(r.mesh, cor); }}, reps)[0]);
      csv.row(s.name, int(s.generated), r.bname, tri, 0.0, "none", 0.0, "culling_analysis", 0, 0, t_plan.median_ms,
              t_plan.q25_ms, t_plan.q75_ms, t_plan.runs, 0, 0, std::nan(""), int(r.plan.enabled),
              static_cast<std::int64_t>(r.plan.triangle_order.size()), 0);
      if (have_embree()) r.embree = std::make_unique<EmbreeRayCaster>(r.mesh, cor);
      for (double p : precisions) {
        progress("02_sampling_time", ++done, total, s.name + " " + r.bname + " p=" + std::to_string(p));
        time_precision(r, p, reps, pairwise_nodes, csv, runs_csv);
      }
    }
  }
  write_meta(dir, args,
             {{"precisions_deg", precisions},
              {"pairwise_nodes_timed", pairwise_nodes},
              {"embree", have_embree()},
              {"generated", "make_hip_model(target_triangles=3000, cam_height_mm=2)"},
              {"note", "single thread; every row's time includes resetting the map once (fill)"}});
  return 0;
}
