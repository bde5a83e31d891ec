// The articular zones (issue 29, item 2). Invariants:
// - on a generated hip whose geometry is known in closed form (a spherical head of 22 mm, a
//   cylindrical neck, a concentric cup of inner radius 24.5 mm, outer 30.5 mm, coverage 100 deg about
//   a known axis), found through find_acetabulum as on a real pelvis: every head vertex is on the
//   head's joint surface and every neck vertex beyond the acetabular shell is not; every inner cup
//   vertex deeper than 2.5 mm below the rim is on the lunate surface, and no outer-wall vertex and no
//   inner vertex within 1.5 mm of the rim is;
// - the head-neck junction (issue 81) of the generated femur, a sphere of radius r on a cylindrical neck of radius
//   a, lies where the neck's surface a / sin(t) comes within r + tol of the centre, t = asin(a / (r + tol)), at
//   every azimuth (to the vertex spacing); with a 3 mm cam at the junction no vertex more than 1 mm outside the
//   head sphere is on the head side, and every vertex on the sphere away from the cam is;
// - to_string spells every class and zone.
#include "impinge/anatomy/articular_zones.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "impinge/io/generated_models.hpp"

using namespace impinge;

namespace {
// The generated femur's head-neck clock: centre the COR, axis from the neck towards the head
// (make_hip_model's neck points (0.80, 0.25, -0.55) from the head), 12 and 3 any two perpendiculars.
ClockFace generated_clock(const HipModel& h) {
  ClockFace k;
  k.centre = h.cor;
  k.axis = -Eigen::Vector3d(0.80, 0.25, -0.55).normalized();
  k.twelve = (Eigen::Vector3d::UnitZ() - k.axis.z() * k.axis).normalized();
  k.three = k.axis.cross(k.twelve);
  return k;
}
}  // namespace

TEST(ArticularZones, GeneratedHipZonesMatchItsClosedForm) {
  HipModelOptions o;
  o.target_triangles = 12000;
  const HipModel h = make_hip_model(o);
  const double r_head = o.head_radius_mm, r_in = r_head + o.cartilage_gap_mm, r_out = r_in + o.cup_wall_mm;
  const Eigen::Vector3d pole = Eigen::Vector3d(-0.65, -0.2, 0.73).normalized();  // make_hip_model's cup axis
  // A pelvic frame for the clock only (RAS working frame: X anterior +y, Y superior +z, Z right +x).
  AnatomicalFrame frame;
  frame.axes.col(0) = Eigen::Vector3d::UnitY();
  frame.axes.col(1) = Eigen::Vector3d::UnitZ();
  frame.axes.col(2) = Eigen::Vector3d::UnitX();
  const Acetabulum A = find_acetabulum(h.socket, h.cor, r_head, frame);
  SphereFitResult head;
  head.centre = h.cor;
  head.radius = r_head;
  head.rms_residual = 0.05;
  const ArticularZones z = find_articular_zones(h.ball, head, generated_clock(h), h.socket, A);
  EXPECT_EQ(z.head_tolerance_mm, 1.0);
  // Femur: the head (distance r_head) in, but for the row of vertices next to the junction (read to this coarse
  // mesh's spacing, conservatively: 5 deg here); the neck beyond the acetabular shell out.
  const double shell = r_in + z.lunate_tolerance_mm + (A.sphere.centre - h.cor).norm();
  const Eigen::Vector3d down_neck = Eigen::Vector3d(0.80, 0.25, -0.55).normalized();
  const double sphere_starts = std::asin(o.neck_radius_mm / r_head) * 180 / M_PI;
  int head_vertices = 0, neck_vertices = 0;
  for (Eigen::Index i = 0; i < h.ball.V.rows(); ++i) {
    const double d = (h.ball.V.row(i).transpose() - h.cor).norm();
    const double from_neck = std::acos((h.ball.V.row(i).transpose() - h.cor).normalized().dot(down_neck)) * 180 / M_PI;
    if (std::abs(d - r_head) < 1e-6 && from_neck > sphere_starts + 5) {
      ++head_vertices;
      EXPECT_TRUE(z.femur[std::size_t(i)]) << "head vertex " << i;
    } else if (d > shell + 0.5) {
      ++neck_vertices;
      EXPECT_FALSE(z.femur[std::size_t(i)]) << "neck vertex " << i << " at " << d << " mm";
    }
  }
  EXPECT_GT(head_vertices, 100);
  EXPECT_GT(neck_vertices, 100);
  // Pelvis: the depth below the rim of a point at angle a from the pole is r (cos a - cos coverage).
  const double cos_rim = std::cos(o.cup_coverage_deg * M_PI / 180);
  int deep = 0, outer = 0, near_rim = 0;
  for (Eigen::Index i = 0; i < h.socket.V.rows(); ++i) {
    const Eigen::Vector3d p = h.socket.V.row(i).transpose() - h.cor;
    const double r = p.norm(), depth = r * (p.normalized().dot(pole) - cos_rim);
    const bool inner = std::abs(r - r_in) < 1e-6, wall = std::abs(r - r_out) < 1e-6;
    if (wall) {
      ++outer;
      EXPECT_FALSE(z.pelvis[std::size_t(i)]) << "outer wall vertex " << i;
    }
    if (inner && depth > 2.5) {
      ++deep;
      EXPECT_TRUE(z.pelvis[std::size_t(i)]) << "inner vertex " << i << " " << depth << " mm below the rim";
    }
    if (inner && depth < 1.5) {
      ++near_rim;
      EXPECT_FALSE(z.pelvis[std::size_t(i)]) << "rim vertex " << i << " " << depth << " mm below the rim";
    }
  }
  EXPECT_GT(deep, 100);
  EXPECT_GT(outer, 100);
  EXPECT_GT(near_rim, 10);
}

