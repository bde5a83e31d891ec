// CGAL exact references against closed forms: first hit from inside a fine sphere and closest
// distance from outside; the point index against brute force.
#include "impinge/casters/exact_reference.hpp"

#include <gtest/gtest.h>

#include <random>

#include "impinge/core/spherical_frame.hpp"
#include "impinge/io/generated_models.hpp"
#include "impinge/sampling/naive_sampling.hpp"
#include "test_support.hpp"

using namespace impinge;

TEST(ExactReference, FirstHitAndClosestDistance) {
  if (!have_exact_reference()) GTEST_SKIP() << "built without CGAL";
  const Eigen::Vector3d c(1, 2, 3);
  const TriangleMesh s = make_uv_sphere(10, c, 120, 60, Eigen::Vector3d(0.1, 0.2, 1));
  const ExactReference ref(s);
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> U(0, 1);
  const Eigen::Vector3d o = c + Eigen::Vector3d(0.5, -1, 2);
  for (int k = 0; k < 300; ++k) {
    const Eigen::Vector3d u = direction(std::acos(2 * U(rng) - 1), 2 * kPi * U(rng));
    const auto t = ref.first_hit(o, u);
    ASSERT_TRUE(t.has_value());
    EXPECT_NEAR(*t, cast_ray_naive(s, o, u)->first, 1e-9);  // the naive caster, independent code
    const Eigen::Vector3d far = c + 15 * u;
    EXPECT_NEAR(ref.closest_distance(far), 5, 0.05);  // inscribed mesh: within the facet sagitta
  }
  EXPECT_FALSE(ref.first_hit(c + Eigen::Vector3d(50, 0, 0), Eigen::Vector3d(1, 0, 0)).has_value());
}

TEST(ExactReference, PointIndexMatchesBruteForce) {
  if (!have_exact_reference()) GTEST_SKIP() << "built without CGAL";
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> U(-10, 10);
  std::vector<Eigen::Vector3d> pts(2000);
  for (auto& p : pts) p = {U(rng), U(rng), U(rng)};
  const PointCloudIndex index(pts);
  for (int k = 0; k < 200; ++k) {
    const Eigen::Vector3d q(U(rng), U(rng), U(rng));
    double best = 1e9;
    for (const auto& p : pts) best = std::min(best, (p - q).norm());
    EXPECT_NEAR(index.nearest_distance(q), best, 1e-12);
  }
}
