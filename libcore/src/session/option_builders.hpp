#pragma once
// The option table's row builders (option_table.cpp, option_rows.cpp): typed rows whose setters check a
// value's type, range or choice and name the option, the value and what is valid in their errors.
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "impinge/core/enum_names.hpp"
#include "impinge/core/range.hpp"

#include "impinge/core/error.hpp"
#include "impinge/session/option_table.hpp"

namespace impinge::detail {

/// The shortest decimal text that reads back as x ("inf" for infinity; integers without a point).
std::string shortest(double x);
/// "a, b, c".
std::string joined(const std::vector<std::string>& v);
/// x with its unit ("12 mm").
std::string with_unit(double x, const std::string& unit);

/// The value as T; an impinge::Error naming `as` and what was `expected` otherwise.
template <typename T>
const T& value_as(const OptionValue& v, const std::string& as, const char* expected) {
  const T* x = std::get_if<T>(&v);
  require(x != nullptr, [&] { return as + ": expected " + expected; });
  return *x;
}

/// The checked number of a number or integer row: finite (or infinite where the row's max is), whole for
/// an integer row, within [row.min, row.max]. Throws impinge::Error naming `as`, the value and the range.
double checked_number(const OptionRow& row, const OptionValue& v, const std::string& as);
/// A checked list of finite numbers: `count` of them (0: at least one).
std::vector<double> checked_numbers(const OptionValue& v, const std::string& as, std::size_t count);

// The rows' builders. `ref` is a generic lambda giving the member (const or not) of a RunOptions.
struct Rows {
  std::vector<OptionRow> rows;

  OptionRow& add(std::string name, std::string key, OptionType type, std::string unit, unsigned uses,
                 std::string help) {
    OptionRow r;
    r.name = std::move(name), r.key = std::move(key), r.type = type, r.unit = std::move(unit), r.uses = uses;
    r.help = std::move(help);
    rows.push_back(std::move(r));
    return rows.back();
  }

  // A number member whose valid values are `range` (the member's declared Range).
  template <typename Ref>
  OptionRow& number(std::string name, std::string key, std::string unit, unsigned uses, const Range& range,
                    std::string help, Ref ref, OptionType type = OptionType::number) {
    OptionRow& r = add(std::move(name), std::move(key), type, std::move(unit), uses, std::move(help));
    r.min = range.min, r.max = range.max, r.min_open = range.min_open;
    const OptionRow spec = r;  // the range and unit, for the setter's checks
    r.set = [ref, spec](RunOptions& o, const OptionValue& v, const std::string& as) {
      using T = std::decay_t<decltype(ref(o))>;
      ref(o) = static_cast<T>(checked_number(spec, v, as));
    };
    r.get = [ref](const RunOptions& o) -> OptionValue { return static_cast<double>(ref(o)); };
    return r;
  }

  template <typename Ref>
  OptionRow& integer(std::string name, std::string key, std::string unit, unsigned uses, const Range& range,
                     std::string help, Ref ref) {
    return number(std::move(name), std::move(key), std::move(unit), uses, range, std::move(help), ref,
                  OptionType::integer);
  }

  // A string member; `choices` empty: any text (text, path). An empty member reads as nothing (auto).
  template <typename Ref>
  OptionRow& text(std::string name, std::string key, OptionType type, unsigned uses, std::vector<std::string> choices,
                  std::string help, Ref ref) {
    OptionRow& r = add(std::move(name), std::move(key), type, "", uses, std::move(help));
    r.choices = std::move(choices);
    const std::vector<std::string> valid = r.choices;
    r.set = [ref, valid](RunOptions& o, const OptionValue& v, const std::string& as) {
      if (std::holds_alternative<std::monostate>(v)) {
        ref(o).clear();
        return;
      }
      const std::string& s = value_as<std::string>(v, as, "a string");
      bool ok = valid.empty();
      for (const std::string& c : valid) ok = ok || c == s;
      require(ok, [&] { return as + ": '" + s + "' is not one of " + joined(valid); });
      ref(o) = s;
    };
    r.get = [ref](const RunOptions& o) -> OptionValue {
      if (ref(o).empty()) return std::monostate{};
      return std::string(ref(o));
    };
    return r;
  }

  template <typename Ref>
  OptionRow& flag(std::string name, std::string key, OptionType type, unsigned uses, std::string help, Ref ref,
                  bool inverted = false) {
    OptionRow& r = add(std::move(name), std::move(key), type, "", uses, std::move(help));
    r.set = [ref, inverted](RunOptions& o, const OptionValue& v, const std::string& as) {
      ref(o) = value_as<bool>(v, as, "true or false") != inverted;
    };
    r.get = [ref, inverted](const RunOptions& o) -> OptionValue { return bool(ref(o)) != inverted; };
    return r;
  }

  // A choice stored as an enum, or as an optional enum (unset: nothing, "auto"), spelled by the enum's one name
  // table (enum_names.hpp).
  template <typename Ref, typename E, std::size_t N>
  OptionRow& choice(std::string name, std::string key, unsigned uses, const EnumNames<E, N>& names, std::string help,
                    Ref ref) {
    OptionRow& r = add(std::move(name), std::move(key), OptionType::choice, "", uses, std::move(help));
    r.choices = enum_choices(names);
    r.set = [ref, names](RunOptions& o, const OptionValue& v, const std::string& as) {
      if constexpr (std::is_same_v<std::decay_t<decltype(ref(o))>, std::optional<E>>) {
        if (std::holds_alternative<std::monostate>(v)) {
          ref(o).reset();
          return;
        }
      }
      ref(o) = parse_enum(names, value_as<std::string>(v, as, "a string"), as);
    };
    r.get = [ref, names](const RunOptions& o) -> OptionValue {
      if constexpr (std::is_same_v<std::decay_t<decltype(ref(o))>, std::optional<E>>) {
        if (!ref(o)) return std::monostate{};
        return std::string(enum_name(names, *ref(o)));
      } else {
        return std::string(enum_name(names, ref(o)));
      }
    };
    return r;
  }

  template <typename Ref>
  OptionRow& numbers(std::string name, std::string key, std::string unit, unsigned uses, std::string help, Ref ref) {
    OptionRow& r = add(std::move(name), std::move(key), OptionType::numbers, std::move(unit), uses, std::move(help));
    r.set = [ref](RunOptions& o, const OptionValue& v, const std::string& as) {
      if (std::holds_alternative<std::monostate>(v)) {
        ref(o).clear();
        return;
      }
      ref(o) = checked_numbers(v, as, 0);
    };
    r.get = [ref](const RunOptions& o) -> OptionValue {
      if (ref(o).empty()) return std::monostate{};
      return std::vector<double>(ref(o));
    };
    return r;
  }
};

// A mesh option: a path, or a mesh in memory (Python's (V, F)).
template <typename PathRef, typename MeshRef>
void set_mesh(RunOptions& o, const OptionValue& v, const std::string& as, PathRef path, MeshRef mesh) {
  if (const auto* p = std::get_if<std::string>(&v)) {
    path(o) = *p;
    mesh(o).reset();
  } else if (const auto* m = std::get_if<TriangleMesh>(&v)) {
    mesh(o) = *m;
    path(o).clear();
  } else {
    require(std::holds_alternative<std::monostate>(v), as + ": expected a mesh file or a mesh");
    path(o).clear();
    mesh(o).reset();
  }
}

}  // namespace impinge::detail
