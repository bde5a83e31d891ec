// fast_angles.hpp and the fast look-up it serves. Invariants checked:
//  - fast_polar_angle and fast_azimuth are within kFastAngleMaxError (1e-13 rad) of long-double
//    atan2 on 4 million random directions and on every edge case (axes, signed zeros, octant
//    boundaries, tiny and huge components);
//  - fast_acos_coarse is within kFastAcosCoarseMaxError (3e-8 rad) of long-double acos on a
//    dense grid of [-1, 1] (refined near +-1, where acos is steepest) and at the ends;
//  - the vectorised equiangular look-up (scan_gaps_compact) moves no gap by more than 1e-4 mm
//    against a reference that uses libm acos/atan2 and the same bilinear stencil, on the
//    generated 12k hip and on a real subject when ../shared/data is present.
#include "impinge/core/fast_angles.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>

#include "impinge/anatomy/sphere_fit.hpp"
#include "impinge/detection/detection.hpp"
#include "impinge/io/generated_models.hpp"
#include "impinge/io/mesh_io.hpp"
#include "impinge/sampling/sampling.hpp"
#include "test_support.hpp"

using namespace impinge;

namespace {
long double exact_polar(double rho, double z) { return std::atan2((long double)rho, (long double)z); }
long double exact_azimuth(double y, double x) {
  long double a = std::atan2((long double)y, (long double)x);
  return a < 0 ? a + 2 * 3.14159265358979323846264338327950288L : a;
}

void expect_angles(double x, double y, double z) {
  const double rho = std::sqrt(x * x + y * y);
  if (rho == 0 && z == 0) return;  // underflows to the zero vector: no direction (callers skip it)
  EXPECT_LE(std::abs((long double)fast_polar_angle(rho, z) - exact_polar(rho, z)), kFastAngleMaxError)
      << x << " " << y << " " << z;
  if (rho == 0) return;  // on the axis the azimuth is arbitrary
  long double da = std::abs((long double)fast_azimuth(y, x) - exact_azimuth(y, x));
  da = std::min(da, std::abs(da - 2 * 3.14159265358979323846264338327950288L));  // 0 and 2 pi are one azimuth
  EXPECT_LE(da, kFastAngleMaxError) << x << " " << y << " " << z;
}
}  // namespace

TEST(FastAngles, RandomDirectionsWithinTheBound) {
  std::mt19937_64 rng(42);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> e(-12, 12);
  double worst = 0;
  for (int i = 0; i < 4000000; ++i) {
    double x = g(rng), y = g(rng), z = g(rng);
    if (i % 4 == 1) x *= std::pow(10.0, e(rng));  // very unequal components
    if (i % 4 == 2) y *= std::pow(10.0, e(rng));
    const double rho = std::sqrt(x * x + y * y);
    const long double d1 = std::abs((long double)fast_polar_angle(rho, z) - exact_polar(rho, z));
    long double d2 = std::abs((long double)fast_azimuth(y, x) - exact_azimuth(y, x));
    d2 = std::min(d2, std::abs(d2 - 2 * 3.14159265358979323846264338327950288L));
    worst = std::max(worst, double(std::max(d1, d2)));
  }
  EXPECT_LE(worst, kFastAngleMaxError);
  RecordProperty("worst_error_rad", std::to_string(worst));
}

TEST(FastAngles, CoarseAcosWithinItsBound) {
  double worst = 0;
  auto check = [&](double x) {
    const double e = double(std::abs((long double)fast_acos_coarse(x) - std::acos((long double)x)));
    worst = std::max(worst, e);
  };
  for (int i = -2000000; i <= 2000000; ++i) check(i / 2000000.0);
  for (int k = 1; k <= 52; ++k)  // within 2^-k of the ends
    for (double s : {1.0, -1.0}) check(s * (1 - std::ldexp(1.0, -k)));
  EXPECT_LE(worst, kFastAcosCoarseMaxError);
  EXPECT_GT(worst, 1e-9);  // the polynomial's own error: the check measures what it claims
  EXPECT_EQ(fast_acos_coarse(1.0), 0.0);
  EXPECT_NEAR(fast_acos_coarse(-1.0), 3.14159265358979323846, 1e-8);
}

TEST(FastAngles, EdgeCases) {
  const double t8 = std::tan(3.14159265358979323846 / 8);
  const double v[] = {0.0, -0.0, 1.0, -1.0, 1e-300, -1e-300, 1e300, t8, -t8, std::nextafter(t8, 1.0), 0.5, -2.0};
  for (double x : v)
    for (double y : v)
      for (double z : v) {
        if (x == 0 && y == 0 && z == 0) continue;
        if (std::abs(x) > 1e200 || std::abs(y) > 1e200) continue;  // x^2 + y^2 overflows: not a direction we get
        expect_angles(x, y, z);
      }
  EXPECT_EQ(fast_polar_angle(0, 1), 0.0);
  EXPECT_NEAR(fast_polar_angle(0, -1), 3.14159265358979323846, 1e-15);
  EXPECT_EQ(fast_azimuth(0, 1), 0.0);
  EXPECT_NEAR(fast_azimuth(0, -1), 3.14159265358979323846, 1e-15);
  EXPECT_NEAR(fast_azimuth(1, 0), 3.14159265358979323846 / 2, 1e-15);
}

