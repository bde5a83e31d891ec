#pragma once
/// @file interrupt.hpp
/// Stopping a long call from its front end (issue 80: Ctrl-C in a long Python `Joint.motion`). A front end
/// installs a poll for the duration of a call (InterruptScope; the Python module's asks Python whether a signal
/// arrived); the library's long loops (a motion's frames, the ROM searches' poses, map sampling, a plan's poses)
/// ask between units of work (interruption_point, interruption_requested). The poll runs on the thread that
/// installed it, at most every InterruptScope::kPollPeriod; once it has said stop, every later question on any
/// thread is answered "stop" until the scope ends. Without a scope (the CLI, which SIGINT ends) a question costs one
/// relaxed atomic load. Source: impinge.

#include <atomic>
#include <chrono>
#include <functional>
#include <stdexcept>

namespace impinge {

/// Thrown by interruption_point once the front end's poll asked to stop. Not an impinge::Error: nothing is wrong
/// with the input; the front end that installed the scope reports the stop its own way (Python: KeyboardInterrupt).
class Interrupted : public std::runtime_error {
 public:
  Interrupted() : std::runtime_error("interrupted") {}
};

/// A poll installed on the calling thread while the scope lives (scopes nest: the inner one is asked). `poll` is
/// called on this thread only, from inside interruption_point/interruption_requested, at most every kPollPeriod;
/// it returns true to stop (and must not throw). Worker threads (OpenMP) cannot tell which call they serve: they
/// stop once any live scope has stopped.
class InterruptScope {
 public:
  static constexpr std::chrono::milliseconds kPollPeriod{50};
  explicit InterruptScope(std::function<bool()> poll);
  ~InterruptScope();
  InterruptScope(const InterruptScope&) = delete;
  InterruptScope& operator=(const InterruptScope&) = delete;
  /// True once the poll has said stop.
  bool stopped() const { return stopped_.load(std::memory_order_relaxed); }
  /// Polls now if due (on the installing thread); true when stopped.
  bool poll_if_due();

 private:
  std::function<bool()> poll_;
  std::chrono::steady_clock::time_point next_poll_;
  std::atomic<bool> stopped_{false};
  InterruptScope* outer_ = nullptr;  ///< the scope this one hides on its thread
};

/// Whether the call should stop: on a thread with a scope, that scope's answer (polling it when due); on any other
/// thread, whether any live scope has stopped. False without a scope. Never throws: for loop bodies that may not
/// throw (OpenMP regions without a catch); call interruption_point after the loop.
bool interruption_requested();

/// Throws Interrupted when interruption_requested().
void interruption_point();

}  // namespace impinge
