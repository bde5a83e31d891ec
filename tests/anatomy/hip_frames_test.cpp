// Anatomical frames found from the bones (hip_frames, pelvis_frame, femur_frame). Invariants:
// - the frames are orthonormal and right-handed, with the landmarks where anatomy puts them
//   (ASIS anterior-superior, PSIS posterior, knee below the hip);
// - they do not depend on how the subject lay in the scanner: moving both meshes by 20 random
//   rigid motions (any axis, up to 180 deg) gives the same frames relative to the bones within
//   0.5 deg, on every shared subject and on a mirrored (left) copy of one;
// - clinical angles move the femur as clinicians mean (tested on real femurs, both sides):
//   +90 flexion puts the knee anterior, +30 adduction medial, +30 internal rotation turns the
//   femoral neck posterior;
// - given landmarks replace found ones.
#include <gtest/gtest.h>

#include <random>

#include "impinge/anatomy/hip_frames.hpp"
#include "impinge/core/error.hpp"
#include "test_support.hpp"

using namespace impinge;
using impinge::test::load_real_joint;

namespace {

const char* const kSubjects[] = {"lhdl-ct", "mc22", "tlem2-mri"};

// A left hip: the right one mirrored through the sagittal plane x = 0 (faces flipped to keep
// their orientation).
void mirror_to_left(TriangleMesh& m) {
  m.V.col(0) *= -1;
  m.F.col(1).swap(m.F.col(2));
}

struct Case {
  std::string name;
  TriangleMesh femur, pelvis;
  Side side;
};

std::vector<Case> cases() {
  std::vector<Case> out;
  for (const char* s : kSubjects) {
    auto j = load_real_joint(s);
    if (!j) continue;
    out.push_back({s, j->femur, j->pelvis, Side::right});
    if (std::string(s) == "lhdl-ct") {
      Case left{std::string(s) + " mirrored left", j->femur, j->pelvis, Side::left};
      mirror_to_left(left.femur);
      mirror_to_left(left.pelvis);
      out.push_back(left);
    }
  }
  return out;
}

// Knee centre (epicondyles' midpoint) and a femoral-neck point (the centroid of the femur's
// vertices in a shell just outside the head) from the femur mesh and its landmarks.
Eigen::Vector3d knee_centre(const HipFrames& h) {
  return 0.5 * (h.femur_landmarks.epicondyle_lateral + h.femur_landmarks.epicondyle_medial);
}
Eigen::Vector3d neck_point(const TriangleMesh& femur, const HipFrames& h) {
  const double r = h.head.radius;
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  int n = 0;
  for (Eigen::Index i = 0; i < femur.V.rows(); ++i) {
    const double d = (femur.V.row(i).transpose() - h.head.centre).norm();
    if (d > r + 4 && d < r + 12) s += femur.V.row(i).transpose(), ++n;
  }
  EXPECT_GT(n, 20);
  return s / n;
}

}  // namespace

