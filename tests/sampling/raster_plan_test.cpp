// raster_plan.hpp and its use by the rasteriser. Invariants checked:
//  - on closed, consistently oriented meshes the culled exact-mode map equals the full one node
//    for node (generated head with the COR inside; two nested-layer spheres with the COR inside
//    one and outside both; the same meshes with every face flipped; a real pelvis and femur
//    when ../shared/data is present);
//  - the keep sign follows the COR (inside: leaving faces; outside: entering faces) and flips
//    with the orientation;
//  - an open mesh disables culling and says why; the triangle order lists each kept triangle
//    once.
#include "impinge/sampling/raster_plan.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <utility>
#include <vector>

#include "impinge/anatomy/sphere_fit.hpp"
#include "impinge/io/generated_models.hpp"
#include "impinge/io/mesh_io.hpp"
#include "impinge/sampling/rasterize.hpp"
#include "test_support.hpp"

using namespace impinge;

namespace {
TriangleMesh flipped(TriangleMesh m) {
  m.F.col(1).swap(m.F.col(2));
  return m;
}

/// Culled and full exact-mode maps at precision p: number of nodes that differ.
std::int64_t differing_nodes(const TriangleMesh& m, const Eigen::Vector3d& cor, double p, const RasterPlan& fc) {
  RadialDistanceMap a{EquiangularGrid(p)}, b{EquiangularGrid(p)};
  const SamplingStats sa = rasterize(m, cor, DistanceMode::exact, a);
  const SamplingStats sb = rasterize(m, cor, DistanceMode::exact, b, RasterizeOptions{&fc});
  EXPECT_EQ(sa.nodes_covered, sb.nodes_covered);
  EXPECT_EQ(sb.triangles, sa.triangles);
  std::int64_t diff = 0;
  for (std::int64_t i = 0; i < a.num_nodes(); ++i) diff += a.at(i) != b.at(i);
  return diff;
}
}  // namespace

TEST(RasterPlan, HeadWithTheCorInsideKeepsLeavingFaces) {
  HipModelOptions o;
  o.target_triangles = 3000;
  o.cam_height_mm = 3;
  const HipModel h = make_hip_model(o);
  for (const TriangleMesh& m : {h.ball, flipped(h.ball)}) {
    const RasterPlan fc = plan_rasterization(m, h.cor);
    ASSERT_TRUE(fc.enabled) << fc.reason;
    EXPECT_EQ(fc.boundary_edges, 0);
    EXPECT_EQ(fc.rays_agreeing, fc.rays_checked);
    EXPECT_EQ(std::int64_t(fc.triangle_order.size()), m.F.rows());  // star-shaped: every face leaves
    for (double p : {2.0, 0.5}) EXPECT_EQ(differing_nodes(m, h.cor, p, fc), 0) << "p " << p;
  }
  EXPECT_EQ(plan_rasterization(h.ball, h.cor).keep_sign, -plan_rasterization(flipped(h.ball), h.cor).keep_sign);
}

namespace {
/// Two disjoint closed spheres in one mesh (radius 10 at the origin, 8 at x = 30): a ray from
/// inside the first leaves it, then enters and leaves the second.
TriangleMesh two_spheres() {
  const TriangleMesh a = make_uv_sphere(10, Eigen::Vector3d::Zero(), 48, 24, Eigen::Vector3d(0.3, 0.2, 1).normalized());
  const TriangleMesh b =
      make_uv_sphere(8, Eigen::Vector3d(30, 0, 0), 48, 24, Eigen::Vector3d(0.1, 1, 0.2).normalized());
  TriangleMesh m;
  m.V.resize(a.V.rows() + b.V.rows(), 3);
  m.V << a.V, b.V;
  m.F.resize(a.F.rows() + b.F.rows(), 3);
  m.F << a.F, (b.F.array() + int(a.V.rows())).matrix();
  m.source = "two spheres";
  return m;
}
}  // namespace

TEST(RasterPlan, NestedLayersCullHalfTheFarShellAndKeepTheMap) {
  const TriangleMesh m = two_spheres();
  for (const Eigen::Vector3d& cor : {Eigen::Vector3d(1, 2, -1), Eigen::Vector3d(-25, 3, 1)}) {
    for (const TriangleMesh& mm : {m, flipped(m)}) {
      const RasterPlan fc = plan_rasterization(mm, cor);
      ASSERT_TRUE(fc.enabled) << fc.reason;
      EXPECT_LT(std::int64_t(fc.triangle_order.size()), mm.F.rows());
      for (double p : {2.0, 0.5}) EXPECT_EQ(differing_nodes(mm, cor, p, fc), 0) << "p " << p;
    }
  }
  // Inside the first sphere the kept faces leave the solid; outside both they enter it.
  EXPECT_EQ(plan_rasterization(m, Eigen::Vector3d(1, 2, -1)).keep_sign,
            -plan_rasterization(m, Eigen::Vector3d(-25, 3, 1)).keep_sign);
}

