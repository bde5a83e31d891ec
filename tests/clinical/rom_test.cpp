// ROM limits (rom.cpp). Invariants:
// - analytic oracle: a sphere head with a cylindrical neck of radius n in a concentric cup of inner
//   radius R whose rim lies at polar angle beta from its pole; rotating the femur about the axis
//   that turns the neck away from the opening's axis, the neck's surface first meets the rim's
//   inner edge when the angle between neck and opening axes reaches (180 - beta) - asin(n / R)
//   (the rim point at angle gamma from the neck axis is R sin(gamma) from it). The search finds it
//   within 0.2 deg, at several cup coverages and in both rotation senses about the axis;
// - extra-articular oracle: a trochanter block hidden behind the head meets an iliac plate hidden
//   behind the cup at the closed-form angle (within 0.2 deg) with layered maps, and is invisible
//   without them; with layers, the occupancy bounds give the full scan's limits;
// - the ROM envelope by adaptive refinement agrees with every pose scanned (to 0.1 %), and with the
//   ROM limit along internal rotation;
// - a right hip and its mirrored left copy give the same limits within 0.2 deg;
// - contact classes (issue 29): counting every vertex can only end a search earlier than counting
//   impingement alone, and where it does, on every shared subject and motion, the earlier contact is
//   on the joint surfaces (articular); a search of the joint surfaces alone ends on articular contacts;
//   the impingement search never does;
// - pre-existing overlap at the baseline is excluded and reported, not taken for a limit;
// - bad options are errors.
#include "impinge/clinical/rom.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <iostream>
#include <limits>
#include <memory>

#include "impinge/anatomy/femur_frame.hpp"
#include "impinge/casters/first_hit_caster.hpp"
#include "impinge/casters/signed_distance.hpp"
#include "impinge/core/error.hpp"
#include "impinge/io/generated_models.hpp"
#include "test_support.hpp"

using namespace impinge;

namespace {
using test::scan_options;
// The right hip of generated model `h` (made with `mo`), its true head as the COR.
std::unique_ptr<HipJoint> joint_of(const HipModel& h, const HipModelOptions& mo, const HipJointOptions& o) {
  SphereFitResult head;
  head.centre = h.cor;
  head.radius = mo.head_radius_mm;
  return std::make_unique<HipJoint>(h.ball, h.socket, Side::right, head, Landmarks{}, o);
}
// The generated 12k-triangle hip with a 2 mm cam, its true head as the COR, scan neutral.
HipModelOptions cam_model() {
  HipModelOptions mo;
  mo.target_triangles = 12000;
  mo.cam_height_mm = 2;
  return mo;
}
std::unique_ptr<HipJoint> cam_hip(double precision_deg, const HipJointOptions* options = nullptr) {
  const HipModelOptions mo = cam_model();
  return joint_of(make_hip_model(mo), mo, options ? *options : scan_options(precision_deg));
}
}  // namespace

