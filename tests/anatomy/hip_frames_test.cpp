// Anatomical frames found from the bones (hip_frames, pelvis_frame, femur_frame). Invariants:
// - the frames are orthonormal and right-handed, with the landmarks where anatomy puts them
//   (ASIS anterior-superior, PSIS posterior, knee below the hip);
// - they do not depend on how the subject lay in the scanner: moving both meshes by 20 random
//   rigid motions (any axis, up to 180 deg) gives the same frames relative to the bones within
//   0.5 deg, on every shared subject and on a mirrored (left) copy of one;
// - clinical angles move the femur as clinicians mean (tested on real femurs, both sides):
//   +90 flexion puts the knee anterior, +30 adduction medial, +30 internal rotation turns the
//   femoral neck posterior;
// - given landmarks replace found ones;
// - the femoral landmarks are checked against the bone (check_femur_landmarks): a swapped pair, or posterior condyles
//   in front of the knee, are refused naming them and the offset (analytic bounds on the generated hip; every shared
//   hip's found landmarks pass, swapped they are refused); the neck and the acetabulum show which way they point
//   (the generated hip's axes).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "impinge/anatomy/hip_frames.hpp"
#include "impinge/core/error.hpp"
#include "impinge/io/generated_models.hpp"
#include "test_support.hpp"

using namespace impinge;
using impinge::test::error_of;
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

// The bones' own side, without landmarks (head_to_neck_direction, acetabular_opening_direction). Analytic oracle: the
// generated hip's neck and cup are rotationally symmetric about their axes (make_hip_model: the neck along
// (0.80, 0.25, -0.55) from the head centre, the cup's pole along (-0.65, -0.2, 0.73)), so the mean directions lie on
// those axes: the neck's, and the opposite of the pole's.
TEST(HipSide, TheGeneratedNeckAndCupGiveTheirAxes) {
  const HipModelOptions o;
  const HipModel h = make_hip_model(o);
  const Eigen::Vector3d neck = Eigen::Vector3d(0.80, 0.25, -0.55).normalized();
  const Eigen::Vector3d opening = -Eigen::Vector3d(-0.65, -0.2, 0.73).normalized();
  const double within = std::cos(0.1 * M_PI / 180);
  for (const double r : {o.head_radius_mm, std::nan("")}) {  // NaN: the radius from the vertices about the centre
    const auto n = head_to_neck_direction(h.ball, h.cor, r);
    ASSERT_TRUE(n);
    EXPECT_GT(n->dot(neck), within) << n->transpose();
  }
  const auto a = acetabular_opening_direction(h.socket, h.cor, o.head_radius_mm);
  ASSERT_TRUE(a);
  EXPECT_GT(a->dot(opening), within) << a->transpose();
  // The head's radius from its vertices: most of those within 35 mm lie on the sphere.
  EXPECT_NEAR(head_radius_about(h.ball.V, h.cor), o.head_radius_mm, 1e-9);
  // Nothing about a centre far from the bones: no direction (and no radius).
  const Eigen::Vector3d far = h.cor + Eigen::Vector3d(500, 0, 0);
  EXPECT_FALSE(head_to_neck_direction(h.ball, far, o.head_radius_mm));
  EXPECT_FALSE(head_to_neck_direction(h.ball, far, std::nan("")));
  EXPECT_FALSE(acetabular_opening_direction(h.socket, far, o.head_radius_mm));
  EXPECT_TRUE(std::isnan(head_radius_about(h.ball.V, far)));
}

namespace {
// Landmarks of the generated (right, RAS) femur as a whole femur would have them: the knee centre 400 mm below the
// head and 25 mm lateral, the epicondyles 80 mm apart across it (lateral +x), the posterior condyles 44 mm apart and
// 25 mm behind it (-y).
FemurLandmarks generated_landmarks(const Eigen::Vector3d& head) {
  const Eigen::Vector3d knee = head + Eigen::Vector3d(25, 0, -400);
  FemurLandmarks L;
  L.head_centre = head;
  L.epicondyle_lateral = knee + Eigen::Vector3d(40, 0, 0);
  L.epicondyle_medial = knee - Eigen::Vector3d(40, 0, 0);
  L.posterior_condyle_lateral = knee + Eigen::Vector3d(22, -25, -5);
  L.posterior_condyle_medial = knee + Eigen::Vector3d(-22, -25, -5);
  return L;
}

// The offset (mm) an error of check_femur_landmarks gives: the number after `lead`, or NaN.
double offset_after(const std::string& error, const std::string& lead) {
  const auto at = error.find(lead);
  return at == std::string::npos ? std::nan("") : std::stod(error.substr(at + lead.size()));
}

// The error of check_femur_landmarks on `L` (all given, from "s.json"), or "(no error)" when it passes.
std::string femur_error(const FemurLandmarks& L, const TriangleMesh& femur, Side side) {
  Landmarks given = L.as_map();
  given.erase("head_centre");
  return error_of([&] { check_femur_landmarks(L, femur, std::nan(""), side, given, "s.json"); });
}
}  // namespace