TEST(RasterPlan, OpenMeshDisablesCullingAndSaysWhy) {
  HipModelOptions o;
  o.target_triangles = 1000;
  TriangleMesh m = make_hip_model(o).ball;
  m.F.conservativeResize(m.F.rows() - 1, 3);
  const RasterPlan fc = plan_rasterization(m, make_hip_model(o).cor);
  EXPECT_FALSE(fc.enabled);
  EXPECT_EQ(fc.boundary_edges, 3);
  EXPECT_NE(fc.reason.find("directed edges"), std::string::npos);
  // Disabled: every triangle is listed once, and rasterising with it changes nothing.
  std::vector<std::int32_t> order = fc.triangle_order;
  std::sort(order.begin(), order.end());
  ASSERT_EQ(std::int64_t(order.size()), m.F.rows());
  for (std::size_t k = 0; k < order.size(); ++k) EXPECT_EQ(order[k], std::int32_t(k));
  EXPECT_EQ(differing_nodes(m, make_hip_model(o).cor, 2.0, fc), 0);
}

TEST(RasterPlan, RealBonesCulledMapsEqualFullMaps) {
  const auto real = test::load_real_joint("lhdl-ct");
  if (!real) GTEST_SKIP() << "shared data absent: " << IMPINGE_SHARED_DATA;
  for (const TriangleMesh* m : {&real->femur, &real->pelvis}) {
    const RasterPlan fc = plan_rasterization(*m, real->cor);
    ASSERT_TRUE(fc.enabled) << m->source << ": " << fc.reason;
    EXPECT_EQ(differing_nodes(*m, real->cor, 0.25, fc), 0) << m->source;
  }
}

// A plan made without cones (sample_surface's own, for a map up to 8 MB) has rasterize() make them as it draws
// them: the map of the full (unplanned) rasterisation node for node, and the counts of the plan with cones
// (triangles edge-on, culled, at a pole, across the seam; node tests; nodes covered), on a fresh map, on a dirty
// map reset, and kept under nearer values; the generated hip and, when ../shared/data is there, lhdl-ct.
TEST(RasterPlan, PlanWithoutConesDrawsTheSameMapAndCounts) {
  const HipModel h = make_hip_model(HipModelOptions{});
  std::vector<std::pair<TriangleMesh, Eigen::Vector3d>> meshes{{h.ball, h.cor}, {h.socket, h.cor}};
  if (const auto real = test::load_real_joint("lhdl-ct")) {
    meshes.emplace_back(real->femur, real->cor);
    meshes.emplace_back(real->pelvis, real->cor);
  }
  for (std::size_t k = 0; k < meshes.size(); ++k) {
    const auto& [m, cor] = meshes[k];
    const RasterPlan with = plan_rasterization(m, cor), without = plan_rasterization(m, cor, 8, false);
    EXPECT_TRUE(with.with_cones);
    EXPECT_FALSE(without.with_cones);
    EXPECT_TRUE(without.cones.empty());
    EXPECT_EQ(without.triangle_order, with.triangle_order) << m.source;
    for (double p : {0.5, 0.25}) {
      if (k >= 2 && p < 0.5) continue;  // the real bones at the default spacing only
      RadialDistanceMap full{EquiangularGrid(p)}, a{EquiangularGrid(p)}, b{EquiangularGrid(p)};
      rasterize(m, cor, DistanceMode::exact, full);
      const SamplingStats sa = rasterize(m, cor, DistanceMode::exact, a, RasterizeOptions{&with, true, MapStart::reset});
      std::fill(b.data(), b.data() + b.num_nodes(), 0.5f);  // dirty: the reset must clear it
      const SamplingStats sb =
          rasterize(m, cor, DistanceMode::exact, b, RasterizeOptions{&without, true, MapStart::reset});
      std::int64_t differ = 0;
      for (std::int64_t i = 0; i < full.num_nodes(); ++i) differ += full.at(i) != b.at(i);
      EXPECT_EQ(differ, 0) << m.source << " p=" << p;
      EXPECT_GT(sb.nodes_covered, 1000) << m.source;
      EXPECT_EQ(sb.nodes_covered, sa.nodes_covered) << m.source;
      EXPECT_EQ(sb.node_tests, sa.node_tests) << m.source;
      EXPECT_EQ(sb.triangles, sa.triangles) << m.source;
      EXPECT_EQ(sb.triangles_edge_on, sa.triangles_edge_on) << m.source;
      EXPECT_EQ(sb.triangles_culled, sa.triangles_culled) << m.source;
      EXPECT_EQ(sb.pole_triangles, sa.pole_triangles) << m.source;
      EXPECT_EQ(sb.seam_triangles, sa.seam_triangles) << m.source;
      RadialDistanceMap kept{EquiangularGrid(p)};
      std::fill(kept.data(), kept.data() + kept.num_nodes(), 0.5f);  // nearer than any surface: nothing changes
      EXPECT_EQ(rasterize(m, cor, DistanceMode::exact, kept, RasterizeOptions{&without, true, MapStart::keep}).nodes_covered, 0);
      EXPECT_EQ(std::count(kept.data(), kept.data() + kept.num_nodes(), 0.5f), kept.num_nodes());
    }
  }
}

TEST(RasterPlan, BadInputThrows) {
  HipModelOptions o;
  o.target_triangles = 300;
  const HipModel h = make_hip_model(o);
  EXPECT_THROW(plan_rasterization(h.ball, Eigen::Vector3d(NAN, 0, 0)), std::exception);
  EXPECT_THROW(plan_rasterization(h.ball, h.cor, 0), std::exception);
}
