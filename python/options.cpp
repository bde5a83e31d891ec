// The option table (session/option_table.hpp) in Python: keyword values converted by each row's type,
// defaults from the clinical preset, and impinge.options(), the table itself, for the stub's and the study
// spec's tests (python/tests/test_options.py) and for users.
#include <cmath>
#include <algorithm>
#include <map>
#include <deque>

#include "bindings.hpp"
#include "impinge/core/error.hpp"
#include "impinge/session/plan_run.hpp"
#include "impinge/session/session.hpp"

namespace impinge::python {

namespace {

std::string type_of(const py::handle& v) { return py::str(v.get_type().attr("__name__")).cast<std::string>(); }

bool is_path(const py::handle& v) { return py::isinstance<py::str>(v) || py::hasattr(v, "__fspath__"); }

std::string fspath(const py::handle& v) {
  return py::str(py::module_::import("os").attr("fspath")(v)).cast<std::string>();
}

std::vector<double> numbers(const py::handle& v, const std::string& as) {
  if (py::isinstance<py::str>(v) || (!py::isinstance<py::sequence>(v) && !py::isinstance<py::array>(v)))
    throw Error(as + ": expected a list of numbers, got " + type_of(v));
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(v);
  if (!a || a.ndim() != 1) throw Error(as + ": expected a flat list of numbers");
  return std::vector<double>(a.data(), a.data() + a.size());
}

const char* use_name(unsigned bit) {
  switch (bit) {
    case use_distance: return "distance";
    case use_motion: return "motion";
    case use_rom: return "rom";
    case use_generate: return "generate";
    case use_joint: return "joint";
    case use_rom_limits: return "rom_limits";
    case use_rom_map: return "rom_map";
    case use_study: return "study";
    case use_generated_hip: return "generated_hip";
    case use_morphology: return "morphology";
    case use_plan: return "plan";
    case use_joint_plan: return "joint_plan";
    case use_view: return "view";
    default: return "?";
  }
}

// The OptionUse bit named `name` (as impinge.options() names the uses).
unsigned use_bit(const std::string& name) {
  std::string names;
  for (unsigned bit = 1; bit <= use_last; bit <<= 1) {
    if (name == use_name(bit)) return bit;
    names += (names.empty() ? "" : ", ") + std::string(use_name(bit));
  }
  throw Error("check_options: use '" + name + "' is not one of " + names);
}

}  // namespace

OptionValue to_value(const OptionRow& row, const py::handle& v, const std::string& as) {
  if (v.is_none()) return std::monostate{};
  switch (row.type) {
    case OptionType::text:
    case OptionType::choice:
      if (!py::isinstance<py::str>(v)) throw Error(as + ": expected a string, got " + type_of(v));
      return v.cast<std::string>();
    case OptionType::path:
      if (!is_path(v)) throw Error(as + ": expected a path, got " + type_of(v));
      return fspath(v);
    case OptionType::mesh:
      if (is_path(v)) return fspath(v);
      return to_mesh(v, as);
    case OptionType::number:
    case OptionType::integer:
      if (py::isinstance<py::str>(v)) return parse_option_text(row, v.cast<std::string>(), as);  // 'inf'
      if (py::isinstance<py::bool_>(v) || !(py::isinstance<py::float_>(v) || py::isinstance<py::int_>(v) ||
                                            py::hasattr(v, "__float__")))
        throw Error(as + ": expected a number, got " + type_of(v));
      return py::float_(py::reinterpret_borrow<py::object>(v)).cast<double>();
    case OptionType::flag:
    case OptionType::on_off:
      if (!py::isinstance<py::bool_>(v)) throw Error(as + ": expected True or False, got " + type_of(v));
      return v.cast<bool>();
    case OptionType::numbers:
    case OptionType::point:
    case OptionType::region:
      if (py::isinstance<py::str>(v)) return parse_option_text(row, v.cast<std::string>(), as);  // 'auto'
      return numbers(v, as);
    case OptionType::landmarks: {
      if (!py::isinstance<py::dict>(v)) throw Error(as + ": expected a dict name -> (x, y, z) mm");
      Landmarks l;
      for (const auto& [k, p] : py::reinterpret_borrow<py::dict>(v)) {
        const std::string name = py::str(k).cast<std::string>();
        const std::vector<double> x = numbers(p, as + "['" + name + "']");
        if (x.size() != 3) throw Error(as + "['" + name + "']: expected three numbers (x, y, z) mm");
        l[name] = Eigen::Vector3d(x[0], x[1], x[2]);
      }
      return l;
    }
    case OptionType::path_pair: {
      if (py::isinstance<py::str>(v) || !py::isinstance<py::sequence>(v))
        throw Error(as + ": expected a pair (ball_path, socket_path)");
      std::vector<std::string> p;
      for (const py::handle& x : py::reinterpret_borrow<py::sequence>(v)) p.push_back(fspath(x));
      return p;
    }
  }
  throw Error(as + ": unknown option type");
}

py::object to_python(const OptionRow& row, const OptionValue& v) {
  if (std::holds_alternative<std::monostate>(v)) return py::none();
  if (const auto* b = std::get_if<bool>(&v)) return py::bool_(*b);
  if (const auto* x = std::get_if<double>(&v)) {
    if (row.type == OptionType::integer) return py::int_(static_cast<long long>(*x));
    return py::float_(*x);
  }
  if (const auto* s = std::get_if<std::string>(&v)) return py::str(*s);
  if (const auto* l = std::get_if<std::vector<double>>(&v)) return py::cast(*l);
  if (const auto* p = std::get_if<std::vector<std::string>>(&v)) return py::tuple(py::cast(*p));
  return py::str(option_text(row, v));
}

const OptionRow& option_row(const std::string& key) {
  for (const OptionRow& r : option_table())
    if (r.key == key) return r;
  throw Error("no option '" + key + "' in the option table");
}

py::object default_of(const std::string& key) {
  const OptionRow& r = option_row(key);
  return to_python(r, r.get(RunOptions::clinical()));
}

void set_options(RunOptions& run, const py::dict& given, unsigned use, const std::string& caller) {
  std::string known;
  for (const OptionRow& r : option_table())
    if (r.uses & use) known += (known.empty() ? "" : ", ") + r.key;
  for (const auto& [k, v] : given) {
    const std::string key = py::str(k).cast<std::string>();
    bool ok = false;
    for (const OptionRow& r : option_table())
      ok = ok || ((r.uses & use) && (r.key == key || std::count(r.old_keys.begin(), r.old_keys.end(), key)));
    if (!ok) throw Error(caller + ": unknown option '" + key + "' (options: " + known + ")");
  }
  for (const OptionRow& r : option_table()) {  // the table's order: preset first
    if (!(r.uses & use)) continue;
    std::string key = r.key;  // the key given: the row's, or a former one (warned)
    for (const std::string& old : r.old_keys) {
      if (!given.contains(old)) continue;
      if (given.contains(r.key))
        throw Error(caller + ": give " + r.key + " or " + old + " (its former name), not both");
      const std::string msg = caller + ": '" + old + "' is deprecated and will be removed in the next release: use '" +
                              r.key + "'";
      if (PyErr_WarnEx(PyExc_DeprecationWarning, msg.c_str(), 1) != 0) throw py::error_already_set();
      key = old;
    }
    if (!given.contains(key)) continue;
    const py::object v = given[py::str(key)];
    if (!v.is_none()) r.set(run, to_value(r, v, key), key);
  }
}

void set_cli_options(RunOptions& run, const std::vector<std::string>& args, unsigned use, const std::string& caller) {
  // The tokens as the CLI gives them: --name VALUE, --name=VALUE, or --flag; a former name warns.
  std::map<const OptionRow*, std::pair<std::string, std::string>> given;  // row -> (name as given, text)
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a.rfind("--", 0) != 0) throw Error(caller + ": '" + a + "': expected an option --NAME");
    const std::size_t eq = a.find('=');
    const std::string name = a.substr(2, eq == std::string::npos ? std::string::npos : eq - 2);
    const OptionRow* r = find_option(name);
    if (r == nullptr || !(r->uses & use) || (r->name != name && !std::count(r->old_names.begin(), r->old_names.end(), name)))
      throw Error(caller + ": unknown option --" + name);
    if (given.count(r)) {
      const std::string before = given[r].first;
      if (before != name)
        throw Error(caller + ": give --" + r->name + " or --" + (name == r->name ? before : name) +
                    " (its former name), not both");
      throw Error(caller + ": --" + name + " given twice");
    }
    std::string text;
    if (eq != std::string::npos) {
      text = a.substr(eq + 1);
      if (r->type == OptionType::flag && text != "true" && text != "false")
        throw Error(caller + ": --" + name + "=" + text + ": a flag takes no value (or true, false)");
    } else if (r->type != OptionType::flag) {
      if (i + 1 >= args.size()) throw Error(caller + ": --" + name + " needs a value");
      text = args[++i];
    }
    if (name != r->name) {
      const std::string msg =
          caller + ": --" + name + " is deprecated and will be removed in the next release: use --" + r->name;
      if (PyErr_WarnEx(PyExc_DeprecationWarning, msg.c_str(), 1) != 0) throw py::error_already_set();
    }
    given[r] = {name, text};
  }
  for (const OptionRow& r : option_table()) {  // the table's order: preset first
    const auto it = given.find(&r);
    if (it == given.end()) continue;
    const std::string as = "--" + it->second.first;
    r.set(run, r.type == OptionType::flag ? OptionValue(it->second.second != "false")
                                          : parse_option_text(r, it->second.second, as),
          as);
  }
}

