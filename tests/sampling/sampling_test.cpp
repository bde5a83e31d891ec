// Filling maps of any scheme: accelerated helix sampling (rasterise an equiangular map,
// resample it at the helix points) agrees with casting every helix point's ray within the
// bilinear resampling bound; the automatic method picks rasterisation for equiangular maps and
// resampling otherwise; rasterising into a helix map is refused with a clear error.
#include "impinge/sampling/sampling.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include "impinge/casters/first_hit_caster.hpp"
#include "impinge/core/error.hpp"
#include "impinge/core/spherical_frame.hpp"
#include "impinge/io/generated_models.hpp"
#include "impinge/sampling/rasterize.hpp"
#include "impinge/schemes/helix_scheme.hpp"

using namespace impinge;

TEST(Sampling, AcceleratedHelixAgreesWithRayCasting) {
  // Sphere of radius 22 mm, 3 mm off the COR, 1-deg facets (32k triangles).
  const Eigen::Vector3d centre(1.5, -2.0, 1.6);
  const TriangleMesh s = make_uv_sphere(22, centre, 180, 90, Eigen::Vector3d(0.2, 0.1, 0.97));
  const auto helix = make_scheme("helix", 40);
  RadialDistanceMapDouble fast(helix), cast(helix);
  SamplingOptions o;
  const SamplingReport rep = sample_surface(s, Eigen::Vector3d::Zero(), o, fast);
  EXPECT_EQ(rep.method, SamplingMethod::resample);
  EXPECT_GT(rep.resample_precision_deg, 0);
  o.method = SamplingMethod::ray_cast;
  sample_surface(s, Eigen::Vector3d::Zero(), o, cast);
  // Bound: bilinear interpolation over a cell of diagonal h = sqrt(2) p of a radius function
  // whose second derivative is below 2 (offset + offset^2 / r) ~ 7 mm; plus twice the facet sagitta.
  const double h = std::sqrt(2.0) * rep.resample_precision_deg * kDegToRad;
  const double bound = h * h / 8 * 7 + 2 * 22 * (1 - std::cos(std::sqrt(2.0) * kPi / 180));
  double worst = 0;
  for (std::int64_t i = 0; i < fast.num_nodes(); ++i) {
    ASSERT_TRUE(fast.has_surface(i) && cast.has_surface(i)) << i;
    worst = std::max(worst, std::abs(fast.at(i) - cast.at(i)));
  }
  EXPECT_LT(worst, bound);
  EXPECT_GT(worst, 0);  // the two methods are different computations
}

TEST(Sampling, BvhRayCastGivesTheNaiveFirstHitsForEveryScheme) {
  // Exact node values through a BVH (issue 12): every registered scheme's nodes get the first hit
  // of the naive ray cast (every triangle, double precision) to within Embree's float precision,
  // on an off-centre faceted sphere.
  if (!FirstHitCaster::available()) GTEST_SKIP() << "no ray caster in this build";
  const TriangleMesh sphere = make_uv_sphere(22, Eigen::Vector3d(1.5, -2.0, 1.6), 72, 36, Eigen::Vector3d(0.2, 0.1, 0.97));
  for (const auto& [name, unit] : scheme_names()) {
    SCOPED_TRACE(name);
    const auto scheme = make_scheme(name, resolution_for_spacing(name, 4.0));
    RadialDistanceMapDouble bvh(scheme), naive(scheme);
    SamplingOptions o;
    o.method = SamplingMethod::ray_cast_bvh;
    const SamplingReport rep = sample_surface(sphere, Eigen::Vector3d::Zero(), o, bvh);
    EXPECT_EQ(rep.method, SamplingMethod::ray_cast_bvh);
    o.method = SamplingMethod::ray_cast;
    sample_surface(sphere, Eigen::Vector3d::Zero(), o, naive);
    double worst = 0;
    for (std::int64_t i = 0; i < bvh.num_nodes(); ++i) {
      ASSERT_TRUE(bvh.has_surface(i) && naive.has_surface(i)) << i;
      worst = std::max(worst, std::abs(bvh.at(i) - naive.at(i)));
    }
    EXPECT_LT(worst, 1e-4);
  }
  EXPECT_EQ(parse_sampling_method("ray-cast-bvh"), SamplingMethod::ray_cast_bvh);
}

TEST(Sampling, MethodChoiceAndErrors) {
  const TriangleMesh s = make_uv_sphere(20, Eigen::Vector3d::Zero(), 24, 12);
  RadialDistanceMap eq{EquiangularGrid(5)};
  const SamplingReport r = sample_surface(s, Eigen::Vector3d(0.1, 0.2, 0.3), SamplingOptions{}, eq);
  EXPECT_EQ(r.method, SamplingMethod::rasterize);
  EXPECT_EQ(r.nodes_covered, eq.num_nodes());
  RadialDistanceMap hx{HelixScheme(20)};
  SamplingOptions o;
  o.method = SamplingMethod::rasterize;
  EXPECT_THROW(sample_surface(s, Eigen::Vector3d::Zero(), o, hx), Error);
  o.method = SamplingMethod::automatic;
  EXPECT_EQ(sample_surface(s, Eigen::Vector3d(0.1, 0.2, 0.3), o, hx).nodes_covered, hx.num_nodes());
  EXPECT_THROW(parse_sampling_method("fast"), Error);
  EXPECT_THROW(make_scheme("no-such-scheme", 8), Error);
  o.resample_oversampling = 0;  // a temporary map coarser than matched: refused, naming the mesh
  EXPECT_THROW(sample_surface(s, Eigen::Vector3d::Zero(), o, hx), Error);
  // Oversampling 2 resamples from a grid at half the matched precision.
  o.resample_oversampling = 1;
  const double p1 = sample_surface(s, Eigen::Vector3d::Zero(), o, hx).resample_precision_deg;
  o.resample_oversampling = 2;
  const double p2 = sample_surface(s, Eigen::Vector3d::Zero(), o, hx).resample_precision_deg;
  EXPECT_NEAR(p2, p1 / 2, 0.05 * p1);  // both rounded to some 180 / n
}

TEST(Sampling, RasterizingIntoAUsedMapGivesAFreshMap) {
  // sample_surface fills the map: +inf where no surface, whatever it held before (with a plan,
  // where the reset is fused with the drawing, and without). A rasterisation refused for a
  // helix map leaves that map untouched.
  const HipModel h = make_hip_model(HipModelOptions{});
  for (const bool cull : {true, false}) {
    SamplingOptions o;
    o.cull_faces = cull;
    RadialDistanceMap fresh{EquiangularGrid(1)}, used{EquiangularGrid(1)};
    sample_surface(h.socket, h.cor, o, fresh);
    std::fill(used.data(), used.data() + used.num_nodes(), 0.25f);
    const SamplingReport r = sample_surface(h.socket, h.cor, o, used);
    ASSERT_GT(r.nodes_covered, 0);
    EXPECT_LT(r.nodes_covered, used.num_nodes());  // the socket leaves directions without surface
    for (std::int64_t i = 0; i < used.num_nodes(); ++i) ASSERT_EQ(used.at(i), fresh.at(i)) << "node " << i;
  }
  RadialDistanceMap hx{HelixScheme(20)};
  std::fill(hx.data(), hx.data() + hx.num_nodes(), 0.25f);
  EXPECT_THROW(rasterize(h.socket, h.cor, DistanceMode::exact, hx, RasterizeOptions{nullptr, true, MapStart::reset}), Error);
  EXPECT_EQ(std::count(hx.data(), hx.data() + hx.num_nodes(), 0.25f), hx.num_nodes());
}
