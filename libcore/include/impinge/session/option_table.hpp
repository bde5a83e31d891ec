#pragma once
/// @file option_table.hpp
/// The one table of every option a front end exposes: the CLI's (`impinge distance|motion|rom|
/// generate`), Python's (`impinge.Joint(...)`, `Joint.rom_limits`, `Joint.rom_map`,
/// `impinge.generated_hip`), the `.pyi` stub's and the study files' (`[joint]`, `[[task]]`). Each row
/// holds the option's CLI name, its Python and study key, type, unit, help text, where it applies, and
/// the field of RunOptions it sets: a field of a library options struct (SessionOptions::hip, RomRequest,
/// PlanRequest, ...) or a session-only one. The field holds the default (its initialiser, or the preset
/// RunOptions::clinical() where that differs) and declares its valid range (a Range beside it) or its
/// choices (its enum's name table), which the row takes; so no front end holds a default or a range of its
/// own. The CLI builds its options from the rows, Python its keywords, the study spec its keys, the build
/// the `.pyi` stub (python/gen_stub.py); tests/session's option_table_test and python/tests' test_options
/// fail when a front end differs from the table. Adding an option: docs/architecture.md, "Options: each
/// bound once".

#include <functional>
#include <string>
#include <variant>
#include <vector>

#include "impinge/anatomy/anatomical_frame.hpp"
#include "impinge/core/mesh.hpp"
#include "impinge/io/generated_models.hpp"
#include "impinge/session/plan_run.hpp"
#include "impinge/session/runs.hpp"
#include "impinge/session/session.hpp"
#include "impinge/session/view.hpp"