std::string keywords_doc(unsigned use) {
  std::string keys;
  for (const OptionRow& r : option_table())
    if (r.uses & use) keys += (keys.empty() ? "" : ", ") + r.key;
  return "Keywords, the rows of impinge.options() with '" + std::string(use_name(use)) +
         "' in their uses (None or absent: the clinical preset's default): " + keys + ".";
}

const char* keep_doc(std::string doc) {
  static std::deque<std::string> docs;  // a deque: earlier strings never move
  docs.push_back(std::move(doc));
  return docs.back().c_str();
}

void bind_options(py::module_& m) {
  m.def(
      "options",
      []() {
        const RunOptions clinical = RunOptions::clinical(), thesis = RunOptions::thesis();
        py::list rows;
        for (const OptionRow& r : option_table()) {
          py::dict d;
          d["name"] = r.name;
          d["key"] = r.key;
          d["type"] = to_string(r.type);
          d["unit"] = r.unit;
          d["choices"] = r.choices;
          d["min"] = r.min;
          d["max"] = r.max;
          d["min_exclusive"] = r.min_open;
          d["required"] = r.required;
          d["default"] = to_python(r, r.get(clinical));
          d["thesis_default"] = to_python(r, r.get(thesis));
          d["help"] = r.help;
          d["old_names"] = r.old_names;
          d["old_keys"] = r.old_keys;
          py::list uses;
          for (unsigned bit = 1; bit <= use_last; bit <<= 1)
            if (r.uses & bit) uses.append(use_name(bit));
          d["uses"] = uses;
          rows.append(d);
        }
        return rows;
      },
      "The option table (the session layer's, session/option_table.hpp) -> a list of dicts, one per option: name "
      "(the CLI's, without dashes), key (Python's keyword and the study files' key), type (text, path, choice, "
      "number, integer, flag, on_off, numbers, point, region, mesh, landmarks, path_pair), unit, choices, min and "
      "max (numbers; the field's declared range), min_exclusive (min itself is not valid), required (by the CLI), "
      "default (the clinical preset's; None: decided from other options, as "
      "help says), thesis_default (the thesis preset's), help, uses (distance, motion, rom, generate: CLI "
      "commands; joint: Joint(...); rom_limits, rom_map: those methods and the study kinds rom and envelope; "
      "study: a study file's [joint] and [[task]]; generated_hip: that function).");
  m.def(
      "check_options",
      [](const std::string& use, const py::kwargs& given) {
        const unsigned bit = use_bit(use);
        RunOptions run = RunOptions::clinical();
        set_options(run, given, bit, use);
        if (bit == use_joint_plan || bit == use_plan) check_plan_request(run.session, run.plan, run.rom.labrum);
        if (bit == use_joint || bit == use_study) resolved_hip_options(run.session);  // the maps' scheme, the joint's
        py::dict d;
        for (const OptionRow& r : option_table())
          if (r.uses & bit) d[py::str(r.key)] = to_python(r, r.get(run));
        return d;
      },
      py::arg("use"),
      "Check keywords as the call of `use` checks them (a use of impinge.options(): joint, rom_limits, rom_map, "
      "joint_plan, study, generated_hip, ...), building nothing: each value through its option-table row (type, "
      "range, choice); for joint and study the settings together as a Joint resolves them (the maps' scheme at "
      "its resolution, the joint's options), without the meshes; for joint_plan the plan's own checks (the "
      "targets' text, the target motion file, a target at all) -> dict key -> value of every row of that use, as the call would take it (the clinical "
      "preset's default where not given). Raises impinge.Error naming the key, the value and what is valid. "
      "impinge.study checks every study key through it before any task runs (impinge).");
}

}  // namespace impinge::python