TEST(HipFrames, FramesAreOrthonormalAndLandmarksLieWhereAnatomyPutsThem) {
  const auto cs = cases();
  if (cs.empty()) GTEST_SKIP() << "shared data absent";
  for (const Case& c : cs) {
    SCOPED_TRACE(c.name);
    const HipFrames h = find_hip_frames(c.femur, c.pelvis, c.side);
    for (const AnatomicalFrame* f : {&h.pelvis, &h.femur}) {
      EXPECT_LT((f->axes.transpose() * f->axes - Eigen::Matrix3d::Identity()).norm(), 1e-12);
      EXPECT_NEAR(f->axes.determinant(), 1.0, 1e-12);
    }
    const double m = c.side == Side::right ? 1 : -1;
    const PelvisLandmarks& p = h.pelvis_landmarks;
    // In the pelvic frame: ASIS superior and anterior of the hip centre, the hip's own ASIS lateral
    // (on its side), the other one across the midline; PSIS posterior; pubis inferior, medial.
    const Eigen::Vector3d own_asis = h.pelvis.to_local(c.side == Side::right ? p.asis_right : p.asis_left);
    const Eigen::Vector3d other_asis = h.pelvis.to_local(c.side == Side::right ? p.asis_left : p.asis_right);
    EXPECT_GT(own_asis.y(), 20);
    EXPECT_GT(own_asis.x(), 0);
    EXPECT_GT(m * own_asis.z(), 0);
    EXPECT_LT(m * other_asis.z(), -120);
    for (const auto& q : {p.psis_right, p.psis_left}) EXPECT_LT(h.pelvis.to_local(q).x(), -80);
    // Pubis (in the anterior pelvic plane frame): below the hip centre, anterior, medial, and
    // in the APP with both ASIS within a few mm.
    HipFrameOptions app;
    app.pelvis = PelvisFrameKind::anterior_pelvic_plane;
    const AnatomicalFrame P = pelvis_frame(p, h.head.centre, app.pelvis);
    for (const auto& q : {p.pubic_tubercle_right, p.pubic_tubercle_left}) {
      EXPECT_LT(P.to_local(q).y(), -5);
      EXPECT_GT(P.to_local(q).x(), 30);
      EXPECT_LT(m * P.to_local(q).z(), -40);  // medial of the hip centre
    }
    EXPECT_LT(p.app_out_of_plane_mm, 3);
    // Inter-ASIS distance of an adult pelvis: 190-280 mm.
    EXPECT_GT((p.asis_right - p.asis_left).norm(), 190);
    EXPECT_LT((p.asis_right - p.asis_left).norm(), 280);
    // Femur: the knee far below the head along y; epicondyles 60-110 mm apart; the lateral one on
    // the body's outer side (z towards the right on a right femur).
    const Eigen::Vector3d knee = h.femur.to_local(knee_centre(h));
    EXPECT_LT(knee.y(), -300);
    const double width = (h.femur_landmarks.epicondyle_lateral - h.femur_landmarks.epicondyle_medial).norm();
    EXPECT_GT(width, 60);
    EXPECT_LT(width, 110);
    EXPECT_GT(m * h.femur.to_local(h.femur_landmarks.epicondyle_lateral).z(), 25);
    // Head radius of an adult femur and a tight fit.
    EXPECT_GT(h.head.radius, 18);
    EXPECT_LT(h.head.radius, 30);
    // The subject lay near anatomical neutral in the scanner (supine, leg straight): within 35 deg.
    EXPECT_LT(std::abs(h.scan_pose.flexion_deg), 35);
    EXPECT_LT(std::abs(h.scan_pose.adduction_deg), 35);
  }
}

TEST(HipFrames, IndependentOfTheScanPlacementWithinHalfADegree) {
  const auto cs = cases();
  if (cs.empty()) GTEST_SKIP() << "shared data absent";
  std::mt19937_64 rng(2002);
  std::uniform_real_distribution<double> shift(-500, 500);
  for (const Case& c : cs) {
    SCOPED_TRACE(c.name);
    const HipFrames ref = find_hip_frames(c.femur, c.pelvis, c.side);
    for (int k = 0; k < 8; ++k) {  // eight random placements per subject
      const Eigen::Matrix3d Q = test::random_rotation(rng);
      const Eigen::Vector3d t(shift(rng), shift(rng), shift(rng));
      const HipFrames h = find_hip_frames(test::transformed(c.femur, Q, t), test::transformed(c.pelvis, Q, t), c.side);
      // Relative to the bones: the moved frame's axes are Q times the reference's.
      EXPECT_LT(rotation_angle_deg(Q * ref.pelvis.axes, h.pelvis.axes), 0.5) << "motion " << k;
      EXPECT_LT(rotation_angle_deg(Q * ref.femur.axes, h.femur.axes), 0.5) << "motion " << k;
      EXPECT_LT((Q * ref.head.centre + t - h.head.centre).norm(), 0.05) << "motion " << k;
    }
  }
}

TEST(HipFrames, ClinicalAnglesMoveTheFemurAsCliniciansMeanOnBothSides) {
  const auto cs = cases();
  if (cs.empty()) GTEST_SKIP() << "shared data absent";
  for (const Case& c : cs) {
    SCOPED_TRACE(c.name);
    const HipFrames h = find_hip_frames(c.femur, c.pelvis, c.side);
    const double m = c.side == Side::right ? 1 : -1;
    const Eigen::Vector3d o = h.head.centre;
    // A femur point posed at `a`, in the pelvic frame.
    auto posed = [&](const Eigen::Vector3d& p, const PoseAngles& a) {
      const Eigen::Matrix3d R = femur_rotation(h.pelvis, h.femur, a, c.side);
      return h.pelvis.to_local(o + R * (p - o));
    };
    const Eigen::Vector3d knee = knee_centre(h);
    const double len = (knee - o).norm();
    // Neutral: knee straight below the hip centre.
    const Eigen::Vector3d k0 = posed(knee, {});
    EXPECT_NEAR(k0.y(), -len, 1e-9);
    // +90 flexion: knee anterior of the hip centre, at thigh length.
    EXPECT_NEAR(posed(knee, {90, 0, 0}).x(), len, 1e-6);
    EXPECT_LT(posed(knee, {-20, 0, 0}).x(), -0.3 * len);  // extension: posterior
    // +30 adduction: knee medial (towards the midline: -z on the right, +z on the left).
    EXPECT_NEAR(m * posed(knee, {0, 30, 0}).z(), -len * 0.5, 1e-6);
    EXPECT_GT(m * posed(knee, {0, -30, 0}).z(), 0.4 * len);  // abduction: lateral
    // +30 internal rotation: the femoral neck (from its base to the head) turns posterior.
    const Eigen::Vector3d neck = neck_point(c.femur, h);
    const double x0 = o.x() * 0 + (h.pelvis.to_local(o) - posed(neck, {})).x();
    const double x30 = (h.pelvis.to_local(o) - posed(neck, {0, 0, 30})).x();
    EXPECT_LT(x30, x0 - 3);
    EXPECT_LT(x30, 0) << "neck axis still anterior at 30 deg internal rotation: anteversion over 30 deg?";
    // Angles round-trip through the posed rotation.
    const PoseAngles a{35, -12, 17};
    const PoseAngles b =
        jcs_angles(h.pelvis.axes.transpose() * femur_rotation(h.pelvis, h.femur, a, c.side) * h.femur.axes, c.side);
    EXPECT_NEAR(b.flexion_deg, a.flexion_deg, 1e-9);
    EXPECT_NEAR(b.adduction_deg, a.adduction_deg, 1e-9);
    EXPECT_NEAR(b.internal_rotation_deg, a.internal_rotation_deg, 1e-9);
  }
}

