// run_morphology and its record (session/morphology_run.hpp) against a shape whose morphology is known in closed
// form: the generated hip (make_hip_model), a sphere head of radius R on a cylindrical neck of radius r along the
// head-neck clock's axis. Its alpha angle at every hour is where the neck's surface leaves the head's radius plus
// the 0.5 mm tolerance (a 0 rms fit): r / sin(alpha) = R + 0.5; its anterior head-neck offset ratio is
// (R - r) / 2R (Eijer et al. 2001). A cam at the antero-superior junction raises the alpha angle there and leaves
// the postero-inferior hours. The CLI's and Python's runs of the same: tests/end_to_end, python/tests.
#include "impinge/session/morphology_run.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "impinge/io/generated_models.hpp"
#include "test_support.hpp"

namespace impinge {
namespace {

MorphologyRun morphology_of(double cam_mm) {
  HipModelOptions g;
  g.target_triangles = 12000;
  g.cam_height_mm = cam_mm;
  const HipModel h = make_hip_model(g);
  SessionOptions o;
  o.input.ball_mesh = h.ball;
  o.input.socket_mesh = h.socket;
  o.hip.neutral = Neutral::scan;  // a proximal femur and a cup: no landmarks for anatomical frames
  return run_morphology(o);
}

TEST(MorphologyRun, AGeneratedHipHasItsAnalyticAlphaAngleAndOffset) {
  const HipModelOptions g;
  const double R = g.head_radius_mm, r = g.neck_radius_mm;
  const MorphologyRun run = morphology_of(0);
  const Morphology& m = run.morphology;
  EXPECT_NEAR(m.head_radius_mm, R, 0.05);
  const double alpha = std::asin(r / (R + 0.5)) * 180 / M_PI;
  for (int h = 1; h <= 12; ++h) EXPECT_NEAR(m.alpha_deg[std::size_t(h - 1)], alpha, 0.5) << "hour " << h;
  EXPECT_NEAR(m.head_neck_offset_ratio, (R - r) / (2 * R), 0.005);
  // The record gives the same values, each with its unit and source; what cannot be measured is null and said.
  const nlohmann::json j = morphology_record(run);
  EXPECT_EQ(j["femur"]["alpha_deg_by_hour"]["unit"], "deg");
  EXPECT_DOUBLE_EQ(j["femur"]["alpha_deg_by_hour"]["value"]["3"].get<double>(), m.alpha_deg[2]);
  EXPECT_DOUBLE_EQ(j["femur"]["head_radius_mm"]["value"].get<double>(), m.head_radius_mm);
  EXPECT_TRUE(j["femur"]["version_posterior_condylar_deg"]["value"].is_null());  // no knee: no version
  bool said = false;
  for (const auto& n : j["notes"]) said = said || n.get<std::string>().find("no femoral landmarks") != std::string::npos;
  EXPECT_TRUE(said) << j["notes"].dump();
}

// Issue 81: every measure of morphology.json names the frame of its angles, points or axes and where it came from;
// the fitted head's residual is written (it was null in the femoral frame), and without a knee neither version
// convention is measured.
TEST(MorphologyRun, EveryMeasureNamesItsFrameAndWhereItCameFrom) {
  const MorphologyRun run = morphology_of(0);
  const nlohmann::json j = morphology_record(run);
  for (const char* part : {"femur", "acetabulum"})
    for (const auto& [name, v] : j[part].items()) {
      if (!v.is_object() || !v.contains("value")) continue;
      EXPECT_FALSE(v.value("frame", std::string()).empty()) << part << "." << name;
      EXPECT_FALSE(v.value("obtained", std::string()).empty()) << part << "." << name;
    }
  EXPECT_EQ(j["femur"]["head_centre_mm"]["obtained"].get<std::string>().rfind("fitted", 0), 0u);
  ASSERT_TRUE(j["femur"]["head_fit_rms_mm"]["value"].is_number());
  EXPECT_EQ(j["femur"]["frame"]["head_fit_rms_mm"], j["femur"]["head_fit_rms_mm"]["value"]);
  EXPECT_TRUE(j["femur"]["version_posterior_condylar_shaft_deg"]["value"].is_null());
  EXPECT_TRUE(j["femur"]["version_transepicondylar_shaft_deg"]["value"].is_null());
  EXPECT_EQ(j["acetabulum"]["radiographic_anteversion_deg"]["frame"].get<std::string>().rfind("scan", 0), 0u);
}

TEST(MorphologyRun, ACamRaisesTheAlphaAngleWhereItSits) {
  const MorphologyRun plain = morphology_of(0), cam = morphology_of(2);
  const auto& a0 = plain.morphology.alpha_deg;
  const auto& a2 = cam.morphology.alpha_deg;
  EXPECT_GT(std::max({a2[11], a2[0], a2[1]}), 55);  // 12, 1 and 2 o'clock: antero-superior
  for (int h : {6, 7, 8}) EXPECT_NEAR(a2[std::size_t(h - 1)], a0[std::size_t(h - 1)], 3) << "hour " << h;
}

}  // namespace
}  // namespace impinge
