// HipJoint: a hip posed by clinical angles. Invariants:
// - the same minimum gaps at five clinical poses whatever the subject's placement in the scanner
//   (20 random rigid motions, rotations up to 180 deg about any axis, of both meshes together),
//   within 0.05 mm, on every shared subject and a mirrored (left) copy of one;
// - scan neutral is the plain Joint posed by pose_rotation, bit for bit;
// - posed_femur places the femur where femur_rotation says, in the working frame; scan neutral has no pelvic
//   frame to pose in, and says so;
// - both pelvic frames (issue 81): with pelvic landmarks built so that the ISB frame is the anterior pelvic
//   plane (APP) frame turned by a known angle theta about their common Z, APP angles (f, a, r) pose the femur
//   as ISB angles (f + theta, a, r) (both joint coordinate systems turn about Z first), so every limit in the
//   APP is the ISB search along the motion with its flexion shifted by theta (flexion's limit the ISB one less
//   theta, extension's the ISB one plus theta); with theta = 0 both frames give the same limits;
// - the labrum split in four (with_labrum's splits, issue 81: the plan's labrum) is the same surface: 4^splits the
//   triangles, every vertex on a triangle of the labrum unsplit (brute force over its triangles, 1e-9 mm), the
//   labral limits within 0.05 deg of the unsplit labrum's (the exact search's tessellation tolerance); splits
//   outside 0..5 are an error naming them.
#include "impinge/clinical/hip_joint.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>

#include "impinge/clinical/rom.hpp"
#include "impinge/core/error.hpp"
#include "impinge/io/generated_models.hpp"
#include "test_support.hpp"

using namespace impinge;

namespace {
const PoseAngles kClinicalPoses[] = {{0, 0, 0}, {90, 0, 0}, {90, 10, 20}, {0, -30, 0}, {-10, 0, -20}};

HipJointOptions options(double precision_deg) {
  HipJointOptions o;
  o.joint.scheme = make_scheme("equiangular", precision_deg);
  o.joint.mode = DistanceMode::exact;
  return o;
}
}  // namespace

TEST(HipJoint, SameMinimumGapsForAnyScanPlacement) {
  std::mt19937_64 rng(2026);
  std::uniform_real_distribution<double> shift(-400, 400);
  bool any = false;
  for (const char* name : {"lhdl-ct", "mc22", "tlem2-mri", "lhdl-ct-left"}) {
    const bool left = std::string(name) == "lhdl-ct-left";
    auto j = test::load_real_joint(left ? "lhdl-ct" : name);
    if (!j) continue;
    any = true;
    SCOPED_TRACE(name);
    if (left) {
      for (TriangleMesh* m : {&j->femur, &j->pelvis}) {
        m->V.col(0) *= -1;
        m->F.col(1).swap(m->F.col(2));
      }
    }
    const Side side = left ? Side::left : Side::right;
    auto gaps = [&](const TriangleMesh& femur, const TriangleMesh& pelvis) {
      const HipJoint hip(femur, pelvis, side, locate_femoral_head(femur), {}, options(0.25));
      std::vector<std::pair<double, double>> out;
      for (const PoseAngles& a : kClinicalPoses) {
        const PoseResult r = hip.detect(a);
        out.emplace_back(r.ball.min_gap_mm, r.socket.min_gap_mm);
      }
      return out;
    };
    const auto ref = gaps(j->femur, j->pelvis);
    // Six random placements per subject (each a rotation and a shift of up to 400 mm per axis): a
    // placement that the set-up does not undo shows in every pose's gaps.
    for (int k = 0; k < 6; ++k) {
      const Eigen::Matrix3d Q = test::random_rotation(rng);
      const Eigen::Vector3d t(shift(rng), shift(rng), shift(rng));
      const auto moved = gaps(test::transformed(j->femur, Q, t), test::transformed(j->pelvis, Q, t));
      for (std::size_t p = 0; p < ref.size(); ++p) {
        EXPECT_NEAR(moved[p].first, ref[p].first, 0.05) << "motion " << k << ", pose " << p;
        EXPECT_NEAR(moved[p].second, ref[p].second, 0.05) << "motion " << k << ", pose " << p;
      }
    }
  }
  if (!any) GTEST_SKIP() << "shared data absent";
}

