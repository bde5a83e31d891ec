#pragma once
/// @file view.hpp
/// `impinge view` (issue 79): the thesis' Joint3D (section 3.4) in the browser. The CLI checks the options through the
/// option table, then runs the server (Python: `python3 -m impinge.view`, aiohttp around impinge.Joint) with the
/// same `impinge distance` options, which the server's Joint reads through the same table (Joint._from_cli).

#include <string>
#include <vector>

#include "impinge/core/range.hpp"

namespace impinge {

/// Options of `impinge view`'s server.
struct ViewOptions {
  /// The address the server listens on, "127.0.0.1" (this machine only). Another one (e.g. "0.0.0.0") serves the
  /// network too: the page's token still guards every request, and the CLI warns.
  std::string host = "127.0.0.1";
  int port = 0;  ///< TCP port; 0: a free one chosen by the system (printed with the page's address)
  static constexpr Range kPortRange{0, 65535};  ///< of port
  bool open_browser = true;  ///< open the page in the user's browser (webbrowser: $BROWSER, xdg-open)
  /// Write one self-contained HTML file here instead of serving (no server, no network when it is opened): the meshes
  /// and the poses `export_poses` names, each pose's values as the server would send them. Empty: serve.
  std::string export_path;
  /// Which poses an export holds: "auto" (the motion's frames with --motion, else "rom"), "rom" (neutral and, per
  /// standard motion, the pose 2 deg before its limit and at it), "motion", or "F,A,R;F,A,R;..." (degrees, ISB).
  std::string export_poses = "auto";
  /// An `impinge plan` output folder (plan.json, femur_resected.ply, pelvis_resected.ply) to show: the resected
  /// bones coloured by resection_mm, before and after, with each target's limit before and after. Empty: none.
  std::string plan_dir;
  /// A folder whose motion files (.csv, .mot, .sto, directly in it) the page may choose from; the server reads no
  /// other file for them (a name with a path, '..', or a link out of the folder is refused). Empty: none.
  std::string motion_folder;
  double export_max_mb = 25;  ///< the export's largest size, MB (10^6 bytes); more poses are decimated to fit
  static constexpr Range kExportMaxMbRange{1, 2000};  ///< of export_max_mb, MB
};

/// How to start the server: the interpreter and its arguments (argv, [0] the program) and the PYTHONPATH entry
/// that holds the `impinge` package.
struct ViewCommand {
  std::vector<std::string> argv;
  std::string python_path;
};

/// The server's command for `view` and `distance_args` (the `impinge distance` options given, as the CLI's tokens:
/// "--name=value" or "--flag"). The interpreter is $IMPINGE_PYTHON (a path, or a name looked up on PATH) or
/// /usr/bin/python3 (Debian's, with numpy; 3.11 or later: it runs with -P, so the current folder is not imported);
/// the package is found in $IMPINGE_PYTHONPATH, else `build_python_dir` (the build tree's BUILD/python) when it holds
/// impinge/view. Throws impinge::Error naming what is missing (no package, no interpreter) and how to get it.
ViewCommand view_command(const ViewOptions& view, const std::vector<std::string>& distance_args,
                         const std::string& build_python_dir);

/// A warning for a host other than this machine's loopback ("127.0.0.1", "::1", "localhost"); empty otherwise.
std::string view_host_warning(const std::string& host);

}  // namespace impinge
