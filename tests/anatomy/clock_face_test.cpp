// Clock faces (acetabular and femoral head-neck). Invariants:
// - hour() is the angle from 12 towards 3 in hours: 12, 3, 6, 9 on the axes, 1.5 half-way;
//   sectors cover (k, k+1];
// - on every shared subject and a mirrored left copy: the acetabular sphere lies within a few mm
//   of the head centre, the opening faces lateral, inferior and anterior with inclination and
//   anteversion in the anatomical range (Murray 1993 radiographic definitions), 12 o'clock is
//   superior, 3 o'clock anterior on both sides, the notch (6 o'clock) is where the cup's extent
//   is least; mirrored points get the same hours on the mirrored hip;
// - the femoral clock's axis runs along the neck (neck-shaft angle 115-145 deg);
// - analytic oracle: the acetabular sphere is fitted on the whole lunate surface whatever the joint space:
//   a cup of inner radius r_h + 5.5 mm (an MRI's joint space) with a fossa 4 mm deeper gives its centre and
//   radius within 0.05 mm and the lunate area within 3 % of the analytic band's, where the head radius + 4 mm
//   cut of the old fit held none of it;
// - clock_summary keeps every tested vertex's area and finds the closest vertex's hour;
// - analytic oracle: the femoral clock's axis is the generated hip's neck axis (within 0.2 deg), and stays within
//   0.2 deg of it when the triangles on one side of the neck are split in four (the same surface, three times the
//   vertices there): the axis follows the surface, not the tessellation.
#include "impinge/anatomy/clock_face.hpp"
#include "impinge/clinical/clock_summary.hpp"
#include "impinge/core/error.hpp"

#include <gtest/gtest.h>

#include "impinge/anatomy/hip_frames.hpp"
#include "impinge/io/generated_models.hpp"
#include "test_support.hpp"

using namespace impinge;

TEST(ClockFace, HoursAndSectors) {
  ClockFace c;
  c.centre = Eigen::Vector3d(1, 2, 3);
  c.twelve = Eigen::Vector3d(0, 1, 0);
  c.three = Eigen::Vector3d(1, 0, 0);
  c.axis = Eigen::Vector3d(0, 0, -1);
  auto h = [&](double x, double y) { return c.hour(c.centre + Eigen::Vector3d(x, y, 7)); };
  EXPECT_NEAR(h(0, 1), 12, 1e-12);
  EXPECT_NEAR(h(1, 0), 3, 1e-12);
  EXPECT_NEAR(h(0, -1), 6, 1e-12);
  EXPECT_NEAR(h(-1, 0), 9, 1e-12);
  EXPECT_NEAR(h(1, 1), 1.5, 1e-12);
  EXPECT_TRUE(std::isnan(h(0, 0)));
  EXPECT_EQ(ClockFace::sector(0.5), 0);
  EXPECT_EQ(ClockFace::sector(1.0), 0);
  EXPECT_EQ(ClockFace::sector(1.0001), 1);
  EXPECT_EQ(ClockFace::sector(12), 11);
  std::mt19937_64 rng(3);
  const Eigen::Matrix3d R = test::random_rotation(rng);
  const ClockFace m = c.transformed(R, Eigen::Vector3d(5, 6, 7));
  EXPECT_NEAR(m.hour(R * (c.centre + Eigen::Vector3d(1, 1, 0)) + Eigen::Vector3d(5, 6, 7)), 1.5, 1e-12);
}

TEST(ClockFace, AcetabulumSphereFitsTheWholeLunateSurface) {
  // Cup about c: inner radius 27.5 mm from the pole to 100 deg, except the fossa (within 25 deg of the pole)
  // 4 mm deeper; the head (radius 22 mm) 0.8 mm off the cup's centre. The pelvic frame: the identity.
  const Eigen::Vector3d c(0.5, -0.3, 0.4), head(0.5, 0.3, -0.1);
  const double r_cup = 27.5, fossa_deg = 25, coverage_deg = 100;
  TriangleMesh cup = make_cup(r_cup, r_cup + 5, coverage_deg, c, -Eigen::Vector3d::UnitZ(), 360, 200);
  double band_area = 0;
  for (Eigen::Index i = 0; i < cup.V.rows(); ++i) {
    const Eigen::Vector3d d = cup.V.row(i).transpose() - c;
    const double polar = std::acos(std::clamp(d.normalized().dot(-Eigen::Vector3d::UnitZ()), -1.0, 1.0)) * 180 / M_PI;
    if (std::abs(d.norm() - r_cup) < 1e-6 && polar < fossa_deg) cup.V.row(i) = (c + d.normalized() * (r_cup + 4)).transpose();
  }
  // The lunate band between the fossa's edge and the rim, on the sphere: 2 pi r^2 (cos a - cos b).
  band_area = 2 * M_PI * r_cup * r_cup * (std::cos(fossa_deg * M_PI / 180) - std::cos(coverage_deg * M_PI / 180));
  cup.source = "analytic cup";
  AnatomicalFrame frame;
  const Acetabulum A = find_acetabulum(cup, head, 22.0, frame);
  EXPECT_LT((A.sphere.centre - c).norm(), 0.05) << A.sphere.centre.transpose();
  EXPECT_NEAR(A.sphere.radius, r_cup, 0.05);
  EXPECT_NEAR(A.joint_space_mode_mm, r_cup - 22.0, 1.0);
  // The fossa's ring of triangles that slope down to it and the rim's edge are left out: a little under.
  EXPECT_NEAR(A.lunate_area_mm2, band_area, 0.03 * band_area) << A.lunate_area_mm2 << " of " << band_area;
}