TEST(HipJoint, ScanNeutralIsThePlainJointPosedByPoseRotation) {
  HipModelOptions mo;
  mo.target_triangles = 3000;
  mo.cam_height_mm = 2;
  const HipModel h = make_hip_model(mo);
  HipJointOptions o = options(1.0);
  o.neutral = Neutral::scan;
  SphereFitResult head;
  head.centre = h.cor;
  head.radius = mo.head_radius_mm;
  const HipJoint hip(h.ball, h.socket, Side::right, head, {}, o);
  const Joint plain(h.ball, h.socket, h.cor, o.joint);
  for (const PoseAngles& a : kClinicalPoses) {
    const PoseResult r = hip.detect(a), q = plain.detect(pose_rotation(a, Side::right));
    EXPECT_EQ(r.ball_gaps.status, q.ball_gaps.status);
    for (std::size_t i = 0; i < r.ball_gaps.gap_mm.size(); ++i)
      if (!std::isnan(q.ball_gaps.gap_mm[i])) {
        EXPECT_EQ(r.ball_gaps.gap_mm[i], q.ball_gaps.gap_mm[i]) << i;
      }
    EXPECT_EQ(r.socket.min_gap_mm, q.socket.min_gap_mm);
  }
  // Scan neutral has no pelvic frame to pose in: asked for one, it says so.
  EXPECT_FALSE(hip.pelvis_frame_kind());
  EXPECT_FALSE(hip.has_pelvis_frame(PelvisFrameKind::isb) || hip.has_pelvis_frame(PelvisFrameKind::anterior_pelvic_plane));
  EXPECT_EQ(test::error_of([&] { hip.femur_rotation({}, PelvisFrameKind::anterior_pelvic_plane); }),
            "hip joint: no app pelvic frame to pose in (scan neutral: no pelvic frame)");
  // The generated model is a proximal femur and a cup: anatomical neutral is refused clearly.
  HipJointOptions anat = options(1.0);
  EXPECT_THROW(HipJoint(h.ball, h.socket, Side::right, head, {}, anat), Error);
}

TEST(HipJoint, PosedFemurIsFemurRotationInTheWorkingFrame) {
  auto j = test::load_real_joint("lhdl-ct");
  if (!j) GTEST_SKIP() << "shared data absent";
  const HipJoint hip(j->femur, j->pelvis, Side::right, fit_femoral_head(j->femur), {}, options(1.0));
  const PoseAngles a{60, -10, 15};
  const FemurPose pose = hip.femur_pose(a);
  const Vertices V = hip.posed_femur(pose.R, pose.t);
  const Eigen::Matrix3d Rw = femur_rotation(hip.frames()->pelvis, hip.frames()->femur, a, Side::right);
  const Eigen::Vector3d tw = hip.femur_translation(pose.t);  // the joint centre's (and the seat), working frame
  for (Eigen::Index i = 0; i < j->femur.V.rows(); i += 997) {
    const Eigen::Vector3d expect = j->cor + Rw * (j->femur.V.row(i).transpose() - j->cor) + tw;
    EXPECT_LT((V.row(i).transpose() - expect).norm(), 1e-9);
  }
  const Vertices P = hip.pelvis_vertices();
  EXPECT_LT((P - j->pelvis.V).cwiseAbs().maxCoeff(), 1e-9);
  // Reusing a PoseResult gives the same answer as a fresh one.
  PoseResult reused;
  hip.detect({10, 0, 0}, reused);
  hip.detect(a, reused);
  const PoseResult fresh = hip.detect(a);
  EXPECT_EQ(reused.ball_gaps.status, fresh.ball_gaps.status);
  EXPECT_EQ(reused.socket.min_gap_mm, fresh.socket.min_gap_mm);
  EXPECT_EQ(reused.ball.level_area_mm2, fresh.ball.level_area_mm2);
}

