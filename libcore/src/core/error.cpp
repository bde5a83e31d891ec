#include "impinge/core/error.hpp"

namespace impinge {
void require(bool condition, const std::string& message) {
  if (!condition) throw Error(message);
}
}  // namespace impinge