TEST(Rom, NeckMeetsTheRimWhereTheClosedFormSays) {
  for (const double coverage : {95.0, 100.0, 110.0}) {
    SCOPED_TRACE(coverage);
    HipModelOptions mo;
    mo.target_triangles = 20000;
    mo.cup_coverage_deg = coverage;
    const HipModel h = make_hip_model(mo);
    const std::unique_ptr<HipJoint> joint = joint_of(h, mo, scan_options(0.1));
    const HipJoint& hip = *joint;
    // The generator's axes (generated_models.cpp): neck direction and cup pole.
    const Eigen::Vector3d neck = Eigen::Vector3d(0.80, 0.25, -0.55).normalized();
    const Eigen::Vector3d opening = -Eigen::Vector3d(-0.65, -0.2, 0.73).normalized();
    const double psi0 = std::acos(neck.dot(opening)) * 180 / M_PI;
    const double inner = mo.head_radius_mm + mo.cartilage_gap_mm;
    const double psi_contact = (180 - coverage) - std::asin(mo.neck_radius_mm / inner) * 180 / M_PI;
    const Eigen::Vector3d k = opening.cross(neck).normalized();  // turns the neck away from the opening axis
    RomOptions ro;
    ro.step_deg = 1;
    ro.contact_depth_mm = 0;  // the first touch: the closed form's
    const RomBaseline base = rom_baseline(hip, Eigen::Matrix3d::Identity(), ro);
    EXPECT_EQ(base.excluded_vertices, 0);
    const RomLimit l = find_rom_limit(
        hip, std::function<Eigen::Matrix3d(double)>([&](double t) {
          return Eigen::AngleAxisd(t * M_PI / 180, k).toRotationMatrix();
        }),
        ro, base);
    EXPECT_NEAR(l.limit_deg, psi_contact - psi0, 0.2) << "psi0 " << psi0;
    EXPECT_LE(l.min_gap_at_limit_mm, 0);
    EXPECT_TRUE(l.monotone);
    EXPECT_EQ(l.limited_by, ImpingementSite::intra_articular);
    // The contact lies on the rim's inner edge: R from the COR, at the rim's polar angle.
    EXPECT_NEAR((l.contact_mm - h.cor).norm(), inner, 0.3);
    // Turning the other way about the same axis the neck first crosses the opening axis, then meets the
    // rim on the far side: psi falls to 0 and rises again, so the limit is psi0 + psi_contact.
    const RomLimit back = find_rom_limit(
        hip, std::function<Eigen::Matrix3d(double)>([&](double t) {
          return Eigen::AngleAxisd(-t * M_PI / 180, k).toRotationMatrix();
        }),
        ro, base);
    EXPECT_NEAR(back.limit_deg, psi_contact + psi0, 0.2);
  }
}

TEST(Rom, MirroredLeftHipHasTheSameLimits) {
  auto j = test::load_real_joint("lhdl-ct");
  if (!j) GTEST_SKIP() << "shared data absent";
  TriangleMesh fl = j->femur, pl = j->pelvis;
  for (TriangleMesh* m : {&fl, &pl}) {
    m->V.col(0) *= -1;
    m->F.col(1).swap(m->F.col(2));
  }
  HipJointOptions o;
  o.joint.scheme = make_scheme("equiangular", 0.25);
  const HipJoint right(j->femur, j->pelvis, Side::right, locate_femoral_head(j->femur), {}, o);
  const HipJoint left(fl, pl, Side::left, locate_femoral_head(fl), {}, o);
  RomOptions ro;
  const RomBaseline br = rom_baseline(right, right.femur_rotation({}), ro);
  const RomBaseline bl = rom_baseline(left, left.femur_rotation({}), ro);
  int limited = 0;
  for (const StandardMotion& m : standard_motions()) {
    if (m.name != "flexion" && m.name != "internal_rotation_90_flexion" && m.name != "fadir" &&
        m.name != "abduction")
      continue;
    SCOPED_TRACE(m.name);
    const RomLimit a = find_rom_limit(right, m.angles, ro, br), b = find_rom_limit(left, m.angles, ro, bl);
    EXPECT_EQ(std::isnan(a.limit_deg), std::isnan(b.limit_deg));
    if (!std::isnan(a.limit_deg)) {
      ++limited;
      EXPECT_NEAR(a.limit_deg, b.limit_deg, 0.2);
      EXPECT_NEAR(a.socket_clock_h, b.socket_clock_h, 0.05);
    }
  }
  EXPECT_GT(limited, 1);
}

