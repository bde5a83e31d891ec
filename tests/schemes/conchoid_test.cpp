// Conchoid (thesis sec. 5.1): GSL arc length against closed forms (b = 0: a circle, a * phi;
// a -> b: the cardioid, 4 a sin(phi / 2)); Table 10 and the closed form 3.03 b to the printed
// digits; equal-length angles cut the curve into equal lengths; a ray from an origin on the axis meets
// the curve where the closed-form direction of that point says (and from the conchoid's own origin, at
// its own angle), and equal-angle rays from there cut segments whose lengths follow
// sqrt(a^2 + b^2 + 2ab cos phi) (thesis Fig. 53); the weighted grid keeps the scheme invariants.
#include "impinge/schemes/conchoid.hpp"

#include <gtest/gtest.h>

#include <random>

#include "impinge/core/error.hpp"
#include "impinge/core/spherical_frame.hpp"
#include "impinge/maps/radial_distance_map.hpp"
#include "impinge/schemes/conchoid_grid.hpp"

using namespace impinge;

TEST(Conchoid, ArcLengthClosedForms) {
  const Conchoid circle(20, 0);
  for (double phi : {0.1, 1.0, kPi / 2, kPi}) EXPECT_NEAR(circle.arc_length(phi), 20 * phi, 1e-10);
  const Conchoid cardioid(10 + 1e-9, 10);
  for (double phi : {0.3, 1.2, kPi / 2, 2.5}) EXPECT_NEAR(cardioid.arc_length(phi), 40 * std::sin(phi / 2), 1e-6);
  EXPECT_THROW(Conchoid(1, 2), Error);
}

TEST(Conchoid, ThesisNumbersToPrintedDigits) {
  EXPECT_NEAR(conchoid_length_thesis(1.0), 3.03, 0.005);    // "3.03 b"
  EXPECT_NEAR(kMenschikA / kMenschikB, 1.15, 0.005);        // "a = 1.15 b"
  const std::vector<double> t10 = conchoid_angles_eq16(4);  // Table 10: 0, 27, 56, 90 deg
  const double printed[] = {0, 27, 56, 90};
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(t10[i] * kRadToDeg, printed[i], 0.5) << i;
  // Eq. 16 at 1 deg: phi_i = 2 asin(0.00785 i)
  EXPECT_NEAR(conchoid_angles_eq16(91)[10], 2 * std::asin(0.0785), 2e-4);
}

TEST(Conchoid, EqualLengthAnglesCutEqualLengths) {
  const Conchoid c(kMenschikA, kMenschikB);
  const std::vector<double> a = c.equal_length_angles(31, kPi / 2);
  const double seg = c.arc_length(kPi / 2) / 30;
  for (int i = 1; i < 31; ++i) EXPECT_NEAR(c.arc_length(a[i]) - c.arc_length(a[i - 1]), seg, 1e-9);
  // the rays near the pole (long curve, r large) are closer together than equal angles
  EXPECT_LT(a[1], kPi / 2 / 30);
}

TEST(Conchoid, RaysFromAnOriginOnTheAxisMeetTheCurveWhereItsDirectionSays) {
  const Conchoid c(kMenschikA, kMenschikB);
  for (double psi : {0.0, 0.2, 0.9, kPi / 2 - 1e-3}) EXPECT_NEAR(c.angle_seen_from(0, psi, kPi / 2), psi, 1e-12);
  for (double cx : {5.0, 15.39, kMenschikB})
    for (double psi : {0.05, 0.7, 1.5, 2.0}) {
      const double rim = std::atan2(c.radius(kPi / 2), -cx);  // the last direction that meets phi <= 90 deg
      if (psi > rim) continue;
      const double phi = c.angle_seen_from(cx, psi, kPi / 2);
      const double r = c.radius(phi);
      EXPECT_NEAR(std::atan2(r * std::sin(phi), r * std::cos(phi) - cx), psi, 1e-11) << cx << " " << psi;
    }
  EXPECT_THROW(c.angle_seen_from(kMenschikB + 1, 0.5, kPi / 2), Error);  // outside [0, b]
  EXPECT_THROW(c.angle_seen_from(5.0, 3.0, kPi / 2), Error);             // misses the hip curve
  // Thesis Fig. 53 b: from the conchoid's origin, equal-angle segments run from (a + b) dphi at the pole to
  // sqrt(a^2 + b^2) dphi at the rim: 40 % longer at the bottom, not the thesis' 30 %.
  const double d = kPi / 1800, a = kMenschikA, b = kMenschikB;
  EXPECT_NEAR(c.arc_length(d) / (c.arc_length(kPi / 2) - c.arc_length(kPi / 2 - d)), (a + b) / std::hypot(a, b), 1e-3);
}

TEST(ConchoidGrid, SchemeInvariants) {
  const ConchoidGrid g(2);
  EXPECT_EQ(g.num_nodes(), (180 / 2 + 1) * (360 / 2));  // equal node count to the equiangular grid
  for (std::int64_t i = g.columns(); i < g.num_nodes() - g.columns(); ++i) ASSERT_EQ(g.node(g.node_direction(i)), i);
  RadialDistanceMap map{g};
  std::fill(map.data(), map.data() + map.num_nodes(), 9.5f);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> U(0, 1);
  for (int j = 0; j < 2000; ++j) {
    const Eigen::Vector3d u = direction(std::acos(2 * U(rng) - 1), 2 * kPi * U(rng));
    EXPECT_NEAR(map.lookup(u), 9.5, 1e-5);
  }
  EXPECT_THROW(ConchoidGrid(0.7), Error);
}
