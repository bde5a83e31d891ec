#pragma once
/// @file mesh_io.hpp
/// Reading meshes (PLY, STL, OBJ, OFF through assimp) and writing per-vertex gap PLY files.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "impinge/core/mesh.hpp"
#include "impinge/io/vtk_output.hpp"

namespace impinge {

/// Load a triangle mesh from `path`. Coordinates are taken as millimetres in the file's own frame.
/// Format by extension: `.ply` (ascii or binary) and `.off` by impinge's own strict readers (Debian
/// 12's assimp 5.2.4 hangs or writes out of bounds on some malformed files of these two formats,
/// found by fuzzing), every other extension (STL, OBJ, ...) by assimp.
///
/// Vertex order: PLY and OFF keep the file's vertices in order and count. STL and OBJ store
/// corners per face; their identical corners are welded (assimp JoinIdenticalVertices), so
/// their vertices are in first-use order.
/// Degenerate triangles (repeated index or zero area) are removed and counted in
/// `degenerate_faces_skipped`. Several meshes in one file are concatenated.
///
/// Throws impinge::Error naming `path` and the element (line, byte offset, vertex or face) for: a
/// missing or unreadable file, a malformed or truncated file (header, count, type, value), no vertices or no triangles, a non-triangle face ("face 7 has 4
/// vertices"), an out-of-range index, a non-finite coordinate, or no triangle left after
/// removing the degenerate ones.
TriangleMesh load_mesh(const std::string& path);

/// Write `mesh` with per-vertex `gap_mm` as a binary little-endian PLY readable by ParaView
/// and MeshLab: properties x y z (float, mm), gap_mm (float; NaN where untested or no
/// surface), quality (= gap_mm, MeshLab's scalar), level (uchar impingement level, 255 when
/// untested), red green blue (uchar colour of the level); then the faces.
/// `V` (n x 3, mm) replaces mesh.V so callers can write a posed copy; `gap_mm`, `level` and
/// `rgb` (n x 3) give one entry per vertex. With `distance_mm` (n values, or null), a property
/// distance_mm (float, the signed Euclidean distance; NaN beyond its reach) after quality, and with
/// `sign_undecided` too (n flags), a property sign_undecided (uchar, 1 where the other mesh cannot decide the
/// distance's sign: signed_distance.hpp, rule 3) after it.
/// Throws impinge::Error if the file cannot be written or the sizes disagree.
void write_gap_ply(const std::string& path, PointsRef V, const Faces& F, const Eigen::VectorXf& gap_mm,
                   const Eigen::Matrix<unsigned char, Eigen::Dynamic, 1>& level,
                   const Eigen::Matrix<unsigned char, Eigen::Dynamic, 3, Eigen::RowMajor>& rgb,
                   const Eigen::VectorXf* distance_mm = nullptr,
                   const std::vector<std::uint8_t>* sign_undecided = nullptr);

/// Write a plain mesh (x y z float, faces) as binary little-endian PLY. Throws on I/O error.
void write_ply(const std::string& path, const TriangleMesh& mesh);
/// The same with per-vertex float properties after x y z, named as `arrays` name them (each f32 with n values, e.g.
/// resection_mm). Throws impinge::Error naming the file on I/O errors or an array of another length.
void write_ply(const std::string& path, const TriangleMesh& mesh, const std::vector<PointArray>& arrays);

}  // namespace impinge
