// Level boundaries follow the documented half-open intervals; purple includes gap == 0.
#include "impinge/detection/impingement_levels.hpp"

#include <gtest/gtest.h>

#include "impinge/core/error.hpp"

using namespace impinge;

TEST(ImpingementLevels, DefaultBoundaries) {
  const ImpingementLevels lv;
  EXPECT_EQ(lv.count(), 5);
  EXPECT_EQ(lv.level(10), 0);
  EXPECT_EQ(lv.level(4.0), 0);
  EXPECT_EQ(lv.level(3.99), 1);
  EXPECT_EQ(lv.level(8.0 / 3.0), 1);
  EXPECT_EQ(lv.level(2.0), 2);
  EXPECT_EQ(lv.level(1.0), 3);
  EXPECT_EQ(lv.level(1e-9), 3);
  EXPECT_EQ(lv.level(0.0), 4);
  EXPECT_EQ(lv.level(-3.0), 4);
  EXPECT_EQ(lv.name(4), "purple");
}

TEST(ImpingementLevels, ParseAndValidate) {
  const ImpingementLevels lv = parse_levels("3,1,0");
  EXPECT_EQ(lv.count(), 4);
  EXPECT_EQ(lv.level(2), 1);
  EXPECT_EQ(lv.level(0.5), 2);
  EXPECT_EQ(lv.level(0), 3);
  EXPECT_THROW(parse_levels("1,2"), Error);
  EXPECT_THROW(parse_levels("4,x,0"), Error);
  EXPECT_THROW(parse_levels(""), Error);
}
