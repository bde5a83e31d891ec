#pragma once
// VTK meshes for the CLI: wherever a command takes a mesh (--ball, --socket, or the femur and pelvis of a
// subject.json), a .vtp (XML PolyData, OpenSim's bone geometry) or .vtk (legacy) file is read by VTK's own
// readers through its Python bindings (python/impinge/vtk_meshes.py, as Python's impinge.load_mesh reads it),
// written to a temporary PLY and read back, in the file's vertex order and named by the VTK file.

#include <string>

#include "impinge/session/session.hpp"

namespace impinge::cli {

/// A text quoted for the shell ('...').
std::string shell_quote(const std::string& text);

/// The VTK files of `input` read into its ball_mesh and socket_mesh (mm, as the files have them). Throws
/// impinge::Error naming the file when VTK cannot read it or its Python bindings are missing.
void read_vtk_inputs(SessionInput& input);

}  // namespace impinge::cli
