#pragma once
/// @file pose.hpp
/// Joint pose: clinical hip angles (flexion, adduction, internal rotation) in the ISB joint
/// coordinate system (Wu et al. 2002, J Biomech 35:543, sec. 3.3; Grood and Suntay 1983), and
/// the rotation of the femur about the centre of rotation that they describe.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <string>

#include "impinge/anatomy/anatomical_frame.hpp"
#include "impinge/core/enum_names.hpp"

namespace impinge {

/// Body side; adduction and internal rotation are mirrored for the left side so that the
/// signs mean the same on both hips.
enum class Side { right, left };

/// Clinical hip angles in degrees, ISB signs: flexion, adduction and internal rotation positive.
/// OpenSim's hip_flexion, hip_adduction and hip_rotation coordinates use the same signs.
struct PoseAngles {
  double flexion_deg = 0;            ///< about the pelvic Z axis (medio-lateral); + moves the knee anterior
  double adduction_deg = 0;          ///< about the floating axis; + moves the knee medial (negative = abduction)
  double internal_rotation_deg = 0;  ///< about the femoral Y axis (long axis); + turns the anterior femur medially
};

/// What the zero pose is.
enum class Neutral {
  anatomical,  ///< the femoral ISB frame's axes parallel to the pelvic frame's (both found from the bones)
  scan,        ///< the scan pose; angles about the working frame's axes (RAS: Z = +x, X = +y, Y = +z)
};
/// The names of the neutrals: "anatomical", "scan" (the option table's choices, parse_neutral).
inline constexpr EnumNames<Neutral, 2> kNeutralNames{{{Neutral::anatomical, "anatomical"}, {Neutral::scan, "scan"}}};
/// "anatomical" or "scan".
inline const char* to_string(Neutral neutral) { return enum_name(kNeutralNames, neutral); }

/// Rotation (3 x 3) of the joint coordinate system in the pelvic frame's own axes: the femoral
/// frame's axes relative to the pelvic frame's, R = Rz(flexion) Rx(m adduction) Ry(m internal
/// rotation) with m = +1 for the right side and -1 for the left (ISB hip JCS: e1 = pelvic Z,
/// e3 = femoral y, e2 = e3 x e1 floating; Cardan sequence Z-X-Y). Throws impinge::Error on a
/// non-finite angle.
Eigen::Matrix3d jcs_rotation(const PoseAngles& angles, Side side);

/// Inverse of jcs_rotation: the angles (degrees) of a relative rotation R (3 x 3), with
/// adduction in [-90, 90] deg; flexion and internal rotation in (-180, 180] deg. Gimbal lock
/// at adduction +-90 deg (then internal rotation is reported as 0).
PoseAngles jcs_angles(const Eigen::Matrix3d& R, Side side);

/// Rotation (3 x 3, working frame) to apply to the femur about the centre of rotation,
/// x' = cor + R (x - cor), to bring it from where it lies in the scan to `angles`:
/// R = P jcs_rotation(angles) F^T with P, F the pelvic and femoral frames' axes (working frame).
/// At zero angles the femoral axes become parallel to the pelvic ones (anatomical neutral).
Eigen::Matrix3d femur_rotation(const AnatomicalFrame& pelvis, const AnatomicalFrame& femur, const PoseAngles& angles,
                               Side side);

/// The scan-neutral rotation: femur_rotation with both frames' axes equal to the working
/// frame's anatomical axes (X = +y anterior, Y = +z superior, Z = +x right), so zero angles
/// leave the femur where it was scanned. Equivalent to R = Rx(flexion) Ry(m adduction)
/// Rz(m internal rotation) about the working frame's x, y, z axes.
Eigen::Matrix3d pose_rotation(const PoseAngles& angles, Side side);

/// The working frame's anatomical axes as an ISB basis (columns X anterior = +y, Y superior
/// = +z, Z right = +x).
Eigen::Matrix3d scan_axes();

/// Parse "FLEX,ADD,IR" (degrees); throws impinge::Error naming the text on a bad value.
PoseAngles parse_pose(const std::string& text);

/// Parse "anatomical" / "scan"; throws impinge::Error naming `context` otherwise.
Neutral parse_neutral(const std::string& text, const std::string& context);

}  // namespace impinge