// A motion whose start lies past another motion's limit is not reachable, with the angle of the block, and
// not a 0 deg limit: on lhdl-ct, rotation started at 20 deg past the flexion limit is not_reachable and its
// note gives the flexion limit; started 20 deg short of it, it is searched as usual.
TEST(Rom, AMotionWhoseStartIsBlockedIsNotReachable) {
  auto j = test::load_real_joint("lhdl-ct");
  if (!j) GTEST_SKIP() << "shared data absent";
  HipJointOptions o;
  o.joint.scheme = make_scheme("equiangular", 0.5);
  const HipJoint hip(j->femur, j->pelvis, Side::right, locate_femoral_head(j->femur, j->pelvis), {}, o);
  const RomOptions ro;
  const RomBaseline base = rom_baseline(hip, hip.femur_rotation({}), ro);
  const RomLimit flexion = find_rom_limits(hip, {standard_motions()[0]}, ro, base)[0];
  ASSERT_EQ(flexion.status, RomLimitStatus::limited);
  ASSERT_LT(flexion.limit_deg, 145);
  const double past = flexion.limit_deg + 20, short_of = flexion.limit_deg - 20;
  const std::vector<StandardMotion> motions = {
      {"past", [past](double t) { return PoseAngles{past, 0, t}; }, PoseAngles{past, 0, 0}},
      {"short", [short_of](double t) { return PoseAngles{short_of, 0, t}; }, PoseAngles{short_of, 0, 0}}};
  const auto limits = find_rom_limits(hip, motions, ro, base);
  EXPECT_EQ(limits[0].status, RomLimitStatus::not_reachable);
  EXPECT_TRUE(std::isnan(limits[0].limit_deg));
  EXPECT_FALSE(limits[0].contact_at_start);
  // The note names where the way is blocked: the flexion limit (the same search, within its tolerance).
  const std::string& note = limits[0].note;
  const auto at = note.find("meet at flexion ");
  ASSERT_NE(at, std::string::npos) << note;
  EXPECT_NEAR(std::stod(note.substr(at + 16)), flexion.limit_deg, 0.2) << note;
  EXPECT_NE(limits[1].status, RomLimitStatus::not_reachable);
  EXPECT_TRUE(limits[1].note.empty());
  EXPECT_STREQ(to_string(RomLimitStatus::not_reachable), "not_reachable");
}

TEST(Rom, OnlyTheJointSurfacesMeetingIsArticularAndItNeverEndsASearch) {
  int subjects = 0, articular_earlier = 0;
  for (const char* name : {"lhdl-ct", "mc22", "tlem2-mri", "mc22-left"}) {
    auto j = test::load_real_joint(name);
    if (!j) continue;
    ++subjects;
    SCOPED_TRACE(name);
    HipJointOptions o;
    o.joint.scheme = make_scheme("equiangular", 0.5);
    const Side side = std::string(name) == "mc22-left" ? Side::left : Side::right;
    const HipJoint hip(j->femur, j->pelvis, side, locate_femoral_head(j->femur, j->pelvis), {}, o);
    ASSERT_TRUE(hip.articular().has_value());
    RomOptions impingement, all, articular;
    all.contacts = RomContacts::all;
    articular.contacts = RomContacts::articular;
    const RomBaseline bi = rom_baseline(hip, hip.femur_rotation({}), impingement);
    const RomBaseline ba = rom_baseline(hip, hip.femur_rotation({}), all);
    const RomBaseline bj = rom_baseline(hip, hip.femur_rotation({}), articular);
    EXPECT_GT(bi.articular_vertices, 0);
    EXPECT_EQ(ba.articular_vertices, 0);
    const std::vector<StandardMotion> motions = standard_motions();
    const auto li = find_rom_limits(hip, motions, impingement, bi), la = find_rom_limits(hip, motions, all, ba),
               lj = find_rom_limits(hip, motions, articular, bj);
    for (std::size_t k = 0; k < motions.size(); ++k) {
      SCOPED_TRACE(motions[k].name);
      const double inf = std::numeric_limits<double>::infinity();
      // A start that counting every contact cannot reach (the joint space closes on the way to 90 deg flexion)
      // is as early as a contact gets: nothing to compare.
      if (la[k].status == RomLimitStatus::not_reachable) continue;
      EXPECT_NE(li[k].status, RomLimitStatus::not_reachable);  // what 'all' reaches, 'impingement' reaches
      const double a = std::isnan(la[k].limit_deg) ? inf : la[k].limit_deg;
      const double i = std::isnan(li[k].limit_deg) ? inf : li[k].limit_deg;
      EXPECT_LE(a, i + 0.1);
      if (a < i - 0.2) {
        ++articular_earlier;
        // The earlier contact is articular, or an impingement contact that the impingement search's
        // steps passed as a graze (a pelvis vertex's class depends on the head point it meets): then
        // that search, started at the same pose, counts it at once.
        if (la[k].contact_class != ContactClass::articular) {
          const double from = la[k].limit_deg;
          const auto& angles = motions[k].angles;
          const RomLimit s = find_rom_limit(
              hip, std::function<PoseAngles(double)>([&](double t) { return angles(from + t); }), impingement, bi);
          EXPECT_TRUE(s.contact_at_start);
        }
      }
      if (!std::isnan(li[k].limit_deg)) {
        EXPECT_NE(li[k].contact_class, ContactClass::articular);
      }
      if (!std::isnan(lj[k].limit_deg)) {
        EXPECT_EQ(lj[k].contact_class, ContactClass::articular);
      }
    }
  }
  if (subjects == 0) GTEST_SKIP() << "shared data absent";
  EXPECT_GT(articular_earlier, 0);  // the MRI hips' joint spaces close before they impinge
}