// Swapped epicondyles or posterior condyles turn the femoral frame half a turn about its long axis (lhdl-ct's version
// read -21.4 and 158.7 deg instead of 21.3): refused naming both and the offset, which can be no more than the pair's
// separation (80 mm, 44 mm) and, medial lying within 20 deg of the model's -x, no less than cos 20 deg of it;
// posterior condyles placed in front of the knee likewise. The rules use the side (a left femur is the mirror image).
TEST(FemurLandmarks, ASwappedPairOrCondylesInFrontAreRefusedNamingThem) {
  const HipModel h = make_hip_model(HipModelOptions{});
  const FemurLandmarks L = generated_landmarks(h.cor);
  EXPECT_EQ(femur_error(L, h.ball, Side::right), "(no error)");
  FemurLandmarks e = L;
  std::swap(e.epicondyle_lateral, e.epicondyle_medial);
  std::string err = femur_error(e, h.ball, Side::right);
  EXPECT_NE(err.find("s.json: landmarks epicondyle_lateral (given) and epicondyle_medial (given): "), std::string::npos)
      << err;
  EXPECT_NE(err.find("are they swapped?"), std::string::npos) << err;
  double d = offset_after(err, "the lateral epicondyle lies ");
  EXPECT_GT(d, 80 * std::cos(20 * M_PI / 180)) << err;
  EXPECT_LE(d, 80 + 1e-9) << err;
  FemurLandmarks p = L;
  std::swap(p.posterior_condyle_lateral, p.posterior_condyle_medial);
  err = femur_error(p, h.ball, Side::right);
  EXPECT_NE(err.find("posterior_condyle_lateral (given) and posterior_condyle_medial (given)"), std::string::npos);
  d = offset_after(err, "the lateral posterior condyle lies ");
  EXPECT_GT(d, 44 * std::cos(20 * M_PI / 180)) << err;
  EXPECT_LE(d, 44 + 1e-9) << err;
  FemurLandmarks front = L;
  front.posterior_condyle_lateral.y() += 50;  // 25 mm in front of the knee
  front.posterior_condyle_medial.y() += 50;
  err = femur_error(front, h.ball, Side::right);
  d = offset_after(err, "their midpoint lies ");
  EXPECT_GT(d, 25 * std::cos(20 * M_PI / 180)) << err;
  EXPECT_LE(d, 25 + 1e-9) << err;
  // A landmark found names the mesh, not the landmarks' file.
  err = error_of([&] { check_femur_landmarks(e, h.ball, std::nan(""), Side::right, {}, "s.json"); });
  EXPECT_EQ(err.rfind(h.ball.source + ": landmarks epicondyle_lateral (found) and epicondyle_medial (found)", 0), 0u)
      << err;
  // The left hip: the mirror image passes as a left femur; read as a right one its posterior condyles lie in front.
  TriangleMesh left = h.ball;
  mirror_to_left(left);
  FemurLandmarks ml = L;
  for (Eigen::Vector3d* q : {&ml.head_centre, &ml.epicondyle_lateral, &ml.epicondyle_medial,
                             &ml.posterior_condyle_lateral, &ml.posterior_condyle_medial})
    q->x() *= -1;
  EXPECT_EQ(femur_error(ml, left, Side::left), "(no error)");
  EXPECT_NE(femur_error(ml, left, Side::right).find("anterior of the epicondyles' midpoint"), std::string::npos);
}

// On every shared hip the landmarks impinge finds pass, and each swapped pair is refused.
TEST(FemurLandmarks, FoundPassAndSwappedAreRefusedOnEverySharedHip) {
  int hips = 0;
  for (const char* s : {"lhdl-ct", "mc22", "mc22-left", "tlem2-mri"}) {
    auto j = load_real_joint(s);
    if (!j) continue;
    ++hips;
    SCOPED_TRACE(s);
    const Side side = std::string(s) == "mc22-left" ? Side::left : Side::right;
    const HipFrames h = find_hip_frames(j->femur, j->pelvis, side);  // checks the found landmarks
    FemurLandmarks e = h.femur_landmarks;
    std::swap(e.epicondyle_lateral, e.epicondyle_medial);
    EXPECT_NE(error_of([&] { check_femur_landmarks(e, j->femur, h.head.radius, side, {}, ""); })
                  .find("the lateral epicondyle lies "),
              std::string::npos);
    FemurLandmarks p = h.femur_landmarks;
    std::swap(p.posterior_condyle_lateral, p.posterior_condyle_medial);
    EXPECT_NE(error_of([&] { check_femur_landmarks(p, j->femur, h.head.radius, side, {}, ""); })
                  .find("the lateral posterior condyle lies "),
              std::string::npos);
  }
  if (hips == 0) GTEST_SKIP() << "shared data absent";
}
