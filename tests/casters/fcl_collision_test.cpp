// fcl_collision.hpp and pairwise.hpp (the two collision baselines). Invariants checked:
//  - the generated hip (2.5 mm cartilage gap) has no contact at the neutral pose in either;
//  - pushed 3 mm into the cup, both report contacts, and FCL's triangle pairs equal the
//    exhaustive pair-wise count (two independent triangle-triangle tests);
//  - FCL's distance at the neutral pose is the cartilage gap of the faceted model (within the
//    facets' sagitta) and 0 when pushed in;
//  - the pair-wise region keeps only triangles near the COR.
#include "impinge/casters/fcl_collision.hpp"

#include <gtest/gtest.h>

#include "impinge/casters/exact_reference.hpp"
#include "impinge/casters/pairwise.hpp"
#include "impinge/io/generated_models.hpp"

using namespace impinge;

namespace {
HipModel hip(int triangles) {
  HipModelOptions o;
  o.target_triangles = triangles;
  return make_hip_model(o);
}
/// Push direction: from the COR towards the cup's pole (the socket's vertex centroid).
Eigen::Vector3d push(const HipModel& h, double mm) {
  return (h.socket.V.colwise().mean().transpose() - h.cor).normalized() * mm;
}
}  // namespace

TEST(FclJoint, NoContactAtRestContactsWhenPushedAndTheGap) {
  if (!have_fcl()) GTEST_SKIP() << "FCL missing in this build";
  const HipModel h = hip(3000);
  const FclJoint j(h.ball, h.socket, h.cor);
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  EXPECT_EQ(j.collide(I, Eigen::Vector3d::Zero()).contacts, 0);
  EXPECT_GT(j.collide(I, push(h, 3)).contacts, 0);
  const double d = j.distance(I, Eigen::Vector3d::Zero());
  EXPECT_GT(d, 2.0);
  EXPECT_LT(d, 2.6);
  EXPECT_LE(j.distance(I, push(h, 3)), 0.0);
}

TEST(PairwiseJoint, CountsTheSamePairsAsFcl) {
  if (!have_fcl() || !have_exact_reference()) GTEST_SKIP() << "FCL or CGAL missing in this build";
  const HipModel h = hip(1000);
  const FclJoint f(h.ball, h.socket, h.cor);
  const PairwiseJoint p(h.ball, h.socket, h.cor);
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  EXPECT_EQ(p.intersect(I, Eigen::Vector3d::Zero()).intersecting_pairs, 0);
  const PairwiseResult r = p.intersect(I, push(h, 3));
  EXPECT_EQ(r.pairs_tested, r.ball_triangles * r.socket_triangles);
  EXPECT_EQ(r.ball_triangles, h.ball.F.rows());
  const std::int64_t fc = f.collide(I, push(h, 3)).contacts;
  EXPECT_GT(r.intersecting_pairs, 0);
  EXPECT_NEAR(double(r.intersecting_pairs), double(fc), 0.01 * double(fc) + 1);
}

TEST(PairwiseJoint, RegionKeepsOnlyTrianglesNearTheCor) {
  if (!have_exact_reference()) GTEST_SKIP() << "CGAL missing in this build";
  const HipModel h = hip(1000);
  const PairwiseJoint all(h.ball, h.socket, h.cor), near(h.ball, h.socket, h.cor, 23.0);
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const PairwiseResult a = all.intersect(I, Eigen::Vector3d::Zero()), b = near.intersect(I, Eigen::Vector3d::Zero());
  EXPECT_LT(b.ball_triangles, a.ball_triangles);  // the neck reaches 50 mm
  EXPECT_GT(b.ball_triangles, 0);
  EXPECT_LE(b.socket_triangles, a.socket_triangles);
  EXPECT_THROW(PairwiseJoint(h.ball, h.socket, h.cor, -1.0), std::exception);
}
