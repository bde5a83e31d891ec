// Number lists: exact parse, count check, and errors that quote the option and the bad item.
#include "impinge/core/parse.hpp"

#include <gtest/gtest.h>

#include "impinge/core/error.hpp"

using namespace impinge;

TEST(Parse, NumberLists) {
  EXPECT_EQ(parse_number_list("1,-2.5,3e1", "--x"), (std::vector<double>{1, -2.5, 30}));
  EXPECT_EQ(parse_number_list("7", "--x", 1), (std::vector<double>{7}));
  try {
    parse_number_list("1,abc,3", "--cor", 3);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--cor"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("'abc'"), std::string::npos);
  }
  EXPECT_THROW(parse_number_list("1,2", "--cor", 3), Error);
  EXPECT_THROW(parse_number_list("1,nan", "--x"), Error);
  EXPECT_THROW(parse_number_list("1,2x", "--x"), Error);
  EXPECT_THROW(parse_number_list("", "--x"), Error);
}
