#include "impinge/core/range.hpp"

#include <cmath>
#include <cstdlib>
#include <sstream>

#include "impinge/core/error.hpp"

namespace impinge {

std::string shortest_decimal(double x) {
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  if (x == std::floor(x) && std::fabs(x) < 1e15) return std::to_string(static_cast<long long>(x));
  for (int p = 1; p <= 17; ++p) {
    std::ostringstream o;
    o.precision(p);
    o << x;
    if (std::strtod(o.str().c_str(), nullptr) == x) return o.str();
  }
  return std::to_string(x);
}

std::string Range::text() const {
  return std::string(min_open ? "(" : "[") + shortest_decimal(min) + ", " + shortest_decimal(max) + "]";
}

void check_in_range(const std::string& name, double x, const Range& range, const std::string& unit) {
  const std::string u = unit.empty() ? "" : " " + unit;
  require(!std::isnan(x), [&] { return name + ": not a number (valid: " + range.text() + u + ")"; });
  require(range.contains(x), [&] {
    return name + " " + shortest_decimal(x) + u + " is outside the valid range " + range.text() + u;
  });
}

}  // namespace impinge
