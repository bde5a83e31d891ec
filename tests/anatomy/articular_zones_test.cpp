// The articular zones (issue 29, item 2). Invariants:
// - on a generated hip whose geometry is known in closed form (a spherical head of 22 mm, a
//   cylindrical neck, a concentric cup of inner radius 24.5 mm, outer 30.5 mm, coverage 100 deg about
//   a known axis), found through find_acetabulum as on a real pelvis: every head vertex is on the
//   head's joint surface and every neck vertex beyond the acetabular shell is not; every inner cup
//   vertex deeper than 2.5 mm below the rim is on the lunate surface, and no outer-wall vertex and no
//   inner vertex within 1.5 mm of the rim is;
// - to_string spells every class.
#include "impinge/anatomy/articular_zones.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "impinge/io/generated_models.hpp"

using namespace impinge;

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
  const ArticularZones z = find_articular_zones(h.ball, head, h.socket, A);
  EXPECT_EQ(z.head_tolerance_mm, 1.0);
  // Femur: the head (distance r_head) in; the neck beyond the acetabular shell out.
  const double shell = r_in + z.lunate_tolerance_mm + (A.sphere.centre - h.cor).norm();
  int head_vertices = 0, neck_vertices = 0;
  for (Eigen::Index i = 0; i < h.ball.V.rows(); ++i) {
    const double d = (h.ball.V.row(i).transpose() - h.cor).norm();
    if (std::abs(d - r_head) < 1e-6) {
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

TEST(ArticularZones, EveryClassHasItsSpelling) {
  EXPECT_STREQ(to_string(ContactClass::none), "");
  EXPECT_STREQ(to_string(ContactClass::articular), "articular");
  EXPECT_STREQ(to_string(ContactClass::intra_articular_impingement), "intra_articular_impingement");
  EXPECT_STREQ(to_string(ContactClass::extra_articular_impingement), "extra_articular_impingement");
}
