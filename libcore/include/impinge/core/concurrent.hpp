#pragma once
/// @file concurrent.hpp
/// Two independent jobs at once: the pattern behind reading both bones, building both bodies and writing
/// both gap files (issue 52: a one-pose run keeps the second core busy where its work splits in two), and a
/// few dependent jobs on two threads (run_task_graph: a joint's two bodies built as their parts, so that the
/// core the smaller body leaves idle takes on the larger one's).

#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <future>
#include <mutex>
#include <stdexcept>
#include <utility>
#include <vector>

#include "impinge/core/interrupt.hpp"

namespace impinge {

/// Runs `second` on a new thread while `first` runs on this one, and returns after both have finished
/// (neither is left running if the other throws). Errors: if `first` threw, its exception is rethrown (the
/// first-named job's message wins, as a serial run would have shown it); otherwise `second`'s, if it threw.
/// Both callables take no arguments; their results travel through what they capture. Throws
/// std::system_error if no thread can be started.
template <class First, class Second>
void run_both(First&& first, Second&& second) {
  auto other = std::async(std::launch::async, std::forward<Second>(second));
  std::exception_ptr first_error;
  try {
    std::forward<First>(first)();
  } catch (...) {
    first_error = std::current_exception();
  }
  // Waiting, a front end's poll still runs on this thread (core/interrupt.hpp): a stop reaches `second`'s loops.
  while (other.wait_for(InterruptScope::kPollPeriod) != std::future_status::ready) (void)interruption_requested();
  if (first_error) std::rethrow_exception(first_error);
  other.get();
}

/// One job of run_task_graph: `run` starts once every job listed in `after` (indices into the same list,
/// each below this job's own) has ended without an error. `error_rank`: of several jobs that threw, the one
/// with the smallest rank (then the earliest in the list) is rethrown.
struct GraphTask {
  std::function<void()> run;
  std::vector<std::size_t> after;
  int error_rank = 0;
};

/// Runs `tasks` on this thread and one more (two in all; `threads` 1: on this one alone, in list order). A
/// thread that is free takes the first job in the list whose jobs `after` have ended: list them by priority,
/// the longest chains first. Every job runs once, whichever thread runs it, so results do not depend on the
/// schedule as long as concurrent jobs touch disjoint data. Errors: once a job throws, no job starts any more;
/// after the running ones have ended, the exception of the job that threw with the smallest error_rank
/// (then the first in the list) is rethrown. std::invalid_argument if an `after` index is not below its
/// job's; std::system_error if the second thread cannot be started.
inline void run_task_graph(std::vector<GraphTask>& tasks, int threads = 2) {
  const std::size_t n = tasks.size();
  for (std::size_t k = 0; k < n; ++k)
    for (const std::size_t j : tasks[k].after)
      if (j >= k) throw std::invalid_argument("run_task_graph: a job may only wait for jobs before it");
  enum class State { waiting, running, done, failed };
  std::vector<State> state(n, State::waiting);
  std::vector<std::exception_ptr> error(n);
  std::mutex m;
  std::condition_variable changed;
  bool stop = false;
  std::size_t open = n;  // jobs neither done nor failed nor given up
  auto ready = [&](std::size_t k) {
    if (state[k] != State::waiting) return false;
    for (const std::size_t j : tasks[k].after)
      if (state[j] != State::done) return false;
    return true;
  };
  auto worker = [&] {
    std::unique_lock<std::mutex> lock(m);
    for (;;) {
      std::size_t next = n;
      if (!stop)
        for (std::size_t k = 0; k < n && next == n; ++k)
          if (ready(k)) next = k;
      if (next == n) {
        bool running = false;
        for (const State s : state) running = running || s == State::running;
        if (stop || open == 0 || !running) {
          // Nothing can start now or later: every job has ended, an error stopped the run, or (cannot happen
          // with `after` below each job) no job is running that could make one ready.
          changed.notify_all();
          return;
        }
        // Waiting, a front end's poll still runs on this thread (the caller's, which may hold the poll): a stop
        // then reaches the running job's loops (core/interrupt.hpp).
        if (changed.wait_for(lock, InterruptScope::kPollPeriod) == std::cv_status::timeout) {
          lock.unlock();
          (void)interruption_requested();
          lock.lock();
        }
        continue;
      }
      state[next] = State::running;
      lock.unlock();
      std::exception_ptr e;
      try {
        tasks[next].run();
      } catch (...) {
        e = std::current_exception();
      }
      lock.lock();
      state[next] = e ? State::failed : State::done;
      error[next] = e;
      --open;
      if (e) stop = true;
      changed.notify_all();
    }
  };
  if (threads > 1) {
    auto other = std::async(std::launch::async, worker);
    worker();
    other.get();
  } else {
    worker();
  }
  std::size_t first = n;
  for (std::size_t k = 0; k < n; ++k)
    if (error[k] && (first == n || tasks[k].error_rank < tasks[first].error_rank)) first = k;
  if (first < n) std::rethrow_exception(error[first]);
}

}  // namespace impinge