namespace impinge {

/// A command's own arguments (the CLI's): where to write, which pose or motion, how to show it.
struct CommandArguments {
  std::string out;           ///< output folder (every command)
  std::string pose;          ///< `distance`: "FLEX,ADD,IR", degrees
  bool render = false;       ///< `distance`: also shaded renders (render.png)
  std::string motion;        ///< `motion`: the motion file (.csv, .mot, .sto)
  int vtp_every = 0;         ///< `motion`: VTP file every N frames; 0: automatic (at most 100 files)
  static constexpr Range kVtpEveryRange{0, 1e9};
  bool quiet = false;        ///< `motion`: no progress bar or final line
};

/// What one front-end call sets: the session (inputs, COR, maps, frames), a ROM run, a generated
/// model, and the command's own arguments. Its presets are the named default sets.
/// Default-constructed it holds the library structs' own defaults (SessionOptions{}, RomRequest{}, ...); the
/// front ends start from clinical().
struct RunOptions {
  std::string preset;  ///< the preset it started from ("clinical", "thesis"; empty: the structs' defaults)
  SessionOptions session;
  RomRequest rom;
  HipModelOptions generate;
  PlanRequest plan;  ///< `impinge plan`, Joint.plan, a study's `plan` task
  CommandArguments command;
  ViewOptions view;  ///< `impinge view`'s server
  /// The front ends' defaults (CLI, Python, studies): layered maps (4 crossings) for hidden vertices,
  /// Euclidean distances beside the gaps, the ROM metric the distance, the ROM map on its 0..120 x
  /// -20..40 deg grid; the joint-centre method follows the neutral (equidistant, Puls et al. 2010, at
  /// anatomical neutral).
  static RunOptions clinical();
  /// The thesis' set-up (single-layer maps, radial gaps only, rotation about the femoral head centre,
  /// the ROM metric the radial gap; thesis ch. 3 and sec. 5.2): the thesis experiments' start.
  static RunOptions thesis();
  /// A preset by name: "clinical" or "thesis". Throws impinge::Error naming `context` otherwise.
  static RunOptions named(const std::string& name, const std::string& context);
};

/// The settings a preset sets (SessionOptions' hip, grid, query_strategy and max_memory_gb; not its inputs, COR or
/// poses) copied from `from` into `to`.
void take_session_settings(SessionOptions& to, const SessionOptions& from);

/// What an option's value is.
enum class OptionType {
  text,       ///< a string
  path,       ///< a file path
  choice,     ///< one of OptionRow::choices
  number,     ///< a real number within OptionRow::min..max
  integer,    ///< a whole number within OptionRow::min..max
  flag,       ///< CLI: present or not; Python and studies: True/False
  on_off,     ///< CLI: on|off; Python and studies: True/False
  numbers,    ///< CLI: "a,b,c"; Python and studies: a list of numbers
  point,      ///< "auto" or x, y, z (mm)
  region,     ///< x, y, z, r (mm)
  mesh,       ///< CLI: a mesh file; Python: a file or (V, F) arrays
  landmarks,  ///< Python: dict name -> (x, y, z) mm
  path_pair,  ///< Python: (ball_path, socket_path)
};
/// "text", "path", "choice", ... (the names impinge.options() gives).
const char* to_string(OptionType type);

/// Where an option applies (bits of OptionRow::uses).
enum OptionUse : unsigned {
  use_distance = 1u << 0,     ///< `impinge distance`
  use_motion = 1u << 1,       ///< `impinge motion`
  use_rom = 1u << 2,          ///< `impinge rom`
  use_generate = 1u << 3,     ///< `impinge generate`
  use_joint = 1u << 4,        ///< Python Joint(...)
  use_rom_limits = 1u << 5,   ///< Python Joint.rom_limits(...); a study's `rom` task
  use_rom_map = 1u << 6,      ///< Python Joint.rom_map(...); a study's `envelope` task
  use_study = 1u << 7,        ///< a study's [joint] and [[task]] keys
  use_generated_hip = 1u << 8,  ///< Python generated_hip(...)
  use_morphology = 1u << 9,     ///< `impinge morphology`, Python impinge.morphology(...)
  use_plan = 1u << 10,          ///< `impinge plan`
  use_joint_plan = 1u << 11,    ///< Python Joint.plan(...); a study's `plan` task
  use_view = 1u << 12,          ///< `impinge view` (its server's Joint: Python Joint._from_cli)
  use_last = use_view,          ///< the highest bit (for loops over the bits)
  use_cli_commands = use_distance | use_motion | use_rom | use_generate | use_morphology | use_plan,
};

/// A value given to an option: nothing ("auto": the preset's rule), a flag, a number, a text, a list
/// of numbers, a mesh in memory, landmarks, or a list of texts (a path pair).
using OptionValue = std::variant<std::monostate, bool, double, std::string, std::vector<double>, TriangleMesh,
                                 Landmarks, std::vector<std::string>>;

/// One option. `set` checks the value (its type, range or choice) and stores it in RunOptions;
/// its errors name the option as the user wrote it (`as`: "--max-radius" or "max_radius_mm"), the
/// value, and what is valid. `get` reads the value back (the default: get(RunOptions::clinical())).
struct OptionRow {
  std::string name;  ///< CLI long name without dashes, e.g. "max-radius"
  std::string key;   ///< Python keyword and study key, e.g. "max_radius_mm"
  OptionType type = OptionType::text;
  std::string unit;  ///< "mm", "deg", "mm^3" ...; empty when none
  unsigned uses = 0;                 ///< OptionUse bits
  std::vector<std::string> choices;  ///< OptionType::choice: the valid values
  /// number, integer: the valid range, from the field's declared Range (e.g. JointOptions::kLayersRange), with 0
  /// added where the row's 0 means "none" (max-radius, sparse); inclusive unless min_open; max inf: "inf" allowed.
  double min = -1e308, max = 1e308;
  bool min_open = false;  ///< min itself is not valid (a length that must be > 0)
  bool required = false;             ///< the CLI commands that use it need it (but those in optional_for)
  unsigned optional_for = 0;         ///< OptionUse bits of commands where a required row may be left out
  /// Former CLI names (without dashes) still accepted for one release: the CLI says which name replaces one.
  /// Naming convention: CLI names carry no unit (the unit is in the help and the value's name: NUMBER mm); Python
  /// and study keys carry it on lengths and angles (`clearance_mm`, `step_deg`).
  std::vector<std::string> old_names;
  /// Former Python keywords and study keys still accepted for one release (Python warns with a
  /// DeprecationWarning naming the key that replaces one; a study spec names it in its warning).
  std::vector<std::string> old_keys;
  std::string help;
  std::function<void(RunOptions&, const OptionValue&, const std::string& as)> set;
  std::function<OptionValue(const RunOptions&)> get;
};

/// Every option, in the order the CLI's help lists them. Built once; thread-safe to read.
const std::vector<OptionRow>& option_table();
/// The row named `name` (CLI name, former CLI name, key or former key); nullptr when none.
const OptionRow* find_option(const std::string& name);

/// A CLI text as the row's value: "auto" or "" for a point is nothing; numbers must be finite (or
/// "inf" where the row's max is infinite); "on|off|true|false" for on_off. Throws impinge::Error
/// naming `as`, the text and what is valid.
OptionValue parse_option_text(const OptionRow& row, const std::string& text, const std::string& as);
/// A value as the CLI's help and impinge.options() show it: numbers in shortest form, lists
/// comma-separated, nothing as "auto", flags as true/false.
std::string option_text(const OptionRow& row, const OptionValue& value);

}  // namespace impinge
