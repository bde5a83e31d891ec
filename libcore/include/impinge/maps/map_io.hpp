#pragma once
/// @file map_io.hpp
/// Radial distance maps saved and loaded, so that a study builds its maps once and reuses them
/// across runs and processes.
///
/// File format (version 1, little-endian, no padding):
///   magic        8 bytes  "IMPMAP\r\n"
///   version      uint32   1
///   name_length  uint32   length of the scheme name (1..64)
///   name         bytes    registry name of the sampling scheme ("equiangular", "helix", ...)
///   resolution   float64  the scheme's resolution (make_scheme(name, resolution))
///   value_bytes  uint32   4 (float32 values) or 8 (float64)
///   num_nodes    int64    must equal the scheme's node count
///   cor          3 x float64  centre of rotation the distances are measured from, mm, the map's frame
///   values       num_nodes x value  distance per node, mm; +inf = no surface
///   checksum     uint64   FNV-1a 64 of every byte before it
/// Loading checks every field, the file length and the checksum, so a corrupt, truncated or
/// mismatched file is an error, never a wrong map.

#include <Eigen/Core>
#include <string>

#include "impinge/maps/radial_distance_map.hpp"

namespace impinge {

/// Save `map` with the COR it was built about (`cor`: mm, the map's frame) to `path`.
/// Throws impinge::Error naming the file on an I/O error.
template <typename Scalar>
void save_map(const std::string& path, const RadialDistanceMapT<Scalar>& map, const Eigen::Vector3d& cor);

/// Load a map saved by save_map; `cor` (optional) receives its COR (mm). The value type must
/// match Scalar (float: 4-byte values, double: 8-byte). Throws impinge::Error naming the file
/// and the offending field on: an unreadable or truncated file, a wrong magic or version, an
/// unknown scheme or invalid resolution, a node count that does not match the scheme, a value
/// type other than Scalar's, a NaN or non-positive distance, trailing bytes, or a checksum
/// mismatch.
template <typename Scalar>
RadialDistanceMapT<Scalar> load_map(const std::string& path, Eigen::Vector3d* cor = nullptr);

/// FNV-1a 64-bit hash of `n` bytes (Fowler, Noll, Vo), the file's checksum.
std::uint64_t fnv1a64(const void* data, std::size_t n, std::uint64_t seed = 14695981039346656037ull);

}  // namespace impinge
