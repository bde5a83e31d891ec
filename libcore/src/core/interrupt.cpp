#include "impinge/core/interrupt.hpp"

#include <utility>

namespace impinge {

namespace {
std::atomic<int> live_scopes{0};     // scopes alive on any thread
std::atomic<int> stopped_scopes{0};  // of them, those whose poll said stop
thread_local InterruptScope* this_thread_scope = nullptr;
}  // namespace

InterruptScope::InterruptScope(std::function<bool()> poll)
    : poll_(std::move(poll)), next_poll_(std::chrono::steady_clock::now()), outer_(this_thread_scope) {
  this_thread_scope = this;
  live_scopes.fetch_add(1);
}

InterruptScope::~InterruptScope() {
  this_thread_scope = outer_;
  if (stopped()) stopped_scopes.fetch_sub(1);
  live_scopes.fetch_sub(1);
}

bool InterruptScope::poll_if_due() {
  if (stopped()) return true;
  const auto now = std::chrono::steady_clock::now();
  if (now < next_poll_) return false;
  next_poll_ = now + kPollPeriod;
  if (poll_ && poll_()) {
    stopped_.store(true);
    stopped_scopes.fetch_add(1);
  }
  return stopped();
}

bool interruption_requested() {
  if (live_scopes.load(std::memory_order_relaxed) == 0) return false;
  if (InterruptScope* s = this_thread_scope) return s->poll_if_due();
  return stopped_scopes.load(std::memory_order_relaxed) > 0;
}

void interruption_point() {
  if (interruption_requested()) throw Interrupted();
}

}  // namespace impinge
