#pragma once
// Private to libcore: a Z-order (Morton) key of a direction, for ordering vertices and triangles
// so that neighbours on the sphere are neighbours in memory order (scan sets, face culling).
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

}  // namespace impinge::detail
