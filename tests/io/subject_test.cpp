// subject.json parsing and frames: LPS maps to RAS by negating x and y; bad keys name the file.
#include "impinge/io/subject.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

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

// Issue 80: nlohmann keeps the last of a key given twice, and `in >> j` stopped after the first value: both were
// accepted without a word. A key twice (at any depth, named with the keys it sits under) and anything after the
// object are errors naming the file and the key, or the line, column and offset.
TEST(Subject, AKeyTwiceOrDataAfterTheObjectIsAnError) {
  const std::string d = test::temp_dir("subject_strict");
  auto message = [&](const std::string& body) -> std::string {
    test::write_text(d + "/s.json", body);
    try {
      load_subject(d + "/s.json");
    } catch (const Error& e) {
      return e.what();
    }
    return "no error";
  };
  const std::string ok = R"({"side": "right", "frame": "RAS", "femur": "f", "pelvis": "p"})";
  EXPECT_EQ(message(ok + "\n  \n"), "no error");  // white space after the object is no data
  EXPECT_EQ(message(R"({"side": "right", "frame": "RAS", "side": "left", "femur": "f", "pelvis": "p"})"),
            d + "/s.json: key 'side' appears twice: which value is meant?");
  EXPECT_EQ(message(R"({"side": "right", "frame": "RAS", "femur": "f", "pelvis": "p",
                       "landmarks": {"hip_centre": [1, 2, 3], "asis_left": [0, 0, 0], "hip_centre": [1, 2, 4]}})"),
            d + "/s.json: key 'landmarks.hip_centre' appears twice: which value is meant?");
  // The same key in two objects is no repeat.
  EXPECT_EQ(message(R"({"side": "right", "frame": "RAS", "femur": "f", "pelvis": "p", "_a": {"side": 1},
                       "_b": [{"side": 2}, {"side": 3}]})"),
            "no error");
  // Offsets counted by hand: the second object starts on line 2, column 3, 65 bytes in (62 + newline + two spaces).
  EXPECT_EQ(message(ok + "\n  {\"side\": \"left\"}\n"),
            d + "/s.json: line 2, column 3 (offset 65): '{\"side\": \"left\"}...' after the JSON object: a "
                "subject file holds one object");
  EXPECT_EQ(message(ok + " garbage"), d + "/s.json: line 1, column 64 (offset 63): 'garbage...' after the JSON "
                                          "object: a subject file holds one object");
  const std::string bad = message("{\n  \"side\": right}");
  EXPECT_NE(bad.find("s.json: not valid JSON at line 2, column "), std::string::npos) << bad;
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

// The writer (save_subject, `impinge generate`'s subject.json) and the reader share one key list: what is written
// reads back as it was, every key written is one the reader knows, and a file outside the json's folder is kept
// by its absolute path.
namespace {
std::string read_text(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}
}  // namespace

TEST(Subject, WhatIsWrittenReadsBack) {
  const std::string d = test::temp_dir("subject_write");
  SubjectInfo in;
  in.side = Side::left;
  in.frame = FrameConvention::LPS;
  in.femur_path = d + "/femur_l.ply";
  in.pelvis_path = "/elsewhere/pelvis.ply";
  in.neutral = "scan";
  in.landmarks["asis_left"] = Eigen::Vector3d(1.5, -2, 3.25);
  in.generated = true;
  in.true_cor_mm = Eigen::Vector3d(0.5, 1, -2);
  in.head_radius_mm = 24.5;
  save_subject(d + "/subject.json", in);
  const SubjectInfo out = load_subject(d + "/subject.json");
  EXPECT_EQ(out.side, in.side);
  EXPECT_EQ(out.frame, in.frame);
  EXPECT_EQ(out.femur_path, d + "/femur_l.ply");
  EXPECT_EQ(out.pelvis_path, "/elsewhere/pelvis.ply");
  EXPECT_EQ(out.neutral, "scan");
  ASSERT_EQ(out.landmarks.count("asis_left"), 1u);
  EXPECT_EQ(out.landmarks.at("asis_left"), in.landmarks.at("asis_left"));
  EXPECT_TRUE(out.generated);
  ASSERT_TRUE(out.true_cor_mm);
  EXPECT_EQ(*out.true_cor_mm, *in.true_cor_mm);
  EXPECT_EQ(out.head_radius_mm, 24.5);
  const std::string text = read_text(d + "/subject.json");
  EXPECT_NE(text.find("\"femur\": \"femur_l.ply\""), std::string::npos) << text;  // relative to its folder
  // A subject without the generated model's keys writes none of them.
  SubjectInfo plain;
  plain.femur_path = d + "/f.ply", plain.pelvis_path = d + "/p.ply";
  save_subject(d + "/plain.json", plain);
  const std::string p = read_text(d + "/plain.json");
  EXPECT_EQ(p.find("generated"), std::string::npos) << p;
  EXPECT_FALSE(load_subject(d + "/plain.json").true_cor_mm);
  // The generated model's keys are checked when read.
  test::write_text(d + "/bad.json",
                   R"({"side": "right", "frame": "RAS", "femur": "f", "pelvis": "p", "true_cor_mm": [1, 2]})");
  EXPECT_NE(test::error_of([&] { load_subject(d + "/bad.json"); }).find("'true_cor_mm' must be three finite numbers"),
            std::string::npos);
}
