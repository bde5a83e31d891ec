#pragma once
/// @file hip_frames.hpp
/// Both anatomical frames of a hip found from its bones: the head sphere (centre of rotation),
/// the pelvic landmarks and frame, the femoral landmarks and frame (Wu et al. 2002).

#include <Eigen/Core>
#include <optional>
#include <string>

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
  /// The file the given landmarks come from (Session: the subject.json), named first in the errors of the landmarks
  /// given; empty: the mesh (not an option: where messages point).
  std::string landmarks_file;
};

/// Both frames of a hip, in the working frame (mm).
struct HipFrames {
  SphereFitResult head;     ///< the femoral head sphere: its centre is the centre of rotation and both frames' origin
  /// "found" (locate_femoral_head) or "given" (landmark "hip_centre"); run_morphology sets "fitted" for the head
  /// sphere it fitted and gave as hip_centre.
  std::string head_source;
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

/// The femoral head's radius about `centre` (mm, working frame) where no sphere was fitted: the median distance from
/// it of the vertices of `V` (n x 3, mm) within 35 mm; NaN when fewer than 10 lie there (no head). Source: impinge.
double head_radius_about(PointsRef V, const Eigen::Vector3d& centre);

/// Where the femoral neck leaves the head: the unit direction (working frame) of the area-weighted mean of the unit
/// directions from the head centre `centre` (mm) to the femur's vertices between radius + 2 mm and 2.5 x radius
/// (`radius` mm; NaN: head_radius_about), the neck and the trochanters: lateral and distal of the head (on the
/// shared hips 0.72-0.77 lateral). Empty when fewer than 10 vertices lie there or their directions cancel.
/// Source: impinge.
std::optional<Eigen::Vector3d> head_to_neck_direction(const TriangleMesh& femur, const Eigen::Vector3d& centre,
                                                      double radius);

/// Which way the acetabulum opens, from the bone alone (no frame, no landmarks): the unit direction (working frame)
/// opposite the area-weighted mean of the unit directions from the head centre `centre` (mm) to the pelvis'
/// vertices within radius + 15 mm (`radius` mm, the femoral head's): out of the cup, lateral, anterior and inferior
/// (on the shared hips 0.75-0.84 lateral, 0.30-0.32 anterior, 0.45-0.60 inferior; the generated cup: its axis).
/// Empty when fewer than 10 vertices lie there or their directions cancel. Source: impinge.
std::optional<Eigen::Vector3d> acetabular_opening_direction(const TriangleMesh& pelvis, const Eigen::Vector3d& centre,
                                                            double radius);

/// Check the femoral landmarks against the femur (working frame, mm). Medial is where the head lies from its neck:
/// the opposite of head_to_neck_direction(femur, L.head_centre, head_radius) across the mechanical axis (from the
/// epicondyles' midpoint to the head centre); anterior is medial x the mechanical axis (a left femur: the axis x
/// medial), the ISB frame's x (Wu et al. 2002). Each lateral landmark must lie lateral of its medial one (the shared
/// hips: the epicondyles 63-83 mm, the posterior condyles 40-47 mm), and the posterior condyles' midpoint posterior
/// of the epicondyles' (20-25 mm). Nothing is checked when the femur shows no neck (head_to_neck_direction empty).
/// Throws impinge::Error naming `landmarks_file` (when a landmark of the pair was given and it is not empty, else
/// `femur.source`), both landmarks, whether each was given or found (`given`), the offset (mm) and the rule: a swapped
/// pair turns the femoral frame half a turn about its long axis (on lhdl-ct the femoral version read 158.7 deg
/// instead of 21.3 with the posterior condyles swapped, -21.4 with the epicondyles swapped).
void check_femur_landmarks(const FemurLandmarks& L, const TriangleMesh& femur, double head_radius, Side side,
                           const Landmarks& given, const std::string& landmarks_file);

/// Find both frames of a hip from a whole femur and a whole pelvis (working frame, mm), in
/// any placement in the scanner: locate_femoral_head (unless `given` has "hip_centre"), then
/// find_pelvis_landmarks, find_femur_landmarks, pelvis_frame and femur_frame. `given`: landmarks
/// (mm, working frame) that replace found ones, then checked (check_landmarks, check_femur_landmarks). Throws
/// impinge::Error naming the mesh (or options.landmarks_file) and the step that failed.
HipFrames find_hip_frames(const TriangleMesh& femur, const TriangleMesh& pelvis, Side side, const Landmarks& given = {},
                          const HipFrameOptions& options = {});

}  // namespace impinge
