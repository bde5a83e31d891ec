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
//   meta.json
// Command: build/experiments/exp_02_sampling_time --out results --data ../shared/data/hips [--quick]
// Quick mode: p = 1, 0.5, 0.1 and 300 pairwise nodes; full: also 0.05 and 2000 pairwise nodes.
// Every time is the median of --repetitions runs after a warm-up, single thread; the map is
// reset to "no surface" inside each timed run (so each method's row includes one reset: the
// rasterisations use MapStart::reset, which with the plan resets in bands fused with the drawing).
#include <algorithm>
#include <iostream>
#include <random>

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
void time_precision(const BodyRun& r, double p, int reps, int pairwise_nodes, CsvWriter& csv) {
  const Subject& s = r.s;
  const TriangleMesh& mesh = r.mesh;
  const Eigen::Vector3d& cor = r.cor;
  const RasterPlan& plan = r.plan;
  const std::string& bname = r.bname;
  const auto tri = static_cast<std::int64_t>(mesh.F.rows());
  RadialDistanceMap map{EquiangularGrid(p)};
  const std::int64_t nodes = map.num_nodes();
  auto reset = [&] { std::fill(map.data(), map.data() + nodes, RadialDistanceMap::no_surface()); };
  auto put = [&](const std::string& method, double ms, std::int64_t covered, int extrapolated, std::int64_t timed,
                 std::int64_t rasterised, const std::string& scheme = "equiangular", double res = -1,
                 std::int64_t tests = 0) {
    csv.row(s.name, int(s.generated), bname, tri, p, scheme, res < 0 ? p : res, method,
            scheme == "equiangular" ? nodes : static_cast<std::int64_t>(res * res), covered, ms, extrapolated,
            timed, s.name == "generated-3k" ? thesis_ms(method, p) : std::nan(""), int(plan.enabled), rasterised,
            tests);
  };
  put("fill", median_ms(reset, reps), 0, 0, nodes, 0);
  SamplingStats st;
  const auto fresh = MapStart::reset;
  double t = median_ms([&] { st = rasterize(mesh, cor, DistanceMode::linear, map, RasterizeOptions{nullptr, true, fresh}); }, reps);
  put("rsid_linear", t, st.nodes_covered, 0, nodes, st.triangles - st.triangles_culled, "equiangular", -1,
      st.node_tests);
  t = median_ms([&] { st = rasterize(mesh, cor, DistanceMode::exact, map, RasterizeOptions{nullptr, true, fresh}); }, reps);
  put("rsid_exact", t, st.nodes_covered, 0, nodes, st.triangles - st.triangles_culled, "equiangular", -1,
      st.node_tests);
  const RadialDistanceMap full = map;
  t = median_ms([&] { st = rasterize(mesh, cor, DistanceMode::exact, map, RasterizeOptions{&plan, true, fresh}); }, reps);
  put("rsid_exact_culled", t, st.nodes_covered, 0, nodes, st.triangles - st.triangles_culled, "equiangular", -1,
      st.node_tests);
  std::int64_t differing = 0;
  for (std::int64_t i = 0; i < nodes; ++i) differing += map.at(i) != full.at(i);
  if (differing != 0)
    std::cerr << "02_sampling_time: WARNING " << s.name << " " << bname << " p=" << p
              << ": culled map differs at " << differing << " nodes\n";
  {
    const int k = static_cast<int>(matched_helix_turns(p));
    RadialDistanceMap helix(make_scheme("helix", k));
    SamplingOptions o;
    o.plan = &plan;
    SamplingReport rep;
    t = median_ms([&] { rep = sample_surface(mesh, cor, o, helix); }, reps);
    put("usid_accelerated", t, rep.nodes_covered, 0, helix.num_nodes(), rep.raster.triangles, "helix", k);
  }
  if (r.embree) {
    std::int64_t covered = 0;
    t = median_ms([&] { covered = r.embree->fill_map(map); }, p < 0.1 ? std::min(reps, 3) : reps);
    put("embree_node_cast", t, covered, 0, nodes, tri);
  }
  {  // Pairwise O(m n): a random subset of nodes, scaled to the whole map.
    std::mt19937_64 rng(11);
    std::uniform_int_distribution<std::int64_t> pick(0, nodes - 1);
    std::vector<std::int64_t> sample(static_cast<std::size_t>(std::min<std::int64_t>(pairwise_nodes, nodes)));
    for (auto& i : sample) i = pick(rng);
    volatile double sink = 0;  // keeps the casts from being optimised away
    t = median_ms(
        [&] {
          for (std::int64_t i : sample) {
            const auto h = cast_ray_naive(mesh, cor, map.scheme().node_direction(i));
            sink = sink + (h ? h->first : 0);
          }
        },
        1);
    put("pairwise", t * double(nodes) / double(sample.size()), -1, 1, static_cast<std::int64_t>(sample.size()),
        tri);
  }
}

}  // namespace

int main(int argc, char** argv) {
  const Args args = parse_args(argc, argv, "02_sampling_time: thesis Tables 3 and 8, sampling time by method");
  const std::string dir = experiment_dir(args, "02_sampling_time");
  const std::vector<Subject> subjects = load_subjects(args, {3000});
  std::vector<double> precisions{1, 0.5, 0.1};
  if (!args.quick) precisions.push_back(0.05);
  const int pairwise_nodes = args.quick ? 300 : 2000;
  const int reps = args.repetitions;

  CsvWriter csv(dir + "/sampling_time.csv",
                {"subject", "generated", "body", "triangles", "precision_deg", "scheme", "resolution", "method",
                 "nodes", "nodes_covered", "time_ms", "extrapolated", "nodes_timed", "thesis_ms", "culling_enabled",
                 "triangles_rasterised", "node_tests"});
  const int total = static_cast<int>(subjects.size() * 2 * precisions.size());
  int done = 0;
  for (const Subject& s : subjects) {
    const Eigen::Vector3d cor = subject_cor(s);
    for (int body = 0; body < 2; ++body) {
      BodyRun r{s, body == 0 ? s.femur : s.pelvis, body == 0 ? "femur" : "pelvis", cor, {}, nullptr};
      const auto tri = static_cast<std::int64_t>(r.mesh.F.rows());
      const double t_plan = median_ms([&] { r.plan = plan_rasterization(r.mesh, cor); }, reps);
      csv.row(s.name, int(s.generated), r.bname, tri, 0.0, "none", 0.0, "culling_analysis", 0, 0, t_plan, 0, 0,
              std::nan(""), int(r.plan.enabled), static_cast<std::int64_t>(r.plan.triangle_order.size()), 0);
      if (have_embree()) r.embree = std::make_unique<EmbreeRayCaster>(r.mesh, cor);
      for (double p : precisions) {
        progress("02_sampling_time", ++done, total, s.name + " " + r.bname + " p=" + std::to_string(p));
        time_precision(r, p, reps, pairwise_nodes, csv);
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
