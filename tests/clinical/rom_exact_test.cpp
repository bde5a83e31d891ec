// ROM limits at first contact, exact between vertices (rom_exact.cpp, issue 81). Invariants:
// - analytic oracle: two triangular prisms whose ridges cross (the femur's along y, the pelvis' along x)
//   first meet edge against edge, in the middle of both ridges, where no vertex lies: rotating the femur
//   about -y, its ridge at (x0, z0) reaches the pelvis' ridge at height zp when rho sin(phi0 + theta) = zp
//   (rho, phi0: the ridge's radius and angle in the x-z plane). The exact search finds it within 0.05 deg;
//   the per-vertex search only later (no vertex ever reaches the other ridge first);
// - the same surface tessellated otherwise: splitting every triangle of either bone in four (midpoints,
//   written here, independent of the library) of a generated hip with a cam moves no limit by more than
//   0.05 deg, no least distance at the start or the limit by more than 0.01 mm;
// - renumbering the vertices and faces (and turning each face's corners) moves nothing;
// - at a contact depth > 0 the limit is a depth and first_contact_deg still the first touch, no later.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <map>
#include <numeric>
#include <random>

#include "impinge/clinical/rom.hpp"
#include "impinge/io/generated_models.hpp"
#include "test_support.hpp"

using namespace impinge;
using Eigen::Vector3d;

namespace {
using test::renumbered;
using test::scan_options;
// A closed prism: the triangle (p0, p1, p2) swept by e; faces wound outward.
TriangleMesh make_prism(const Vector3d& p0, const Vector3d& p1, const Vector3d& p2, const Vector3d& e) {
  TriangleMesh m;
  m.V.resize(6, 3);
  const Vector3d p[3] = {p0, p1, p2};
  for (int i = 0; i < 3; ++i) m.V.row(i) = p[i].transpose(), m.V.row(i + 3) = (p[i] + e).transpose();
  m.F.resize(8, 3);
  m.F << 0, 2, 1, 3, 4, 5, 0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4, 2, 0, 3, 2, 3, 5;
  const Vector3d centre = (p0 + p1 + p2) / 3 + e / 2;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {  // outward: the normal points away from the centre
    const Vector3d a = m.V.row(m.F(f, 0)), b = m.V.row(m.F(f, 1)), c = m.V.row(m.F(f, 2));
    if ((b - a).cross(c - a).dot(a - centre) < 0) std::swap(m.F(f, 1), m.F(f, 2));
  }
  m.source = "prism";
  return m;
}
std::vector<RomLimit> limits_of(const TriangleMesh& femur, const TriangleMesh& pelvis, const HipModel& h,
                                const HipModelOptions& mo, const RomOptions& ro) {
  SphereFitResult head;
  head.centre = h.cor;
  head.radius = mo.head_radius_mm;
  const HipJoint hip(femur, pelvis, Side::right, head, Landmarks{}, scan_options(0.5));
  return find_rom_limits(hip, standard_motions(), ro, rom_baseline(hip, Eigen::Matrix3d::Identity(), ro));
}
}  // namespace

TEST(RomExact, CrossedRidgesMeetEdgeAgainstEdgeWhereTheClosedFormSays) {
  const Vector3d cor(60, -20, 30);
  // The femur: a head sphere and a prism whose ridge (x0, z0) = (40, 10) runs along y in [-10, 10], its faces
  // falling at 45 deg; the pelvis: a cup and a prism whose ridge runs along x in [20, 45] at z = 25, y = 0.
  const TriangleMesh femur = test::concatenated(
      make_uv_sphere(22, cor, 48, 24, Vector3d(0.3, 0.2, 0.93).normalized()),
      make_prism(cor + Vector3d(40, -10, 10), cor + Vector3d(32, -10, 2), cor + Vector3d(48, -10, 2), Vector3d(0, 20, 0)));
  const TriangleMesh pelvis = test::concatenated(
      make_cup(24.5, 30.5, 80, cor, Vector3d::UnitZ(), 48, 20),
      make_prism(cor + Vector3d(20, 0, 25), cor + Vector3d(20, -8, 33), cor + Vector3d(20, 8, 33), Vector3d(25, 0, 0)));
  const double rho = std::hypot(40.0, 10.0), phi0 = std::atan2(10.0, 40.0);
  const double want = (std::asin(25 / rho) - phi0) * 180 / M_PI;
  SphereFitResult head;
  head.centre = cor;
  head.radius = 22;
  const auto rotation = std::function<Eigen::Matrix3d(double)>(
      [](double t) { return Eigen::AngleAxisd(t * M_PI / 180, -Vector3d::UnitY()).toRotationMatrix(); });
  RomOptions ro;
  ro.step_deg = 1;
  ro.tolerance_deg = 0.01;
  const HipJoint hip(femur, pelvis, Side::right, head, {}, scan_options(0.25));
  const RomBaseline base = rom_baseline(hip, Eigen::Matrix3d::Identity(), ro);
  ASSERT_NE(base.contact, nullptr);
  const RomLimit l = find_rom_limit(hip, rotation, ro, base);
  EXPECT_NEAR(l.limit_deg, want, 0.05) << "closed form " << want;
  EXPECT_EQ(l.first_contact_deg, l.limit_deg);
  EXPECT_NEAR(l.min_gap_at_limit_mm, 0, 1e-9);
  // Where they touch: the ridges' crossing, (rho cos(phi0 + theta), 0, 25) from the COR.
  const double a = (want * M_PI / 180) + phi0;
  EXPECT_NEAR((l.contact_mm - (cor + Vector3d(rho * std::cos(a), 0, 25))).norm(), 0, 0.05);
  // Vertex by vertex the ridges pass each other: the limit comes later (a face of one meets a vertex of
  // the other), or not at all.
  RomOptions by_vertex = ro;
  by_vertex.exact_contact = false;
  const RomLimit v = find_rom_limit(hip, rotation, by_vertex, rom_baseline(hip, Eigen::Matrix3d::Identity(), by_vertex));
  EXPECT_TRUE(std::isnan(v.limit_deg) || v.limit_deg > want + 1) << v.limit_deg;
}