TEST(Rom, PreExistingOverlapIsExcludedAndBadOptionsAreErrors) {
  HipModelOptions mo;
  mo.target_triangles = 3000;
  const HipModel h = make_hip_model(mo);
  const std::unique_ptr<HipJoint> joint = joint_of(h, mo, scan_options(1.0));
  const HipJoint& hip = *joint;
  RomOptions ro;
  ro.threshold_mm = mo.cartilage_gap_mm + 0.5;  // the whole head is "in contact" at the baseline
  const RomBaseline base = rom_baseline(hip, Eigen::Matrix3d::Identity(), ro);
  EXPECT_GT(base.excluded_vertices, 100);
  EXPECT_LT(base.min_gap_mm, ro.threshold_mm);
  const RomLimit l = find_rom_limit(hip, std::function<PoseAngles(double)>([](double t) { return PoseAngles{t, 0, 0}; }),
                                    ro, base);
  EXPECT_FALSE(l.contact_at_start);
  EXPECT_EQ(l.excluded_vertices, base.excluded_vertices);
  RomOptions bad;
  bad.tolerance_deg = 5;
  bad.step_deg = 1;
  EXPECT_THROW(rom_baseline(hip, Eigen::Matrix3d::Identity(), bad), Error);
}

TEST(Rom, ClusterBoundsGiveTheFullScansResults) {
  // The bounds only skip clusters and vertices that cannot reach the threshold, at this pose or
  // (reused over widened caps) at nearby ones: limits, exact least gaps and ROM map equal the search
  // that looks up every first-surface vertex (generated hip with a cam, and lhdl-ct when present).
  std::vector<std::unique_ptr<HipJoint>> hips;
  hips.push_back(cam_hip(0.25));
  if (auto j = test::load_real_joint("lhdl-ct")) {
    HipJointOptions o;
    o.joint.scheme = make_scheme("equiangular", 0.25);
    hips.push_back(std::make_unique<HipJoint>(j->femur, j->pelvis, Side::right, locate_femoral_head(j->femur),
                                              Landmarks{}, o));
  }
  for (const auto& hip : hips)
    for (double threshold : {0.0, 1.5}) {  // bone contact, and a cartilage offset
      SCOPED_TRACE(threshold);
      RomOptions with, without;
      with.threshold_mm = without.threshold_mm = threshold;
      with.exact_contact = without.exact_contact = false;  // the per-vertex scans' bounds
      without.use_bounds = false;
      const RomBaseline base = rom_baseline(*hip, hip->femur_rotation({}), with);
      const auto a = find_rom_limits(*hip, standard_motions(), with, base);
      const auto b = find_rom_limits(*hip, standard_motions(), without, base);
      std::int64_t skipped = 0;
      for (std::size_t k = 0; k < a.size(); ++k) {
        EXPECT_EQ(std::isnan(a[k].limit_deg), std::isnan(b[k].limit_deg)) << k;
        if (!std::isnan(a[k].limit_deg)) {
          EXPECT_EQ(a[k].limit_deg, b[k].limit_deg) << k;
          EXPECT_EQ(a[k].min_gap_at_limit_mm, b[k].min_gap_at_limit_mm) << k;  // the exact least gap
        }
        EXPECT_EQ(a[k].status, b[k].status) << k;
        if (a[k].status != RomLimitStatus::not_reachable) EXPECT_EQ(a[k].min_gap_at_start_mm, b[k].min_gap_at_start_mm) << k;
        EXPECT_EQ(b[k].vertices_skipped, 0);
        skipped += a[k].vertices_skipped;
      }
      EXPECT_GT(skipped, 0);
      const std::vector<double> flex{0, 45, 90}, add{-10, 10};
      const auto ma = rom_map(*hip, flex, add, with, base), mb = rom_map(*hip, flex, add, without, base);
      for (std::size_t k = 0; k < ma.size(); ++k) {
        EXPECT_EQ(ma[k].status, mb[k].status);
        if (ma[k].status == RomMapStatus::limited) {
          EXPECT_EQ(ma[k].max_internal_rotation_deg, mb[k].max_internal_rotation_deg);
        }
      }
    }
}

