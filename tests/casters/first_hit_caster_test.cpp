// FirstHitCaster (issue 15): the exact first hit from the COR, against CGAL's AABB tree (double) as
// the oracle. Invariants: random rays agree with CGAL; a ray along a triangle edge-on to the COR
// (the radial rim of a generated cup) meets the rim's inner edge, not a meaningless distance; a ray
// exactly through a vertex shared by a fan does not slip between its triangles; all of it with either of
// Embree's tree builders (HierarchyBuild), which give the same hits.
#include "impinge/casters/first_hit_caster.hpp"

#include <gtest/gtest.h>

#include <random>

#include "impinge/casters/exact_reference.hpp"
#include "impinge/core/error.hpp"
#include "impinge/io/generated_models.hpp"

using namespace impinge;

TEST(FirstHitCaster, AgreesWithCgalOnRandomRays) {
  if (!have_exact_reference() || !FirstHitCaster::available()) GTEST_SKIP() << "no CGAL or Embree in this build";
  HipModelOptions ho;
  ho.target_triangles = 3000;
  const HipModel h = make_hip_model(ho);
  for (const TriangleMesh* m : {&h.ball, &h.socket})
    for (const HierarchyBuild build : {HierarchyBuild::quality, HierarchyBuild::fast}) {
      const FirstHitCaster c(*m, h.cor, build);
      const ExactReference ref(*m);
      std::mt19937_64 rng(7);
      std::normal_distribution<double> g;
      int hits = 0;
      for (int k = 0; k < 2000; ++k) {
        const Eigen::Vector3d u = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
        const auto want = ref.first_hit(h.cor, u);
        const double got = c.first_hit(3.7 * u);  // any length
        if (!want) {
          EXPECT_TRUE(std::isinf(got)) << k;
          continue;
        }
        ++hits;
        EXPECT_NEAR(got, *want, 1e-3) << k;
      }
      EXPECT_GT(hits, 200);
    }
}

// The two builders (issue 52: the fast one for a few poses) differ in the tree only: every ray of a hip model,
// random and through every vertex (shared vertices, the case watertightness is about), gives the same first hit and
// the same crossings, bit for bit.
TEST(FirstHitCaster, FastAndQualityTreesGiveTheSameHits) {
  if (!have_embree()) GTEST_SKIP() << "no Embree in this build (CGAL's tree has one build)";
  HipModelOptions ho;
  ho.target_triangles = 20000;
  const HipModel h = make_hip_model(ho);
  for (const TriangleMesh* m : {&h.ball, &h.socket}) {
    const FirstHitCaster quality(*m, h.cor, HierarchyBuild::quality), fast(*m, h.cor, HierarchyBuild::fast);
    EXPECT_EQ(quality.orientation(), fast.orientation());
    EXPECT_EQ(quality.origin_inside(), fast.origin_inside());
    std::vector<Eigen::Vector3d> rays;
    std::mt19937_64 rng(11);
    std::normal_distribution<double> g;
    for (int k = 0; k < 5000; ++k) rays.emplace_back(g(rng), g(rng), g(rng));
    for (Eigen::Index i = 0; i < m->V.rows(); ++i) rays.push_back(m->V.row(i).transpose() - h.cor);
    std::vector<RayCrossing> a, b;
    int hits = 0;
    for (std::size_t k = 0; k < rays.size(); ++k) {
      const double q = quality.first_hit(rays[k]);
      ASSERT_EQ(q, fast.first_hit(rays[k])) << "ray " << k;
      hits += std::isfinite(q);
      quality.crossings(rays[k], a);
      fast.crossings(rays[k], b);
      ASSERT_EQ(a.size(), b.size()) << "ray " << k;
      for (std::size_t j = 0; j < a.size(); ++j) {
        ASSERT_EQ(a[j].distance_mm, b[j].distance_mm) << "ray " << k << " crossing " << j;
        ASSERT_EQ(a[j].entering, b[j].entering) << "ray " << k << " crossing " << j;
      }
    }
    EXPECT_GT(hits, 5000);
  }
}