namespace {
/// Reference gap with libm trigonometry and the grid's own bilinear stencil.
double reference_gap(const RadialDistanceMap& map, const Eigen::Vector3d& q, double side) {
  const auto& grid = equiangular_grid_of(map.scheme());
  const double r = q.norm();
  const double phi = std::acos(std::clamp(q.z() / r, -1.0, 1.0));
  double theta = std::atan2(q.y(), q.x());
  if (theta < 0) theta += 2 * 3.14159265358979323846;
  std::int64_t nd[4];
  double w[4];
  grid.stencil_angles(phi, theta, nd, w);
  double d = 0;
  for (int k = 0; k < 4; ++k) {
    if (w[k] == 0) continue;
    if (!map.has_surface(nd[k])) return std::numeric_limits<double>::quiet_NaN();
    d += w[k] * map.at(nd[k]);
  }
  return side * (d - r);
}

/// Largest |fast - reference| gap over both scans of a joint at precision p, in mm; also counts
/// vertices where one is NaN and the other is not (a coverage edge crossed by the rounding).
void compare_scans(const TriangleMesh& ball, const TriangleMesh& socket, const Eigen::Vector3d& cor, double p) {
  SamplingOptions o;
  RadialDistanceMap bm(make_scheme("equiangular", p)), sm(make_scheme("equiangular", p));
  sample_surface(ball, cor, o, bm);
  sample_surface(socket, cor, o, sm);
  const Vertices bp = ball.V.rowwise() - cor.transpose(), sp = socket.V.rowwise() - cor.transpose();
  const ScanSet bs = make_scan_set(bp, first_surface_mask(bp, bm, 1.0, 1e30));
  const ScanSet ss = make_scan_set(sp, first_surface_mask(sp, sm, 1.0, 1e30));
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> a(-0.3, 0.3);
  const Eigen::Matrix3d R =
      (Eigen::AngleAxisd(a(rng), Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(a(rng), Eigen::Vector3d::UnitY()))
          .toRotationMatrix();
  double worst = 0;
  int nan_mismatch = 0, compared = 0;
  for (int scan = 0; scan < 2; ++scan) {
    const ScanSet& set = scan == 0 ? bs : ss;
    const RadialDistanceMap& other = scan == 0 ? sm : bm;
    const Eigen::Matrix3d Rs = scan == 0 ? R : Eigen::Matrix3d(R.transpose());
    const double side = scan == 0 ? 1 : -1;
    std::vector<float> fast(static_cast<std::size_t>(set.size()));
    scan_gaps_compact(set, Rs, Eigen::Vector3d::Zero(), other, scan == 0 ? ScanSide::inside : ScanSide::outside,
                      fast.data());
    for (std::int64_t j = 0; j < set.size(); ++j) {
      const Eigen::Vector3d q = Rs * Eigen::Vector3d(set.x[j], set.y[j], set.z[j]);
      const double ref = reference_gap(other, q, side);
      if (std::isnan(ref) != std::isnan(fast[j])) {
        ++nan_mismatch;
        continue;
      }
      if (std::isnan(ref)) continue;
      ++compared;
      // Includes the float rounding of the output gap (half an ulp: <= 7.6e-6 mm below 128 mm).
      worst = std::max(worst, std::abs(double(fast[j]) - ref));
    }
  }
  EXPECT_GT(compared, 100);
  EXPECT_LE(worst, 1e-4) << "p = " << p;
  EXPECT_EQ(nan_mismatch, 0);
  std::cout << "p = " << p << ": " << compared << " gaps, largest change " << worst << " mm\n";
}
}  // namespace

TEST(FastLookup, MovesNoGapByMoreThanATenThousandthMillimetreGenerated) {
  HipModelOptions o;
  o.target_triangles = 12000;
  o.cam_height_mm = 3;
  const HipModel h = make_hip_model(o);
  for (double p : {0.5, 0.1, 0.05}) compare_scans(h.ball, h.socket, h.cor, p);
}

TEST(FastLookup, MovesNoGapByMoreThanATenThousandthMillimetreRealSubject) {
  const auto real = test::load_real_joint("lhdl-ct");
  if (!real) GTEST_SKIP() << "shared data absent: " << IMPINGE_SHARED_DATA;
  for (double p : {0.1, 0.05}) compare_scans(real->femur, real->pelvis, real->cor, p);
}
