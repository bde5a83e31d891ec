// Thesis Eq. 5 and 6 are inverse to each other; theta is wrapped into [0, 2 pi).
#include "impinge/core/spherical_frame.hpp"

#include <gtest/gtest.h>

#include <random>

using namespace impinge;

TEST(SphericalFrame, Eq5AndEq6RoundTrip) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> U(-50, 50);
  for (int k = 0; k < 1000; ++k) {
    const Eigen::Vector3d p(U(rng), U(rng), U(rng));
    const SphericalCoordinates s = to_spherical(p);
    EXPECT_GE(s.theta, 0);
    EXPECT_LT(s.theta, 2 * kPi);
    EXPECT_GE(s.phi, 0);
    EXPECT_LE(s.phi, kPi);
    EXPECT_LT((s.d * direction(s.phi, s.theta) - p).norm(), 1e-12 * (1 + p.norm()));
  }
  EXPECT_NEAR(to_spherical({0, -1, 0}).theta, 1.5 * kPi, 1e-15);
  EXPECT_EQ(to_spherical({0, 0, 0}).d, 0);
  EXPECT_EQ(to_spherical({0, 0, -2}).phi, kPi);
}