TEST(HipFrames, GivenLandmarksReplaceFoundOnes) {
  auto j = load_real_joint("lhdl-ct");
  if (!j) GTEST_SKIP() << "shared data absent";
  const HipFrames found = find_hip_frames(j->femur, j->pelvis, Side::right);
  Landmarks given = found.pelvis_landmarks.as_map();
  for (const auto& [k, v] : found.femur_landmarks.as_map()) given[k == "head_centre" ? "hip_centre" : k] = v;
  given["asis_left"] += Eigen::Vector3d(0, 0, 30);  // tilt the ASIS line by about 7 deg
  const HipFrames h = find_hip_frames(j->femur, j->pelvis, Side::right, given);
  EXPECT_EQ(h.pelvis_landmarks.source.at("asis_left"), "given");
  EXPECT_EQ(h.head_source, "given");
  EXPECT_EQ((h.pelvis_landmarks.asis_left - given["asis_left"]).norm(), 0.0);
  EXPECT_GT(rotation_angle_deg(found.pelvis.axes, h.pelvis.axes), 3);
  EXPECT_LT(rotation_angle_deg(found.femur.axes, h.femur.axes), 1e-5);  // acos near 1: ~1e-6 deg resolution
  given["epicondyle_medial"] = Eigen::Vector3d(std::nan(""), 0, 0);
  EXPECT_THROW(find_hip_frames(j->femur, j->pelvis, Side::right, given), Error);
}

// The part of `m` whose faces have every corner with `keep(vertex)` true.
template <typename Keep>
TriangleMesh sub_mesh(const TriangleMesh& m, Keep keep) {
  std::vector<std::uint8_t> k(static_cast<std::size_t>(m.V.rows()));
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) k[static_cast<std::size_t>(i)] = keep(m.V.row(i));
  return submesh(m, k);
}

TEST(HipFrames, AHalfPelvisOrACutFemurIsAClearError) {
  auto j = load_real_joint("lhdl-ct");
  if (!j) GTEST_SKIP() << "shared data absent";
  // The proximal femur only (the generated models' situation): no distal condyles.
  const double zmax = j->femur.V.col(2).maxCoeff();
  const TriangleMesh cut = sub_mesh(j->femur, [&](const auto& v) { return v(2) > zmax - 90; });
  try {
    find_femur_landmarks(cut, j->cor, Side::right);
    ADD_FAILURE() << "a proximal femur gave epicondyles";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("not a whole femur"), std::string::npos) << e.what();
  }
  // The right hip bone only: no contralateral ASIS.
  const HipFrames h = find_hip_frames(j->femur, j->pelvis, Side::right);
  const Eigen::Vector3d mid = 0.5 * (h.pelvis_landmarks.asis_right + h.pelvis_landmarks.asis_left);
  const Eigen::Vector3d right = h.pelvis.axes.col(2);
  const TriangleMesh half = sub_mesh(j->pelvis, [&](const auto& v) { return (v.transpose() - mid).dot(right) > 0; });
  try {
    const PelvisLandmarks p = find_pelvis_landmarks(half, j->cor, Side::right);
    ADD_FAILURE() << "a single hip bone gave ASIS " << (p.asis_right - p.asis_left).norm() << " mm apart";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("whole pelvis"), std::string::npos) << e.what();
  }
}
