#pragma once
/// @file vtk_output.hpp
/// ParaView output: VTK XML PolyData (.vtp, binary appended) files with per-point arrays and a
/// ParaView Data collection (.pvd) that plays them as an animation (VTK file formats, Kitware,
/// "VTK XML formats", https://docs.vtk.org/en/latest/design_documents/VTKFileFormats.html).

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "impinge/core/mesh.hpp"

namespace impinge {

/// A named per-point array: exactly one of `f32` or `u8` holds n values.
struct PointArray {
  std::string name;
  std::vector<float> f32;
  std::vector<std::uint8_t> u8;
};

/// Write `path` as VTK XML PolyData (version 1.0, little-endian, UInt64 headers, raw appended
/// binary): points V (n x 3, mm, written as float32), triangles F (m x 3, 0-based), and the
/// point arrays (each n values). Throws impinge::Error naming the file on a bad index, an array
/// of the wrong length, or an I/O error.
void write_vtp(const std::string& path, PointsRef V, const Faces& F, const std::vector<PointArray>& arrays);

/// One entry of a .pvd collection: a time step (s) and a file path relative to the .pvd.
struct PvdEntry {
  double time_s = 0;
  std::string file;
};

/// Write `path` as a ParaView Data collection listing `entries` as time steps. Throws
/// impinge::Error naming the file on an I/O error.
void write_pvd(const std::string& path, const std::vector<PvdEntry>& entries);

}  // namespace impinge
