// require: each form throws impinge::Error with its message exactly when the condition fails; a fixed message (a
// string literal, the const char* form) and a callable's text (called only then) alike.
#include "impinge/core/error.hpp"

#include <gtest/gtest.h>

#include <string>

#include "test_support.hpp"

using namespace impinge;

using test::error_of;

TEST(Require, EachFormThrowsItsMessageOnlyWhenTheConditionFails) {
  EXPECT_NO_THROW(require(true, "fixed"));
  EXPECT_NO_THROW(require(true, std::string("built")));
  EXPECT_EQ(error_of([] { require(false, "a fixed message"); }), "a fixed message");
  EXPECT_EQ(error_of([] { require(false, std::string("built ") + std::to_string(3)); }), "built 3");
  EXPECT_EQ(error_of([] { require(false, [] { return std::string("called"); }); }), "called");
  int calls = 0;
  require(true, [&] {
    ++calls;
    return std::string("never");
  });
  EXPECT_EQ(calls, 0);  // the text is not built when the check holds
}