TEST(RomExact, SplittingEveryTriangleInFourOrRenumberingMovesNoLimit) {
  HipModelOptions mo;
  mo.target_triangles = 3000;
  mo.cam_height_mm = 2;
  const HipModel h = make_hip_model(mo);
  RomOptions ro;
  const auto original = limits_of(h.ball, h.socket, h, mo, ro);
  const auto split_femur = limits_of(split_in_four(h.ball), h.socket, h, mo, ro);
  const auto split_pelvis = limits_of(h.ball, split_in_four(h.socket), h, mo, ro);
  const auto renumbered_both = limits_of(renumbered(h.ball, 1), renumbered(h.socket, 2), h, mo, ro);
  int limited = 0;
  for (std::size_t k = 0; k < original.size(); ++k) {
    SCOPED_TRACE(standard_motions()[k].name);
    const RomLimit& o = original[k];
    limited += o.status == RomLimitStatus::limited;
    for (const auto* other : {&split_femur, &split_pelvis}) {
      const RomLimit& x = (*other)[k];
      EXPECT_EQ(x.status, o.status);
      if (o.status == RomLimitStatus::limited) {
        EXPECT_NEAR(x.limit_deg, o.limit_deg, 0.05);
        EXPECT_NEAR(x.min_gap_at_limit_mm, o.min_gap_at_limit_mm, 0.01);
      }
      if (o.status != RomLimitStatus::not_reachable) {
        EXPECT_NEAR(x.min_gap_at_start_mm, o.min_gap_at_start_mm, 0.01);
      }
    }
    const RomLimit& r = renumbered_both[k];
    EXPECT_EQ(r.status, o.status);
    if (o.status == RomLimitStatus::limited) {
      EXPECT_EQ(r.limit_deg, o.limit_deg);
      EXPECT_NEAR(r.min_gap_at_limit_mm, o.min_gap_at_limit_mm, 1e-9);
      EXPECT_NEAR((r.contact_mm - o.contact_mm).norm(), 0, 1e-6);
    }
  }
  EXPECT_GE(limited, 3);
}

TEST(RomExact, AtADepthTheFirstTouchComesNoLater) {
  HipModelOptions mo;
  mo.target_triangles = 3000;
  mo.cam_height_mm = 2;
  const HipModel h = make_hip_model(mo);
  RomOptions touch, deep;
  deep.contact_depth_mm = 0.5;
  const auto a = limits_of(h.ball, h.socket, h, mo, touch), b = limits_of(h.ball, h.socket, h, mo, deep);
  int compared = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    SCOPED_TRACE(standard_motions()[k].name);
    if (a[k].status != RomLimitStatus::limited || b[k].status != RomLimitStatus::limited) continue;
    ++compared;
    EXPECT_EQ(b[k].first_contact_deg, a[k].limit_deg);  // the same search at depth 0
    EXPECT_GE(b[k].limit_deg, b[k].first_contact_deg - 0.1);
    EXPECT_LE(b[k].min_gap_at_limit_mm, -deep.contact_depth_mm);  // the depth, by the per-vertex distance
  }
  EXPECT_GE(compared, 3);
}
