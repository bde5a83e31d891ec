#pragma once
// Private to libcore: Z-order (Morton) keys of a direction or a position, for ordering vertices and
// triangles so that neighbours on the sphere or in space are neighbours in memory order (scan sets,
// face culling, distance scan clusters).
#include <algorithm>
#include <cmath>
#include <cstdint>

namespace impinge::detail {

/// Key of the direction of (x, y, z) (any length): its (phi, theta) cell on a 4096 x 8192 grid
/// with the two cell indices' bits interleaved. The zero vector gets a valid key.
inline std::uint64_t direction_z_order(double x, double y, double z) {
  constexpr double kPi = 3.14159265358979323846;
  const double phi = std::atan2(std::hypot(x, y), z), theta = std::atan2(y, x) + kPi;
  const auto a = static_cast<std::uint32_t>(std::clamp(phi / kPi * 4096.0, 0.0, 4095.0));
  const auto b = static_cast<std::uint32_t>(std::clamp(theta / kPi * 4096.0, 0.0, 8191.0));
  std::uint64_t key = 0;
  for (int k = 0; k < 16; ++k)
    key |= (std::uint64_t((a >> k) & 1u) << (2 * k + 1)) | (std::uint64_t((b >> k) & 1u) << (2 * k));
  return key;
}

/// Key of a position's cell on a grid of 2^21 cells a side: (x, y, z) in cell units from the grid's low
/// corner (each in [0, 2^21); clamped), the three cell indices' bits interleaved. Orders points so that
/// neighbours in space are mostly neighbours in memory order (distance scan clusters).
inline std::uint64_t position_z_order(double x, double y, double z) {
  const auto spread = [](double v) {  // 21 bits -> every third bit
    std::uint64_t s = static_cast<std::uint64_t>(std::clamp(v, 0.0, 2097151.0));
    s = (s | s << 32) & 0x1f00000000ffffULL;
    s = (s | s << 16) & 0x1f0000ff0000ffULL;
    s = (s | s << 8) & 0x100f00f00f00f00fULL;
    s = (s | s << 4) & 0x10c30c30c30c30c3ULL;
    s = (s | s << 2) & 0x1249249249249249ULL;
    return s;
  };
  return spread(x) | spread(y) << 1 | spread(z) << 2;
}

}  // namespace impinge::detail
