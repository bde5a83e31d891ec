#include "impinge/anatomy/hip_frames.hpp"

#include <cmath>

#include "impinge/core/error.hpp"

namespace impinge {

HipFrames find_hip_frames(const TriangleMesh& femur, const TriangleMesh& pelvis, Side side, const Landmarks& given,
                          const HipFrameOptions& options) {
  HipFrames h;
  const auto hc = given.find("hip_centre");
  if (hc != given.end()) {
    require(hc->second.allFinite(), femur.source + ": given landmark hip_centre is not finite");
    h.head.centre = hc->second;
    h.head.radius = std::nan("");
    h.head.rms_residual = std::nan("");
    h.head_source = "given";
  } else {
    h.head = locate_femoral_head(femur, pelvis, options.head);  // the end in the acetabulum
    h.head_source = "found";
  }
  h.pelvis_landmarks = find_pelvis_landmarks(pelvis, h.head.centre, side, given);
  h.femur_landmarks = find_femur_landmarks(femur, h.head.centre, side, given);
  h.femur_landmarks.source["head_centre"] = h.head_source;
  h.pelvis = pelvis_frame(h.pelvis_landmarks, h.head.centre, options.pelvis);
  h.femur = femur_frame(h.femur_landmarks, side, options.femur);
  h.femur.quality_mm = h.head.rms_residual;
  h.scan_pose = jcs_angles(h.pelvis.axes.transpose() * h.femur.axes, side);
  return h;
}

}  // namespace impinge
