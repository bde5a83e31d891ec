// Rasterisation (thesis Algorithm 1) against independent oracles:
//  - each pole case (vertex, edge, face; north and south) covers every pole-row node with the
//    exact plane distance;
//  - a closed mesh around the COR covers 100 % of nodes, including triangles across the seam;
//  - exact mode agrees with the naive O(m*n) ray caster (Moller-Trumbore, double) to float
//    precision on the nodes both cover, and the two coverages differ only on silhouette edges;
//  - linear mode stays within its interpolation bound (vertex-distance range of the triangle
//    down to the plane distance) of the exact ray cast;
//  - on a sphere off the COR the map converges to the analytic ray-sphere distance as p shrinks;
//  - row spans give the same map, node for node, as testing every node of each box (random,
//    pole, seam, grid-aligned and row-tangent triangles; real bones), and a plan made for
//    another mesh or COR is refused.
#include "impinge/sampling/rasterize.hpp"

#include <gtest/gtest.h>

#include <random>

#include "impinge/core/error.hpp"
#include "impinge/core/spherical_frame.hpp"
#include "impinge/io/generated_models.hpp"
#include "impinge/sampling/naive_sampling.hpp"
#include "impinge/sampling/raster_plan.hpp"
#include "test_support.hpp"

using namespace impinge;

namespace {
TriangleMesh make_mesh(const std::vector<Eigen::Vector3d>& v, const std::vector<Eigen::Vector3i>& f) {
  TriangleMesh m;
  m.source = "test";
  m.V.resize(static_cast<Eigen::Index>(v.size()), 3);
  for (std::size_t i = 0; i < v.size(); ++i) m.V.row(static_cast<Eigen::Index>(i)) = v[i].transpose();
  m.F.resize(static_cast<Eigen::Index>(f.size()), 3);
  for (std::size_t i = 0; i < f.size(); ++i) m.F.row(static_cast<Eigen::Index>(i)) = f[i].transpose();
  return m;
}

// Plane z = h (h > 0 north, h < 0 south) meshed so that the pole is a vertex, on an edge, or
// inside a face.
TriangleMesh pole_patch(const std::string& kase, double h) {
  if (kase == "vertex")  // fan of 6 triangles around (0, 0, h)
  {
    std::vector<Eigen::Vector3d> v{{0, 0, h}};
    std::vector<Eigen::Vector3i> f;
    for (int k = 0; k < 6; ++k) v.push_back({3 * std::cos(k * kPi / 3 + 0.2), 3 * std::sin(k * kPi / 3 + 0.2), h});
    for (int k = 0; k < 6; ++k) f.push_back({0, 1 + k, 1 + (k + 1) % 6});
    return make_mesh(v, f);
  }
  if (kase == "edge")  // square split along the diagonal through the pole
    return make_mesh({{-2, -2, h}, {2, -2, h}, {2, 2, h}, {-2, 2, h}}, {{0, 1, 2}, {0, 2, 3}});
  return make_mesh({{-1.5, -1, h}, {2.5, -0.7, h}, {-0.4, 2.2, h}}, {{0, 1, 2}});  // face
}

struct Compare {
  std::int64_t both = 0, only_raster = 0, only_naive = 0;
  double max_rel = 0;
};
template <typename M>
Compare compare_maps(const M& raster, const M& naive) {
  Compare c;
  for (std::int64_t i = 0; i < raster.num_nodes(); ++i) {
    const bool a = raster.has_surface(i), b = naive.has_surface(i);
    if (a && b) {
      ++c.both;
      c.max_rel = std::max(c.max_rel, std::abs(double(raster.at(i)) - naive.at(i)) / naive.at(i));
    } else if (a) {
      ++c.only_raster;
    } else if (b) {
      ++c.only_naive;
    }
  }
  return c;
}
}  // namespace

class PoleCase : public ::testing::TestWithParam<std::tuple<std::string, double, DistanceMode>> {};