TEST(Rom, TrochanterMeetsTheIliacPlateWhereTheClosedFormSays) {
  // Extra-articular path (issue 14): a femur of a head sphere (radius 22 mm about the COR) and a
  // trochanter block, x in [35, 50], y in [-8, 8], z in [5, 20] mm, hidden behind the head from the COR;
  // a pelvis of a cup (24.5 to 30.5 mm, covering 80 deg about +z) and an iliac plate, x in [10, 60],
  // y in [-20, 20], z in [45, 55] mm, hidden behind the cup. Rotating the femur by theta about -y
  // (x turns towards +z), block corner (x, z) reaches the plate's lower face z = 45 when
  // x sin(theta) + z cos(theta) = 45, i.e. theta = asin(45 / rho) - atan2(z, x), rho = |(x, z)|;
  // a convex block meets a plane first at a corner, so the limit is the least over the corners. No
  // other part can meet: the head and the cup are concentric, the block stays beyond 36 mm, the cup
  // within 30.5 mm. Without layered maps the hidden block is not tested and there is no limit.
  if (!FirstHitCaster::available()) GTEST_SKIP() << "no ray caster in this build";
  const Eigen::Vector3d cor(60, -20, 30);
  const Eigen::Vector3d c = cor;
  const TriangleMesh femur = test::concatenated(make_uv_sphere(22, cor, 96, 48, Eigen::Vector3d(0.3, 0.2, 0.93).normalized()),
                                                test::make_box(c + Eigen::Vector3d(35, -8, 5), c + Eigen::Vector3d(50, 8, 20)));
  const TriangleMesh pelvis =
      test::concatenated(make_cup(24.5, 30.5, 80, cor, Eigen::Vector3d::UnitZ(), 96, 40),
                         test::make_box(c + Eigen::Vector3d(10, -20, 45), c + Eigen::Vector3d(60, 20, 55)));
  double want = 1e9;
  for (const double x : {35.0, 50.0})
    for (const double z : {5.0, 20.0}) {
      const double rho = std::hypot(x, z);
      if (rho > 45) want = std::min(want, (std::asin(45 / rho) - std::atan2(z, x)) * 180 / M_PI);
    }
  SphereFitResult head;
  head.centre = cor;
  head.radius = 22;
  const auto rotation = std::function<Eigen::Matrix3d(double)>(
      [](double t) { return Eigen::AngleAxisd(t * M_PI / 180, -Eigen::Vector3d::UnitY()).toRotationMatrix(); });
  RomOptions ro;
  ro.step_deg = 1;
  ro.contact_depth_mm = 0;  // the first touch: the closed form's
  ro.exact_contact = false;  // the per-vertex scans (the exact test sees the block with any maps: below)
  for (const int layers : {0, 4}) {
    SCOPED_TRACE(layers);
    HipJointOptions o = scan_options(0.25);
    o.joint.layers = layers;
    const HipJoint hip(femur, pelvis, Side::right, head, {}, o);
    const RomBaseline base = rom_baseline(hip, Eigen::Matrix3d::Identity(), ro);
    EXPECT_EQ(base.excluded_vertices, 0);
    for (const bool bounds : {true, false}) {
      ro.use_bounds = bounds;
      const RomLimit l = find_rom_limit(hip, rotation, ro, base);
      if (layers == 0) {
        EXPECT_TRUE(std::isnan(l.limit_deg)) << l.limit_deg;  // the thesis' maps cannot see it
        continue;
      }
      EXPECT_NEAR(l.limit_deg, want, 0.2) << "closed form " << want;
      EXPECT_EQ(l.limited_by, ImpingementSite::extra_articular);
      EXPECT_TRUE(l.limited_by_hidden_vertex);
      EXPECT_TRUE(l.limited_by_ball);
      if (bounds) {
        EXPECT_GT(l.vertices_skipped, 0);
      }
    }
  }
}

