#pragma once
// Private to libcore: strict readers for PLY and OFF, used by load_mesh instead of assimp for those
// two formats. Debian 12's assimp 5.2.4 hangs on a PLY header without `end_header` and writes out of
// bounds on OFF faces with bad indices (both found by the fuzz harness, tests/fuzz/regressions/mesh);
// these readers check every count, type and byte against the file before they read it.

#include <string>

#include "impinge/core/mesh.hpp"

namespace impinge::detail {

/// Read a PLY file (Turk 1994; ascii, binary_little_endian or binary_big_endian 1.0) whose bytes are
/// `bytes`. The `vertex` element must have scalar properties x, y, z (any numeric type; others are
/// skipped); the `face` element a list property `vertex_indices` (or `vertex_index`) of integer type
/// with three entries per face; other elements are skipped. Vertices keep the file's order and count.
/// Throws impinge::Error naming `path` and the line, element or byte offset on: a malformed header, an
/// unknown type, a count the file cannot hold, a truncated body, a non-numeric ascii value, a face
/// that is not a triangle, or data after the last element. Indices are range-checked by the caller
/// (validate_mesh).
TriangleMesh read_ply(const std::string& path, const std::string& bytes);

/// Read an OFF file (Geomview's Object File Format: `OFF`, then `nv nf ne`, nv lines `x y z`, nf
/// lines `n i_1 .. i_n [colour]`; `#` comments). Faces must be triangles. Throws impinge::Error naming
/// `path` and the line on any malformed or missing value.
TriangleMesh read_off(const std::string& path, const std::string& bytes);
/// Wavefront OBJ (v and f lines; f's i, i/t, i//n, i/t/n and negative indices) from its bytes, vertices in the
/// file's order. Throws impinge::Error naming `path`, the line and the face or value.
TriangleMesh read_obj(const std::string& path, const std::string& bytes);

}  // namespace impinge::detail
