#pragma once
/// @file error.hpp
/// The one exception type impinge throws for bad input or impossible requests.

#include <stdexcept>
#include <string>

namespace impinge {

/// Error raised on bad input (unreadable file, non-finite coordinate, out-of-range index,
/// empty mesh, invalid parameter). The message always names the file and/or the offending
/// element, e.g. "femur.ply: face 12 has vertex index 9001 >= 8000 vertices".
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

/// Throw impinge::Error(message) unless `condition` holds.
void require(bool condition, const std::string& message);

}  // namespace impinge
