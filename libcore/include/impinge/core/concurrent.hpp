#pragma once
/// @file concurrent.hpp
/// Two independent jobs at once: the pattern behind reading both bones, building both bodies and writing
/// both gap files (issue 52: a one-pose run keeps the second core busy where its work splits in two).

#include <exception>
#include <future>
#include <utility>

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
  other.wait();
  if (first_error) std::rethrow_exception(first_error);
  other.get();
}

}  // namespace impinge
