// subject.json parsing and frames: LPS maps to RAS by negating x and y; bad keys name the file.
#include "impinge/io/subject.hpp"

#include <gtest/gtest.h>

#include "impinge/core/error.hpp"
#include "test_support.hpp"

using namespace impinge;

TEST(Subject, ParsesAndResolvesPaths) {
  const std::string d = test::temp_dir("subject");
  test::write_text(d + "/subject.json",
                   R"({"side": "left", "frame": "LPS", "units": "mm", "femur": "f.ply", "pelvis": "p.ply"})");
  const SubjectInfo s = load_subject(d + "/subject.json");
  EXPECT_EQ(s.side, Side::left);
  EXPECT_EQ(s.frame, FrameConvention::LPS);
  EXPECT_EQ(s.femur_path, d + "/f.ply");
  const Eigen::Matrix3d M = to_working_frame(FrameConvention::LPS);
  EXPECT_EQ(M * Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(-1, -2, 3));  // left -> right negated
  EXPECT_EQ(M * M, Eigen::Matrix3d::Identity());
  EXPECT_EQ(to_working_frame(FrameConvention::RAS), Eigen::Matrix3d::Identity());
}

TEST(Subject, BadFilesNameFileAndKey) {
  const std::string d = test::temp_dir("subject_bad");
  auto expect = [&](const std::string& body, const std::string& fragment) {
    test::write_text(d + "/s.json", body);
    try {
      load_subject(d + "/s.json");
      FAIL() << body;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("s.json"), std::string::npos) << e.what();
    }
  };
  expect("{not json", "not valid JSON");
  expect(R"({"frame": "LPS", "femur": "f", "pelvis": "p"})", "'side'");
  expect(R"({"side": "up", "frame": "LPS", "femur": "f", "pelvis": "p"})", "side 'up'");
  expect(R"({"side": "right", "frame": "XYZ", "femur": "f", "pelvis": "p"})", "frame 'XYZ'");
  expect(R"({"side": "right", "frame": "RAS", "units": "cm", "femur": "f", "pelvis": "p"})", "units");
  expect(R"({"side": "right", "frame": "RAS", "femur": "f", "pelvis": "p", "landmarks": {"asis": [1, 2, 3]}})",
         "unknown name 'asis'");
  expect(R"({"side": "right", "frame": "RAS", "femur": "f", "pelvis": "p", "landmarks": {"asis_left": [1, 2]}})",
         "'asis_left' must be three finite numbers");
  expect(R"({"side": "right", "frame": "RAS", "femur": "f", "pelvis": "p", "landmarks": [1]})", "'landmarks'");
  expect(R"({"side": "right", "frame": "RAS", "femur": "f", "pelvis": "p", "neutral": "supine"})",
         "key 'neutral': 'supine' is not one of anatomical, scan");
  EXPECT_THROW(load_subject(d + "/absent.json"), Error);
}

TEST(Subject, LandmarksAreReadInTheFilesFrame) {
  const std::string d = test::temp_dir("subject_landmarks");
  test::write_text(d + "/subject.json", R"({"side": "right", "frame": "LPS", "femur": "f.ply", "pelvis": "p.ply",
      "landmarks": {"asis_right": [-10.5, 2, 3], "hip_centre": [0, 0, 1e2]}})");
  const SubjectInfo s = load_subject(d + "/subject.json");
  ASSERT_EQ(s.landmarks.size(), 2u);
  EXPECT_EQ(s.landmarks.at("asis_right"), Eigen::Vector3d(-10.5, 2, 3));
  EXPECT_EQ(s.landmarks.at("hip_centre"), Eigen::Vector3d(0, 0, 100));
}