TEST(HipJoint, CorOutsideTheFemurIsAnErrorUnlessAllowedAndWrongUnitsWarn) {
  HipModelOptions mo;
  mo.target_triangles = 3000;
  const HipModel h = make_hip_model(mo);
  HipJointOptions o = options(2.0);
  o.neutral = Neutral::scan;
  SphereFitResult outside;
  outside.centre = h.cor + Eigen::Vector3d(-40, 0, 0);  // beside the head, away from the neck
  outside.radius = mo.head_radius_mm;
  try {
    HipJoint(h.ball, h.socket, Side::right, outside, {}, o);
    ADD_FAILURE() << "a COR outside the femur was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("outside the femur mesh"), std::string::npos) << e.what();
  }
  o.allow_cor_outside_ball = true;
  EXPECT_NO_THROW(HipJoint(h.ball, h.socket, Side::right, outside, {}, o));
  // The same hip in metres' worth of numbers scaled up: a 2.2 m head warns about the units.
  o.allow_cor_outside_ball = false;
  TriangleMesh big_ball = h.ball, big_socket = h.socket;
  big_ball.V *= 100;
  big_socket.V *= 100;
  SphereFitResult big;
  big.centre = 100 * h.cor;
  big.radius = 100 * mo.head_radius_mm;
  const HipJoint scaled(big_ball, big_socket, Side::right, big, {}, o);
  ASSERT_EQ(scaled.warnings().size(), 1u);
  EXPECT_NE(scaled.warnings()[0].find("millimetres"), std::string::npos) << scaled.warnings()[0];
  SphereFitResult head;
  head.centre = h.cor;
  head.radius = mo.head_radius_mm;
  EXPECT_TRUE(HipJoint(h.ball, h.socket, Side::right, head, {}, o).warnings().empty());
}

namespace {
// lhdl-ct's pelvic landmarks with both PSIS moved so that the ISB frame is the APP frame turned by theta_deg about
// their common Z (the ASIS line): X_isb = cos(theta) X_app - sin(theta) Y_app, i.e. P_app = P_isb Rz(theta). The APP
// axes come from the landmarks here (Y along the ASIS midpoint less the pubic tubercles' midpoint, normal to Z).
Landmarks landmarks_tilted(const PelvisLandmarks& L, double theta_deg) {
  const Eigen::Vector3d z = (L.asis_right - L.asis_left).normalized();
  const Eigen::Vector3d mid_asis = 0.5 * (L.asis_right + L.asis_left);
  Eigen::Vector3d y = mid_asis - 0.5 * (L.pubic_tubercle_right + L.pubic_tubercle_left);
  y = (y - y.dot(z) * z).normalized();
  const Eigen::Vector3d x = y.cross(z);
  const double t = theta_deg * M_PI / 180;
  const Eigen::Vector3d x_isb = std::cos(t) * x - std::sin(t) * y;
  Landmarks given = L.as_map();
  given["psis_right"] = mid_asis - 150 * x_isb + 45 * z;
  given["psis_left"] = mid_asis - 150 * x_isb - 45 * z;
  return given;
}
}  // namespace

TEST(HipJoint, LimitsInTheAnteriorPelvicPlaneAreTheMotionsAboutItsAxes) {
  auto j = test::load_real_joint("lhdl-ct");
  if (!j) GTEST_SKIP() << "shared data absent";
  const PelvisLandmarks found = find_pelvis_landmarks(j->pelvis, j->cor, Side::right);
  const std::vector<StandardMotion> motions = standard_motions();
  RomOptions ro;
  ro.tolerance_deg = 0.02;
  for (const double theta : {0.0, 12.0}) {
    SCOPED_TRACE(theta);
    const HipJoint hip(j->femur, j->pelvis, Side::right, fit_femoral_head(j->femur), landmarks_tilted(found, theta),
                       options(0.5));
    ASSERT_EQ(hip.pelvis_frame_kind(), PelvisFrameKind::isb);
    ASSERT_TRUE(hip.has_pelvis_frame(PelvisFrameKind::anterior_pelvic_plane)) << hip.other_pelvis_frame_note();
    const PoseRotation app = [&hip](const PoseAngles& a) {
      return hip.femur_rotation(a, PelvisFrameKind::anterior_pelvic_plane);
    };
    for (const PoseAngles& a : kClinicalPoses)
      EXPECT_LT((app(a) - hip.femur_rotation({a.flexion_deg + theta, a.adduction_deg, a.internal_rotation_deg})).norm(),
                1e-9);
    const std::vector<RomLimit> in_isb = find_rom_limits(hip, motions, ro, rom_baseline(hip, hip.femur_rotation({}), ro));
    const std::vector<RomLimit> in_app = find_rom_limits(hip, motions, ro, rom_baseline(hip, app({}), ro), app);
    // The oracle: the ISB search along each motion with its flexion shifted, from the shifted neutral.
    const RomBaseline shifted_base = rom_baseline(hip, hip.femur_rotation({theta, 0, 0}), ro);
    int compared = 0;
    for (std::size_t k = 0; k < motions.size(); ++k) {
      SCOPED_TRACE(motions[k].name);
      const RomLimit& l = in_app[k];
      if (theta == 0) {
        EXPECT_EQ(l.status, in_isb[k].status);
        EXPECT_TRUE(l.limit_deg == in_isb[k].limit_deg || (std::isnan(l.limit_deg) && std::isnan(in_isb[k].limit_deg)));
        continue;
      }
      if (l.status == RomLimitStatus::not_reachable) continue;
      const auto& m = motions[k];
      const RomLimit oracle = find_rom_limit(
          hip,
          std::function<PoseAngles(double)>([&m, theta](double t) {
            PoseAngles p = m.angles(t);
            p.flexion_deg += theta;
            return p;
          }),
          ro, shifted_base);
      EXPECT_EQ(std::isnan(l.limit_deg), std::isnan(oracle.limit_deg));
      if (std::isfinite(oracle.limit_deg)) {
        EXPECT_NEAR(l.limit_deg, oracle.limit_deg, 2 * ro.tolerance_deg);
        ++compared;
      }
    }
    if (theta == 0) continue;
    EXPECT_GE(compared, 6);
    // Flexion and extension turn about the shared Z: the APP limits are the ISB ones moved by theta.
    ASSERT_EQ(motions[0].name, "flexion");
    ASSERT_EQ(motions[1].name, "extension");
    if (std::isfinite(in_isb[0].limit_deg)) {
      EXPECT_NEAR(in_app[0].limit_deg, in_isb[0].limit_deg - theta, 0.1);
    }
    if (std::isfinite(in_isb[1].limit_deg)) {
      EXPECT_NEAR(in_app[1].limit_deg, in_isb[1].limit_deg + theta, 0.1);
    }
  }
}

