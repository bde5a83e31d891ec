// Google Benchmark micro-benchmarks of sampling and query (never timing asserts in tests).
//   build/benchmarks/impinge_bench [--benchmark_filter=...] [--benchmark_repetitions=N]
// Subject: lhdl-ct from ../shared/data/hips when present (IMPINGE_BENCH_SUBJECT overrides the
// folder), else the generated 12k hip model. Meshes and maps are built once.
// Scheme index: 0-3 equiangular at p = 1, 0.5, 0.1, 0.05 deg; 4-7 helix at the matched turns
// k = 229, 458, 2292, 4584 (thesis Table 6). BM_RegisteredSchemeQuery takes every registered scheme
// (scheme_names()) at a largest node spacing of 0.1 deg, dense and sparse, with no list here.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>

#include "impinge/anatomy/sphere_fit.hpp"
#include "impinge/casters/embree_ray_caster.hpp"
#include "impinge/casters/exact_reference.hpp"
#include "impinge/casters/fcl_collision.hpp"
#include "impinge/casters/first_hit_caster.hpp"
#include "impinge/casters/signed_distance.hpp"
#include "impinge/casters/pairwise.hpp"
#include "impinge/core/provenance.hpp"
#include "impinge/detection/detection.hpp"
#include "impinge/io/generated_models.hpp"
#include "impinge/io/mesh_io.hpp"
#include "impinge/io/subject.hpp"
#include "impinge/sampling/naive_sampling.hpp"
#include "impinge/sampling/rasterize.hpp"
#include "impinge/sampling/sampling.hpp"
#include "impinge/session/session.hpp"

using namespace impinge;

