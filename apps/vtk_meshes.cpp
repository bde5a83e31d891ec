#include "vtk_meshes.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "impinge/core/error.hpp"
#include "impinge/io/mesh_io.hpp"
#include "impinge/io/subject.hpp"

namespace impinge::cli {

namespace fs = std::filesystem;

std::string shell_quote(const std::string& text) {
  std::string q = "'";
  for (char c : text) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

namespace {

bool is_vtk(const std::string& path) {
  std::string p = path;
  std::transform(p.begin(), p.end(), p.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return p.size() > 4 && (p.compare(p.size() - 4, 4, ".vtp") == 0 || p.compare(p.size() - 4, 4, ".vtk") == 0);
}

TriangleMesh read_vtk(const std::string& path) {
  const char* env = std::getenv("IMPINGE_PYTHON_DIR");
  const std::string script = std::string(env != nullptr ? env : IMPINGE_PYTHON_DIR) + "/vtk_meshes.py";
  require(fs::exists(script), path + ": reading a VTK file needs " + script +
                                  " (set IMPINGE_PYTHON_DIR to impinge's python/impinge folder)");
  char dir_template[] = "/tmp/impinge-vtk-XXXXXX";
  const char* dir = ::mkdtemp(dir_template);
  require(dir != nullptr, path + ": cannot make a temporary folder to convert it");
  const std::string ply = std::string(dir) + "/mesh.ply", err = std::string(dir) + "/error.txt";
  const int rc = std::system(("/usr/bin/python3 " + shell_quote(script) + " " + shell_quote(path) + " " +
                              shell_quote(ply) + " 2> " + shell_quote(err)).c_str());
  std::string message;
  if (rc != 0) {
    std::ifstream e(err);
    std::getline(e, message);
  }
  TriangleMesh mesh;
  try {
    if (rc == 0) mesh = load_mesh(ply);
  } catch (...) {
    fs::remove_all(dir);
    throw;
  }
  fs::remove_all(dir);
  require(rc == 0, [&] { return message.empty() ? path + ": VTK cannot read it" : message; });
  mesh.source = path;
  return mesh;
}

}  // namespace

void read_vtk_inputs(SessionInput& in) {
  std::string femur = in.ball, pelvis = in.socket;
  if (!in.subject.empty() && (femur.empty() || pelvis.empty())) {
    const SubjectInfo s = load_subject(in.subject);
    if (femur.empty() && !in.ball_mesh) femur = s.femur_path;
    if (pelvis.empty() && !in.socket_mesh) pelvis = s.pelvis_path;
  }
  if (!in.ball_mesh && is_vtk(femur)) in.ball_mesh = read_vtk(femur), in.ball.clear();
  if (!in.socket_mesh && is_vtk(pelvis)) in.socket_mesh = read_vtk(pelvis), in.socket.clear();
}

}  // namespace impinge::cli
