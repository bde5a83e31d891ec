// clinical/resection.hpp's measures against closed forms: the enclosed volume of a cube (exact) and of a sphere's
// inscribed polyhedron (below 4/3 pi r^3, within its tessellation error), unchanged by winding or placement; the
// femoral neck's least diameter of the generated hip, whose neck is a cylinder of known radius, along an axis found
// here independently (the centroid direction of the neck's vertices). The plan itself: session/plan_run_test.cpp.
#include "impinge/clinical/resection.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "impinge/io/generated_models.hpp"
#include "test_support.hpp"

namespace impinge {
namespace {

TriangleMesh cube(double side) {
  TriangleMesh m;
  m.V.resize(8, 3);
  for (int i = 0; i < 8; ++i) m.V.row(i) << side * (i & 1), side * ((i >> 1) & 1), side * ((i >> 2) & 1);
  m.F.resize(12, 3);
  m.F << 0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5;
  return m;
}

// A UV sphere of radius r: every vertex on the sphere (an inscribed polyhedron).
TriangleMesh sphere(double r, int rings, int segments) {
  TriangleMesh m;
  m.V.resize(2 + (rings - 1) * segments, 3);
  m.V.row(0) << 0, 0, r;
  for (int i = 1; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const double t = M_PI * i / rings, p = 2 * M_PI * j / segments;
      m.V.row(1 + (i - 1) * segments + j) << r * std::sin(t) * std::cos(p), r * std::sin(t) * std::sin(p),
          r * std::cos(t);
    }
  const int south = static_cast<int>(m.V.rows()) - 1;
  m.V.row(south) << 0, 0, -r;
  std::vector<Eigen::Vector3i> f;
  auto at = [&](int i, int j) { return 1 + (i - 1) * segments + (j % segments); };
  for (int j = 0; j < segments; ++j) f.emplace_back(0, at(1, j), at(1, j + 1));
  for (int i = 1; i + 1 < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      f.emplace_back(at(i, j), at(i + 1, j), at(i + 1, j + 1));
      f.emplace_back(at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
  for (int j = 0; j < segments; ++j) f.emplace_back(south, at(rings - 1, j + 1), at(rings - 1, j));
  m.F.resize(static_cast<Eigen::Index>(f.size()), 3);
  for (std::size_t k = 0; k < f.size(); ++k) m.F.row(static_cast<Eigen::Index>(k)) = f[k].transpose();
  return m;
}

TEST(Resection, EnclosedVolumeIsTheClosedForms) {
  TriangleMesh c = cube(10);
  EXPECT_NEAR(enclosed_volume(c.V, c.F), 1000, 1e-9);
  c.V.rowwise() += Eigen::RowVector3d(123, -45, 6).eval();  // placement does not matter
  EXPECT_NEAR(enclosed_volume(c.V, c.F), 1000, 1e-9);
  c.F.col(1).swap(c.F.col(2));  // nor the winding (the absolute value)
  EXPECT_NEAR(enclosed_volume(c.V, c.F), 1000, 1e-9);
  const double r = 22, exact = 4.0 / 3.0 * M_PI * r * r * r;
  const TriangleMesh s = sphere(r, 90, 180);
  const double v = enclosed_volume(s.V, s.F);
  EXPECT_LT(v, exact);  // inscribed
  EXPECT_GT(v, 0.998 * exact);
}

TEST(Resection, NeckDiameterOfACylindricalNeck) {
  const HipModelOptions g;
  const HipModel h = make_hip_model(g);
  // The neck axis, found here: the centroid direction (from the head centre) of the vertices on the neck's wall.
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int n = 0;
  for (Eigen::Index i = 0; i < h.ball.V.rows(); ++i) {
    const Eigen::Vector3d p = h.ball.V.row(i).transpose() - h.cor;
    if (p.norm() > g.head_radius_mm + 2 && p.norm() < g.neck_length_mm - 5) sum += p, ++n;
  }
  ASSERT_GT(n, 50);
  const Eigen::Vector3d towards_head = -sum.normalized();
  const double d = neck_diameter_mm(h.ball.V, h.ball.F, h.cor, g.head_radius_mm, towards_head);
  EXPECT_NEAR(d, 2 * g.neck_radius_mm, 0.2);
  // No neck (a sphere alone): no diameter.
  const TriangleMesh s = sphere(g.head_radius_mm, 40, 80);
  EXPECT_TRUE(std::isnan(neck_diameter_mm(s.V, s.F, Eigen::Vector3d::Zero(), g.head_radius_mm, towards_head)));
}

}  // namespace
}  // namespace impinge
