// Google Benchmark micro-benchmarks of sampling and query (never timing asserts in tests).
//   build/benchmarks/impinge_bench [--benchmark_filter=...] [--benchmark_repetitions=N]
// Subject: lhdl-ct from ../shared/data/hips when present (IMPINGE_BENCH_SUBJECT overrides the
// folder), else the generated 12k hip model. Meshes and maps are built once.
// Scheme index: 0-3 equiangular at p = 1, 0.5, 0.1, 0.05 deg; 4-7 helix at the matched turns
// k = 229, 458, 2292, 4584 (thesis Table 6).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>

#include "impinge/detection.hpp"
#include "impinge/generated_models.hpp"
#include "impinge/mesh_io.hpp"
#include "impinge/rasterize.hpp"
#include "impinge/sampling.hpp"
#include "impinge/sphere_fit.hpp"
#include "impinge/subject.hpp"

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
      const SubjectInfo info = load_subject(dir + "/subject.json");
      sc->name = info.name;
      sc->femur = load_mesh(info.femur_path);
      sc->pelvis = load_mesh(info.pelvis_path);
      transform_vertices(sc->femur.V, to_anatomical(info.frame));
      transform_vertices(sc->pelvis.V, to_anatomical(info.frame));
      sc->cor = fit_femoral_head(sc->femur).centre;
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
};
const Built& built(int pi, DistanceMode mode) {
  static std::map<std::pair<int, int>, std::unique_ptr<Built>> cache;
  auto& b = cache[{pi, int(mode)}];
  if (!b) {
    const Scene& s = scene();
    const auto scheme = scheme_of(pi);
    b = std::make_unique<Built>(Built{RadialDistanceMap(scheme), RadialDistanceMap(scheme), {}, {}, {}, {}});
    SamplingOptions o;
    o.mode = mode;
    sample_surface(s.femur, s.cor, o, b->femur_map);
    sample_surface(s.pelvis, s.cor, o, b->pelvis_map);
    b->femur_mask = first_surface_mask(s.femur_rel, b->femur_map, 1.0, 1e30);
    b->pelvis_mask = first_surface_mask(s.pelvis_rel, b->pelvis_map, 1.0, 1e30);
    b->femur_set = make_scan_set(s.femur_rel, b->femur_mask);
    b->pelvis_set = make_scan_set(s.pelvis_rel, b->pelvis_mask);
  }
  return *b;
}

// args: body (0 femur, 1 pelvis), precision index, mode (0 exact, 1 linear)
void BM_Rasterize(benchmark::State& st) {
  const Scene& s = scene();
  const TriangleMesh& m = st.range(0) == 0 ? s.femur : s.pelvis;
  const DistanceMode mode = st.range(2) == 0 ? DistanceMode::exact : DistanceMode::linear;
  RadialDistanceMap map{EquiangularGrid(kPrecisions[st.range(1)])};
  for (auto _ : st) {
    std::fill(map.data(), map.data() + map.num_nodes(), RadialDistanceMap::no_surface());
    benchmark::DoNotOptimize(rasterize(m, s.cor, mode, map));
  }
  st.SetLabel(s.name + (st.range(0) == 0 ? " femur " : " pelvis ") + to_string(mode));
  st.counters["triangles"] = double(m.F.rows());
  st.counters["nodes"] = double(map.num_nodes());
}
BENCHMARK(BM_Rasterize)->ArgsProduct({{0, 1}, {0, 1, 2, 3}, {0, 1}})->Unit(benchmark::kMillisecond)->UseRealTime();

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
// precision index). Items = map look-ups (vertices on their first surface); ns per item.
void BM_Query(benchmark::State& st) {
  const Scene& s = scene();
  const Built& b = built(int(st.range(1)), DistanceMode::exact);
  const bool ball = st.range(0) == 0;
  const ScanSet& set = ball ? b.femur_set : b.pelvis_set;
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
BENCHMARK(BM_Query)->ArgsProduct({{0, 1}, {0, 1, 2, 3, 4, 5, 6, 7}})->Unit(benchmark::kMicrosecond)->UseRealTime();

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  return "unknown";
}
}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  benchmark::AddCustomContext("cpu_model", cpu_model());
  benchmark::AddCustomContext("subject", scene().name);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
