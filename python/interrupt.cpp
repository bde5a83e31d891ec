// Ctrl-C in the module's long calls (issue 80): the library's loops polled for Python's signals (bindings.hpp).
#include <exception>
#include <optional>

#include "bindings.hpp"
#include "impinge/core/interrupt.hpp"

namespace impinge::python {

namespace {
// Whether the calling thread is Python's main thread, the one that runs signal handlers (GIL held).
bool on_main_thread() {
  static const unsigned long main_ident =
      py::module_::import("threading").attr("main_thread")().attr("ident").cast<unsigned long>();
  return PyThread_get_thread_ident() == main_ident;
}
}  // namespace

void run_interruptible(const std::function<void()>& work) {
  if (!on_main_thread()) {  // no signal handler runs here: nothing to poll
    py::gil_scoped_release release;
    work();
    return;
  }
  std::optional<py::error_already_set> raised;  // the signal handler's exception (KeyboardInterrupt)
  std::exception_ptr failure;
  {
    InterruptScope scope([&raised] {
      py::gil_scoped_acquire gil;  // this thread's state, saved by the release below
      if (PyErr_CheckSignals() == 0) return false;
      raised.emplace();  // fetches (and clears) the handler's exception
      return true;
    });
    py::gil_scoped_release release;
    try {
      work();
    } catch (...) {
      failure = std::current_exception();
    }
  }
  // The stop first: whatever the loops made of it (Interrupted, an error naming it, or a partial result).
  if (raised) throw *raised;
  if (failure) std::rethrow_exception(failure);
}

}  // namespace impinge::python
