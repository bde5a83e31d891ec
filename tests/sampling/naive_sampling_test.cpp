// The naive caster is itself an oracle, so it is checked against closed forms: rays from
// inside a fine sphere hit it at the analytic distance (minus faceting), rays that miss a
// single triangle return nothing, and the nearest of two shells is returned.
#include "impinge/sampling/naive_sampling.hpp"

#include <gtest/gtest.h>

#include <random>

#include "impinge/core/spherical_frame.hpp"
#include "impinge/io/generated_models.hpp"
#include "impinge/schemes/equiangular_grid.hpp"
#include "test_support.hpp"

using namespace impinge;

TEST(NaiveSampling, RayHitsSphereAtAnalyticDistance) {
  const Eigen::Vector3d c(1, 2, 3);
  const TriangleMesh s = make_uv_sphere(10, c, 200, 100);
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> U(0, 1);
  const Eigen::Vector3d o = c + Eigen::Vector3d(1.0, -2.0, 0.5);
  for (int k = 0; k < 200; ++k) {
    const Eigen::Vector3d u = direction(std::acos(2 * U(rng) - 1), 2 * kPi * U(rng));
    const auto hit = cast_ray_naive(s, o, u);
    ASSERT_TRUE(hit.has_value());
    // inscribed mesh: hit inside the sphere by at most the sagitta 10 (1 - cos(1.8 deg / 2 * sqrt 2))
    const double exact = test::ray_sphere_far(o, u, c, 10);
    EXPECT_LE(hit->first, exact + 1e-9);
    EXPECT_GE(hit->first, exact - 5e-3);
  }
}

TEST(NaiveSampling, NearestOfTwoShellsAndMisses) {
  const TriangleMesh cup = make_cup(20, 25, 60, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 24, 6);
  const auto up = cast_ray_naive(cup, Eigen::Vector3d::Zero(), direction(0.3, 0.4));
  ASSERT_TRUE(up.has_value());
  // inner shell (faceted: 24 segments, sagitta over a cell diagonal < 0.35 mm), not outer
  EXPECT_LE(up->first, 20 + 1e-9);
  EXPECT_GE(up->first, 20 - 0.35);
  EXPECT_FALSE(cast_ray_naive(cup, Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, -1)).has_value());
  RadialDistanceMap map{EquiangularGrid(5)};
  sample_naive(cup, Eigen::Vector3d::Zero(), map);
  EXPECT_TRUE(map.has_surface(0));                     // north pole row
  EXPECT_FALSE(map.has_surface(map.num_nodes() - 1));  // south pole row: no cup there
}

// cast_rays_naive (several rays in one pass, used by the rasterisation plan) against cast_ray_naive ray by ray:
// the same nearest triangle and the same distance to the bit, hits and misses alike (rays from inside a cup).
TEST(NaiveSampling, RaysInOnePassEqualOneByOne) {
  const TriangleMesh cup = make_cup(20, 25, 60, Eigen::Vector3d(1, -2, 3), Eigen::Vector3d(0.2, 0.1, 1).normalized(), 48,
                                    12);
  const Eigen::Vector3d o(1.5, -2.5, 3.2);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> U(0, 1);
  std::vector<Eigen::Vector3d> dirs;
  for (int k = 0; k < 64; ++k) dirs.push_back(direction(std::acos(2 * U(rng) - 1), 2 * kPi * U(rng)));
  // And rays through corners and edge midpoints (where two or more triangles tie, edges inclusive): the same
  // first triangle of the tie.
  for (Eigen::Index f = 0; f < cup.F.rows(); f += 97) {
    const Eigen::Vector3d a = cup.V.row(cup.F(f, 0)).transpose(), b = cup.V.row(cup.F(f, 1)).transpose();
    dirs.push_back((a - o).normalized());
    dirs.push_back((0.5 * (a + b) - o).normalized());
  }
  const auto all = cast_rays_naive(cup, o, dirs);
  ASSERT_EQ(all.size(), dirs.size());
  int hits = 0;
  for (std::size_t k = 0; k < dirs.size(); ++k) {
    const auto one = cast_ray_naive(cup, o, dirs[k]);
    ASSERT_EQ(all[k].has_value(), one.has_value()) << k;
    if (!one) continue;
    ++hits;
    EXPECT_EQ(all[k]->first, one->first) << k;
    EXPECT_EQ(all[k]->second, one->second) << k;
  }
  EXPECT_GT(hits, 10);
  EXPECT_LT(hits, static_cast<int>(dirs.size()));  // both hits and misses were compared
  EXPECT_TRUE(cast_rays_naive(cup, o, {}).empty());
}
