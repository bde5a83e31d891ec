// femoral_version_deg (clinical/morphology.hpp) against a closed-form construction: in a frame whose z is the
// projection axis and whose x is the condylar axis towards medial, a neck axis at azimuth theta towards anterior
// (+y) reads theta whatever its component along z, the condyles' heights along z, or how the frame is turned in
// space. Across another axis (the mechanical axis, tilted from the shaft) the same neck reads the azimuth of its
// projection there, computed here by rotating that axis onto z (an independent path).
#include "impinge/clinical/morphology.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

namespace impinge {
namespace {

constexpr double kDeg = 180.0 / M_PI;

// The azimuth (deg) of v about `axis`, from `x` towards `axis` x `x`, by turning `axis` onto z and `x` into the xz
// plane.
double azimuth_deg(const Eigen::Vector3d& v, const Eigen::Vector3d& axis, const Eigen::Vector3d& x) {
  const Eigen::Matrix3d R = Eigen::Quaterniond::FromTwoVectors(axis, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d xr = R * x;
  const double turn = -std::atan2(xr.y(), xr.x());
  const Eigen::Vector3d w = Eigen::AngleAxisd(turn, Eigen::Vector3d::UnitZ()) * (R * v);
  return std::atan2(w.y(), w.x()) * kDeg;
}

TEST(FemoralVersion, ReadsTheNecksAzimuthAcrossTheGivenAxis) {
  std::mt19937 rng(81);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 200; ++trial) {
    // A random frame: z the projection axis, x towards medial, y anterior.
    const Eigen::Matrix3d Q = Eigen::Quaterniond(Eigen::Vector4d(u(rng), u(rng), u(rng), u(rng)).normalized())
                                  .toRotationMatrix();
    const Eigen::Vector3d x = Q.col(0), y = Q.col(1), z = Q.col(2);
    const double theta = 160 * u(rng);  // the version, deg
    const Eigen::Vector3d neck =
        std::cos(theta / kDeg) * x + std::sin(theta / kDeg) * y + 3 * u(rng) * z;  // any slope along z
    const Eigen::Vector3d knee(10 * u(rng), 10 * u(rng), 10 * u(rng));
    const Eigen::Vector3d medial = knee + 25 * x + 5 * u(rng) * z, lateral = knee - 22 * x + 5 * u(rng) * z;
    const Eigen::Vector3d anterior = y + 0.7 * u(rng) * x + 2 * u(rng) * z;  // on the anterior side only
    EXPECT_NEAR(femoral_version_deg(neck, medial, lateral, 7.5 * z, anterior), theta, 1e-9) << trial;
    EXPECT_NEAR(femoral_version_deg(neck, medial, lateral, z, -anterior), -theta, 1e-9) << trial;
    // Across an axis tilted 8 deg from z (the mechanical axis beside the shaft): the azimuth of the neck about it,
    // from the condylar axis projected there.
    const Eigen::Vector3d tilted = Eigen::AngleAxisd(8 / kDeg, (x + u(rng) * y).normalized()) * z;
    const Eigen::Vector3d cx = (medial - lateral) - (medial - lateral).dot(tilted) * tilted;
    EXPECT_NEAR(femoral_version_deg(neck, medial, lateral, tilted, anterior), azimuth_deg(neck, tilted, cx), 1e-9)
        << trial;
  }
}

}  // namespace
}  // namespace impinge
