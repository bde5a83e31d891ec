#pragma once
/// @file pose.hpp
/// Joint pose: rotation of the ball about the COR from anatomical angles.

#include <Eigen/Core>
#include <Eigen/LU>
#include <string>

namespace impinge {

/// Body side; abduction and rotation are mirrored for the left side.
enum class Side { right, left };

/// Anatomical joint angles in degrees.
struct PoseAngles {
  double flexion_deg = 0;    ///< about the medio-lateral axis (x), + moves the knee anterior
  double abduction_deg = 0;  ///< about the antero-posterior axis (y), + moves the knee lateral
  double rotation_deg = 0;   ///< about the superior-inferior axis (z), + internal rotation
};

/// Rotation matrix (3 x 3) of the ball in the anatomical frame (RAS: +x right, +y anterior,
/// +z superior): R = Rx(flexion) * Ry(abduction') * Rz(rotation'), where for the right side
/// abduction' = -abduction and rotation' = +rotation, and for the left side abduction' =
/// +abduction and rotation' = -rotation, so that + always means flexion, abduction and
/// internal rotation. Applied about the COR: x' = cor + R (x - cor).
/// Throws impinge::Error on non-finite angles.
Eigen::Matrix3d pose_rotation(const PoseAngles& angles, Side side);

/// Parse "FLEX,ABD,ROT" (degrees); throws impinge::Error naming the text on a bad value.
PoseAngles parse_pose(const std::string& text);

}  // namespace impinge
