#pragma once
/// @file error.hpp
/// The one exception type impinge throws for bad input or impossible requests.

#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>

namespace impinge {

/// Error raised on bad input (unreadable file, non-finite coordinate, out-of-range index,
/// empty mesh, invalid parameter). The message always names the file and/or the offending
/// element, e.g. "femur.ply: face 12 has vertex index 9001 >= 8000 vertices".
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

/// Memory ran out building something large (maps, ray-casting hierarchies, meshes): a std::bad_alloc or Embree's
/// RTC_ERROR_OUT_OF_MEMORY, told as what was being built, its size and how to make it smaller (issue 80). An
/// Error, so that every front end reports it as one line; Python raises it as MemoryError.
class OutOfMemory : public Error {
 public:
  explicit OutOfMemory(const std::string& message) : Error(message) {}
};

/// Throw impinge::Error(message) unless `condition` holds.
void require(bool condition, const std::string& message);

/// x as a message shows it: the shortest of six significant digits (std::ostream's default: 23.0448, 1e+06).
std::string number_text(double x);

/// Throw impinge::Error(message) unless `condition` holds: a fixed message (a string literal), which becomes a
/// std::string only then. Without it every call with a literal built and freed a string, held or not (issue 52:
/// checks inside loops).
inline void require(bool condition, const char* message) {
  if (!condition) throw Error(message);
}

/// Throw impinge::Error(message()) unless `condition` holds; `message` (a callable returning the text)
/// is called only then. For checks made once per node, vertex or cell, where building the text every
/// time would cost more than the check (sampling a layered map built a million strings).
template <typename Message, typename = std::enable_if_t<std::is_invocable_r_v<std::string, Message>>>
void require(bool condition, Message&& message) {
  if (!condition) throw Error(std::forward<Message>(message)());
}

}  // namespace impinge
