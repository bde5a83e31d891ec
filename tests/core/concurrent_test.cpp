// run_both: both jobs run and finish before it returns, whichever throws; the first job's error wins when both
// throw (the message a serial run would have shown), else the second's reaches the caller.
#include "impinge/core/concurrent.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <random>
#include <vector>
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

// run_task_graph: every job runs once, after the jobs it waits for have ended; brute force over random graphs
// (each job's start and end stamped from one counter).
TEST(Concurrent, TaskGraphRunsEveryJobOnceAfterTheJobsItWaitsFor) {
  std::mt19937 rng(7);
  for (int graph = 0; graph < 50; ++graph) {
    const std::size_t n = 1 + rng() % 12;
    std::atomic<int> clock{0};
    std::vector<int> start(n, -1), end(n, -1), runs(n, 0);
    std::vector<GraphTask> tasks(n);
    for (std::size_t k = 0; k < n; ++k) {
      for (std::size_t j = 0; j < k; ++j)
        if (rng() % 3 == 0) tasks[k].after.push_back(j);
      tasks[k].run = [&, k] {
        start[k] = clock++;
        ++runs[k];
        if (k % 2 == 0) std::this_thread::sleep_for(std::chrono::microseconds(200));
        end[k] = clock++;
      };
    }
    run_task_graph(tasks, 1 + graph % 2);
    for (std::size_t k = 0; k < n; ++k) {
      ASSERT_EQ(runs[k], 1) << "graph " << graph << " job " << k;
      for (const std::size_t j : tasks[k].after) ASSERT_LT(end[j], start[k]) << "graph " << graph << " job " << k;
    }
  }
}

// Two jobs that each wait (up to 10 s) for the other to have started can only both see it on two threads.
TEST(Concurrent, TaskGraphRunsReadyJobsOnTwoThreads) {
  std::atomic<bool> started[2] = {false, false};
  bool saw[2] = {false, false};
  std::vector<GraphTask> tasks(2);
  for (int k = 0; k < 2; ++k)
    tasks[static_cast<std::size_t>(k)].run = [&, k] {
      started[k] = true;
      const auto t0 = std::chrono::steady_clock::now();
      while (!started[1 - k] && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(10))
        std::this_thread::yield();
      saw[k] = started[1 - k];
    };
  run_task_graph(tasks);
  EXPECT_TRUE(saw[0]);
  EXPECT_TRUE(saw[1]);
}

// One thread takes the ready jobs in list order.
TEST(Concurrent, TaskGraphOnOneThreadRunsReadyJobsInListOrder) {
  std::vector<int> order;
  std::vector<GraphTask> tasks(4);
  for (int k = 0; k < 4; ++k) tasks[static_cast<std::size_t>(k)].run = [&, k] { order.push_back(k); };
  tasks[1].after = {0};
  tasks[2].after = {};
  tasks[3].after = {1};
  run_task_graph(tasks, 1);
  EXPECT_EQ(order, (std::vector<int>{0, 1, 2, 3}));
}

// A failure: no job waiting for it runs, the job already running ends first, and of two failures the smaller
// error_rank is rethrown (the ball's error before the socket's, whichever thread threw first).
TEST(Concurrent, TaskGraphStopsAtAnErrorAndRethrowsTheSmallestRank) {
  std::atomic<bool> slow_started{false}, slow_done{false}, dependent_ran{false};
  std::vector<GraphTask> tasks(4);
  tasks[0].run = [&] {  // fails once the other job is under way (at most 10 s later)
    const auto t0 = std::chrono::steady_clock::now();
    while (!slow_started && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(10)) std::this_thread::yield();
    throw std::runtime_error("socket");
  };
  tasks[0].error_rank = 1;
  tasks[1].run = [&] {
    slow_started = true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    slow_done = true;
    throw std::runtime_error("ball");
  };
  tasks[1].error_rank = 0;
  tasks[2].run = [&] { dependent_ran = true; };
  tasks[2].after = {0};
  tasks[3].run = [&] { dependent_ran = true; };
  tasks[3].after = {1};
  try {
    run_task_graph(tasks);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "ball");
  }
  EXPECT_TRUE(slow_done);
  EXPECT_FALSE(dependent_ran);
}

TEST(Concurrent, TaskGraphRejectsAJobWaitingForALaterOne) {
  std::vector<GraphTask> tasks(2);
  tasks[0].run = tasks[1].run = [] {};
  tasks[0].after = {1};
  EXPECT_THROW(run_task_graph(tasks), std::invalid_argument);
  tasks[0].after = {0};
  EXPECT_THROW(run_task_graph(tasks), std::invalid_argument);
}
