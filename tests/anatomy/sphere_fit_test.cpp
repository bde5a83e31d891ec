// Sphere fits against known spheres: exact points give the exact sphere; a noisy partial cap
// (30 % of the sphere, sigma = 0.05 mm) gives the centre within 0.05 mm and the radius within
// 0.03 mm with the geometric fit; the automatic head fit finds a generated head's centre and
// radius despite the neck and a cam bump; too few / coplanar points throw.
#include "impinge/anatomy/sphere_fit.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>

#include "impinge/core/error.hpp"
#include "impinge/core/spherical_frame.hpp"
#include "impinge/io/generated_models.hpp"
#include "test_support.hpp"

using namespace impinge;
using PointMatrix = Eigen::Matrix<double, Eigen::Dynamic, 3>;

namespace {
PointMatrix cap_points(const Eigen::Vector3d& c, double r, double max_phi, double sigma, int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(0, 1);
  std::normal_distribution<double> N(0, sigma > 0 ? sigma : 1);
  PointMatrix P(n, 3);
  for (int i = 0; i < n; ++i) {
    const double z = 1 - U(rng) * (1 - std::cos(max_phi));
    const double phi = std::acos(z), th = 2 * kPi * U(rng);
    const double rr = r + (sigma > 0 ? N(rng) : 0.0);
    P.row(i) = (c + rr * direction(phi, th)).transpose();
  }
  return P;
}
}  // namespace

TEST(SphereFit, ExactPointsGiveExactSphere) {
  const Eigen::Vector3d c(12, -4, 100);
  const PointMatrix P = cap_points(c, 23, kPi, 0, 200, 1);
  for (const SphereFitResult& f : {fit_sphere_algebraic(P), fit_sphere_geometric(P)}) {
    EXPECT_LT((f.centre - c).norm(), 1e-8);
    EXPECT_NEAR(f.radius, 23, 1e-8);
    EXPECT_LT(f.rms_residual, 1e-8);
  }
}

TEST(SphereFit, NoisyPartialCapRecovered) {
  const Eigen::Vector3d c(-30, 55, 7);
  // a cap of half-angle 66 deg covers (1 - cos 66)/2 = 30 % of the sphere
  const PointMatrix P = cap_points(c, 22, 66 * kDegToRad, 0.05, 3000, 2);
  const SphereFitResult g = fit_sphere_geometric(P);
  EXPECT_TRUE(g.converged);
  EXPECT_LT((g.centre - c).norm(), 0.05);
  EXPECT_NEAR(g.radius, 22, 0.03);
  EXPECT_NEAR(g.rms_residual, 0.05, 0.01);
}

TEST(SphereFit, AutomaticHeadFitOnGeneratedFemur) {
  for (double cam : {0.0, 3.0}) {
    HipModelOptions o;
    o.target_triangles = 12000;
    o.cam_height_mm = cam;
    const HipModel h = make_hip_model(o);
    const SphereFitResult f = fit_femoral_head(h.ball);
    // a cam bump leaves some biased inliers on its flanks: allow 0.1 mm there
    EXPECT_LT((f.centre - h.cor).norm(), cam > 0 ? 0.1 : 0.02) << "cam " << cam;
    EXPECT_NEAR(f.radius, o.head_radius_mm, 0.05);
    EXPECT_GT(f.points_used, 1000);
  }
}

TEST(SphereFit, HeadFitStopsBeforeItsFixedPointOnlyWhenAsked) {
  HipModelOptions o;
  o.target_triangles = 12000;
  o.cam_height_mm = 3;
  const HipModel h = make_hip_model(o);
  const SphereFitResult whole = fit_femoral_head(h.ball);
  // Asked to go on: the same sphere as without the question, bit for bit.
  int asked = 0;
  const SphereFitResult on = fit_femoral_head(h.ball, {}, [&](const SphereFitResult&) { return ++asked > 0; });
  EXPECT_EQ(asked, 1);
  EXPECT_EQ(on.centre, whole.centre);
  EXPECT_EQ(on.radius, whole.radius);
  EXPECT_EQ(on.points_used, whole.points_used);
  // Told to stop: the sphere it was asked about, after the refinement rounds, still on the head.
  SphereFitResult seen;
  const SphereFitResult stopped = fit_femoral_head(h.ball, {}, [&](const SphereFitResult& s) {
    seen = s;
    return false;
  });
  EXPECT_EQ(stopped.centre, seen.centre);
  EXPECT_EQ(stopped.radius, seen.radius);
  EXPECT_EQ(stopped.iterations, HeadFitOptions{}.refinement_rounds);
  EXPECT_LT((stopped.centre - h.cor).norm(), 0.1);
  EXPECT_NEAR(stopped.radius, o.head_radius_mm, 0.05);
}

TEST(SphereFit, RegionFitAndErrors) {
  HipModelOptions o;
  const HipModel h = make_hip_model(o);
  const SphereFitResult f = fit_sphere_in_region(h.ball, h.cor, o.head_radius_mm * 1.01);
  EXPECT_LT((f.centre - h.cor).norm(), 0.05);
  EXPECT_THROW(fit_sphere_in_region(h.ball, h.cor + Eigen::Vector3d(500, 0, 0), 1), Error);
  EXPECT_THROW(fit_sphere_algebraic(PointMatrix::Zero(3, 3)), Error);
  PointMatrix flat(10, 3);
  for (int i = 0; i < 10; ++i) flat.row(i) << i, i * i, 0;
  EXPECT_THROW(fit_sphere_algebraic(flat), Error);
}

