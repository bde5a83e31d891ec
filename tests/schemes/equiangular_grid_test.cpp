// Invariants: node counts follow thesis Table 2; node(direction(i)) == i off the poles; every
// pole-row node points at the pole; stencils have non-negative weights summing to 1 and
// reproduce the direction's (phi, theta) bilinearly; bad precisions throw.
#include "impinge/schemes/equiangular_grid.hpp"

#include <gtest/gtest.h>

#include <random>

#include "impinge/core/error.hpp"
#include "impinge/core/spherical_frame.hpp"

using namespace impinge;

TEST(EquiangularGrid, NodeCountsMatchThesisTable2) {
  // Table 2: (180/p + 1) * (360/p)
  EXPECT_EQ(EquiangularGrid(1).num_nodes(), 65160);
  EXPECT_EQ(EquiangularGrid(0.5).num_nodes(), 259920);
  EXPECT_EQ(EquiangularGrid(0.1).num_nodes(), 6483600);
  EXPECT_EQ(EquiangularGrid(0.05).num_nodes(), 25927200);
}

TEST(EquiangularGrid, NodeOfDirectionRoundTrips) {
  for (double p : {5.0, 1.0, 0.5, 0.25}) {
    const EquiangularGrid g(p);
    for (std::int64_t i = g.columns(); i < g.num_nodes() - g.columns(); ++i)
      ASSERT_EQ(g.node(g.node_direction(i)), i) << "p=" << p << " i=" << i;
    for (int c = 0; c < g.columns(); ++c) {
      EXPECT_EQ(g.node_direction(c), Eigen::Vector3d(0, 0, 1));
      EXPECT_EQ(g.node_direction(g.num_nodes() - 1 - c), Eigen::Vector3d(0, 0, -1));
    }
  }
}

TEST(EquiangularGrid, StencilIsBilinearInPhiTheta) {
  const EquiangularGrid g(1.0);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> U(0, 1);
  for (int k = 0; k < 2000; ++k) {
    const double phi = std::acos(2 * U(rng) - 1), theta = 2 * kPi * U(rng);
    const Stencil s = g.interpolate(direction(phi, theta));
    double wsum = 0, phi_i = 0;
    for (int j = 0; j < 4; ++j) {
      EXPECT_GE(s.weights[j], -1e-15);
      wsum += s.weights[j];
      phi_i += s.weights[j] * (s.nodes[j] / g.columns()) * g.step();
    }
    EXPECT_NEAR(wsum, 1.0, 1e-12);
    EXPECT_NEAR(phi_i, phi, 1e-9);  // phi is linear in the row index
  }
  EXPECT_NEAR(g.max_node_spacing(), kPi / 180, 1e-15);
}

TEST(EquiangularGrid, RejectsBadPrecision) {
  EXPECT_THROW(EquiangularGrid(0), Error);
  EXPECT_THROW(EquiangularGrid(-1), Error);
  EXPECT_THROW(EquiangularGrid(0.7), Error);  // 180 / 0.7 not integral
  EXPECT_THROW(EquiangularGrid(std::nan("")), Error);
  EXPECT_NO_THROW(EquiangularGrid(0.05));
}
