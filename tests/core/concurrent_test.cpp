// run_both: both jobs run and finish before it returns, whichever throws; the first job's error wins when both
// throw (the message a serial run would have shown), else the second's reaches the caller.
#include "impinge/core/concurrent.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <string>
#include <thread>

using namespace impinge;

TEST(Concurrent, RunBothRunsBothAndWaitsForThem) {
  int a = 0, b = 0;
  run_both([&] { a = 1; }, [&] { b = 2; });
  EXPECT_EQ(a, 1);
  EXPECT_EQ(b, 2);
}

TEST(Concurrent, RunBothRethrowsTheFirstJobsErrorAfterTheSecondHasFinished) {
  std::atomic<bool> second_done{false};
  try {
    run_both([] { throw std::runtime_error("first"); },
             [&] {
               std::this_thread::sleep_for(std::chrono::milliseconds(50));
               second_done = true;
               throw std::runtime_error("second");
             });
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "first");
  }
  EXPECT_TRUE(second_done);
}

TEST(Concurrent, RunBothRethrowsTheSecondJobsErrorWhenTheFirstSucceeds) {
  bool first_done = false;
  try {
    run_both([&] { first_done = true; }, [] { throw std::invalid_argument("second"); });
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "second");
  }
  EXPECT_TRUE(first_done);
}