TEST(Rom, LayeredClusterBoundsGiveTheFullScansResults) {
  // With layered maps, the occupancy bounds skip only hidden clusters that cannot reach the threshold:
  // the limits equal those of the search that looks up every hidden vertex (tlem2-mri, whose adduction
  // is limited outside the joint).
  auto j = test::load_real_joint("tlem2-mri");
  if (!j) GTEST_SKIP() << "shared data absent";
  if (!FirstHitCaster::available()) GTEST_SKIP() << "no ray caster in this build";
  HipJointOptions o;
  o.joint.scheme = make_scheme("equiangular", 0.5);
  o.joint.layers = 4;
  const HipJoint hip(j->femur, j->pelvis, Side::right, locate_femoral_head(j->femur), {}, o);
  RomOptions with, without;
  with.exact_contact = without.exact_contact = false;  // the per-vertex scans' bounds
  without.use_bounds = false;
  const RomBaseline base = rom_baseline(hip, hip.femur_rotation({}), with);
  const auto a = find_rom_limits(hip, standard_motions(), with, base);
  const auto b = find_rom_limits(hip, standard_motions(), without, base);
  int extra = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(std::isnan(a[k].limit_deg), std::isnan(b[k].limit_deg)) << k;
    if (!std::isnan(a[k].limit_deg)) {
      EXPECT_EQ(a[k].limit_deg, b[k].limit_deg) << k;
      EXPECT_EQ(a[k].limited_by, b[k].limited_by) << k;
    }
    extra += a[k].limited_by_hidden_vertex;
  }
  EXPECT_GT(extra, 0);
}

TEST(Rom, EnvelopeByRefinementAgreesWithEveryPoseScanned) {
  // The adaptive envelope (coarse lattice, cells split where their corners disagree) against the
  // brute force that scans every pose of the same grid, on a generated hip with a cam; and against
  // the ROM limit of internal rotation from neutral (the first pose in contact along that line).
  const std::unique_ptr<HipJoint> cam = cam_hip(0.5);
  const HipJoint& hip = *cam;
  RomOptions ro;
  const RomBaseline base = rom_baseline(hip, hip.femur_rotation({}), ro);
  RomEnvelopeOptions eo;
  eo.step_deg = 4;
  eo.flexion_min_deg = -32, eo.flexion_max_deg = 128;
  eo.adduction_min_deg = -52, eo.adduction_max_deg = 40;
  eo.internal_rotation_min_deg = -60, eo.internal_rotation_max_deg = 60;
  eo.coarse_steps = 4;
  const RomEnvelope fast = rom_envelope(hip, eo, ro, base);
  eo.coarse_steps = 1;
  const RomEnvelope all = rom_envelope(hip, eo, ro, base);
  ASSERT_EQ(fast.valid.size(), all.valid.size());
  EXPECT_EQ(all.poses_evaluated, all.poses);
  EXPECT_LT(fast.poses_evaluated, fast.poses / 2);
  std::int64_t differ = 0, valid = 0;
  for (std::size_t p = 0; p < all.valid.size(); ++p) differ += fast.valid[p] != all.valid[p], valid += all.valid[p];
  EXPECT_GT(valid, all.poses / 10);
  EXPECT_LT(valid, all.poses);  // both kinds occur
  EXPECT_LE(differ, all.poses / 1000) << differ << " of " << all.poses;
  std::cout << "envelope: " << fast.poses_evaluated << " of " << fast.poses << " scanned, " << differ << " differ, " << valid << " valid\n";
  // Internal rotation at flexion 0, adduction 0 (index 8 and 13): valid up to the limit, not beyond.
  const RomLimit l = find_rom_limit(hip, std::function<PoseAngles(double)>([](double t) { return PoseAngles{0, 0, t}; }),
                                    ro, base);
  ASSERT_TRUE(l.limit_deg > 0 && l.limit_deg < 60) << l.limit_deg;
  ASSERT_DOUBLE_EQ(all.flexion_deg[8], 0);
  ASSERT_DOUBLE_EQ(all.adduction_deg[13], 0);
  for (std::size_t k = 0; k < all.internal_rotation_deg.size(); ++k) {
    const double t = all.internal_rotation_deg[k];
    if (t < 0) continue;
    if (t < l.limit_deg - 0.2) {
      EXPECT_TRUE(all.at(8, 13, k)) << t;
    }
    if (t > l.limit_deg + 0.2 && l.monotone) {
      EXPECT_FALSE(all.at(8, 13, k)) << t;
    }
  }
  eo.step_deg = 3;  // 92 deg of adduction is not a whole number of 3-deg steps
  EXPECT_THROW(rom_envelope(hip, eo, ro, base), Error);
}