namespace {
const double kPrecisions[] = {1.0, 0.5, 0.1, 0.05};
const double kTurns[] = {229, 458, 2292, 4584};
std::shared_ptr<const SamplingScheme> scheme_of(int index) {
  return index < 4 ? make_scheme("equiangular", kPrecisions[index]) : make_scheme("helix", kTurns[index - 4]);
}

struct Scene {
  std::string name;
  TriangleMesh femur, pelvis;
  Eigen::Vector3d cor;
  Vertices femur_rel, pelvis_rel;
};

const Scene& scene() {
  static const std::unique_ptr<Scene> s = [] {
    auto sc = std::make_unique<Scene>();
    const char* env = std::getenv("IMPINGE_BENCH_SUBJECT");
    const std::string dir = env ? env : std::string(IMPINGE_SHARED_DATA) + "/lhdl-ct";
    if (std::filesystem::exists(dir + "/subject.json")) {
      // Read and centred as every front end does it (the session layer).
      SessionInput in;
      in.subject = dir + "/subject.json";
      LoadedInput li = load_input(in);
      sc->name = li.name;
      sc->cor = find_centre_of_rotation(li, {}).head.centre;
      sc->femur = std::move(li.femur);
      sc->pelvis = std::move(li.pelvis);
    } else {
      HipModelOptions o;
      o.target_triangles = 12000;
      const HipModel h = make_hip_model(o);
      sc->name = "generated-12k";
      sc->femur = h.ball;
      sc->pelvis = h.socket;
      sc->cor = h.cor;
    }
    sc->femur_rel = sc->femur.V.rowwise() - sc->cor.transpose();
    sc->pelvis_rel = sc->pelvis.V.rowwise() - sc->cor.transpose();
    return sc;
  }();
  return *s;
}

/// Maps and first-surface masks per (precision index, mode), built on first use.
struct Built {
  RadialDistanceMap femur_map, pelvis_map;
  std::vector<std::uint8_t> femur_mask, pelvis_mask;
  ScanSet femur_set, pelvis_set;
  ScanSet femur_hip, pelvis_hip;  ///< the sets restricted to the hip region (<= 45 mm from the COR)
};
const Built& built(int pi, DistanceMode mode) {
  static std::map<std::pair<int, int>, std::unique_ptr<Built>> cache;
  auto& b = cache[{pi, int(mode)}];
  if (!b) {
    const Scene& s = scene();
    const auto scheme = scheme_of(pi);
    b = std::make_unique<Built>(Built{RadialDistanceMap(scheme), RadialDistanceMap(scheme), {}, {}, {}, {}, {}, {}});
    SamplingOptions o;
    o.mode = mode;
    sample_surface(s.femur, s.cor, o, b->femur_map);
    sample_surface(s.pelvis, s.cor, o, b->pelvis_map);
    b->femur_mask = first_surface_mask(s.femur_rel, b->femur_map, 1.0, 1e30);
    b->pelvis_mask = first_surface_mask(s.pelvis_rel, b->pelvis_map, 1.0, 1e30);
    b->femur_set = make_scan_set(s.femur_rel, b->femur_mask);
    b->pelvis_set = make_scan_set(s.pelvis_rel, b->pelvis_mask);
    auto region = [](const Vertices& P, std::vector<std::uint8_t> m) {
      for (Eigen::Index i = 0; i < P.rows(); ++i) m[std::size_t(i)] &= P.row(i).norm() <= 45 ? 1 : 0;
      return make_scan_set(P, m);
    };
    b->femur_hip = region(s.femur_rel, b->femur_mask);
    b->pelvis_hip = region(s.pelvis_rel, b->pelvis_mask);
  }
  return *b;
}

// args: body (0 femur, 1 pelvis), precision index, mode (0 exact, 1 linear, 2 exact with
// face culling; the culling analysis is done once, outside the timed loop, like a BVH build).
// The timed loop includes resetting the map (MapStart::reset: std::fill, BM_FillMap's floor,
// then drawing; with the plan, in bands fused with the drawing).
void BM_Rasterize(benchmark::State& st) {
  const Scene& s = scene();
  const TriangleMesh& m = st.range(0) == 0 ? s.femur : s.pelvis;
  const DistanceMode mode = st.range(2) == 1 ? DistanceMode::linear : DistanceMode::exact;
  const RasterPlan fc = plan_rasterization(m, s.cor);
  const RasterPlan* cull = st.range(2) == 2 ? &fc : nullptr;
  RadialDistanceMap map{EquiangularGrid(kPrecisions[st.range(1)])};
  for (auto _ : st) {
    benchmark::DoNotOptimize(rasterize(m, s.cor, mode, map, RasterizeOptions{cull, true, MapStart::reset}));
  }
  st.SetLabel(s.name + (st.range(0) == 0 ? " femur " : " pelvis ") + to_string(mode) +
              (cull ? (fc.enabled ? " culled" : " (culling disabled: " + fc.reason + ")") : ""));
  st.counters["triangles"] = double(m.F.rows());
  st.counters["nodes"] = double(map.num_nodes());
}
BENCHMARK(BM_Rasterize)->ArgsProduct({{0, 1}, {0, 1, 2, 3}, {0, 1, 2}})->Unit(benchmark::kMillisecond)->UseRealTime();

// The once-per-mesh face-culling analysis (args: body).
void BM_RasterPlanAnalysis(benchmark::State& st) {
  const Scene& s = scene();
  const TriangleMesh& m = st.range(0) == 0 ? s.femur : s.pelvis;
  for (auto _ : st) benchmark::DoNotOptimize(plan_rasterization(m, s.cor));
}
BENCHMARK(BM_RasterPlanAnalysis)->DenseRange(0, 1)->Unit(benchmark::kMillisecond)->UseRealTime();

// The floor: std::fill of a map of the same size (args: precision index).
void BM_FillMap(benchmark::State& st) {
  RadialDistanceMap map{EquiangularGrid(kPrecisions[st.range(0)])};
  for (auto _ : st) {
    std::fill(map.data(), map.data() + map.num_nodes(), RadialDistanceMap::no_surface());
    benchmark::ClobberMemory();
  }
  st.counters["nodes"] = double(map.num_nodes());
}
BENCHMARK(BM_FillMap)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->UseRealTime();

// Accelerated helix sampling (thesis sec. 4.2.2): rasterise the matched equiangular map,
// resample it at the helix points, release it. args: body, turns index (229, 458, 2292, 4584).
void BM_HelixSample(benchmark::State& st) {
  const Scene& s = scene();
  const TriangleMesh& m = st.range(0) == 0 ? s.femur : s.pelvis;
  RadialDistanceMap map(scheme_of(4 + int(st.range(1))));
  SamplingOptions o;
  for (auto _ : st) benchmark::DoNotOptimize(sample_surface(m, s.cor, o, map));
  st.SetLabel(s.name + (st.range(0) == 0 ? " femur" : " pelvis") +
              " exact, k=" + std::to_string(int(kTurns[st.range(1)])));
  st.counters["nodes"] = double(map.num_nodes());
}
BENCHMARK(BM_HelixSample)->ArgsProduct({{0, 1}, {0, 1, 2, 3}})->Unit(benchmark::kMillisecond)->UseRealTime();

// One scan (args: 0 = femur vertices against the pelvis map, 1 = pelvis against femur;
// scheme index; set: 0 first-surface vertices, 1 those within 45 mm of the COR).
// Items = map look-ups (vertices on their first surface); ns per item.
void BM_Query(benchmark::State& st) {
  const Scene& s = scene();
  const Built& b = built(int(st.range(1)), DistanceMode::exact);
  const bool ball = st.range(0) == 0;
  const ScanSet& set = st.range(2) ? (ball ? b.femur_hip : b.pelvis_hip) : (ball ? b.femur_set : b.pelvis_set);
  const RadialDistanceMap& other = ball ? b.pelvis_map : b.femur_map;
  std::vector<float> out(static_cast<std::size_t>(set.size()));
  const Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  for (auto _ : st) {
    scan_gaps_compact(set, R, Eigen::Vector3d::Zero(), other, ball ? ScanSide::inside : ScanSide::outside, out.data());
    benchmark::DoNotOptimize(out.data());
  }
  const auto lookups = set.size();
  st.SetItemsProcessed(st.iterations() * lookups);
  st.counters["ns_per_lookup"] = benchmark::Counter(double(lookups) * double(st.iterations()),
                                                    benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  st.SetLabel(s.name + (ball ? " femur vs pelvis map, " : " pelvis vs femur map, ") + other.scheme().name() + " " +
              std::to_string(other.scheme().resolution()));
}
BENCHMARK(BM_Query)
    ->ArgsProduct({{0, 1}, {0, 1, 2, 3, 4, 5, 6, 7}, {0, 1}})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

// Every registered scheme (args: index into scheme_names(), storage 0 dense / 1 sparse) at its
// resolution for a largest node spacing of 0.1 deg: both hip-region scans (vertices within 45 mm of
// the COR) against the other map, exact mode. Items = look-ups.
void BM_RegisteredSchemeQuery(benchmark::State& st) {
  const auto names = scheme_names();
  if (st.range(0) >= std::int64_t(names.size())) return st.SkipWithError("no such registered scheme");
  const std::string name = names[std::size_t(st.range(0))].first;
  static std::map<std::string, std::unique_ptr<Built>> cache;
  auto& b = cache[name];
  const Scene& s = scene();
  if (!b) {
    const auto scheme = make_scheme(name, resolution_for_spacing(name, 0.1));
    b = std::make_unique<Built>(Built{RadialDistanceMap(scheme), RadialDistanceMap(scheme), {}, {}, {}, {}, {}, {}});
    sample_surface(s.femur, s.cor, SamplingOptions{}, b->femur_map);
    sample_surface(s.pelvis, s.cor, SamplingOptions{}, b->pelvis_map);
    auto hip = [](const Vertices& P, const RadialDistanceMap& m) {
      std::vector<std::uint8_t> mask = first_surface_mask(P, m, 1.0, 45.0);
      return make_scan_set(P, mask);
    };
    b->femur_hip = hip(s.femur_rel, b->femur_map);
    b->pelvis_hip = hip(s.pelvis_rel, b->pelvis_map);
  }
  RadialDistanceMap fm = b->femur_map, pm = b->pelvis_map;
  if (st.range(1)) fm.make_sparse(), pm.make_sparse();
  std::vector<float> g1(std::size_t(b->femur_hip.size())), g2(std::size_t(b->pelvis_hip.size()));
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  for (auto _ : st) {
    scan_gaps_compact(b->femur_hip, I, Eigen::Vector3d::Zero(), pm, ScanSide::inside, g1.data());
    scan_gaps_compact(b->pelvis_hip, I, Eigen::Vector3d::Zero(), fm, ScanSide::outside, g2.data());
    benchmark::DoNotOptimize(g1.data());
    benchmark::DoNotOptimize(g2.data());
  }
  const auto lookups = b->femur_hip.size() + b->pelvis_hip.size();
  st.counters["ns_per_lookup"] = benchmark::Counter(double(lookups) * double(st.iterations()),
                                                    benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  st.counters["MiB"] = double(fm.bytes() + pm.bytes()) / (1 << 20);
  st.SetLabel(s.name + " " + name + " " + std::to_string(fm.scheme().resolution()) + (st.range(1) ? " sparse" : " dense"));
}
BENCHMARK(BM_RegisteredSchemeQuery)
    ->ArgsProduct({{0, 1, 2, 3, 4, 5, 6, 7, 8, 9}, {0, 1}})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

// Peers on the same vertices as BM_Query at p = 0.1 deg (the first-surface vertices).
// args: body (0 femur vertices against the pelvis, 1 pelvis against the femur), packet (0, 1),
// set (0 first-surface vertices, 1 those within 45 mm of the COR).
void BM_EmbreeQuery(benchmark::State& st) {
  if (!have_embree()) return st.SkipWithError("no Embree in this build");
  const Scene& s = scene();
  const Built& b = built(2, DistanceMode::exact);
  const bool ball = st.range(0) == 0;
  static const EmbreeRayCaster pelvis(s.pelvis, s.cor), femur(s.femur, s.cor);
  const ScanSet& set = st.range(2) ? (ball ? b.femur_hip : b.pelvis_hip) : (ball ? b.femur_set : b.pelvis_set);
  std::vector<float> out(static_cast<std::size_t>(set.size()));
  for (auto _ : st) {
    scan_gaps_embree(ball ? pelvis : femur, set, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(),
                     ball ? ScanSide::inside : ScanSide::outside, out.data(), st.range(1) == 1);
    benchmark::DoNotOptimize(out.data());
  }
  st.counters["ns_per_lookup"] = benchmark::Counter(double(set.size()) * double(st.iterations()),
                                                    benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  st.SetLabel(s.name + (st.range(1) ? " rtcIntersect8" : " rtcIntersect1"));
}
BENCHMARK(BM_EmbreeQuery)->ArgsProduct({{0, 1}, {0, 1}, {0, 1}})->Unit(benchmark::kMicrosecond)->UseRealTime();

// The set-up's two hierarchies per bone (args: body, 0 femur / 1 pelvis; issue 52, a one-pose run's set-up): the
// closest-point query's (SignedDistanceQuery: kept triangles, edge twins, groups in boxes, Embree's tree) and the
// first-hit caster's (Embree's triangle BVH).
void BM_SignedDistanceBuild(benchmark::State& st) {
  const TriangleMesh& m = st.range(0) == 0 ? scene().femur : scene().pelvis;
  for (auto _ : st) benchmark::DoNotOptimize(SignedDistanceQuery(m).orientation());
  st.counters["triangles"] = double(m.F.rows());
}
BENCHMARK(BM_SignedDistanceBuild)->DenseRange(0, 1)->Unit(benchmark::kMillisecond)->UseRealTime();

// Args: body (0 femur / 1 pelvis), Embree's tree builder (0 quality, the SAH; 1 fast, Morton codes: a one-pose
// run's, HierarchyBuild).
void BM_FirstHitCasterBuild(benchmark::State& st) {
  const TriangleMesh& m = st.range(0) == 0 ? scene().femur : scene().pelvis;
  const HierarchyBuild build = st.range(1) == 0 ? HierarchyBuild::quality : HierarchyBuild::fast;
  for (auto _ : st) {
    FirstHitCaster c(m, scene().cor, build);
    benchmark::DoNotOptimize(&c);
  }
  st.counters["triangles"] = double(m.F.rows());
}
BENCHMARK(BM_FirstHitCasterBuild)->ArgsProduct({{0, 1}, {0, 1}})->Unit(benchmark::kMillisecond)->UseRealTime();

// CGAL AABB tree first intersection on the same vertices (args: body).
void BM_CgalQuery(benchmark::State& st) {
  if (!have_exact_reference()) return st.SkipWithError("no CGAL in this build");
  const Scene& s = scene();
  const Built& b = built(2, DistanceMode::exact);
  const bool ball = st.range(0) == 0;
  static const ExactReference pelvis(s.pelvis), femur(s.femur);
  const ScanSet& set = ball ? b.femur_set : b.pelvis_set;
  for (auto _ : st) {
    double acc = 0;
    for (std::int64_t j = 0; j < set.size(); ++j) {
      const Eigen::Vector3d q(set.x[j], set.y[j], set.z[j]);
      const auto h = (ball ? pelvis : femur).first_hit(s.cor, q.normalized());
      acc += h ? *h - q.norm() : 0;
    }
    benchmark::DoNotOptimize(acc);
  }
  st.counters["ns_per_lookup"] = benchmark::Counter(double(set.size()) * double(st.iterations()),
                                                    benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_CgalQuery)->DenseRange(0, 1)->Unit(benchmark::kMillisecond)->UseRealTime();

/// Push of the femur into the acetabulum: 3 mm from the COR towards the centroid of the pelvis
/// vertices within 45 mm (the acetabular fossa side), as in experiment 03.
Eigen::Vector3d push_3mm(const Scene& s) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  int n = 0;
  for (Eigen::Index i = 0; i < s.pelvis_rel.rows(); ++i)
    if (s.pelvis_rel.row(i).norm() <= 45) c += s.pelvis_rel.row(i).transpose(), ++n;
  return c.normalized() * 3.0;
}

// Both scans of one pose over the hip region (vertices within 45 mm of the COR), femur pushed
// 3 mm in (args: precision index).
void BM_HipPoseScans(benchmark::State& st) {
  const Scene& s = scene();
  const Built& b = built(int(st.range(0)), DistanceMode::exact);
  auto region = [](const Vertices& P, const std::vector<std::uint8_t>& mask) {
    std::vector<std::uint8_t> m = mask;
    for (Eigen::Index i = 0; i < P.rows(); ++i) m[std::size_t(i)] &= P.row(i).norm() <= 45 ? 1 : 0;
    return make_scan_set(P, m);
  };
  const ScanSet fs = region(s.femur_rel, b.femur_mask), ps = region(s.pelvis_rel, b.pelvis_mask);
  const Eigen::Vector3d t = push_3mm(s);
  std::vector<float> g1(std::size_t(fs.size())), g2(std::size_t(ps.size()));
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  for (auto _ : st) {
    scan_gaps_compact(fs, I, t, b.pelvis_map, ScanSide::inside, g1.data());
    scan_gaps_compact(ps, I, Eigen::Vector3d(-t), b.femur_map, ScanSide::outside, g2.data());
    benchmark::DoNotOptimize(g1.data());
    benchmark::DoNotOptimize(g2.data());
  }
  st.counters["vertices"] = double(fs.size() + ps.size());
}
BENCHMARK(BM_HipPoseScans)->DenseRange(0, 3)->Unit(benchmark::kMicrosecond)->UseRealTime();

// FCL OBBRSS collide at the same pose, every contact (args: 0 = rest, 1 = pushed 3 mm).
void BM_FclCollide(benchmark::State& st) {
  if (!have_fcl()) return st.SkipWithError("no FCL in this build");
  const Scene& s = scene();
  static const FclJoint j(s.femur, s.pelvis, s.cor);
  const Eigen::Vector3d t = st.range(0) ? push_3mm(s) : Eigen::Vector3d::Zero();
  std::int64_t contacts = 0;
  for (auto _ : st) contacts = j.collide(Eigen::Matrix3d::Identity(), t).contacts;
  st.counters["contacts"] = double(contacts);
}
BENCHMARK(BM_FclCollide)->DenseRange(0, 1)->Unit(benchmark::kMicrosecond)->UseRealTime();

// Embree casting every node's ray to fill a map (args: body, precision index).
void BM_EmbreeFillMap(benchmark::State& st) {
  if (!have_embree()) return st.SkipWithError("no Embree in this build");
  const Scene& s = scene();
  const EmbreeRayCaster c(st.range(0) == 0 ? s.femur : s.pelvis, s.cor);
  RadialDistanceMap map{EquiangularGrid(kPrecisions[st.range(1)])};
  for (auto _ : st) benchmark::DoNotOptimize(c.fill_map(map));
  st.counters["nodes"] = double(map.num_nodes());
}
BENCHMARK(BM_EmbreeFillMap)->ArgsProduct({{0, 1}, {0, 1, 2, 3}})->Unit(benchmark::kMillisecond)->UseRealTime();

// The thesis' baselines on the generated 3k model (its Table 3/4 level), built once: the
// exhaustive triangle-pair test at the pushed pose, and pair-wise O(m n) sampling of a 5 deg map.
const HipModel& model_3k() {
  static const HipModel h = [] {
    HipModelOptions o;
    o.target_triangles = 3000;
    o.cam_height_mm = 2;
    return make_hip_model(o);
  }();
  return h;
}
void BM_PairwiseDetect(benchmark::State& st) {
  if (!have_exact_reference()) return st.SkipWithError("no CGAL in this build");
  const HipModel& h = model_3k();
  static const PairwiseJoint j(h.ball, h.socket, h.cor);
  const Eigen::Vector3d t = 3.0 * (h.socket.V.colwise().mean().transpose() - h.cor).normalized();
  std::int64_t pairs = 0;
  for (auto _ : st) pairs = j.intersect(Eigen::Matrix3d::Identity(), t).intersecting_pairs;
  st.counters["intersecting_pairs"] = double(pairs);
}
BENCHMARK(BM_PairwiseDetect)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_PairwiseSample(benchmark::State& st) {
  const HipModel& h = model_3k();
  RadialDistanceMap map{EquiangularGrid(5)};
  for (auto _ : st) {
    std::fill(map.data(), map.data() + map.num_nodes(), RadialDistanceMap::no_surface());
    sample_naive(h.socket, h.cor, map);
  }
  st.counters["nodes"] = double(map.num_nodes());
}
BENCHMARK(BM_PairwiseSample)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  for (const auto& [key, value] : impinge::machine_description()) benchmark::AddCustomContext(key, value);
  benchmark::AddCustomContext("subject", scene().name);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
