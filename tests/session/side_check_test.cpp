// The side and the input frame checked against the bones (side_check.cpp). Invariants, on the generated hip (a
// hemipelvis: its cup is 57 mm wide), whose acetabulum opens laterally, anteriorly and inferiorly and whose neck
// leaves the head laterally (make_hip_model):
// - read as what it is (a right hip, in RAS or converted to LPS and read as LPS) it passes, and so does its mirror
//   image read as a left hip;
// - called a left hip it is refused blaming the side (it opens anteriorly as read); read in the wrong frame (RAS
//   meshes read as LPS turn x and y) it is refused blaming the frame (it opens posteriorly as read); the mirror image
//   called a right hip is refused;
// - without a fitted head sphere (a COR given with allow_any) nothing is judged.
#include <gtest/gtest.h>

#include <string>

#include "impinge/io/generated_models.hpp"
#include "impinge/session/session.hpp"
#include "test_support.hpp"

using namespace impinge;
using impinge::test::error_of;

namespace {

const HipModel& model() {
  static const HipModel h = [] {
    HipModelOptions o;
    o.target_triangles = 2000;
    return make_hip_model(o);
  }();
  return h;
}

// The generated hip's meshes converted to `stored` (its frame, or the mirror image: x negated) and read as `side`
// in `frame`; the check's error, or "(no error)".
std::string side_check_error(const std::string& stored, const std::string& side, const std::string& frame) {
  SessionInput input;
  input.ball_mesh = model().ball;
  input.socket_mesh = model().socket;
  Eigen::Matrix3d M = Eigen::Matrix3d::Identity();
  if (stored == "LPS") M = to_working_frame(FrameConvention::LPS);
  if (stored == "mirror") M(0, 0) = -1;
  for (TriangleMesh* m : {&*input.ball_mesh, &*input.socket_mesh}) {
    transform_vertices(m->V, M);
    if (stored == "mirror") m->F.col(1).swap(m->F.col(2));
  }
  input.side = side;
  input.frame = frame;
  const LoadedInput in = load_input(input);
  const CorResult cor = find_centre_of_rotation(in, {});
  return error_of([&] { check_side_and_frame(in, cor, input); });
}

}  // namespace

TEST(SideCheck, AHemipelvisOfTheOtherSideOrFrameIsRefusedNamingWhich) {
  EXPECT_EQ(side_check_error("RAS", "right", "RAS"), "(no error)");
  EXPECT_EQ(side_check_error("LPS", "right", "LPS"), "(no error)");
  EXPECT_EQ(side_check_error("mirror", "left", "RAS"), "(no error)");
  std::string e = side_check_error("RAS", "left", "RAS");
  EXPECT_NE(e.find("side left: the acetabulum of " + model().socket.source + " (a hemipelvis) opens to the right"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("the femoral neck of " + model().ball.source + " leaves the head to the right"), std::string::npos)
      << e;
  EXPECT_NE(e.find("a right hip (it opens anteriorly as read): the side (--side) is wrong"), std::string::npos) << e;
  e = side_check_error("RAS", "right", "LPS");
  EXPECT_NE(e.find("side right: the acetabulum"), std::string::npos) << e;
  EXPECT_NE(e.find("opens to the left"), std::string::npos) << e;
  EXPECT_NE(e.find("opens posteriorly as read, so a right hip read in the wrong frame: the frame (--frame, LPS) is "
                   "wrong"),
            std::string::npos)
      << e;
  e = side_check_error("mirror", "right", "RAS");
  EXPECT_NE(e.find("a left hip (it opens anteriorly as read): the side (--side) is wrong"), std::string::npos) << e;
}

TEST(SideCheck, NoFittedHeadNothingJudged) {
  SessionInput input;
  input.ball_mesh = model().ball;
  input.socket_mesh = model().socket;
  input.side = "left";
  const LoadedInput in = load_input(input);
  CorOptions any;
  any.given = model().cor;
  any.allow_any = true;
  const CorResult cor = find_centre_of_rotation(in, any);
  ASSERT_FALSE(cor.fitted_head);
  EXPECT_EQ(error_of([&] { check_side_and_frame(in, cor, input); }), "(no error)");
}