TEST(ArticularZones, HeadNeckJunctionWhereTheNeckComesWithinTheHeadsReach) {
  HipModelOptions o;
  o.target_triangles = 60000;
  const HipModel h = make_hip_model(o);
  const double r = o.head_radius_mm, a = o.neck_radius_mm, tol = head_junction_tolerance_mm(0.05);
  EXPECT_EQ(tol, 0.5);
  const FemoralHeadZone z = find_femoral_head_zone(h.ball, generated_clock(h), r, tol, 1.0);
  const double exact = std::asin(a / (r + tol)) * 180 / M_PI;
  for (double j : z.junction_deg) {
    EXPECT_GE(j, exact - 1e-6);
    EXPECT_LE(j, exact + 2.0);  // the vertices' spacing along the meridian
  }
  // Every vertex on the sphere is on the head side (the sphere starts at asin(a / r) > exact); every neck vertex
  // farther than r + tol is not.
  int head = 0, neck = 0;
  for (Eigen::Index i = 0; i < h.ball.V.rows(); ++i) {
    const Eigen::Vector3d v = h.ball.V.row(i).transpose();
    const double d = (v - h.cor).norm();
    if (std::abs(d - r) < 1e-6) {
      ++head;
      EXPECT_TRUE(z.on_head_side(v)) << i;
    }
    if (d > r + tol + 0.5) {
      ++neck;
      EXPECT_FALSE(z.on_head_side(v)) << i;
    }
  }
  EXPECT_GT(head, 1000);
  EXPECT_GT(neck, 1000);
}

TEST(ArticularZones, AThreeMillimetreCamIsNeverTheHead) {
  HipModelOptions o;
  o.target_triangles = 60000;
  o.cam_height_mm = 3;
  const HipModel h = make_hip_model(o);
  const double r = o.head_radius_mm;
  const FemoralHeadZone z = find_femoral_head_zone(h.ball, generated_clock(h), r, 0.5, 1.0);
  int cam = 0;
  for (Eigen::Index i = 0; i < h.ball.V.rows(); ++i) {
    const Eigen::Vector3d v = h.ball.V.row(i).transpose();
    if ((v - h.cor).norm() > r + 1) {
      ++cam;
      EXPECT_FALSE(z.on_head_side(v)) << "vertex " << i;
    }
    EXPECT_EQ(z.contains(v), (v - h.cor).norm() <= z.reach_mm && z.on_head_side(v));
  }
  EXPECT_GT(cam, 100);
  // The zones name it: the cam's vertices are the junction's or the neck's, never the head's.
  for (Eigen::Index i = 0; i < h.ball.V.rows(); ++i) {
    const Eigen::Vector3d v = h.ball.V.row(i).transpose();
    if ((v - h.cor).norm() > r + 1) EXPECT_NE(femoral_zone(z, v), FemoralZone::head);
  }
}

TEST(ArticularZones, EveryClassHasItsSpelling) {
  EXPECT_STREQ(to_string(FemoralZone::head_neck_junction), "head_neck_junction");
  EXPECT_STREQ(to_string(FemoralZone::trochanter), "trochanter");
  EXPECT_STREQ(to_string(PelvicZone::aiis), "aiis");
  EXPECT_STREQ(to_string(PelvicZone::none), "");
  EXPECT_STREQ(to_string(ContactClass::none), "");
  EXPECT_STREQ(to_string(ContactClass::articular), "articular");
  EXPECT_STREQ(to_string(ContactClass::intra_articular_impingement), "intra_articular_impingement");
  EXPECT_STREQ(to_string(ContactClass::extra_articular_impingement), "extra_articular_impingement");
}