// The metric (issue 26): with a clearance h > 0 the neck's cylinder comes within Euclidean distance h
// of the rim's inner edge (radius R, angle gamma from the neck axis) when R sin(gamma) - n = h, and the
// rim's radial gap (R less the neck's radius n / sin(gamma) along the same ray) reaches h when
// sin(gamma) = n / (R - h): the distance meets first. Each search finds its own closed form within
// 0.2 deg, and the two differ by their closed forms' difference (1.1 deg at h = 1 mm).
TEST(Rom, TheDistanceMetricMeetsAClearanceWhereTheClosedFormSays) {
  if (!SignedDistanceQuery::available()) GTEST_SKIP() << "no closest-point engine in this build";
  HipModelOptions mo;
  mo.target_triangles = 20000;
  mo.cup_coverage_deg = 100;
  const HipModel h = make_hip_model(mo);
  HipJointOptions jo = scan_options(0.1);
  jo.joint.distances = true;
  jo.joint.distance_reach_mm = 1.5;
  const std::unique_ptr<HipJoint> joint = joint_of(h, mo, jo);
  const HipJoint& hip = *joint;
  const Eigen::Vector3d neck = Eigen::Vector3d(0.80, 0.25, -0.55).normalized();
  const Eigen::Vector3d opening = -Eigen::Vector3d(-0.65, -0.2, 0.73).normalized();
  const double psi0 = std::acos(neck.dot(opening)) * 180 / M_PI;
  const double inner = mo.head_radius_mm + mo.cartilage_gap_mm, n = mo.neck_radius_mm, clearance = 1;
  const double deg = 180 / M_PI;
  const double radial_contact = (180 - mo.cup_coverage_deg) - std::asin(n / (inner - clearance)) * deg;
  const double distance_contact = (180 - mo.cup_coverage_deg) - std::asin((n + clearance) / inner) * deg;
  const Eigen::Vector3d k = opening.cross(neck).normalized();
  const std::function<Eigen::Matrix3d(double)> turn = [&](double t) {
    return Eigen::AngleAxisd(t * M_PI / 180, k).toRotationMatrix();
  };
  RomOptions ro;
  ro.step_deg = 1;
  ro.contact_depth_mm = 0;
  ro.threshold_mm = clearance;
  const RomLimit radial = find_rom_limit(hip, turn, ro, rom_baseline(hip, Eigen::Matrix3d::Identity(), ro));
  ro.metric = RomMetric::distance;
  const RomBaseline base = rom_baseline(hip, Eigen::Matrix3d::Identity(), ro);
  EXPECT_EQ(base.excluded_vertices, 0);
  const RomLimit distance = find_rom_limit(hip, turn, ro, base);
  EXPECT_NEAR(radial.limit_deg, radial_contact - psi0, 0.2);
  EXPECT_NEAR(distance.limit_deg, distance_contact - psi0, 0.2);
  EXPECT_NEAR(radial.limit_deg - distance.limit_deg, radial_contact - distance_contact, 0.2);
  EXPECT_GT(radial_contact - distance_contact, 1.0);  // the geometry separates the two metrics
  // At the limit the least distance has just reached the clearance, from above.
  EXPECT_LE(distance.min_gap_at_limit_mm, clearance);
  EXPECT_GT(distance.min_gap_at_limit_mm, clearance - 0.05);
  // The contact: on the rim's inner edge, or (exact contacts: the femur's closest point) on the neck within
  // the clearance of it.
  EXPECT_GT((distance.contact_mm - h.cor).norm(), inner - clearance - 0.3);
  EXPECT_LT((distance.contact_mm - h.cor).norm(), inner + 0.3);
  // The joint must be able to give the metric its distances.
  EXPECT_THROW(rom_baseline(*joint_of(h, mo, scan_options(0.5)), Eigen::Matrix3d::Identity(), ro), Error);
  ro.threshold_mm = 2;  // beyond the reach of 1.5 mm
  EXPECT_THROW(rom_baseline(hip, Eigen::Matrix3d::Identity(), ro), Error);
  ro.threshold_mm = clearance;
  ro.vertices = RomVertices::first_surface;
  EXPECT_THROW(find_rom_limit(hip, turn, ro, base), Error);
  EXPECT_EQ(parse_rom_metric("distance", "--metric"), RomMetric::distance);
  EXPECT_THROW(parse_rom_metric("euclid", "--metric"), Error);
}

