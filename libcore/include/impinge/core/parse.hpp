#pragma once
/// @file parse.hpp
/// Parsing of comma-separated number lists given on command lines ("30,10,5").

#include <string>
#include <vector>

namespace impinge {

/// Parse "a,b,c" into finite doubles. `what` names the option in error messages. Throws
/// impinge::Error quoting `what`, the text and the offending item when an item is not a finite
/// number, or when `count` > 0 and the list does not hold exactly `count` numbers.
std::vector<double> parse_number_list(const std::string& text, const std::string& what, std::size_t count = 0);

}  // namespace impinge