// fit_sphere_to_surface (issue 81): the sphere of a surface, not of its vertices. Oracles: the analytic sphere of a
// finely tessellated UV sphere and cup (whose flat triangles lie within h^2 / (8 r) of it), and the same mesh split
// in four or renumbered (the same surface: the same points, so the same sphere to rounding).
TEST(SurfaceSphereFit, ABallAndACupGiveTheirSpheres) {
  const Eigen::Vector3d c(10, -20, 30);
  // 0.25 deg-ish facets: 360 x 180 on r = 22 mm, chords 0.38 mm, sagitta < 0.001 mm.
  const TriangleMesh ball = make_uv_sphere(22, c, 360, 180, Eigen::Vector3d(0.2, 0.3, 0.93).normalized());
  const SurfaceSphereFit b = fit_sphere_to_surface(ball, c + Eigen::Vector3d(0.8, -0.5, 0.3), 21.2, 1.5, 0.7,
                                                   SurfaceSide::convex, "test ball");
  EXPECT_LT((b.sphere.centre - c).norm(), 1e-3);
  EXPECT_NEAR(b.sphere.radius, 22, 2e-3);
  EXPECT_NEAR(b.area_in_band_mm2, 4 * M_PI * 22 * 22, 0.01 * 4 * M_PI * 22 * 22);
  // A cup (inner 25, outer 30 mm, 80 deg): the inner surface faces the centre; the outer one, 5 mm out, weighs nothing.
  const TriangleMesh cup = make_cup(25, 30, 80, c, Eigen::Vector3d::UnitZ(), 360, 120);
  const SurfaceSphereFit k =
      fit_sphere_to_surface(cup, c + Eigen::Vector3d(-0.6, 0.4, 0.9), 24.3, 1.5, 0.7, SurfaceSide::concave, "test cup");
  EXPECT_LT((k.sphere.centre - c).norm(), 2e-3);
  EXPECT_NEAR(k.sphere.radius, 25, 2e-3);
  // The wrong side: the ball seen as a socket has no surface facing its centre.
  EXPECT_THROW(fit_sphere_to_surface(ball, c, 22, 1.5, 0.7, SurfaceSide::concave, "test ball"), Error);
}

TEST(SurfaceSphereFit, SplittingRenumberingOrTurningTheMeshInsideOutMovesNothing) {
  // A bumpy, coarse head (1.2-2.5 mm facets, edges in (0.5, 32] mm where the quadrature points coincide exactly).
  const Eigen::Vector3d c(60, -20, 30);
  const TriangleMesh head = make_radial_surface(
      [](const Eigen::Vector3d& u) { return 22 + 0.4 * u.x() * u.y() + 0.3 * u.z() * u.z(); }, c, 96, 48);
  const auto fit = [&](const TriangleMesh& m) {
    return fit_sphere_to_surface(m, c + Eigen::Vector3d(0.5, 0.2, -0.4), 21.5, 1.0, 0.7, SurfaceSide::convex, "head")
        .sphere;
  };
  const SphereFitResult a = fit(head);
  TriangleMesh inside_out = head;
  inside_out.F.col(1).swap(inside_out.F.col(2));
  for (const TriangleMesh& m : {split_in_four(head), test::renumbered(head, 7), inside_out}) {
    const SphereFitResult b = fit(m);
    EXPECT_LT((b.centre - a.centre).norm(), 1e-6) << m.source;
    EXPECT_NEAR(b.radius, a.radius, 1e-6) << m.source;
  }
  // The vertices' fit moves when the mesh is split (its midpoints lie inside the surface's curvature).
  const SphereFitResult v = fit_sphere_geometric(head.V), vs = fit_sphere_geometric(split_in_four(head).V);
  EXPECT_GT(std::abs(vs.radius - v.radius), 1e-3);
}

TEST(SurfaceSphereFit, BadInputsAreErrorsNamingTheMesh) {
  const TriangleMesh ball = make_uv_sphere(22, Eigen::Vector3d::Zero(), 48, 24);
  auto message = [](const std::function<void()>& f) { return test::error_of(f); };
  // Far from any surface, a radius that is not positive, a start that is not finite, no triangles.
  EXPECT_NE(message([&] { fit_sphere_to_surface(ball, Eigen::Vector3d(500, 0, 0), 5, 1, 0.7, SurfaceSide::convex, "x"); })
                .find("no surface within 1 mm of the sphere faces it"),
            std::string::npos);
  for (const double r : {0.0, -3.0, std::nan("")})
    EXPECT_THROW(fit_sphere_to_surface(ball, Eigen::Vector3d::Zero(), r, 1, 0.7, SurfaceSide::convex, "x"), Error);
  TriangleMesh none = ball;
  none.F.resize(0, 3);
  none.source = "empty.ply";
  EXPECT_NE(message([&] { fit_sphere_to_surface(none, Eigen::Vector3d::Zero(), 22, 1, 0.7, SurfaceSide::convex, "x"); })
                .find("empty.ply: x: no surface"),
            std::string::npos);
}