TEST(HipJoint, ALabrumSplitInFourIsTheSameSurfaceAndMovesNoLabralLimit) {
  HipModelOptions mo;
  mo.target_triangles = 3000;
  mo.cup_coverage_deg = 80;  // the labrum clear of the neck at neutral
  const HipModel h = make_hip_model(mo);
  HipJointOptions o = test::scan_options(0.5);
  o.joint.distances = true;
  SphereFitResult head;
  head.centre = h.cor;
  head.radius = mo.head_radius_mm;
  const HipJoint hip(h.ball, h.socket, Side::right, head, {}, o);
  const auto coarse = hip.with_labrum(5.3, 7), fine = hip.with_labrum(5.3, 7, 2);
  const Vertices &Vc = coarse->joint().socket().relative, &Vf = fine->joint().socket().relative;
  const Faces &Fc = coarse->joint().socket().mesh.F, &Ff = fine->joint().socket().mesh.F;
  ASSERT_EQ(Ff.rows(), 16 * Fc.rows());
  // Every vertex of the split labrum lies on a triangle of the unsplit one: in its plane, barycentrics >= 0.
  for (Eigen::Index i = 0; i < Vf.rows(); ++i) {
    const Eigen::Vector3d p = Vf.row(i).transpose();
    bool on = false;
    for (Eigen::Index f = 0; f < Fc.rows() && !on; ++f) {
      const Eigen::Vector3d a = Vc.row(Fc(f, 0)), b = Vc.row(Fc(f, 1)), c = Vc.row(Fc(f, 2));
      const Eigen::Vector3d n = (b - a).cross(c - a);
      if (std::abs(n.normalized().dot(p - a)) > 1e-9) continue;
      const double u = (c - b).cross(p - b).dot(n), v = (a - c).cross(p - c).dot(n), w = (b - a).cross(p - a).dot(n);
      on = u >= -1e-9 * n.squaredNorm() && v >= -1e-9 * n.squaredNorm() && w >= -1e-9 * n.squaredNorm();
    }
    ASSERT_TRUE(on) << "vertex " << i << " of the split labrum off the labrum";
  }
  RomOptions ro;
  ro.metric = RomMetric::distance;
  auto limits = [&](const HipJoint& lh) {
    return find_rom_limits(lh, standard_motions(), ro, rom_baseline(lh, lh.femur_rotation({}), ro));
  };
  const auto a = limits(*coarse), b = limits(*fine);
  int limited = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    SCOPED_TRACE(standard_motions()[k].name);
    EXPECT_EQ(a[k].status, b[k].status);
    if (a[k].status != RomLimitStatus::limited) continue;
    ++limited;
    EXPECT_NEAR(a[k].limit_deg, b[k].limit_deg, 0.05);
  }
  EXPECT_GE(limited, 4);
  for (int bad : {-1, 6})
    EXPECT_EQ(test::error_of([&] { hip.with_labrum(5.3, 7, bad); }),
              "labrum: " + std::to_string(bad) + " splits of its triangles; valid: 0..5");
}
