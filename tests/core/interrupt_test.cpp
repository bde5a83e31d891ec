// InterruptScope (issue 80: Ctrl-C in long Python calls): without a scope nothing stops; the poll runs on the
// installing thread at most every kPollPeriod; once it says stop, every thread's question is answered "stop" until
// the scope ends; a thread waiting in run_both or run_task_graph keeps polling, so a job on the other thread sees
// the stop.
#include "impinge/core/interrupt.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "impinge/core/concurrent.hpp"

using namespace impinge;
using Clock = std::chrono::steady_clock;

TEST(Interrupt, NothingStopsWithoutAScope) {
  EXPECT_FALSE(interruption_requested());
  EXPECT_NO_THROW(interruption_point());
  bool other = true;
  std::thread([&] { other = interruption_requested(); }).join();
  EXPECT_FALSE(other);
}

TEST(Interrupt, ThePollRunsAtMostEveryPeriodOnItsThread) {
  int polls = 0;
  InterruptScope scope([&] { return ++polls, false; });
  const auto end = Clock::now() + 5 * InterruptScope::kPollPeriod;
  std::int64_t asked = 0;
  while (Clock::now() < end) asked += !interruption_requested();
  EXPECT_GT(asked, 1000);  // asked far more often than polled
  EXPECT_GE(polls, 1);     // (a busy machine may leave this thread waiting for whole periods)
  EXPECT_LE(polls, 6);     // 5 periods: at most one poll each, plus the first
  int before = polls;
  std::thread([] { (void)interruption_requested(); }).join();  // another thread never runs this thread's poll
  EXPECT_EQ(polls, before);
}

TEST(Interrupt, AStopReachesEveryThreadUntilTheScopeEnds) {
  {
    InterruptScope scope([] { return true; });
    EXPECT_THROW(interruption_point(), Interrupted);
    EXPECT_TRUE(scope.stopped());
    bool other = false;
    std::thread([&] { other = interruption_requested(); }).join();
    EXPECT_TRUE(other);
  }
  EXPECT_FALSE(interruption_requested());
  bool other = true;
  std::thread([&] { other = interruption_requested(); }).join();
  EXPECT_FALSE(other);
}

TEST(Interrupt, ScopesNestOnAThread) {
  InterruptScope outer([] { return true; });
  {
    InterruptScope inner([] { return false; });
    EXPECT_FALSE(interruption_requested());  // the inner scope answers on its thread
  }
  EXPECT_TRUE(interruption_requested());
}

// A job on run_both's second thread loops until asked to stop; the caller's first job ends at once and waits: its
// waiting polls, the stop reaches the loop.
TEST(Interrupt, AThreadWaitingInRunBothKeepsPolling) {
  std::atomic<bool> stop_now{false};
  InterruptScope scope([&] { return stop_now.load(); });
  const auto t0 = Clock::now();
  std::thread([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    stop_now = true;
  }).detach();
  EXPECT_THROW(run_both([] {},
                        [] {
                          for (const auto end = Clock::now() + std::chrono::seconds(20); Clock::now() < end;)
                            interruption_point();
                        }),
               Interrupted);
  EXPECT_LT(Clock::now() - t0, std::chrono::seconds(5));
}

// The graph's calling thread takes whichever job it reaches first: tried until the loop ran on the other thread,
// the caller then waiting after the short job.
TEST(Interrupt, AThreadWaitingInATaskGraphKeepsPolling) {
  const std::thread::id caller = std::this_thread::get_id();
  bool loop_elsewhere = false;
  for (int tried = 0; !loop_elsewhere && tried < 50; ++tried) {
    std::atomic<bool> stop_now{false};
    InterruptScope scope([&] { return stop_now.load(); });
    std::vector<GraphTask> tasks(2);
    tasks[1].run = [&] {
      if (std::this_thread::get_id() == caller) return;  // not the case tried: again
      loop_elsewhere = true;
      for (const auto end = Clock::now() + std::chrono::seconds(20); Clock::now() < end;) interruption_point();
    };
    tasks[0].run = [&] {  // the first job: the caller's, usually
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      stop_now = true;
    };
    const auto t0 = Clock::now();
    bool interrupted = false;
    try {
      run_task_graph(tasks);
    } catch (const Interrupted&) {
      interrupted = true;
    }
    if (loop_elsewhere) {
      EXPECT_TRUE(interrupted);
      EXPECT_LT(Clock::now() - t0, std::chrono::seconds(5));
    }
  }
  EXPECT_TRUE(loop_elsewhere);
}
