#pragma once
/// @file enum_names.hpp
/// One name table per option enum: the text a user writes for each value (CLI, Python, study files,
/// outputs). The enum's parse_* and to_string functions and the option table's choices all read the same
/// table, so a value's spelling lives in one place (issue 78).
///
/// Declare the table beside the enum:
///   inline constexpr EnumNames<RomMetric, 2> kRomMetricNames{{{RomMetric::distance, "distance"},
///                                                            {RomMetric::radial, "radial"}}};
/// The order of the table is the order the choices are listed in (help texts, error messages).

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "impinge/core/error.hpp"

namespace impinge {

/// One value of an enum and its name.
template <typename E>
struct EnumName {
  E value;
  const char* name;
};

/// An enum's name table.
template <typename E, std::size_t N>
using EnumNames = std::array<EnumName<E>, N>;

/// The names of a table, in its order ("choices" of an option row).
template <typename E, std::size_t N>
std::vector<std::string> enum_choices(const EnumNames<E, N>& names) {
  std::vector<std::string> v;
  for (const EnumName<E>& n : names) v.emplace_back(n.name);
  return v;
}

/// "a, b, c" (as the option table lists choices).
template <typename E, std::size_t N>
std::string enum_choice_list(const EnumNames<E, N>& names) {
  std::string s;
  for (std::size_t i = 0; i < N; ++i) s += (i == 0 ? "" : ", ") + std::string(names[i].name);
  return s;
}

/// The value named `text`. Throws impinge::Error "`context`: 'text' is not one of a, b, c" otherwise.
template <typename E, std::size_t N>
E parse_enum(const EnumNames<E, N>& names, const std::string& text, const std::string& context) {
  for (const EnumName<E>& n : names)
    if (text == n.name) return n.value;
  throw Error(context + ": '" + text + "' is not one of " + enum_choice_list(names));
}

/// The name of `value` (the table's; "?" for a value the table lacks, which a test of each table rules out).
template <typename E, std::size_t N>
const char* enum_name(const EnumNames<E, N>& names, E value) {
  for (const EnumName<E>& n : names)
    if (n.value == value) return n.name;
  return "?";
}

}  // namespace impinge