TEST(ClockFace, AcetabulumAndFemoralClockOnRealHipsBothSides) {
  bool any = false;
  for (const char* name : {"lhdl-ct", "mc22", "tlem2-mri"}) {
    auto j = test::load_real_joint(name);
    if (!j) continue;
    any = true;
    const HipFrames h = find_hip_frames(j->femur, j->pelvis, Side::right);
    const Acetabulum A = find_acetabulum(j->pelvis, h.head.centre, h.head.radius, h.pelvis);
    // Mirrored left copy.
    TriangleMesh fl = j->femur, pl = j->pelvis;
    for (TriangleMesh* m : {&fl, &pl}) {
      m->V.col(0) *= -1;
      m->F.col(1).swap(m->F.col(2));
    }
    const HipFrames hl = find_hip_frames(fl, pl, Side::left);
    const Acetabulum Al = find_acetabulum(pl, hl.head.centre, hl.head.radius, hl.pelvis);
    // The mirrored (left) hip reads the same angles as the right one it mirrors.
    const AcetabularOrientation oR = radiographic_orientation(A, h.pelvis, Side::right);
    const AcetabularOrientation oL = radiographic_orientation(Al, hl.pelvis, Side::left);
    EXPECT_NEAR(oR.inclination_deg, oL.inclination_deg, 1.0);
    EXPECT_NEAR(oR.anteversion_deg, oL.anteversion_deg, 1.0);
    for (const auto& [side, hh, AA] : {std::tuple{Side::right, &h, &A}, std::tuple{Side::left, &hl, &Al}}) {
      SCOPED_TRACE(std::string(name) + (side == Side::right ? " right" : " left"));
      const double m = side == Side::right ? 1 : -1;
      const AnatomicalFrame& P = hh->pelvis;
      EXPECT_LT((AA->sphere.centre - hh->head.centre).norm(), 5);
      EXPECT_GT(AA->sphere.radius, hh->head.radius - 2);
      EXPECT_LT(AA->sphere.radius, hh->head.radius + 5);
      const Eigen::Vector3d n = P.axes.transpose() * AA->opening;  // X anterior, Y superior, Z right
      const double inclination = std::atan2(m * n.z(), -n.y()) * 180 / M_PI;
      const double anteversion = std::asin(n.x()) * 180 / M_PI;
      EXPECT_GT(inclination, 30);
      EXPECT_LT(inclination, 60);
      EXPECT_GT(anteversion, 5);
      EXPECT_LT(anteversion, 35);
      const AcetabularOrientation o = radiographic_orientation(*AA, P, side);
      EXPECT_NEAR(o.inclination_deg, inclination, 1e-9);
      EXPECT_NEAR(o.anteversion_deg, anteversion, 1e-9);
      EXPECT_GT((P.axes.transpose() * AA->clock.twelve).y(), 0.5);  // 12 superior
      EXPECT_GT((P.axes.transpose() * AA->clock.three).x(), 0.7);   // 3 anterior, both sides
      EXPECT_LT(AA->notch_coverage_deg, AA->median_coverage_deg - 4);
      EXPECT_GT(AA->rim_radius_mm, 20);
      EXPECT_LT(AA->rim_radius_mm, 35);
      const ClockFace K = femoral_clock_face(side == Side::right ? j->femur : fl, hh->head.centre, hh->head.radius,
                                             hh->femur);
      const double neck_shaft = 180 - std::acos(K.axis.dot(hh->femur.axes.col(1))) * 180 / M_PI;
      EXPECT_GT(neck_shaft, 115);
      EXPECT_LT(neck_shaft, 145);
      EXPECT_LT(m * K.axis.dot(hh->femur.axes.col(2)), -0.5);  // towards the head: medial
    }
    // Mirror symmetry: the mirror image of a pelvis vertex has the same hour on the left hip.
    for (Eigen::Index i = 0; i < j->pelvis.V.rows(); i += 2003) {
      const double hr = A.clock.hour(j->pelvis.V.row(i).transpose()), hl2 = Al.clock.hour(pl.V.row(i).transpose());
      const double d = std::abs(hr - hl2);
      EXPECT_LT(std::min(d, 12 - d), 1e-6) << name << " vertex " << i;
    }
  }
  if (!any) GTEST_SKIP() << "shared data absent";
}

