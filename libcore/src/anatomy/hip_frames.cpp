#include "impinge/anatomy/hip_frames.hpp"

#include <cmath>

#include "impinge/core/error.hpp"

namespace impinge {

void check_landmarks(const PelvisLandmarks& L, const Eigen::Vector3d& hip_centre, Side side, const Landmarks& given,
                     const std::string& source) {
  auto origin = [&](const char* name) { return given.count(name) ? "given" : "found"; };
  const Landmarks all = L.as_map();
  for (const auto& [name, p] : all)
    require((p - hip_centre).norm() <= 600, [&, name = name, p = p] {
      return source + ": landmark " + name + " (" + origin(name.c_str()) + ") lies " +
             std::to_string(int((p - hip_centre).norm())) + " mm from the hip centre; a pelvic landmark lies within "
             "about 300 mm of it (a typing error, or another frame or unit?)";
    });
  const double width = (L.asis_right - L.asis_left).norm();
  require(width >= 100 && width <= 450, [&] {
    return source + ": the ASIS (asis_right " + origin("asis_right") + ", asis_left " + origin("asis_left") +
           ") are " + std::to_string(int(width)) + " mm apart; an adult pelvis' are about 180-300 mm apart (not a whole pelvis, or a landmark misplaced?)";
  });
  // The hip centre lies on its own side of the ASIS' midpoint (Wu et al. 2002: Z from left to right ASIS).
  const double lateral = (hip_centre - 0.5 * (L.asis_right + L.asis_left)).dot((L.asis_right - L.asis_left) / width);
  require(side == Side::right ? lateral > 0 : lateral < 0, [&] {
    return source + ": the " + std::string(side == Side::right ? "right" : "left") + " hip centre lies " +
           std::to_string(int(std::abs(lateral))) + " mm to the " + (lateral > 0 ? "right" : "left") +
           " of the ASIS' midpoint: the side is wrong, or asis_right (" + origin("asis_right") + ") and asis_left (" +
           origin("asis_left") + ") are swapped";
  });
}

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
  check_landmarks(h.pelvis_landmarks, h.head.centre, side, given, pelvis.source);
  h.femur_landmarks = find_femur_landmarks(femur, h.head.centre, side, given);
  h.femur_landmarks.source["head_centre"] = h.head_source;
  h.pelvis = pelvis_frame(h.pelvis_landmarks, h.head.centre, options.pelvis);
  h.femur = femur_frame(h.femur_landmarks, side, options.femur);
  h.femur.quality_mm = h.head.rms_residual;
  h.scan_pose = jcs_angles(h.pelvis.axes.transpose() * h.femur.axes, side);
  return h;
}

}  // namespace impinge
