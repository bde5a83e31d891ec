// `impinge view`'s server command (session/view.hpp).
#include "impinge/session/view.hpp"

#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "impinge/core/error.hpp"

namespace impinge {

namespace fs = std::filesystem;

ViewCommand view_command(const ViewOptions& view, const std::vector<std::string>& distance_args,
                         const std::string& build_python_dir) {
  check_in_range("--port", view.port, ViewOptions::kPortRange, "");
  require(!view.host.empty(), "--host '': give an address (127.0.0.1: this machine only; 0.0.0.0: every interface)");
  ViewCommand c;
  const char* env_path = std::getenv("IMPINGE_PYTHONPATH");
  if (env_path != nullptr && *env_path != '\0') {
    c.python_path = env_path;
  } else if (!build_python_dir.empty() && fs::exists(fs::path(build_python_dir) / "impinge" / "view" / "__init__.py")) {
    c.python_path = build_python_dir;
  } else {
    throw Error("impinge view: the Python package impinge (impinge/view) is not in " +
                (build_python_dir.empty() ? std::string("this build") : build_python_dir) +
                ": build with IMPINGE_BUILD_PYTHON=ON, or set IMPINGE_PYTHONPATH to the folder holding impinge/");
  }
  const char* env_python = std::getenv("IMPINGE_PYTHON");
  const std::string python = env_python != nullptr && *env_python != '\0' ? env_python : "/usr/bin/python3";
  if (python.find('/') != std::string::npos && !fs::exists(python))
    throw Error("impinge view: no Python interpreter " + python + " (install python3, or set IMPINGE_PYTHON)");
  // -P: the current folder is not put first on sys.path (an impinge/ or aiohttp.py there must not be imported).
  check_in_range("--export-max-mb", view.export_max_mb, ViewOptions::kExportMaxMbRange, "MB");
  const nlohmann::json j = {{"host", view.host},
                            {"port", view.port},
                            {"open_browser", view.open_browser},
                            {"export", view.export_path},
                            {"export_poses", view.export_poses},
                            {"export_max_mb", view.export_max_mb},
                            {"plan", view.plan_dir},
                            {"motion_folder", view.motion_folder}};
  c.argv = {python, "-P", "-m", "impinge.view", "--view-json", j.dump(), "--"};
  c.argv.insert(c.argv.end(), distance_args.begin(), distance_args.end());
  return c;
}

std::string view_host_warning(const std::string& host) {
  std::string h = host;
  for (char& c : h) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (h.rfind("127.", 0) == 0 || h == "::1" || h == "localhost") return "";  // this machine's loopback
  return "--host " + host + " serves the page beyond this machine: anyone who can reach it and knows the page's "
         "token can pose the hip and read the meshes";
}

}  // namespace impinge