TEST(ClockFace, SummaryKeepsEveryAreaAndFindsTheClosestHour) {
  ClockFace c;  // twelve +y, three +x, centre 0
  Vertices V(4, 3);
  V << 0, 1, 0, 1, 0, 0, 0, -1, 0, -1, 0.2, 0;
  ScanGaps g;
  g.gap_mm = {5.0f, 0.5f, std::nanf(""), -1.0f};
  g.status = {ScanGaps::tested, ScanGaps::tested, ScanGaps::beyond_reach, ScanGaps::tested};
  Eigen::VectorXd area(4);
  area << 1, 2, 4, 8;
  ImpingementLevels levels;
  ClockSummary s;
  clock_summary(g, V, area, c, levels, s);
  ASSERT_EQ(s.sector_level_area_mm2.size(), static_cast<std::size_t>(12 * levels.count()));
  double total = 0;
  for (double a : s.sector_level_area_mm2) total += a;
  EXPECT_DOUBLE_EQ(total, 11);  // 1 + 2 + 8: the untested vertex counts nowhere
  EXPECT_NEAR(s.closest_hour, c.hour(V.row(3).transpose()), 1e-12);
  EXPECT_DOUBLE_EQ(s.sector_level_area_mm2[static_cast<std::size_t>(2 * levels.count() + levels.level(0.5f))], 2);
  // The hours computed once (clock_hours: a bone's hours do not change with its pose) give the same
  // summary; hours of another length are refused.
  const std::vector<double> hours = clock_hours(V, c);
  ASSERT_EQ(hours.size(), 4u);
  for (Eigen::Index i = 0; i < V.rows(); ++i) EXPECT_EQ(hours[static_cast<std::size_t>(i)], c.hour(V.row(i).transpose()));
  ClockSummary t;
  clock_summary(g, hours, area, levels, t);
  EXPECT_EQ(t.closest_hour, s.closest_hour);
  EXPECT_EQ(t.sector_level_area_mm2, s.sector_level_area_mm2);
  EXPECT_THROW(clock_summary(g, std::vector<double>(3, 1.0), area, levels, t), Error);
}

namespace {
// Every triangle of `m` whose centroid satisfies `pick` split in four at its edge midpoints (the same surface; the
// neighbours keep their edges, so the mesh gains T-junctions, which a centroid does not mind).
TriangleMesh split_where(const TriangleMesh& m, const std::function<bool(const Eigen::Vector3d&)>& pick) {
  TriangleMesh out;
  out.source = m.source + " (split)";
  std::vector<Eigen::Vector3d> V;
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) V.push_back(m.V.row(i).transpose());
  std::vector<Eigen::Vector3i> F;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    const int a = m.F(f, 0), b = m.F(f, 1), c = m.F(f, 2);
    if (!pick((V[a] + V[b] + V[c]) / 3)) {
      F.emplace_back(a, b, c);
      continue;
    }
    const int ab = static_cast<int>(V.size()), bc = ab + 1, ca = ab + 2;
    V.push_back((V[a] + V[b]) / 2), V.push_back((V[b] + V[c]) / 2), V.push_back((V[c] + V[a]) / 2);
    F.emplace_back(a, ab, ca), F.emplace_back(ab, b, bc), F.emplace_back(ca, bc, c), F.emplace_back(ab, bc, ca);
  }
  out.V.resize(static_cast<Eigen::Index>(V.size()), 3);
  for (std::size_t i = 0; i < V.size(); ++i) out.V.row(static_cast<Eigen::Index>(i)) = V[i].transpose();
  out.F.resize(static_cast<Eigen::Index>(F.size()), 3);
  for (std::size_t i = 0; i < F.size(); ++i) out.F.row(static_cast<Eigen::Index>(i)) = F[i].transpose();
  return out;
}
}  // namespace

TEST(ClockFace, TheFemoralAxisFollowsTheSurfaceNotItsTessellation) {
  HipModelOptions mo;
  mo.target_triangles = 12000;
  const HipModel h = make_hip_model(mo);
  const Eigen::Vector3d neck = Eigen::Vector3d(0.80, 0.25, -0.55).normalized();  // generated_models.cpp's
  AnatomicalFrame F;  // working axes: 12 o'clock towards +y
  auto angle_deg = [](const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
    return std::acos(std::clamp(u.normalized().dot(v.normalized()), -1.0, 1.0)) * 180 / M_PI;
  };
  const ClockFace whole = femoral_clock_face(h.ball, h.cor, mo.head_radius_mm, F);
  EXPECT_LT(angle_deg(whole.axis, -neck), 0.2);  // from the neck to the head
  // Split the triangles on the anterior-superior side of the neck: three times the vertices there.
  const Eigen::Vector3d side = (Eigen::Vector3d(0, 0.5, 1) - neck * neck.dot(Eigen::Vector3d(0, 0.5, 1))).normalized();
  const TriangleMesh refined = split_where(h.ball, [&](const Eigen::Vector3d& p) { return (p - h.cor).dot(side) > 0; });
  ASSERT_GT(refined.V.rows(), h.ball.V.rows() + h.ball.V.rows() / 2);
  const ClockFace split = femoral_clock_face(refined, h.cor, mo.head_radius_mm, F);
  EXPECT_LT(angle_deg(split.axis, whole.axis), 0.2) << "the axis moved with the tessellation";
  EXPECT_LT(angle_deg(split.axis, -neck), 0.3);
}
