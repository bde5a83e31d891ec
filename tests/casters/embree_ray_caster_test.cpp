// embree_ray_caster.hpp. Invariants checked against independent oracles:
//  - first_hit equals CGAL's exact first intersection (ExactReference) to float precision on
//    random directions from the COR of a generated hip socket (not star-shaped: nearest hit);
//  - the rtcIntersect1 and 8-wide packet scans give the same gaps, equal to the exact radial gap;
//  - fill_map equals the naive O(m n) ray cast (sample_naive) node by node;
//  - a build without Embree throws a clear error;
//  - Embree's error codes become errors naming what was being built; out of memory is OutOfMemory (issue 80).
#include "impinge/casters/embree_ray_caster.hpp"
#include "impinge/detection/detection.hpp"

#include <gtest/gtest.h>

#include <random>
#if __has_include(<embree3/rtcore.h>)
#include <embree3/rtcore.h>
#endif

#include "impinge/casters/exact_reference.hpp"
#include "impinge/core/error.hpp"
#include "impinge/io/generated_models.hpp"
#include "impinge/sampling/naive_sampling.hpp"

using namespace impinge;

namespace {
HipModel hip() {
  HipModelOptions o;
  o.target_triangles = 3000;
  return make_hip_model(o);
}
}  // namespace

TEST(EmbreeRayCaster, FirstHitMatchesTheExactReference) {
  if (!have_embree() || !have_exact_reference()) GTEST_SKIP() << "Embree or CGAL missing in this build";
  const HipModel h = hip();
  const EmbreeRayCaster caster(h.socket, h.cor);
  const ExactReference exact(h.socket);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g;
  int hits = 0;
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3d u = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
    const float d = caster.first_hit(float(u.x()), float(u.y()), float(u.z()));
    const auto e = exact.first_hit(h.cor, u);
    ASSERT_EQ(std::isfinite(d), e.has_value()) << i;
    if (!e) continue;
    ++hits;
    EXPECT_NEAR(d, *e, 1e-4 * *e) << i;
  }
  EXPECT_GT(hits, 500);
}

TEST(EmbreeRayCaster, ScansAgreeWithEachOtherAndTheExactRadialGap) {
  if (!have_embree() || !have_exact_reference()) GTEST_SKIP() << "Embree or CGAL missing in this build";
  const HipModel h = hip();
  const EmbreeRayCaster caster(h.socket, h.cor);
  const ExactReference exact(h.socket);
  const Vertices P = h.ball.V.rowwise() - h.cor.transpose();
  const ScanSet set = make_scan_set(P, std::vector<std::uint8_t>(std::size_t(P.rows()), 1));
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.2, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Vector3d t(0.5, -0.3, 1.0);
  std::vector<float> g1(std::size_t(set.size())), g8(std::size_t(set.size()));
  scan_gaps_embree(caster, set, R, t, ScanSide::inside, g1.data(), false);
  scan_gaps_embree(caster, set, R, t, ScanSide::inside, g8.data(), true);
  int compared = 0;
  for (std::int64_t j = 0; j < set.size(); ++j) {
    ASSERT_EQ(std::isnan(g1[j]), std::isnan(g8[j])) << j;
    const Eigen::Vector3d q = R * Eigen::Vector3d(set.x[j], set.y[j], set.z[j]) + t;
    const auto e = exact.first_hit(h.cor, q.normalized());
    ASSERT_EQ(e.has_value(), !std::isnan(g1[j])) << j;
    if (!e) continue;
    ++compared;
    EXPECT_NEAR(g1[j], g8[j], 1e-4);
    EXPECT_NEAR(g1[j], *e - q.norm(), 1e-3) << j;
  }
  EXPECT_GT(compared, 100);
}

TEST(EmbreeRayCaster, FillMapEqualsTheNaiveRayCast) {
  if (!have_embree()) GTEST_SKIP() << "Embree missing in this build";
  const HipModel h = hip();
  const EmbreeRayCaster caster(h.socket, h.cor);
  RadialDistanceMap a(make_scheme("equiangular", 3)), b(make_scheme("equiangular", 3));
  const std::int64_t covered = caster.fill_map(a);
  sample_naive(h.socket, h.cor, b);
  EXPECT_EQ(covered, b.nodes_covered());
  int mismatched = 0;
  for (std::int64_t i = 0; i < a.num_nodes(); ++i) {
    if (a.has_surface(i) != b.has_surface(i)) {
      ++mismatched;  // a ray through an edge or a vertex: the two casters may round differently
      continue;
    }
    if (a.has_surface(i)) {
      EXPECT_NEAR(a.at(i), b.at(i), 1e-3) << i;
    }
  }
  EXPECT_LE(mismatched, 2);
}

TEST(EmbreeRayCaster, WithoutEmbreeTheErrorSaysSo) {
  if (have_embree()) GTEST_SKIP() << "Embree present";
  const HipModel h = hip();
  try {
    EmbreeRayCaster c(h.socket, h.cor);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no Embree"), std::string::npos);
  }
}

// Issue 80: running out of memory inside Embree (RTC_ERROR_OUT_OF_MEMORY) was "embree: ... failed (RTCError 4)",
// followed by the anatomical-neutral hint. It is OutOfMemory saying so and naming what was being built; any other
// code an Error naming the code and its meaning.
TEST(EmbreeRayCaster, ErrorCodesNameWhatWasBuiltAndOutOfMemoryIsSaidSo) {
  const std::string what = "building the ray-casting hierarchy of femur.ply (70422 triangles)";
  bool out_of_memory = false;
  try {
    throw_embree_error(4, what);
  } catch (const OutOfMemory& e) {
    out_of_memory = true;
    EXPECT_EQ(std::string(e.what()), "out of memory " + what);
  } catch (const Error& e) {
    ADD_FAILURE() << e.what();
  }
  EXPECT_TRUE(out_of_memory);
  for (const auto& [code, name] : std::vector<std::pair<int, std::string>>{
           {1, "unknown"}, {2, "invalid argument"}, {3, "invalid operation"}, {5, "unsupported CPU"}, {6, "cancelled"},
           {99, "not an Embree error code"}}) {
    try {
      throw_embree_error(code, what);
    } catch (const OutOfMemory&) {
      ADD_FAILURE() << code << " is not out of memory";
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()),
                "embree: " + what + " failed (RTCError " + std::to_string(code) + ": " + name + ")");
    }
  }
#if __has_include(<embree3/rtcore.h>)
  static_assert(RTC_ERROR_OUT_OF_MEMORY == 4 && RTC_ERROR_CANCELLED == 6);  // the codes the mapping names
#endif
}
