// Both halves of every CPU-dispatched kernel pair (kernels.hpp) give the same results: the
// rasteriser's AVX-512 span pass and row kernel against the generic C++ ones (maps node for node,
// bit for bit), and the equiangular grid's AVX2 look-ups against the generic ones (every gap), on
// real bones (or the generated hip without shared data), with and without a culling plan; and the
// Fibonacci lattice's AVX-512 block stencils against its generic ones (every stencil).
// On a CPU without AVX-512 (or AVX2, for the look-ups) both sides would be the generic kernels: those
// tests report themselves skipped instead of passing on generic against generic; forcing the generic
// kernels is checked on every CPU. ctest also runs the rasteriser, sampling, detection and
// depth-discontinuity suites whole with IMPINGE_KERNELS=generic (tests/CMakeLists.txt).
#include "impinge/core/kernels.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "impinge/io/generated_models.hpp"
#include "impinge/sampling/raster_plan.hpp"
#include "impinge/sampling/rasterize.hpp"
#include "impinge/schemes/equiangular_grid.hpp"
#include "impinge/schemes/fibonacci_scheme.hpp"
#include "test_support.hpp"

using namespace impinge;

namespace {

struct Bones {
  std::vector<TriangleMesh> meshes;
  Eigen::Vector3d cor;
};

Bones bones() {
  if (const auto real = test::load_real_joint("lhdl-ct")) return {{real->femur, real->pelvis}, real->cor};
  const HipModel h = make_hip_model(HipModelOptions{});
  return {{h.ball, h.socket}, h.cor};
}

// Restores the kernel set a test found.
struct KernelScope {
  KernelSet saved = kernel_set();
  ~KernelScope() { set_kernel_set(saved); }
};

// True when this CPU's native kernel set uses `what` ("rasteriser avx512", "look-ups avx2", ...).
bool native_uses(const std::string& what) {
  KernelScope scope;
  set_kernel_set(KernelSet::native);
  return kernel_description().find(what) != std::string::npos;
}

#define SKIP_UNLESS_NATIVE(what)                                                                     \
  if (!native_uses(what))                                                                            \
  GTEST_SKIP() << "this CPU has no wider kernel for '" << (what) << "': both halves would be generic " \
               << "(native: " << kernel_description() << ")"

template <typename M>
M rasterized(const TriangleMesh& m, const Eigen::Vector3d& cor, double p, const RasterPlan* plan, KernelSet set) {
  set_kernel_set(set);
  M map{EquiangularGrid(p)};
  rasterize(m, cor, DistanceMode::exact, map, RasterizeOptions{plan});
  return map;
}

}  // namespace

TEST(Kernels, ForcingGenericIsReported) {
  KernelScope scope;
  set_kernel_set(KernelSet::generic);
  EXPECT_EQ(kernel_set(), KernelSet::generic);
  EXPECT_EQ(kernel_description(),
            "rasteriser generic, look-ups generic, fibonacci stencils generic, distance bounds and joint-centre sums "
            "generic");
  set_kernel_set(KernelSet::native);
  EXPECT_EQ(kernel_set(), KernelSet::native);
  EXPECT_NE(kernel_description().find("rasteriser "), std::string::npos);
}

TEST(Kernels, RasteriserHalvesGiveIdenticalMaps) {
  SKIP_UNLESS_NATIVE("rasteriser avx512");
  KernelScope scope;
  const Bones b = bones();
  for (const TriangleMesh& m : b.meshes) {
    const RasterPlan plan = plan_rasterization(m, b.cor);
    for (double p : {0.5, 0.1}) {
      for (const RasterPlan* pl : {static_cast<const RasterPlan*>(nullptr), &plan}) {
        const auto native = rasterized<RadialDistanceMap>(m, b.cor, p, pl, KernelSet::native);
        const auto generic = rasterized<RadialDistanceMap>(m, b.cor, p, pl, KernelSet::generic);
        std::int64_t differ = 0, covered = 0;
        for (std::int64_t i = 0; i < native.num_nodes(); ++i) {
          differ += std::memcmp(&native.data()[i], &generic.data()[i], sizeof(float)) != 0;
          covered += native.has_surface(i);
        }
        EXPECT_EQ(differ, 0) << m.source << " p=" << p << (pl ? " with plan" : " without plan");
        EXPECT_GT(covered, native.num_nodes() / 10) << m.source;
      }
    }
  }
}