TEST(FirstHitCaster, EdgeOnRimAndRaysThroughVerticesGiveTheNearestSurface) {
  if (!FirstHitCaster::available()) GTEST_SKIP() << "no ray caster in this build";
  const Eigen::Vector3d cor(10, -20, 30), axis = Eigen::Vector3d(-0.5, 0.1, 0.86).normalized();
  // Inner shell 25 mm, outer 30 mm, both on the same angular grid, joined by a radial rim at 100 deg:
  // every outer-shell vertex lies exactly behind an inner-shell vertex, and the rim is edge-on.
  const TriangleMesh cup = make_cup(25, 30, 100, cor, axis, 360, 100);
  for (const HierarchyBuild build : {HierarchyBuild::quality, HierarchyBuild::fast}) {
    const FirstHitCaster c(cup, cor, build);
    EXPECT_GT(c.edge_on_triangles(), 0);
    int checked = 0;
    for (Eigen::Index i = 0; i < cup.V.rows(); ++i) {
      const Eigen::Vector3d p = cup.V.row(i).transpose() - cor;
      const double polar = std::acos(std::clamp(p.normalized().dot(axis), -1.0, 1.0)) * 180 / 3.141592653589793;
      if (p.norm() < 29 || polar > 100 + 1e-9) continue;  // outer-shell vertices, rim included
      ++checked;
      ASSERT_NEAR(c.first_hit(p), 25.0, 1e-4) << "outer vertex " << i << " at " << polar << " deg";
    }
    EXPECT_GT(checked, 30000);
  }
}

TEST(FirstHitCaster, RejectsABadOrigin) {
  if (!FirstHitCaster::available()) GTEST_SKIP() << "no ray caster in this build";
  const TriangleMesh s = make_uv_sphere(10, Eigen::Vector3d::Zero(), 20, 10, Eigen::Vector3d::UnitZ());
  EXPECT_THROW(FirstHitCaster(s, Eigen::Vector3d(std::nan(""), 0, 0)), Error);
}

// first_hit with a bound (the first-surface mask's question, issue 52): against the unbounded first hit, the
// same value when that is nearer than the bound (also just inside it), and a value at least the bound
// otherwise; nothing is nearer than a bound <= 0 or NaN.
TEST(FirstHitCaster, BoundedFirstHitIsTheFirstHitWhenNearer) {
  if (!FirstHitCaster::available()) GTEST_SKIP() << "no ray caster in this build";
  HipModelOptions ho;
  ho.target_triangles = 3000;
  const HipModel h = make_hip_model(ho);
  for (const HierarchyBuild build : {HierarchyBuild::quality, HierarchyBuild::fast}) {
    const FirstHitCaster c(h.socket, h.cor, build);
    std::mt19937_64 rng(3);
    std::normal_distribution<double> g;
    std::uniform_real_distribution<double> scale(0.5, 1.5);
    int nearer = 0, beyond = 0;
    for (int k = 0; k < 3000; ++k) {
      const Eigen::Vector3d u(g(rng), g(rng), g(rng));
      const double full = c.first_hit(u);
      if (!std::isfinite(full)) {
        EXPECT_TRUE(std::isinf(c.first_hit(u, 100.0))) << k;
        continue;
      }
      // A random bound, and bounds a hair either side of the hit itself.
      for (const double within : {full * scale(rng), std::nextafter(full, 0.0), full,
                                  std::nextafter(full, std::numeric_limits<double>::infinity()), full * (1 + 1e-6)}) {
        const double got = c.first_hit(u, within);
        if (full < within) {
          ++nearer;
          ASSERT_EQ(got, full) << "ray " << k << " bound " << within;
        } else {
          ++beyond;
          ASSERT_GE(got, within) << "ray " << k << " bound " << within;
        }
      }
      EXPECT_TRUE(std::isinf(c.first_hit(u, 0.0)));
      EXPECT_TRUE(std::isinf(c.first_hit(u, -1.0)));
      EXPECT_TRUE(std::isinf(c.first_hit(u, std::nan(""))));
    }
    EXPECT_GT(nearer, 1000);
    EXPECT_GT(beyond, 1000);
  }
}
