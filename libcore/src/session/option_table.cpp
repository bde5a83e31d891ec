#include "impinge/session/option_table.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>

#include "impinge/core/parse.hpp"
#include "option_builders.hpp"

namespace impinge {

namespace detail {

// The shortest decimal text that reads back as x.
std::string shortest(double x) { return shortest_decimal(x); }

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const std::string& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

std::string with_unit(double x, const std::string& unit) { return shortest(x) + (unit.empty() ? "" : " " + unit); }

// The checked number of a number or integer row.
double checked_number(const OptionRow& row, const OptionValue& v, const std::string& as) {
  const double x = value_as<double>(v, as, row.type == OptionType::integer ? "a whole number" : "a number");
  require(!std::isnan(x) && (std::isfinite(x) || std::isinf(row.max)),
          [&] { return as + ": " + shortest(x) + " is not a finite number"; });
  require(row.type != OptionType::integer || (std::isfinite(x) && x == std::floor(x)),
          [&] { return as + ": " + shortest(x) + " is not a whole number"; });
  const Range range{row.min, row.max, row.min_open};
  require(range.contains(x), [&] {
    return as + ": " + with_unit(x, row.unit) + " is outside the valid range " + range.text() +
           (row.unit.empty() ? "" : " " + row.unit);
  });
  return x;
}

std::vector<double> checked_numbers(const OptionValue& v, const std::string& as, std::size_t count) {
  const auto& x = value_as<std::vector<double>>(v, as, count ? "a list of numbers" : "a non-empty list of numbers");
  require(!x.empty() && (count == 0 || x.size() == count), [&] {
    return as + ": expected " + (count ? std::to_string(count) + " numbers" : std::string("at least one number")) +
           ", got " + std::to_string(x.size());
  });
  for (double e : x) require(std::isfinite(e), [&] { return as + ": " + shortest(e) + " is not a finite number"; });
  return x;
}

}  // namespace detail


using detail::joined;
using detail::shortest;

void take_session_settings(SessionOptions& to, const SessionOptions& from) {
  to.hip = from.hip;
  to.grid = from.grid;
  to.query_strategy = from.query_strategy;
  to.max_memory_gb = from.max_memory_gb;
}

RunOptions RunOptions::clinical() {
  RunOptions o;
  o.preset = "clinical";
  o.session.hip.joint.layers = 4;        // the whole bone: hidden vertices too, extra-articular (issue 29)
  o.session.hip.joint.distances = true;  // the Euclidean distance beside the radial gap (issue 26)
  o.rom.search.metric = RomMetric::distance;
  o.command.pose = "0,0,0";
  return o;
}

RunOptions RunOptions::thesis() {
  RunOptions o = clinical();
  o.preset = "thesis";
  take_session_settings(o.session, SessionOptions{});          // single-layer maps, radial gaps only
  o.session.hip.joint_centre = JointCentreMethod::femoral_head;  // rotation about the head centre (thesis sec. 3.3)
  o.rom.search = RomOptions{};               // the radial gap
  o.rom.search.contacts = RomContacts::all;  // every vertex counts (sec. 5.2)
  o.rom.search.contact_depth_mm = 0;         // the first touch
  return o;
}

RunOptions RunOptions::named(const std::string& name, const std::string& context) {
  if (name == "clinical") return clinical();
  if (name == "thesis") return thesis();
  throw Error(context + ": '" + name + "' is not one of clinical, thesis");
}

const char* to_string(OptionType type) {
  switch (type) {
    case OptionType::text: return "text";
    case OptionType::path: return "path";
    case OptionType::choice: return "choice";
    case OptionType::number: return "number";
    case OptionType::integer: return "integer";
    case OptionType::flag: return "flag";
    case OptionType::on_off: return "on_off";
    case OptionType::numbers: return "numbers";
    case OptionType::point: return "point";
    case OptionType::region: return "region";
    case OptionType::mesh: return "mesh";
    case OptionType::landmarks: return "landmarks";
    case OptionType::path_pair: return "path_pair";
  }
  return "?";
}

OptionValue parse_option_text(const OptionRow& row, const std::string& text, const std::string& as) {
  switch (row.type) {
    case OptionType::number:
    case OptionType::integer: {
      if (std::isinf(row.max) && (text == "inf" || text == "Inf" || text == "infinity"))
        return std::numeric_limits<double>::infinity();
      const char* s = text.c_str();
      char* end = nullptr;
      errno = 0;
      const double x = std::strtod(s, &end);
      require(!text.empty() && end != s && *end == '\0' && errno != ERANGE && std::isfinite(x), [&] {
        return as + ": '" + text + "' is not a " + (row.type == OptionType::integer ? "whole number" : "finite number") +
               (std::isinf(row.max) ? " (or inf)" : "");
      });
      return x;
    }
    case OptionType::flag:
    case OptionType::on_off: {
      if (text == "on" || text == "true" || text == "1" || text == "yes") return true;
      if (text == "off" || text == "false" || text == "0" || text == "no") return false;
      throw Error(as + ": '" + text + "' is not on or off");
    }
    case OptionType::numbers: return parse_number_list(text, as);
    case OptionType::point:
      if (text.empty() || text == "auto") return std::monostate{};
      return parse_number_list(text, as, 3);
    case OptionType::region: return parse_number_list(text, as, 4);
    default: return text;
  }
}

std::string option_text(const OptionRow& row, const OptionValue& v) {
  if (std::holds_alternative<std::monostate>(v)) return "auto";
  if (const auto* b = std::get_if<bool>(&v)) return row.type == OptionType::on_off ? (*b ? "on" : "off") : (*b ? "true" : "false");
  if (const auto* x = std::get_if<double>(&v)) return shortest(*x);
  if (const auto* s = std::get_if<std::string>(&v)) return *s;
  if (const auto* l = std::get_if<std::vector<double>>(&v)) {
    std::string s;
    for (double x : *l) s += (s.empty() ? "" : ",") + shortest(x);
    return s;
  }
  if (const auto* p = std::get_if<std::vector<std::string>>(&v)) return joined(*p);
  if (std::holds_alternative<TriangleMesh>(v)) return "(mesh in memory)";
  return "(landmarks)";
}

}  // namespace impinge
