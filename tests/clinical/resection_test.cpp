// clinical/resection.hpp's measures against closed forms: the enclosed volume of a cube (exact) and of a sphere's
// inscribed polyhedron (below 4/3 pi r^3, within its tessellation error), unchanged by winding or placement; the
// femoral neck's least diameter of the generated hip, whose neck is a cylinder of known radius, along an axis found
// here independently (the centroid direction of the neck's vertices). plan_resection against CGAL (below); the plan
// through the session: session/plan_run_test.cpp.
#include "impinge/clinical/resection.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <limits>

#include "impinge/casters/exact_reference.hpp"
#include "impinge/clinical/hip_joint.hpp"
#include "impinge/clinical/rom.hpp"
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

// plan_resection itself, not through a session: the generated hip with a 3 mm cam, flexed 8 deg past where its
// bones first meet. The plan's resected femur keeps at least the clearance from the pelvis at every target pose by
// CGAL's exact closest distances, both ways (resected femur vertices to the pelvis; pelvis vertices to the posed
// resected femur), with no vertex inside the other bone by CGAL's ray parity: an oracle independent of the plan's own
// distance queries. Only the femur is cut (the default), no vertex deeper than the safety depth, none of the protected
// (articular) ones at all (there are some: the check is not empty), and a pelvis-only plan leaves the femur whole.
TEST(PlanResection, TheResectedFemurKeepsTheClearanceByCgal) {
  if (!have_exact_reference()) GTEST_SKIP() << "needs CGAL";
  HipModelOptions g;
  g.target_triangles = 12000;
  g.cam_height_mm = 3;
  const HipModel h = make_hip_model(g);
  HipJointOptions o;
  o.neutral = Neutral::scan;
  o.joint.scheme = make_scheme("equiangular", 0.5);
  o.joint.distances = true;
  o.joint.distance_reach_mm = 3;
  SphereFitResult head;
  head.centre = h.cor;
  head.radius = g.head_radius_mm;
  const HipJoint hip(h.ball, h.socket, Side::right, head, Landmarks{}, o);
  const RomBaseline base = rom_baseline(hip, hip.femur_rotation({}), RomOptions{});
  // Where the bones first meet in flexion (least Euclidean distance of both scans below 0), by 1 deg.
  auto least = [&](double flexion) {
    const PoseResult r = hip.detect(PoseAngles{flexion, 0, 0});
    return std::fmin(r.ball.min_distance_mm, r.socket.min_distance_mm);
  };
  double meet = std::nan("");
  for (double f = 0; f <= 130 && std::isnan(meet); f += 1)
    if (least(f) < 0) meet = f;
  ASSERT_FALSE(std::isnan(meet)) << "the cam never meets the rim in flexion";
  ResectionTarget target;
  target.name = "flexion";
  target.angle_deg = meet + 8;
  for (double f = 0; f <= target.angle_deg; f += 1) {
    target.poses.push_back(PoseAngles{f, 0, 0});
    target.theta_deg.push_back(f);
  }
  ResectionOptions ro;
  ro.clearance_mm = 0.3;
  ro.safety_depth_mm = 5;
  const ResectionPlan plan = plan_resection(hip, {target}, base, ro);
  ASSERT_EQ(plan.targets.size(), 1u);
  EXPECT_TRUE(plan.targets[0].reachable) << plan.targets[0].note;
  EXPECT_TRUE(plan.femur.allowed);
  EXPECT_FALSE(plan.pelvis.allowed);
  EXPECT_GT(plan.femur.volume_mm3, 0);
  const auto n = static_cast<std::size_t>(h.ball.V.rows());
  ASSERT_EQ(plan.femur.depth_mm.size(), n);
  std::int64_t cut = 0, protected_count = 0;
  for (const std::uint8_t p : plan.femur.protected_vertex) protected_count += p;
  EXPECT_GT(protected_count, 0) << "the head's joint surface is protected";
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_GE(plan.femur.depth_mm[i], 0) << i;
    EXPECT_LE(plan.femur.depth_mm[i], ro.safety_depth_mm + 1e-9) << i;
    if (!plan.femur.protected_vertex.empty() && plan.femur.protected_vertex[i]) {
      EXPECT_EQ(plan.femur.depth_mm[i], 0) << i;
    }
    cut += plan.femur.depth_mm[i] > 0;
  }
  EXPECT_GT(cut, 0);
  for (const double d : plan.pelvis.depth_mm) EXPECT_EQ(d, 0);
  // The oracle, in the working frame (scan neutral: the joint frame's axes, its origin the COR).
  const ExactReference pelvis(h.socket);
  const Eigen::Vector3d cor = hip.to_working(Eigen::Vector3d::Zero());
  const auto inside = test::inside_by_parity;
  const double allowed = ro.clearance_mm - 2 * ro.tolerance_mm;
  double worst = std::numeric_limits<double>::infinity();
  std::vector<std::size_t> checked;  // every second pose, and always the target pose itself (the last)
  for (std::size_t k = 0; k < target.poses.size(); k += 2) checked.push_back(k);
  if (checked.back() + 1 != target.poses.size()) checked.push_back(target.poses.size() - 1);
  for (const std::size_t k : checked) {
    const FemurPose pose = hip.femur_pose(target.poses[k]);
    TriangleMesh femur = h.ball;
    for (Eigen::Index i = 0; i < femur.V.rows(); ++i)
      femur.V.row(i) = (cor + pose.R * plan.femur.resected.row(i).transpose() + pose.t).transpose();
    for (Eigen::Index i = 0; i < femur.V.rows(); ++i) {
      const Eigen::Vector3d q = femur.V.row(i).transpose();
      const double d = pelvis.closest_distance(q);
      worst = std::min(worst, d);
      ASSERT_GE(d, allowed) << "femur vertex " << i << " at flexion " << target.poses[k].flexion_deg;
      if (d < 3) {
        ASSERT_FALSE(inside(pelvis, q)) << "femur vertex " << i << " inside the pelvis";
      }
    }
    const ExactReference posed(femur);
    for (Eigen::Index i = 0; i < h.socket.V.rows(); ++i) {
      const Eigen::Vector3d q = h.socket.V.row(i).transpose();
      if ((q - cor).norm() > g.neck_length_mm + 20) continue;  // far from the femur's near end
      const double d = posed.closest_distance(q);
      worst = std::min(worst, d);
      ASSERT_GE(d, allowed) << "pelvis vertex " << i << " at flexion " << target.poses[k].flexion_deg;
      if (d < 3) {
        ASSERT_FALSE(inside(posed, q)) << "pelvis vertex " << i << " inside the femur";
      }
    }
  }
  std::cout << "bones first meet at flexion " << meet << " deg; plan to " << target.angle_deg << ": "
            << plan.femur.volume_mm3 << " mm^3, deepest " << plan.femur.deepest_cut_mm << " mm; least distance "
            << worst << " mm (clearance " << ro.clearance_mm << ")\n";
  // The pelvis alone: the femur stays whole.
  ro.bones = ResectBones::pelvis;
  const ResectionPlan rim = plan_resection(hip, {target}, base, ro);
  EXPECT_TRUE(rim.pelvis.allowed);
  EXPECT_FALSE(rim.femur.allowed);
  for (const double d : rim.femur.depth_mm) EXPECT_EQ(d, 0);
  EXPECT_GT(rim.pelvis.volume_mm3, 0);
}

}  // namespace
}  // namespace impinge
