#pragma once
/// @file spherical_frame.hpp
/// The spherical frame of thesis sec. 3.1: polar angle phi in [0, pi] from +z, azimuth theta
/// in [0, 2 pi) from +x toward +y (thesis Eq. 5-6). Radians inside, degrees at interfaces.

#include <Eigen/Core>

namespace impinge {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kDegToRad = kPi / 180.0;
inline constexpr double kRadToDeg = 180.0 / kPi;

/// Spherical coordinates of a point relative to the origin (thesis Eq. 6).
struct SphericalCoordinates {
  double d = 0;      ///< radial distance, mm
  double phi = 0;    ///< polar angle from +z, radians, [0, pi]
  double theta = 0;  ///< azimuth from +x toward +y, radians, [0, 2 pi); 0 on the z axis
};

/// Cartesian point p (mm, relative to the COR) to (d, phi, theta) by thesis Eq. 6, with
/// atan2 for the quadrant and theta wrapped into [0, 2 pi). At the origin returns all zeros.
SphericalCoordinates to_spherical(const Eigen::Vector3d& p);

/// Unit direction of (phi, theta) in radians (thesis Eq. 5 with d = 1).
Eigen::Vector3d direction(double phi, double theta);

}  // namespace impinge
