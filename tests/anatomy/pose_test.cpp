// Clinical hip angles (ISB joint coordinate system, Wu et al. 2002). Invariants:
// - signs: + flexion moves the knee (distal femur, -z in the scan frame) anterior (+y), + adduction
//   moves it medial (-x on the right, +x on the left), + internal rotation turns the anterior
//   femur medially; the left side is the right side's mirror image;
// - the JCS is the Cardan sequence Z-X-Y about the pelvic Z, the floating axis and the femoral y:
//   checked against rotations composed from Rodrigues' formula about those axes;
// - jcs_angles inverts jcs_rotation over the whole range, both sides.
#include "impinge/anatomy/pose.hpp"

#include <gtest/gtest.h>

#include <random>

#include "impinge/core/error.hpp"

using namespace impinge;

namespace {
// Rodrigues' rotation about unit axis u by angle a (degrees), independent of Eigen::AngleAxis.
Eigen::Matrix3d rodrigues(const Eigen::Vector3d& u, double a_deg) {
  const double a = a_deg * M_PI / 180;
  Eigen::Matrix3d K;
  K << 0, -u.z(), u.y(), u.z(), 0, -u.x(), -u.y(), u.x(), 0;
  return Eigen::Matrix3d::Identity() + std::sin(a) * K + (1 - std::cos(a)) * K * K;
}
}  // namespace

TEST(Pose, ClinicalDirectionsInTheScanFrame) {
  const Eigen::Vector3d knee(0, 0, -1), front(0, 1, 0);
  EXPECT_GT((pose_rotation({30, 0, 0}, Side::right) * knee).y(), 0.4);
  EXPECT_GT((pose_rotation({30, 0, 0}, Side::left) * knee).y(), 0.4);
  EXPECT_LT((pose_rotation({0, 20, 0}, Side::right) * knee).x(), -0.3);  // adduction: medial, -x on the right
  EXPECT_GT((pose_rotation({0, 20, 0}, Side::left) * knee).x(), 0.3);
  EXPECT_LT((pose_rotation({0, 0, 20}, Side::right) * front).x(), -0.3);  // internal rotation: front turns medial
  EXPECT_GT((pose_rotation({0, 0, 20}, Side::left) * front).x(), 0.3);
  const Eigen::Matrix3d R = pose_rotation({10, 20, 30}, Side::right);
  EXPECT_LT((R * R.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_NEAR(R.determinant(), 1, 1e-12);
}

TEST(Pose, JcsIsFlexionAboutPelvicZThenAdductionAboutTheFloatingAxisThenRotationAboutFemoralY) {
  std::mt19937_64 rng(43);
  std::uniform_real_distribution<double> ang(-120, 120);
  for (int k = 0; k < 200; ++k) {
    const PoseAngles a{ang(rng), ang(rng) * 0.7, ang(rng)};
    for (const Side side : {Side::right, Side::left}) {
      const double m = side == Side::right ? 1 : -1;
      // Extrinsic form: rotate about the femur's own y (still aligned with the pelvic Y), then about
      // the pelvic X (the floating axis before flexion), then about the pelvic Z.
      const Eigen::Matrix3d expect = rodrigues(Eigen::Vector3d::UnitZ(), a.flexion_deg) *
                                     rodrigues(Eigen::Vector3d::UnitX(), m * a.adduction_deg) *
                                     rodrigues(Eigen::Vector3d::UnitY(), m * a.internal_rotation_deg);
      const Eigen::Matrix3d R = jcs_rotation(a, side);
      EXPECT_LT((R - expect).norm(), 1e-12);
      // The floating axis e2 (perpendicular to the pelvic Z and the posed femoral y) is the pelvic X
      // after flexion: the adduction axis.
      const Eigen::Vector3d e1 = Eigen::Vector3d::UnitZ(), e3 = R.col(1);
      const Eigen::Vector3d e2 = e3.cross(e1).normalized();
      EXPECT_NEAR(std::abs(e2.dot(rodrigues(e1, a.flexion_deg) * Eigen::Vector3d::UnitX())), 1.0, 1e-9);
      // Inverse.
      const PoseAngles b = jcs_angles(R, side);
      EXPECT_NEAR(b.adduction_deg, a.adduction_deg, 1e-8);
      EXPECT_LT((jcs_rotation(b, side) - R).norm(), 1e-10);
    }
  }
}

TEST(Pose, ScanNeutralEqualsTheJcsInTheScanAxes) {
  // X = +y (anterior), Y = +z (superior), Z = +x (right): flexion about x, adduction about y,
  // internal rotation about z in the scan frame.
  const PoseAngles a{20, 10, 5};
  const Eigen::Matrix3d expect = rodrigues(Eigen::Vector3d::UnitX(), 20) * rodrigues(Eigen::Vector3d::UnitY(), 10) *
                                 rodrigues(Eigen::Vector3d::UnitZ(), 5);
  EXPECT_LT((pose_rotation(a, Side::right) - expect).norm(), 1e-12);
  AnatomicalFrame scan;
  scan.axes = scan_axes();
  EXPECT_LT((femur_rotation(scan, scan, a, Side::left) - pose_rotation(a, Side::left)).norm(), 1e-12);
}

TEST(Pose, Parse) {
  const PoseAngles p = parse_pose("10,-5.5,3");
  EXPECT_EQ(p.adduction_deg, -5.5);
  EXPECT_EQ(p.internal_rotation_deg, 3);
  EXPECT_THROW(parse_pose("10,5"), Error);
  EXPECT_THROW(parse_pose("a,b,c"), Error);
  EXPECT_THROW(parse_pose("1,2,inf"), Error);
  EXPECT_EQ(parse_neutral("scan", "--neutral"), Neutral::scan);
  EXPECT_THROW(parse_neutral("supine", "--neutral"), Error);
  EXPECT_THROW(jcs_rotation({0, std::nan(""), 0}, Side::right), Error);
}
