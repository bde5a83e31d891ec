// The side and the input frame checked against the bones (check_side_and_frame, session.hpp): on a whole pelvis by
// where the femoral head lies, on a hemipelvis by which way the acetabulum opens and the femoral neck leaves the head.
#include <cmath>
#include <sstream>

#include "impinge/anatomy/hip_frames.hpp"
#include "impinge/core/error.hpp"
#include "impinge/session/session.hpp"

namespace impinge {

namespace {

std::string num(double x) { return number_text(x); }

// A unit direction (working frame) as "(x, y, z)" to two decimals.
std::string direction_text(const Eigen::Vector3d& d) {
  std::ostringstream o;
  o.setf(std::ios::fixed);
  o.precision(2);
  o << "(" << d.x() << ", " << d.y() << ", " << d.z() << ")";
  return o.str();
}

// Where the side and the frame came from, for messages: the option, the subject's, or the default.
std::string side_origin(const SessionInput& given) {
  return given.side.empty() ? (given.subject.empty() ? "the default right" : "the subject's") : "--side";
}
std::string frame_origin(const SessionInput& given) {
  return given.frame.empty() ? (given.subject.empty() ? "the default RAS" : "the subject's") : "--frame";
}

// A whole pelvis: the femoral head (`head`, working frame) on its side of the pelvis' centroid.
void check_whole_pelvis(const LoadedInput& in, const Eigen::Vector3d& head, const SessionInput& given) {
  const double lateral = head.x() - in.pelvis.V.col(0).mean();  // working frame: +x right
  if (std::abs(lateral) < 30) return;
  const bool right = in.side == Side::right;
  require(right == (lateral > 0), [&] {
    const char* frame = in.frame == FrameConvention::LPS ? "LPS" : "RAS";
    return std::string("side ") + (right ? "right" : "left") + ": the femoral head lies " +
           num(std::round(std::abs(lateral))) + " mm to the " + (lateral > 0 ? "right" : "left") +
           " of the pelvis' centre when the meshes are read as " + frame + ": the side (" + side_origin(given) +
           ") or the frame (" + frame_origin(given) + ") is wrong";
  });
}

// A hemipelvis: the acetabulum opens and the femoral neck leaves the head towards the hip's own side (working frame:
// +x right); both clearly towards the other is an error, blaming the side when the acetabulum opens anteriorly as
// read (a hip of the other side) and the frame when posteriorly (LPS read as RAS turns x and y both).
void check_hemipelvis(const LoadedInput& in, const CorResult& cor, const SessionInput& given) {
  const SphereFitResult* head = std::isfinite(cor.head.radius) ? &cor.head
                                : cor.fitted_head                ? &*cor.fitted_head
                                                                 : nullptr;
  if (head == nullptr) return;
  const auto opening = acetabular_opening_direction(in.pelvis, head->centre, head->radius);
  const auto neck = head_to_neck_direction(in.femur, head->centre, head->radius);
  if (!opening || !neck) return;
  const bool right = in.side == Side::right;
  const double s = right ? 1.0 : -1.0;  // the given side's lateral, along +x
  constexpr double kClearly = 0.3;      // the shared hips' hemipelves: 0.72-0.84 towards their own side
  if (!(s * opening->x() < -kClearly && s * neck->x() < -kClearly)) return;
  const char* frame = in.frame == FrameConvention::LPS ? "LPS" : "RAS";
  const std::string other = right ? "left" : "right";
  std::string verdict;
  if (opening->y() > 0.1)
    verdict = "a " + other + " hip (it opens anteriorly as read): the side (" + side_origin(given) + ") is wrong";
  else if (opening->y() < -0.1)
    verdict = std::string("it opens posteriorly as read, so a ") + (right ? "right" : "left") +
              " hip read in the wrong frame: the frame (" + frame_origin(given) + ", " + frame + ") is wrong";
  else
    verdict = "the side (" + side_origin(given) + ") or the frame (" + frame_origin(given) + ", " + frame +
              ") is wrong";
  throw Error((given.subject.empty() ? std::string() : given.subject + ": ") + "side " + (right ? "right" : "left") +
              ": the acetabulum of " + in.pelvis_source + " (a hemipelvis) opens to the " + other + " (" +
              direction_text(*opening) + " read as " + frame + ", x right, y anterior) and the femoral neck of " +
              in.femur_source + " leaves the head to the " + other + " (" + direction_text(*neck) + "): " + verdict);
}

}  // namespace

void check_side_and_frame(const LoadedInput& in, const CorResult& cor, const SessionInput& given) {
  if (in.pelvis.V.rows() == 0) return;
  const double width = in.pelvis.V.col(0).maxCoeff() - in.pelvis.V.col(0).minCoeff();
  if (width >= 200)
    check_whole_pelvis(in, cor.head.centre, given);
  else
    check_hemipelvis(in, cor, given);
}

}  // namespace impinge
