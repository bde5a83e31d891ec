#include "impinge/core/error.hpp"

#include <sstream>

namespace impinge {
void require(bool condition, const std::string& message) {
  if (!condition) throw Error(message);
}
std::string number_text(double x) {
  std::ostringstream o;
  o << x;
  return o.str();
}

}  // namespace impinge
