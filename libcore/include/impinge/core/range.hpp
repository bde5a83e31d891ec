#pragma once
/// @file range.hpp
/// The valid values of a numeric option, declared once beside the option's field (e.g.
/// `JointOptions::kLayersRange`): the session layer's option table takes its rows' ranges from these
/// declarations, and the library checks its own option structs against the same ones, so a front end
/// never tells a user a range the library refuses (issue 78).

#include <limits>
#include <string>

namespace impinge {

/// A closed interval [min, max], or (min, max] when `min_open` (a length that must be > 0). `max`
/// may be +infinity (then "inf" is a valid value). Units are the field's (see its doc comment).
struct Range {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_open = false;  ///< min itself is not valid
  /// Whether x lies in the range (NaN never does).
  constexpr bool contains(double x) const { return (min_open ? x > min : x >= min) && x <= max; }
  /// "[0, 16]", "(0, 1000]", "[0, inf]".
  std::string text() const;
};

/// The shortest decimal text that reads back as x: integers without a point, "inf" and "-inf" for
/// infinities (as the option table prints values).
std::string shortest_decimal(double x);

/// Check a value of an option struct's field against its declared range. Throws impinge::Error
/// "`name` X `unit` is outside the valid range [a, b] `unit`" (NaN: "is not a number") otherwise.
/// `name` is the field as a user knows it (e.g. "JointOptions::layers").
void check_in_range(const std::string& name, double x, const Range& range, const std::string& unit = "");

}  // namespace impinge
