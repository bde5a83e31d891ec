// Pose angles: + flexion moves the knee (distal femur, -z) anterior (+y), + abduction moves it
// lateral (+x on the right, -x on the left), + rotation turns the anterior femur medially.
#include "impinge/pose.hpp"

#include <gtest/gtest.h>

#include "impinge/error.hpp"

using namespace impinge;

TEST(Pose, AnatomicalDirections) {
  const Eigen::Vector3d knee(0, 0, -1), front(0, 1, 0);
  EXPECT_GT((pose_rotation({30, 0, 0}, Side::right) * knee).y(), 0.4);
  EXPECT_GT((pose_rotation({0, 20, 0}, Side::right) * knee).x(), 0.3);
  EXPECT_LT((pose_rotation({0, 20, 0}, Side::left) * knee).x(), -0.3);
  EXPECT_LT((pose_rotation({0, 0, 20}, Side::right) * front).x(), -0.3);  // medial is -x on the right
  EXPECT_GT((pose_rotation({0, 0, 20}, Side::left) * front).x(), 0.3);
  const Eigen::Matrix3d R = pose_rotation({10, 20, 30}, Side::right);
  EXPECT_LT((R * R.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_NEAR(R.determinant(), 1, 1e-12);
}

TEST(Pose, Parse) {
  const PoseAngles p = parse_pose("10,-5.5,3");
  EXPECT_EQ(p.abduction_deg, -5.5);
  EXPECT_THROW(parse_pose("10,5"), Error);
  EXPECT_THROW(parse_pose("a,b,c"), Error);
  EXPECT_THROW(parse_pose("1,2,inf"), Error);
}
