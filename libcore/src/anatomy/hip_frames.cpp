#include "impinge/anatomy/hip_frames.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

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

double head_radius_about(PointsRef V, const Eigen::Vector3d& centre) {
  std::vector<double> d;
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    const double r = (V.row(i).transpose() - centre).norm();
    if (r < 35) d.push_back(r);
  }
  if (d.size() < 10) return std::nan("");  // no head around the centre
  std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2), d.end());
  return d[d.size() / 2];
}

namespace {

// The unit direction of the area-weighted sum of the unit directions from c to the vertices of `mesh` whose distance
// from c lies in (lo, hi) mm; empty when fewer than 10 do or the sum (over the vertices' areas) is under 1e-3 of it.
std::optional<Eigen::Vector3d> mean_direction(const TriangleMesh& mesh, const Eigen::Vector3d& c, double lo,
                                              double hi) {
  if (!(c.allFinite() && lo < hi)) return std::nullopt;
  const Eigen::VectorXd area = vertex_areas(mesh);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double total = 0;
  int n = 0;
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i) {
    const Eigen::Vector3d d = mesh.V.row(i).transpose() - c;
    const double r = d.norm();
    if (r > lo && r < hi) sum += area[i] * d / r, total += area[i], ++n;
  }
  if (n < 10 || !(sum.norm() > 1e-3 * total)) return std::nullopt;
  return Eigen::Vector3d(sum.normalized());
}

std::string num(double x) {
  std::ostringstream o;
  o.precision(3);
  o << x;
  return o.str();
}

}  // namespace

std::optional<Eigen::Vector3d> head_to_neck_direction(const TriangleMesh& femur, const Eigen::Vector3d& centre,
                                                      double radius) {
  const double r = std::isfinite(radius) ? radius : head_radius_about(femur.V, centre);
  if (!(r > 0)) return std::nullopt;
  return mean_direction(femur, centre, r + 2, 2.5 * r);
}

std::optional<Eigen::Vector3d> acetabular_opening_direction(const TriangleMesh& pelvis, const Eigen::Vector3d& centre,
                                                            double radius) {
  if (!(radius > 0)) return std::nullopt;
  const auto pole = mean_direction(pelvis, centre, 0, radius + 15);
  if (!pole) return std::nullopt;
  return Eigen::Vector3d(-*pole);
}

void check_femur_landmarks(const FemurLandmarks& L, const TriangleMesh& femur, double head_radius, Side side,
                           const Landmarks& given, const std::string& landmarks_file) {
  const auto neck = head_to_neck_direction(femur, L.head_centre, head_radius);
  if (!neck) return;
  const Eigen::Vector3d knee = 0.5 * (L.epicondyle_lateral + L.epicondyle_medial);
  const Eigen::Vector3d y = (L.head_centre - knee).normalized();
  Eigen::Vector3d medial = -(*neck - neck->dot(y) * y);
  if (!(medial.norm() > 0.1)) return;  // the neck along the mechanical axis: no medial side to judge by
  medial.normalize();
  const Eigen::Vector3d anterior = side == Side::right ? y.cross(-medial) : y.cross(medial);
  auto origin = [&](const char* name) { return given.count(name) ? "given" : "found"; };
  auto pair = [&](const char* lateral, const char* medial_name) {
    const bool any_given = given.count(lateral) || given.count(medial_name);
    return (any_given && !landmarks_file.empty() ? landmarks_file : femur.source) + ": landmarks " + lateral + " (" +
           origin(lateral) + ") and " + medial_name + " (" + origin(medial_name) + ")";
  };
  const char* medial_rule = " (medial: where the femoral head lies from its neck, across the axis from the "
                            "epicondyles' midpoint to the head centre)";
  const double epicondyles = (L.epicondyle_medial - L.epicondyle_lateral).dot(medial);
  require(epicondyles > 0, [&] {
    return pair("epicondyle_lateral", "epicondyle_medial") + ": the lateral epicondyle lies " + num(-epicondyles) +
           " mm medial of the medial one" + medial_rule + "; it must lie lateral of it: are they swapped?";
  });
  const double condyles = (L.posterior_condyle_medial - L.posterior_condyle_lateral).dot(medial);
  require(condyles > 0, [&] {
    return pair("posterior_condyle_lateral", "posterior_condyle_medial") + ": the lateral posterior condyle lies " +
           num(-condyles) + " mm medial of the medial one" + medial_rule + "; it must lie lateral of it: are they "
           "swapped?";
  });
  const double behind = (0.5 * (L.posterior_condyle_lateral + L.posterior_condyle_medial) - knee).dot(-anterior);
  require(behind > 0, [&] {
    return pair("posterior_condyle_lateral", "posterior_condyle_medial") + ": their midpoint lies " + num(-behind) +
           " mm anterior of the epicondyles' midpoint (anterior: the axis from there to the head centre x medial, "
           "medial where the head lies from its neck, on a " + (side == Side::right ? "right" : "left") +
           " femur); the posterior condyles must lie posterior of it: given in another frame, or the side wrong?";
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
  check_femur_landmarks(h.femur_landmarks, femur, h.head.radius, side, given, options.landmarks_file);
  h.femur_landmarks.source["head_centre"] = h.head_source;
  h.pelvis = pelvis_frame(h.pelvis_landmarks, h.head.centre, options.pelvis);
  h.femur = femur_frame(h.femur_landmarks, side, options.femur);
  h.femur.quality_mm = h.head.rms_residual;
  h.scan_pose = jcs_angles(h.pelvis.axes.transpose() * h.femur.axes, side);
  return h;
}

}  // namespace impinge