TEST_P(PoleCase, CoversEveryPoleNodeWithThePlaneDistance) {
  const auto [kase, h, mode] = GetParam();
  const TriangleMesh m = pole_patch(kase, h);
  for (double p : {1.0, 0.5}) {
    RadialDistanceMap map{EquiangularGrid(p)};
    const SamplingStats st = rasterize(m, Eigen::Vector3d::Zero(), mode, map);
    EXPECT_GE(st.pole_triangles, 1);
    const int cols = equiangular_grid_of(map.scheme()).columns();
    const std::int64_t first = h > 0 ? 0 : map.num_nodes() - cols;
    for (int c = 0; c < cols; ++c) {
      ASSERT_TRUE(map.has_surface(first + c)) << kase << " column " << c;
      EXPECT_NEAR(map.at(first + c), std::abs(h), 1e-5) << kase << " column " << c;
    }
    // Everything covered is on the plane: exact and linear must both give d = |h| / |cos phi|
    // within the linear bound (vertex distances span [|h|, |corner|]).
    RadialDistanceMap naive{EquiangularGrid(p)};
    sample_naive(m, Eigen::Vector3d::Zero(), naive);
    const Compare c = compare_maps(map, naive);
    EXPECT_GT(c.both, cols);
    EXPECT_LE(c.only_raster + c.only_naive, cols / 10) << kase;  // boundary nodes only
    if (mode == DistanceMode::exact) {
      EXPECT_LT(c.max_rel, 1e-6);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(AllCases, PoleCase,
                         ::testing::Combine(::testing::Values("vertex", "edge", "face"), ::testing::Values(5.0, -5.0),
                                            ::testing::Values(DistanceMode::exact, DistanceMode::linear)));

TEST(Rasterize, ClosedMeshAroundCorCoversEveryNode) {
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 4; ++trial) {
    // random axis: poles and seams fall on arbitrary triangles; one trial with the z axis
    const Eigen::Vector3d axis =
        trial == 0 ? Eigen::Vector3d(Eigen::Vector3d::UnitZ()) : Eigen::Vector3d(test::random_rotation(rng).col(0));
    const TriangleMesh s = make_uv_sphere(20, Eigen::Vector3d::Zero(), 17 + trial, 9 + trial, axis);
    for (DistanceMode mode : {DistanceMode::exact, DistanceMode::linear}) {
      for (double p : {1.0, 0.5}) {
        RadialDistanceMap map{EquiangularGrid(p)};
        const SamplingStats st = rasterize(s, Eigen::Vector3d(0.3, -0.2, 0.1), mode, map);
        EXPECT_EQ(st.nodes_covered, map.num_nodes()) << "trial " << trial << " p " << p;
        EXPECT_GT(st.seam_triangles, 0);
      }
    }
  }
}

TEST(Rasterize, SeamCrossingTriangleMatchesNaive) {
  // One triangle straddling theta = 0 near the equator.
  const Eigen::Vector3d a = 30 * direction(80 * kDegToRad, -7 * kDegToRad);
  const Eigen::Vector3d b = 32 * direction(95 * kDegToRad, 6 * kDegToRad);
  const Eigen::Vector3d c = 29 * direction(101 * kDegToRad, -3 * kDegToRad);
  TriangleMesh m;
  m.V.resize(3, 3);
  m.V << a.transpose(), b.transpose(), c.transpose();
  m.F.resize(1, 3);
  m.F << 0, 1, 2;
  RadialDistanceMap r{EquiangularGrid(0.5)}, n{EquiangularGrid(0.5)};
  const SamplingStats st = rasterize(m, Eigen::Vector3d::Zero(), DistanceMode::exact, r);
  sample_naive(m, Eigen::Vector3d::Zero(), n);
  EXPECT_EQ(st.seam_triangles, 1);
  const Compare cmp = compare_maps(r, n);
  EXPECT_GT(cmp.both, 300);
  EXPECT_LE(cmp.only_raster + cmp.only_naive, 2);
  EXPECT_LT(cmp.max_rel, 1e-6);
}

TEST(Rasterize, ExactModeAgreesWithNaiveOnNonStarShapedMesh) {
  // A cup (inner and outer shells: two hits per ray) and a bumpy star-shaped head, randomly
  // rotated: the rasteriser must keep the nearest hit like the naive caster.
  std::mt19937_64 rng(3);
  const Eigen::Vector3d cor(1.0, -0.5, 0.7);
  std::vector<TriangleMesh> meshes;
  meshes.push_back(make_cup(25, 31, 110, Eigen::Vector3d::Zero(), Eigen::Vector3d(0.3, 0.5, 0.8), 14, 5));
  meshes.push_back(
      make_radial_surface([](const Eigen::Vector3d& u) { return 20 + 2 * std::sin(3 * u.x()) * std::cos(2 * u.y()); },
                          Eigen::Vector3d::Zero(), 13, 8, Eigen::Vector3d(0.2, -0.9, 0.3)));
  for (const TriangleMesh& m0 : meshes) {
    const TriangleMesh m = test::transformed(m0, test::random_rotation(rng), Eigen::Vector3d::Zero());
    RadialDistanceMapDouble r{EquiangularGrid(2.0)}, n{EquiangularGrid(2.0)};
    rasterize(m, cor, DistanceMode::exact, r);
    sample_naive(m, cor, n);
    const Compare c = compare_maps(r, n);
    EXPECT_GT(c.both, 1000);
    EXPECT_LE(c.only_raster + c.only_naive, c.both / 500);
    EXPECT_LT(c.max_rel, 1e-9);  // double map: both are exact ray-plane distances
  }
}

TEST(Rasterize, LinearModeWithinInterpolationBoundOfExact) {
  // Bound for a node in triangle t: the linear value lies in [min_k |v_k|, max_k |v_k|] and the
  // exact one in [dist(COR, plane of t), max_k |v_k|], so |linear - exact| <= max_k |v_k| -
  // dist(COR, plane). Checked on every node against the triangle the naive caster hits.
  const Eigen::Vector3d cor(0.4, 0.2, -0.3);
  const TriangleMesh m = make_radial_surface([](const Eigen::Vector3d& u) { return 22 + 1.5 * u.x() * u.y(); },
                                             Eigen::Vector3d::Zero(), 15, 9, Eigen::Vector3d(0.5, 0.5, 0.7));
  RadialDistanceMapDouble lin{EquiangularGrid(2.0)}, n{EquiangularGrid(2.0)};
  rasterize(m, cor, DistanceMode::linear, lin);
  std::vector<std::int64_t> tri;
  sample_naive(m, cor, n, &tri);
  std::int64_t checked = 0, outside = 0;
  for (std::int64_t i = 0; i < n.num_nodes(); ++i) {
    ASSERT_TRUE(lin.has_surface(i));
    const auto f = tri[static_cast<std::size_t>(i)];
    ASSERT_GE(f, 0);
    Eigen::Vector3d v[3];
    for (int k = 0; k < 3; ++k) v[k] = m.V.row(m.F(f, k)).transpose() - cor;
    const Eigen::Vector3d nrm = (v[1] - v[0]).cross(v[2] - v[0]).normalized();
    const double bound = std::max({v[0].norm(), v[1].norm(), v[2].norm()}) - std::abs(nrm.dot(v[0]));
    ++checked;
    if (std::abs(lin.at(i) - n.at(i)) > bound + 1e-9) ++outside;
  }
  // Nodes on a shared edge may take the neighbour's (equally valid) interpolant.
  EXPECT_LE(outside, checked / 1000);
}

TEST(Rasterize, ConvergesToAnalyticSphereOffTheCor) {
  // Sphere of radius 22 mm centred 4 mm away from the COR, finely meshed; the map's bilinear
  // interpolation error against the analytic ray-sphere distance must shrink with p.
  const Eigen::Vector3d centre(2.5, -1.5, 2.7);
  const TriangleMesh s = make_uv_sphere(22, centre, 720, 360, Eigen::Vector3d(0.1, 0.3, 0.95));
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> U(0, 1);
  std::vector<Eigen::Vector3d> dirs;
  for (int k = 0; k < 4000; ++k) dirs.push_back(direction(std::acos(2 * U(rng) - 1), 2 * kPi * U(rng)));
  double prev = 1e9;
  for (double p : {4.0, 2.0, 1.0}) {
    const RadialDistanceMap map = rasterize_map(s, Eigen::Vector3d::Zero(), p, DistanceMode::exact);
    double worst = 0;
    for (const auto& u : dirs)
      worst = std::max(worst, std::abs(map.lookup(u) - test::ray_sphere_far(Eigen::Vector3d::Zero(), u, centre, 22)));
    // faceting of a 0.5 deg mesh: sagitta <= 22 (1 - cos 0.5 deg) ~ 0.84 um; interpolation
    // error of a smooth radius function: O(h^2), here below (h^2 / 8) * max|r''| with |r''|<~8 mm
    const double h = p * kDegToRad;
    EXPECT_LT(worst, h * h / 8 * 8.0 + 2e-3) << "p=" << p;
    EXPECT_LT(worst, prev) << "p=" << p;
    prev = worst;
  }
}

namespace {
/// Triangles that stress row spans: random sizes from 0.05 to 80 deg anywhere (near the poles
/// and across the seam included), corners on node directions (edges through nodes), edges along
/// meridians, and edges whose great circle is tangent to a row (where a span's end moves by the
/// square root of any rounding).
TriangleMesh span_stress_mesh(double p, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> U(0, 1);
  const double h = p * kDegToRad;
  std::vector<Eigen::Vector3d> v;
  std::vector<Eigen::Vector3i> f;
  auto add = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    const int n = static_cast<int>(v.size());
    v.push_back(a), v.push_back(b), v.push_back(c);
    f.push_back({n, n + 1, n + 2});
  };
  auto radius = [&] { return 20 + 20 * U(rng); };
  for (int t = 0; t < 300; ++t) {
    const double size = std::pow(10.0, -1.3 + 3.2 * U(rng)) * kDegToRad;  // 0.05 .. 80 deg
    double phi0 = std::acos(2 * U(rng) - 1), theta0 = 2 * kPi * U(rng);
    if (t % 10 == 1) phi0 = 0.3 * size * U(rng);        // at the north pole
    if (t % 10 == 2) phi0 = kPi - 0.3 * size * U(rng);  // at the south pole
    if (t % 10 == 3) theta0 = 0.2 * size * (U(rng) - 0.5);  // across the seam
    const Eigen::Vector3d c = direction(phi0, theta0);
    const Eigen::Vector3d e1 = c.unitOrthogonal(), e2 = c.cross(e1);
    Eigen::Vector3d k[3];
    for (auto& x : k) {
      const double a = 2 * kPi * U(rng), s = size * (0.3 + U(rng));
      x = radius() * (c + std::tan(s) * (std::cos(a) * e1 + std::sin(a) * e2)).normalized();
    }
    if (t % 10 == 4)  // corners on node directions
      for (auto& x : k) {
        const double ph = std::round(std::acos(x.normalized().z()) / h) * h;
        const double th = std::round(std::atan2(x.y(), x.x()) / h) * h;
        x = radius() * direction(ph, th);
      }
    if (t % 10 == 5) {  // an edge along a meridian
      const double th = std::round(theta0 / h) * h;
      k[0] = radius() * direction(std::max(phi0 - size, 0.01), th);
      k[1] = radius() * direction(std::min(phi0 + size, kPi - 0.01), th);
    }
    if (t % 10 == 6 || t % 10 == 7) {
      // An edge on the great circle tangent to row r at azimuth th: normal at polar angle
      // pi/2 - phi_r (north of the equator) or its mirror, azimuth th + pi.
      const double phr = std::round(phi0 / h) * h, th = std::round(theta0 / h) * h;
      const Eigen::Vector3d n = direction(phr < kPi / 2 ? kPi / 2 + phr : phr - kPi / 2, th);
      const Eigen::Vector3d touch = direction(phr, th);
      const Eigen::Vector3d along = n.cross(touch).normalized();
      k[0] = radius() * (touch + std::tan(size) * along).normalized();
      k[1] = radius() * (touch - std::tan(size) * (0.5 + U(rng)) * along).normalized();
      k[2] = radius() * (touch + (t % 10 == 6 ? 1 : -1) * std::tan(size) * (touch.cross(along))).normalized();
    }
    add(k[0], k[1], k[2]);
  }
  TriangleMesh m = make_mesh(v, f);
  m.source = "span stress mesh";
  return m;
}

template <typename M>
std::int64_t nodes_not_identical(const M& a, const M& b) {
  std::int64_t n = 0;
  for (std::int64_t i = 0; i < a.num_nodes(); ++i) n += !(a.at(i) == b.at(i));
  return n;
}
}  // namespace

TEST(Rasterize, RowSpansGiveTheSameMapAsWholeBoxes) {
  // Row spans only skip nodes the full box test rejects: the maps must be identical, node for
  // node, in float and double, with and without a culling plan, and test fewer nodes.
  std::mt19937_64 rng(17);
  for (double p : {2.0, 0.5, 0.1, 0.75, 0.3}) {
    const TriangleMesh m = span_stress_mesh(p, rng);
    const Eigen::Vector3d cor = Eigen::Vector3d::Zero();
    const RasterPlan plan = plan_rasterization(m, cor);  // open mesh: disabled, all cones
    ASSERT_FALSE(plan.enabled);
    RadialDistanceMap box{EquiangularGrid(p)}, span{EquiangularGrid(p)}, planned{EquiangularGrid(p)};
    const SamplingStats sb = rasterize(m, cor, DistanceMode::exact, box, RasterizeOptions{nullptr, false});
    const SamplingStats ss = rasterize(m, cor, DistanceMode::exact, span);
    const SamplingStats sp = rasterize(m, cor, DistanceMode::exact, planned, RasterizeOptions{&plan});
    EXPECT_EQ(nodes_not_identical(box, span), 0) << "p=" << p;
    EXPECT_EQ(nodes_not_identical(box, planned), 0) << "p=" << p;
    EXPECT_EQ(sb.nodes_covered, ss.nodes_covered);
    EXPECT_EQ(sb.nodes_covered, sp.nodes_covered);
    EXPECT_GT(sb.nodes_covered, 1000);
    EXPECT_LT(ss.node_tests, sb.node_tests);
    EXPECT_GT(ss.pole_triangles, 0);
    EXPECT_GT(ss.seam_triangles, 0);
    RadialDistanceMapDouble box_d{EquiangularGrid(p)}, span_d{EquiangularGrid(p)};
    rasterize(m, cor, DistanceMode::exact, box_d, RasterizeOptions{nullptr, false});
    rasterize(m, cor, DistanceMode::exact, span_d);
    EXPECT_EQ(nodes_not_identical(box_d, span_d), 0) << "p=" << p;
  }
}

TEST(Rasterize, MapStartResetEqualsAFreshMapAndKeepKeepsNearerValues) {
  // MapStart::reset (with a plan: reset in bands of rows fused with the drawing) must give the
  // map of a fresh one, whatever was in the map before; MapStart::keep must keep nearer values.
  std::mt19937_64 rng(5);
  const HipModel h = make_hip_model(HipModelOptions{});
  const TriangleMesh stress = span_stress_mesh(0.1, rng);  // pole cones reach over many bands
  for (const TriangleMesh* m : {&stress, &h.socket}) {
    const Eigen::Vector3d cor = m == &stress ? Eigen::Vector3d::Zero() : h.cor;
    const RasterPlan plan = plan_rasterization(*m, cor);
    for (double p : {0.1, 0.75}) {  // 51 bands of rows and one (float maps)
      RadialDistanceMap fresh{EquiangularGrid(p)};
      const SamplingStats sf = rasterize(*m, cor, DistanceMode::exact, fresh, RasterizeOptions{&plan});
      ASSERT_GT(sf.nodes_covered, 1000) << m->source;
      RadialDistanceMap dirty{EquiangularGrid(p)}, dirty_unplanned{EquiangularGrid(p)};
      std::fill(dirty.data(), dirty.data() + dirty.num_nodes(), 0.5f);  // nearer than any surface
      std::fill(dirty_unplanned.data(), dirty_unplanned.data() + dirty_unplanned.num_nodes(), 0.5f);
      const SamplingStats sr = rasterize(*m, cor, DistanceMode::exact, dirty, RasterizeOptions{&plan, true, MapStart::reset});
      EXPECT_EQ(nodes_not_identical(fresh, dirty), 0) << m->source << " p=" << p;
      EXPECT_EQ(sr.nodes_covered, sf.nodes_covered);
      EXPECT_EQ(sr.node_tests, sf.node_tests);
      rasterize(*m, cor, DistanceMode::exact, dirty_unplanned, RasterizeOptions{nullptr, true, MapStart::reset});
      RadialDistanceMap fresh_unplanned{EquiangularGrid(p)};
      rasterize(*m, cor, DistanceMode::exact, fresh_unplanned);
      EXPECT_EQ(nodes_not_identical(fresh_unplanned, dirty_unplanned), 0) << m->source << " p=" << p;
      RadialDistanceMapDouble fresh_d{EquiangularGrid(p)}, dirty_d{EquiangularGrid(p)};
      rasterize(*m, cor, DistanceMode::exact, fresh_d, RasterizeOptions{&plan});
      std::fill(dirty_d.data(), dirty_d.data() + dirty_d.num_nodes(), 0.5);
      rasterize(*m, cor, DistanceMode::exact, dirty_d, RasterizeOptions{&plan, true, MapStart::reset});
      EXPECT_EQ(nodes_not_identical(fresh_d, dirty_d), 0) << m->source << " p=" << p;
      // keep: the 0.5 mm values are nearer than every hit, so nothing changes.
      RadialDistanceMap kept{EquiangularGrid(p)};
      std::fill(kept.data(), kept.data() + kept.num_nodes(), 0.5f);
      const SamplingStats sk = rasterize(*m, cor, DistanceMode::exact, kept, RasterizeOptions{&plan, true, MapStart::keep});
      EXPECT_EQ(sk.nodes_covered, 0);
      EXPECT_EQ(std::count(kept.data(), kept.data() + kept.num_nodes(), 0.5f), kept.num_nodes());
    }
  }
}

TEST(Rasterize, RowSpansOnRealBonesGiveTheSameMap) {
  const auto real = test::load_real_joint("lhdl-ct");
  if (!real) GTEST_SKIP() << "shared data absent: " << IMPINGE_SHARED_DATA;
  for (const TriangleMesh* m : {&real->femur, &real->pelvis}) {
    const RasterPlan plan = plan_rasterization(*m, real->cor);
    RadialDistanceMap box{EquiangularGrid(0.1)}, span{EquiangularGrid(0.1)};
    rasterize(*m, real->cor, DistanceMode::exact, box, RasterizeOptions{&plan, false});
    const SamplingStats st = rasterize(*m, real->cor, DistanceMode::exact, span, RasterizeOptions{&plan});
    EXPECT_EQ(nodes_not_identical(box, span), 0) << m->source;
    EXPECT_GT(st.nodes_covered, box.num_nodes() / 10) << m->source;
  }
}

TEST(Rasterize, PlanOfAnotherMeshOrCorIsRefused) {
  const HipModel h = make_hip_model(HipModelOptions{});
  const RasterPlan plan = plan_rasterization(h.socket, h.cor);
  RadialDistanceMap map{EquiangularGrid(2.0)};
  EXPECT_NO_THROW(rasterize(h.socket, h.cor, DistanceMode::exact, map, RasterizeOptions{&plan}));
  EXPECT_THROW(rasterize(h.ball, h.cor, DistanceMode::exact, map, RasterizeOptions{&plan}), Error);
  EXPECT_THROW(rasterize(h.socket, Eigen::Vector3d(h.cor + Eigen::Vector3d(0, 0, 1e-9)), DistanceMode::exact, map, RasterizeOptions{&plan}),
               Error);
  TriangleMesh moved = h.socket;
  moved.V(7, 1) += 1e-12;  // one coordinate, one ulp-scale edit
  EXPECT_THROW(rasterize(moved, h.cor, DistanceMode::exact, map, RasterizeOptions{&plan}), Error);
  // Linear mode does not use the plan's cones (the thesis' algorithm on every triangle).
  EXPECT_NO_THROW(rasterize(h.ball, h.cor, DistanceMode::linear, map, RasterizeOptions{&plan}));
}

TEST(Rasterize, NodesThroughSharedVerticesAreCovered) {
  // A UV sphere of 5 deg about the COR has every vertex on a node direction at 1, 0.5 and 0.25 deg,
  // and its meridian edges along node columns. The edge functions of the triangles around a vertex
  // are rounded independently; without the edge tolerance (kEdgeAngleTolerance) 40 nodes at 0.5 deg
  // were covered by no triangle. The mesh is closed about the COR: every node must be covered, in
  // both modes, float and double, with and without a culling plan, in any orientation of the axis.
  for (const Eigen::Vector3d axis : {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX()}) {
    const TriangleMesh m = make_uv_sphere(22, Eigen::Vector3d::Zero(), 72, 36, axis);
    const RasterPlan plan = plan_rasterization(m, Eigen::Vector3d::Zero());
    for (double p : {1.0, 0.5, 0.25})
      for (DistanceMode mode : {DistanceMode::exact, DistanceMode::linear})
        for (const RasterPlan* pl : {static_cast<const RasterPlan*>(nullptr), &plan}) {
          RadialDistanceMap f{EquiangularGrid(p)};
          RadialDistanceMapDouble d{EquiangularGrid(p)};
          rasterize(m, Eigen::Vector3d::Zero(), mode, f, RasterizeOptions{pl});
          rasterize(m, Eigen::Vector3d::Zero(), mode, d, RasterizeOptions{pl});
          EXPECT_EQ(f.nodes_covered(), f.num_nodes()) << "p=" << p << " " << to_string(mode) << " axis " << axis.x();
          EXPECT_EQ(d.nodes_covered(), d.num_nodes()) << "p=" << p << " " << to_string(mode) << " axis " << axis.x();
        }
  }
}