// The screened distance search (a cut at or below 0: the radial scan lists the candidates, rom_scanner.hpp)
// against whole scans: at each limit, Joint::detect's distances (every vertex within the reach, exact
// closest points) put a counted vertex at or below the cut, and at the bracket's other end none.
TEST(Rom, TheScreenedDistanceSearchEndsWhereWholeScansFirstMeet) {
  if (!SignedDistanceQuery::available()) GTEST_SKIP() << "no closest-point engine in this build";
  HipJointOptions jo = scan_options(0.25);
  jo.joint.distances = true;
  jo.joint.distance_reach_mm = 1;
  const std::unique_ptr<HipJoint> cam = cam_hip(0.25, &jo);
  const HipJoint& hip = *cam;
  RomOptions ro;
  ro.metric = RomMetric::distance;
  ro.contact_depth_mm = 0.25;  // the cut is -0.25 mm: the per-vertex screened search
  const RomBaseline base = rom_baseline(hip, hip.femur_rotation({}), ro);
  const double cut = ro.threshold_mm - ro.contact_depth_mm;
  auto least = [&](double theta, const StandardMotion& m) {
    const Eigen::Matrix3d R = hip.femur_rotation(m.angles(theta));
    const PoseResult r = hip.joint().detect(R, hip.joint_translation(R));
    double d = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < r.ball_gaps.distance_mm.size(); ++i)
      if (!base.skip_ball[i] && r.ball_gaps.distance_mm[i] < d) d = r.ball_gaps.distance_mm[i];
    for (std::size_t i = 0; i < r.socket_gaps.distance_mm.size(); ++i)
      if (!base.skip_socket[i] && r.socket_gaps.distance_mm[i] < d) d = r.socket_gaps.distance_mm[i];
    return d;
  };
  const double width = ro.step_deg / 32;  // the bisection's last bracket: 2 deg halved to <= 0.1 deg
  int limits = 0;
  for (const StandardMotion& m : standard_motions()) {
    SCOPED_TRACE(m.name);
    const RomLimit l = find_rom_limit(hip, m.angles, ro, base);
    if (std::isnan(l.limit_deg) || l.contact_at_start) continue;
    ++limits;
    EXPECT_LE(least(l.limit_deg, m), cut + 1e-6);
    EXPECT_GT(least(l.limit_deg - width, m), cut);
    EXPECT_NEAR(l.min_gap_at_limit_mm, least(l.limit_deg, m), 1e-6);
  }
  EXPECT_GE(limits, 4);
}
