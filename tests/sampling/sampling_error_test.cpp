// Thesis Table 5 (Eq. 7-8 at r = 22 mm) and the slice analysis of sec. 3.5.2 reproduced to the
// printed digits; the interpolation bound helpers against closed forms.
#include "impinge/sampling/sampling_error.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "impinge/core/error.hpp"

using namespace impinge;

TEST(SamplingError, Table5ToPrintedDigits) {
  const double p[] = {1, 0.5, 0.1, 0.05};
  const double mm[] = {0.272, 0.136, 0.027, 0.014}, pct[] = {1.23, 0.62, 0.12, 0.06};
  for (int i = 0; i < 4; ++i) {
    const double n = 360 / p[i];
    EXPECT_NEAR(eq7_max_sampling_error(22, n), mm[i], 0.0005) << p[i];
    EXPECT_NEAR(100 * eq8_relative_error(n), pct[i], 0.005) << p[i];
  }
  EXPECT_THROW(eq7_max_sampling_error(0, 360), Error);
}

TEST(SamplingError, SliceAnalysisOfThesis) {
  const SliceAnalysis a = slice_sampling(22, 1.25);
  EXPECT_EQ(a.dphi_deg.size(), 17u);      // 17 slices above the middle plane
  EXPECT_NEAR(a.min_dphi_deg, 3.0, 0.3);  // "about 3 deg"
  EXPECT_NEAR(a.min_dphi_deg, 90 - std::acos(1.25 / 22) * 180 / 3.14159265358979323846, 1e-12);
  EXPECT_NEAR(a.nyquist_precision_deg, a.min_dphi_deg / 2, 1e-15);
  for (std::size_t i = 1; i < a.dphi_deg.size(); ++i) EXPECT_GT(a.dphi_deg[i], a.dphi_deg[i - 1]);  // Fig. 46b
  EXPECT_THROW(slice_sampling(22, 0), Error);
  EXPECT_THROW(slice_sampling(1, 2), Error);
}

TEST(SamplingError, RadialSecondDerivativeClosedForms) {
  // sphere about the COR: r'' = 0; plane at distance D: r = D / cos(g), r'' = D (1 + sin^2 g) / cos^3 g
  EXPECT_NEAR(radial_second_derivative(22, 0, 1.0 / 22), 0, 1e-12);
  const double D = 20, g = 0.6, r = D / std::cos(g), tan_a = std::tan(g);
  EXPECT_NEAR(radial_second_derivative(r, tan_a, 0), D * (1 + std::sin(g) * std::sin(g)) / std::pow(std::cos(g), 3),
              1e-9);
  EXPECT_NEAR(bilinear_error_bound(0.1, 0.2, 8, 2), (0.01 * 8 + 0.04 * 2) / 8, 1e-15);
}
