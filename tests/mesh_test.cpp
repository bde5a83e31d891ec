// submesh: the triangles whose corners are all kept, vertices renumbered in order of first use;
// checked against a hand-built two-triangle square and brute-force counts on a generated hip.
#include "impinge/mesh.hpp"

#include <gtest/gtest.h>

#include "impinge/error.hpp"
#include "impinge/generated_models.hpp"

using namespace impinge;

TEST(Mesh, SubmeshKeepsTrianglesWhoseCornersAreAllKept) {
  TriangleMesh sq;
  sq.source = "square";
  sq.V.resize(4, 3);
  sq.V << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
  sq.F.resize(2, 3);
  sq.F << 0, 1, 2, 0, 2, 3;
  std::vector<Eigen::Index> kept;
  const TriangleMesh a = submesh(sq, {1, 0, 1, 1}, &kept);  // drops vertex 1 and so triangle 0
  ASSERT_EQ(a.F.rows(), 1);
  EXPECT_EQ(kept, (std::vector<Eigen::Index>{0, 2, 3}));
  for (int c = 0; c < 3; ++c) EXPECT_EQ(a.V.row(a.F(0, c)), sq.V.row(sq.F(1, c)));
  EXPECT_EQ(submesh(sq, {0, 0, 0, 0}).F.rows(), 0);
  EXPECT_THROW(submesh(sq, {1, 1}), Error);

  const HipModel h = make_hip_model({});
  std::vector<std::uint8_t> keep(static_cast<std::size_t>(h.ball.V.rows()));
  for (Eigen::Index i = 0; i < h.ball.V.rows(); ++i) keep[static_cast<std::size_t>(i)] = h.ball.V(i, 2) > h.cor.z();
  Eigen::Index expect = 0;
  for (Eigen::Index f = 0; f < h.ball.F.rows(); ++f)
    expect += keep[h.ball.F(f, 0)] && keep[h.ball.F(f, 1)] && keep[h.ball.F(f, 2)];
  const TriangleMesh b = submesh(h.ball, keep);
  EXPECT_EQ(b.F.rows(), expect);
  EXPECT_NO_THROW(validate_mesh(b));
  EXPECT_GT(b.V.col(2).minCoeff(), h.cor.z());
}
