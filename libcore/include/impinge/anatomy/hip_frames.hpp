#pragma once
/// @file hip_frames.hpp
/// Both anatomical frames of a hip found from its bones: the head sphere (centre of rotation),
/// the pelvic landmarks and frame, the femoral landmarks and frame (Wu et al. 2002).

#include <Eigen/Core>

#include "impinge/anatomy/anatomical_frame.hpp"
#include "impinge/anatomy/femur_frame.hpp"
#include "impinge/anatomy/pelvis_frame.hpp"
#include "impinge/anatomy/pose.hpp"
#include "impinge/anatomy/sphere_fit.hpp"
#include "impinge/core/mesh.hpp"

namespace impinge {

/// Options of find_hip_frames.
struct HipFrameOptions {
  PelvisFrameKind pelvis = PelvisFrameKind::isb;       ///< which pelvic frame
  FemurFrameKind femur = FemurFrameKind::epicondyles;  ///< which femoral medio-lateral line
  HeadFitOptions head;                                 ///< the automatic head fit
};

/// Both frames of a hip, in the working frame (mm).
struct HipFrames {
  SphereFitResult head;     ///< the femoral head sphere: its centre is the centre of rotation and both frames' origin
  std::string head_source;  ///< "found" (locate_femoral_head) or "given" (landmark "hip_centre")
  PelvisLandmarks pelvis_landmarks;
  FemurLandmarks femur_landmarks;
  AnatomicalFrame pelvis, femur;
  PoseAngles scan_pose;  ///< the scan pose as clinical angles (jcs_angles of the femur relative to the pelvis)
};

/// Check the pelvic landmarks against the bones (working frame, mm): each within 600 mm of the hip centre, the
/// ASIS 100-450 mm apart, and the hip centre on its side of the ASIS' midpoint (right of it for a right hip).
/// Throws impinge::Error naming `source`, the landmark, whether it was given or found, and what is expected
/// (swapped ASIS, a landmark in another frame or unit, a wrong side).
void check_landmarks(const PelvisLandmarks& landmarks, const Eigen::Vector3d& hip_centre, Side side,
                     const Landmarks& given, const std::string& source);

/// Find both frames of a hip from a whole femur and a whole pelvis (working frame, mm), in
/// any placement in the scanner: locate_femoral_head (unless `given` has "hip_centre"), then
/// find_pelvis_landmarks, find_femur_landmarks, pelvis_frame and femur_frame. `given`: landmarks
/// (mm, working frame) that replace found ones, then checked (check_landmarks). Throws impinge::Error naming
/// the mesh and the step that failed.
HipFrames find_hip_frames(const TriangleMesh& femur, const TriangleMesh& pelvis, Side side, const Landmarks& given = {},
                          const HipFrameOptions& options = {});

}  // namespace impinge
