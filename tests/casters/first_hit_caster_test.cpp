// FirstHitCaster (issue 15): the exact first hit from the COR, against CGAL's AABB tree (double) as
// the oracle. Invariants: random rays agree with CGAL; a ray along a triangle edge-on to the COR
// (the radial rim of a generated cup) meets the rim's inner edge, not a meaningless distance; a ray
// exactly through a vertex shared by a fan does not slip between its triangles.
#include <gtest/gtest.h>

#include <random>

#include "impinge/casters/exact_reference.hpp"
#include "impinge/casters/first_hit_caster.hpp"
#include "impinge/core/error.hpp"
#include "impinge/io/generated_models.hpp"

using namespace impinge;

TEST(FirstHitCaster, AgreesWithCgalOnRandomRays) {
  if (!have_exact_reference() || !FirstHitCaster::available()) GTEST_SKIP() << "no CGAL or Embree in this build";
  HipModelOptions ho;
  ho.target_triangles = 3000;
  const HipModel h = make_hip_model(ho);
  for (const TriangleMesh* m : {&h.ball, &h.socket}) {
    const FirstHitCaster c(*m, h.cor);
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

TEST(FirstHitCaster, EdgeOnRimAndRaysThroughVerticesGiveTheNearestSurface) {
  if (!FirstHitCaster::available()) GTEST_SKIP() << "no ray caster in this build";
  const Eigen::Vector3d cor(10, -20, 30), axis = Eigen::Vector3d(-0.5, 0.1, 0.86).normalized();
  // Inner shell 25 mm, outer 30 mm, both on the same angular grid, joined by a radial rim at 100 deg:
  // every outer-shell vertex lies exactly behind an inner-shell vertex, and the rim is edge-on.
  const TriangleMesh cup = make_cup(25, 30, 100, cor, axis, 360, 100);
  const FirstHitCaster c(cup, cor);
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

TEST(FirstHitCaster, RejectsABadOrigin) {
  if (!FirstHitCaster::available()) GTEST_SKIP() << "no ray caster in this build";
  const TriangleMesh s = make_uv_sphere(10, Eigen::Vector3d::Zero(), 20, 10, Eigen::Vector3d::UnitZ());
  EXPECT_THROW(FirstHitCaster(s, Eigen::Vector3d(std::nan(""), 0, 0)), Error);
}