TEST(Kernels, LookUpHalvesGiveIdenticalGaps) {
  SKIP_UNLESS_NATIVE("look-ups avx2");
  KernelScope scope;
  const Bones b = bones();
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g(0, 1);
  for (const TriangleMesh& m : b.meshes) {
    const auto map = rasterized<RadialDistanceMap>(m, b.cor, 0.1, nullptr, KernelSet::native);
    // Directions: every vertex of the other bone's kind, plus random ones, as SoA.
    const std::int64_t n = 20000;
    std::vector<double> x(n), y(n), z(n), a(n), c(n), d(n), e(n);
    for (std::int64_t i = 0; i < n; ++i) {
      x[i] = g(rng), y[i] = g(rng), z[i] = g(rng);
    }
    set_kernel_set(KernelSet::native);
    map.lookup_many_soa(x.data(), y.data(), z.data(), n, a.data());
    map.lookup_many_soa_marked(x.data(), y.data(), z.data(), n, d.data());
    set_kernel_set(KernelSet::generic);
    map.lookup_many_soa(x.data(), y.data(), z.data(), n, c.data());
    map.lookup_many_soa_marked(x.data(), y.data(), z.data(), n, e.data());
    // The same value up to the rounding of one fused multiply-add per weight (a few ulp of the
    // distance), and the same class: NaN (no surface), -inf (marked) or finite.
    std::int64_t differ = 0, finite = 0;
    double worst = 0;
    auto compare = [&](double u, double v) {
      const bool same_class = std::isnan(u) == std::isnan(v) && std::isinf(u) == std::isinf(v);
      if (!same_class) return false;
      if (!std::isfinite(u)) return std::isnan(u) || u == v;
      worst = std::max(worst, std::abs(u - v) / std::abs(u));
      return std::abs(u - v) <= 8 * std::numeric_limits<double>::epsilon() * std::abs(u);
    };
    for (std::int64_t i = 0; i < n; ++i) {
      differ += !compare(a[i], c[i]) + !compare(d[i], e[i]);
      finite += std::isfinite(a[i]);
    }
    EXPECT_EQ(differ, 0) << m.source << ": largest relative difference " << worst;
    EXPECT_GT(finite, n / 4) << m.source;
  }
}

// The Fibonacci lattice's AVX-512 block look-up (zone parameters from registers, for blocks whose
// directions span fewer than kZoneWindow zones) against the generic kernel: the same corners and
// the same weights up to rounding, for blocks of nearby directions at many latitudes (the register
// path, including blocks across zone boundaries and at the poles) and for blocks of random
// directions (which span more zones: the fallback).
TEST(Kernels, FibonacciStencilHalvesAgree) {
  SKIP_UNLESS_NATIVE("fibonacci stencils avx512");
  KernelScope scope;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> g(0, 1);
  std::uniform_real_distribution<double> uni(-1, 1);
  for (double nodes : {1000.0, 82483.0, 8250517.0}) {
    const FibonacciScheme s(nodes);
    for (int block = 0; block < 400; ++block) {
      const int m = 1 + int(rng() % kStencilBlock);
      // Half the blocks: a cone of 0.5 to 20 deg around a random axis (nearby directions, as in a
      // scan set); the other half: random directions.
      const double spread = block % 2 ? 0.0 : 0.009 * (1 + block % 40);
      const Eigen::Vector3d axis = block % 20 == 0 ? Eigen::Vector3d(0, 0, block % 40 ? 1 : -1)
                                                   : Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
      std::vector<double> x(m), y(m), z(m);
      for (int j = 0; j < m; ++j) {
        const Eigen::Vector3d u =
            spread > 0 ? (axis + spread * Eigen::Vector3d(uni(rng), uni(rng), uni(rng))).normalized()
                       : Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
        x[j] = 30 * u.x(), y[j] = 30 * u.y(), z[j] = 30 * u.z();
      }
      std::vector<std::int32_t> na(4 * m), nb(4 * m);
      std::vector<double> wa(4 * m), wb(4 * m);
      set_kernel_set(KernelSet::native);
      s.stencils_soa(x.data(), y.data(), z.data(), m, na.data(), wa.data());
      set_kernel_set(KernelSet::generic);
      s.stencils_soa(x.data(), y.data(), z.data(), m, nb.data(), wb.data());
      for (int j = 0; j < m; ++j) {
        // Compare as stencils: the interpolated direction (sum of weights times node directions)
        // and, away from a cell's or triangle's edge, the nodes themselves; weights differ by the
        // rounding of the lattice coordinates (fused multiply-adds or not: 1e-12 at 8 M nodes).
        Eigen::Vector3d pa = Eigen::Vector3d::Zero(), pb = Eigen::Vector3d::Zero();
        double least = 1;
        for (int k = 0; k < 4; ++k) {
          pa += wa[k * m + j] * s.node_direction(na[k * m + j]);
          pb += wb[k * m + j] * s.node_direction(nb[k * m + j]);
          least = std::min(least, std::abs(wa[k * m + j]) > 0 ? wa[k * m + j] : 1.0);
        }
        ASSERT_LT((pa - pb).norm(), 1e-9) << "n " << nodes << " block " << block << " direction " << j;
        if (least > 1e-9)
          for (int k = 0; k < 4; ++k) {
            EXPECT_EQ(na[k * m + j], nb[k * m + j]) << "n " << nodes << " block " << block << " direction " << j;
            EXPECT_NEAR(wa[k * m + j], wb[k * m + j], 1e-9) << "n " << nodes << " block " << block;
          }
      }
    }
  }
}
