// The experiments' timing helpers (experiments/experiment_support.hpp): summarize's median and quartiles against
// numpy's linear interpolation worked by hand, run_alternated's order (a warm-up of each, then rounds in which each
// runs once) and round_sums.
#include "experiment_support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace impinge::experiment;

TEST(ExperimentTiming, QuartilesInterpolateLinearlyBetweenOrderStatistics) {
  // numpy.quantile([4, 1, 3, 2], [0.25, 0.5, 0.75]) = 1.75, 2.5, 3.25
  const Timing t = summarize({4, 1, 3, 2});
  EXPECT_DOUBLE_EQ(t.median_ms, 2.5);
  EXPECT_DOUBLE_EQ(t.q25_ms, 1.75);
  EXPECT_DOUBLE_EQ(t.q75_ms, 3.25);
  EXPECT_EQ(t.runs, 4);
  // An odd count: the middle one; one value: all three equal it.
  EXPECT_DOUBLE_EQ(summarize({5, 1, 9}).median_ms, 5);
  const Timing one = summarize({7});
  EXPECT_DOUBLE_EQ(one.q25_ms, 7);
  EXPECT_DOUBLE_EQ(one.q75_ms, 7);
  const Timing none = summarize({});
  EXPECT_TRUE(std::isnan(none.median_ms));
  EXPECT_EQ(none.runs, 0);
}

TEST(ExperimentTiming, AlternatesAfterOneWarmUpOfEach) {
  std::vector<int> calls;
  const auto runs =
      run_alternated({[&] { calls.push_back(0); }, [&] { calls.push_back(1); }, [&] { calls.push_back(2); }}, 2);
  EXPECT_EQ(calls, (std::vector<int>{0, 1, 2, 0, 1, 2, 0, 1, 2}));
  ASSERT_EQ(runs.size(), 3u);
  for (const auto& r : runs) {
    ASSERT_EQ(r.size(), 2u);
    for (double ms : r) EXPECT_GE(ms, 0);
  }
  const std::vector<double> sums = round_sums({{1, 2}, {10, 20}, {100, 200}}, {0, 2});
  EXPECT_EQ(sums, (std::vector<double>{101, 202}));
}
