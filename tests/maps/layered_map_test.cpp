// Layered radial maps (issue 14): every crossing of a node's ray, and the signed radial distance to the
// nearest boundary read from them. Invariants, each against an independent oracle:
//  - signed_radial_distance follows its definition on hand-made crossing lists;
//  - the crossings of a ray agree with CGAL's all_intersections (double) and with the analytic
//    entry and exit of spheres, also for rays exactly through shared vertices (a cup whose shells
//    share an angular grid: a shared edge must give one crossing, not two or none);
//  - the interpolated signed distance agrees with the analytic one of two disjoint spheres seen from
//    outside and of a sphere seen from inside, within the interpolation error, away from silhouettes
//    (where exact_needed says so);
//  - a mesh that is not closed (a hemisphere) answers by the side of the surface the ray meets;
//  - the occupancy bits cover every radius at which the analytic solid lies;
//  - bad layer counts are refused by name; a real pelvis gives the CGAL crossing counts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "impinge/casters/exact_reference.hpp"
#include "impinge/casters/first_hit_caster.hpp"
#include "impinge/core/error.hpp"
#include "impinge/io/generated_models.hpp"
#include "impinge/maps/layered_map.hpp"
#include "impinge/sampling/layered_sampling.hpp"
#include "impinge/schemes/sampling_scheme.hpp"
#include "test_support.hpp"

using namespace impinge;

namespace {
struct Sphere {
  Eigen::Vector3d c;
  double r;
};
// Analytic crossings of the ray t u (t >= 0, |u| = 1) from the origin with disjoint spheres.
std::vector<RayCrossing> analytic_crossings(const std::vector<Sphere>& spheres, const Eigen::Vector3d& u) {
  std::vector<RayCrossing> out;
  for (const Sphere& s : spheres) {
    const double b = u.dot(s.c), disc = b * b - (s.c.squaredNorm() - s.r * s.r);
    if (disc <= 0) continue;
    const double t0 = b - std::sqrt(disc), t1 = b + std::sqrt(disc);
    if (t0 >= 0) out.push_back({t0, true});
    if (t1 >= 0) out.push_back({t1, false});
  }
  std::sort(out.begin(), out.end(), [](const RayCrossing& a, const RayCrossing& b) { return a.distance_mm < b.distance_mm; });
  return out;
}
// True when the ray towards q passes within `margin` of a sphere's silhouette (where the tessellated
// sphere and the true one differ most, and an interpolation straddles the silhouette).
bool near_silhouette(const std::vector<Sphere>& spheres, const Eigen::Vector3d& q, double margin) {
  const Eigen::Vector3d u = q.normalized();
  for (const Sphere& s : spheres)
    if (std::abs((s.c - s.c.dot(u) * u).norm() - s.r) < margin) return true;
  return false;
}
double analytic_signed(const std::vector<Sphere>& spheres, const Eigen::Vector3d& q) {
  const auto c = analytic_crossings(spheres, q.normalized());
  return signed_radial_distance(c.data(), static_cast<int>(c.size()), true, q.norm());
}
}  // namespace

TEST(SignedRadialDistance, FollowsItsDefinition) {
  const RayCrossing wall[] = {{20, true}, {25, false}};  // a wall from 20 to 25 mm, seen from outside
  EXPECT_DOUBLE_EQ(signed_radial_distance(wall, 2, true, 10), 10);   // before it: outside, 10 to the entry
  EXPECT_DOUBLE_EQ(signed_radial_distance(wall, 2, true, 21), -1);   // inside, 1 past the entry
  EXPECT_DOUBLE_EQ(signed_radial_distance(wall, 2, true, 24.5), -0.5);
  EXPECT_DOUBLE_EQ(signed_radial_distance(wall, 2, true, 31), 6);    // beyond: outside
  EXPECT_TRUE(std::isnan(signed_radial_distance(wall, 2, false, 31)));  // beyond a truncated list: unknown
  EXPECT_DOUBLE_EQ(signed_radial_distance(wall, 2, false, 21), -1);
  const RayCrossing head[] = {{25, false}};  // from inside a head of radius 25
  EXPECT_DOUBLE_EQ(signed_radial_distance(head, 1, true, 20), -5);
  EXPECT_DOUBLE_EQ(signed_radial_distance(head, 1, true, 27), 2);
  EXPECT_TRUE(std::isinf(signed_radial_distance(nullptr, 0, true, 5)));
}

TEST(LayeredMap, RefusesBadLayerCounts) {
  const auto scheme = make_scheme("equiangular", 5.0);
  for (int layers : {0, -1, LayeredMap::kMaxLayers + 1}) {
    try {
      LayeredMap m(scheme, layers);
      ADD_FAILURE() << layers;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("layers"), std::string::npos) << e.what();
    }
  }
}

TEST(LayeredMap, CrossingsOfTwoSpheresAgreeWithCgalAndTheAnalyticOnes) {
  if (!FirstHitCaster::available() || !have_exact_reference()) GTEST_SKIP() << "no ray caster in this build";
  const std::vector<Sphere> spheres = {{{30, 2, -1}, 10}, {{62, 5, 3}, 8}};
  const TriangleMesh mesh = test::concatenated(make_uv_sphere(10, spheres[0].c, 256, 128, Eigen::Vector3d(0.3, 0.5, 0.81).normalized()),
                                         make_uv_sphere(8, spheres[1].c, 256, 128));
  const FirstHitCaster caster(mesh, Eigen::Vector3d::Zero());
  const ExactReference ref(mesh);
  std::mt19937_64 rng(11);
  std::normal_distribution<double> g;
  std::vector<RayCrossing> got;
  int four = 0;
  for (int k = 0; k < 3000; ++k) {
    // Directions towards the spheres (within 25 deg of +x).
    const Eigen::Vector3d u = (Eigen::Vector3d(1, 0, 0) + 0.25 * Eigen::Vector3d(0, g(rng), g(rng))).normalized();
    caster.crossings(u, got);
    const auto cgal = ref.all_hits(Eigen::Vector3d::Zero(), u);
    const auto exact = analytic_crossings(spheres, u);
    ASSERT_EQ(got.size(), cgal.size()) << k;
    for (std::size_t j = 0; j < got.size(); ++j) {
      EXPECT_NEAR(got[j].distance_mm, cgal[j].first, 1e-3) << k;
      EXPECT_EQ(got[j].entering, cgal[j].second < 0) << k;
    }
    // The tessellation is within 0.01 mm of the spheres; a ray grazing one within that may differ.
    if (got.size() == exact.size()) {
      for (std::size_t j = 0; j < got.size(); ++j) {
        EXPECT_NEAR(got[j].distance_mm, exact[j].distance_mm, 0.05) << k;
        EXPECT_EQ(got[j].entering, exact[j].entering) << k;
      }
    }
    four += got.size() == 4;
  }
  EXPECT_GT(four, 100);  // rays through both spheres were tried
}

TEST(LayeredMap, RaysThroughSharedVerticesGiveOneCrossingPerSurface) {
  if (!FirstHitCaster::available()) GTEST_SKIP() << "no ray caster in this build";
  const Eigen::Vector3d cor(10, -20, 30), axis = Eigen::Vector3d(-0.5, 0.1, 0.86).normalized();
  // Shells at 25 and 30 mm on the same angular grid: every ray through an outer vertex passes exactly
  // through an inner vertex too, where six triangles meet.
  const TriangleMesh cup = make_cup(25, 30, 100, cor, axis, 360, 100);
  const FirstHitCaster caster(cup, cor);
  std::vector<RayCrossing> c;
  int checked = 0;
  for (Eigen::Index i = 0; i < cup.V.rows(); i += 7) {
    const Eigen::Vector3d p = cup.V.row(i).transpose() - cor;
    const double polar = std::acos(std::clamp(p.normalized().dot(axis), -1.0, 1.0)) * 180 / M_PI;
    if (p.norm() < 29 || polar > 99.9) continue;
    caster.crossings(p, c);
    ++checked;
    ASSERT_EQ(c.size(), 2u) << "vertex " << i << " at " << polar << " deg";
    EXPECT_TRUE(c[0].entering);
    EXPECT_NEAR(c[0].distance_mm, 25, 1e-4);
    EXPECT_FALSE(c[1].entering);
    EXPECT_NEAR(c[1].distance_mm, 30, 1e-4);
  }
  EXPECT_GT(checked, 3000);
}

TEST(LayeredMap, InterpolatedSignedDistanceAgreesWithTheAnalyticOne) {
  if (!FirstHitCaster::available()) GTEST_SKIP() << "no ray caster in this build";
  const std::vector<Sphere> spheres = {{{30, 2, -1}, 10}, {{62, 5, 3}, 8}};
  const TriangleMesh mesh = test::concatenated(make_uv_sphere(10, spheres[0].c, 256, 128), make_uv_sphere(8, spheres[1].c, 256, 128));
  const FirstHitCaster caster(mesh, Eigen::Vector3d::Zero());
  const ExactReference ref(mesh);
  for (const char* name : {"equiangular", "helix", "healpix"}) {
    SCOPED_TRACE(name);
    LayeredMap map(make_scheme(name, resolution_for_spacing(name, 0.25)), 4);
    const LayeredSamplingReport rep = sample_layered_map(map, caster);
    EXPECT_EQ(rep.nodes_truncated, 0);
    EXPECT_EQ(rep.max_crossings, 4);
    EXPECT_EQ(rep.nodes_not_alternating, 0);
    EXPECT_EQ(map.bytes(), static_cast<std::size_t>(map.num_nodes()) * (4 * 4 + 1));
    std::mt19937_64 rng(5);
    std::normal_distribution<double> g;
    std::vector<double> x, y, z;
    for (int k = 0; k < 20000; ++k) {
      const Eigen::Vector3d q = Eigen::Vector3d(45, 3, 1) + Eigen::Vector3d(14 * g(rng), 5 * g(rng), 5 * g(rng));
      x.push_back(q.x()), y.push_back(q.y()), z.push_back(q.z());
    }
    std::vector<double> s(x.size());
    std::vector<std::uint8_t> exact_needed(x.size());
    map.signed_distance_many_soa(x.data(), y.data(), z.data(), static_cast<std::int64_t>(x.size()), s.data(),
                                 exact_needed.data());
    int compared = 0, inside = 0, flagged = 0, exact_checked = 0;
    for (std::size_t j = 0; j < x.size(); ++j) {
      const Eigen::Vector3d q(x[j], y[j], z[j]);
      const double want = analytic_signed(spheres, q);
      if (exact_needed[j]) {
        ++flagged;
        // Where the map says so, the exact answer from the caster is the mesh's (CGAL's crossings).
        const double e = signed_radial_distance_exact(caster, q);
        std::vector<RayCrossing> c;
        for (const auto& [t, cosine] : ref.all_hits(Eigen::Vector3d::Zero(), q.normalized())) c.push_back({t, cosine < 0});
        const double oracle = signed_radial_distance(c.data(), static_cast<int>(c.size()), true, q.norm());
        if (std::isfinite(oracle)) {
          EXPECT_NEAR(e, oracle, 1e-3) << q.transpose();
          ++exact_checked;
        }
        continue;
      }
      if (near_silhouette(spheres, q, 2.0)) continue;
      if (!std::isfinite(want)) {
        EXPECT_FALSE(s[j] < 0.1) << q.transpose();  // no sphere along this ray: apart
        continue;
      }
      ASSERT_TRUE(std::isfinite(s[j])) << q.transpose() << " want " << want;
      EXPECT_NEAR(s[j], want, 0.1) << q.transpose();
      ++compared;
      inside += want < 0;
    }
    EXPECT_GT(compared, 5000);
    EXPECT_GT(inside, 500);
    EXPECT_GT(flagged, 10);
    EXPECT_GT(exact_checked, 10);
  }
}

TEST(LayeredMap, FromInsideAHeadAndOnAMeshThatIsNotClosed) {
  if (!FirstHitCaster::available()) GTEST_SKIP() << "no ray caster in this build";
  const TriangleMesh sphere = make_uv_sphere(25, Eigen::Vector3d::Zero(), 128, 64);
  // The upper hemisphere only (z >= 0): not closed.
  TriangleMesh half = sphere;
  std::vector<Eigen::Index> keep;
  for (Eigen::Index f = 0; f < sphere.F.rows(); ++f) {
    double zc = 0;
    for (int k = 0; k < 3; ++k) zc += sphere.V(sphere.F(f, k), 2) / 3;
    if (zc > 0) keep.push_back(f);
  }
  half.F.resize(static_cast<Eigen::Index>(keep.size()), 3);
  for (std::size_t k = 0; k < keep.size(); ++k) half.F.row(static_cast<Eigen::Index>(k)) = sphere.F.row(keep[k]);
  const TriangleMesh* const meshes[] = {&sphere, &half};
  for (const TriangleMesh* m : meshes) {
    const FirstHitCaster caster(*m, Eigen::Vector3d::Zero());
    EXPECT_EQ(caster.orientation(), 1);
    LayeredMap map(make_scheme("equiangular", 1.0), 2);
    sample_layered_map(map, caster);
    const double pts[4][3] = {{0, 12, 15}, {0, 20, 20}, {0, 12, -15}, {0, 20, -20}};
    for (const auto& p : pts) {
      const Eigen::Vector3d q(p[0], p[1], p[2]);
      double s;
      map.signed_distance_many_soa(&q.x(), &q.y(), &q.z(), 1, &s);
      if (m == &half && q.z() < 0) {
        EXPECT_TRUE(std::isinf(s)) << q.transpose();  // no surface along the ray: outside, no distance
      } else {
        // The ray leaves the surface at 25 mm: inside before it, outside after it, on either mesh.
        EXPECT_NEAR(s, q.norm() - 25, 0.02) << q.transpose();
      }
    }
  }
}

TEST(LayeredMap, OccupancyCoversTheSolid) {
  if (!FirstHitCaster::available()) GTEST_SKIP() << "no ray caster in this build";
  const std::vector<Sphere> spheres = {{{30, 2, -1}, 10}, {{62, 5, 3}, 8}};
  const TriangleMesh mesh = test::concatenated(make_uv_sphere(10, spheres[0].c, 128, 64), make_uv_sphere(8, spheres[1].c, 128, 64));
  const FirstHitCaster caster(mesh, Eigen::Vector3d::Zero());
  LayeredMap map(make_scheme("equiangular", 1.0), 4);
  sample_layered_map(map, caster);
  const double bin = 2;
  int inside = 0;
  for (std::int64_t i = 0; i < map.num_nodes(); i += 3) {
    const std::uint64_t occ = map.occupancy(i, bin);
    for (double r = 0.25; r < 140; r += 0.5) {
      const int b = std::min(63, static_cast<int>(r / bin));
      const double s = map.node_signed_distance(i, r);
      if (s <= 0) {
        ++inside;
        EXPECT_TRUE((occ >> b) & 1) << "node " << i << " r " << r;
      }
      // Outside and more than a bin from the node's crossings, the bit is clear (else the bound is useless).
      if (s > 2 * bin && b < 63) {
        EXPECT_FALSE((occ >> b) & 1) << "node " << i << " r " << r;
      }
    }
  }
  EXPECT_GT(inside, 1000);
}

TEST(LayeredMap, RealPelvisCrossingCountsAgreeWithCgal) {
  const auto joint = test::load_real_joint("lhdl-ct");
  if (!joint) GTEST_SKIP() << "shared data absent";
  if (!FirstHitCaster::available() || !have_exact_reference()) GTEST_SKIP() << "no ray caster in this build";
  const FirstHitCaster caster(joint->pelvis, joint->cor);
  const ExactReference ref(joint->pelvis);
  LayeredMap map(make_scheme("equiangular", 2.0), 8);
  const LayeredSamplingReport rep = sample_layered_map(map, caster);
  EXPECT_GT(rep.nodes_covered, map.num_nodes() / 3);
  EXPECT_GE(rep.max_crossings, 4);  // the pelvis is far from star-shaped
  EXPECT_LT(rep.nodes_not_alternating, map.num_nodes() / 1000 + 1);
  std::int64_t same = 0, compared = 0;
  for (std::int64_t i = 0; i < map.num_nodes(); ++i) {
    const Eigen::Vector3d u = map.scheme().node_direction(i);
    const auto want = ref.all_hits(joint->cor, u);
    if (want.size() > 8) continue;
    ++compared;
    bool ok = static_cast<int>(want.size()) == map.count(i);
    for (int k = 0; ok && k < map.count(i); ++k)
      ok = std::abs(map.crossing(i, k).distance_mm - want[static_cast<std::size_t>(k)].first) < 1e-3 &&
           map.crossing(i, k).entering == (want[static_cast<std::size_t>(k)].second * caster.orientation() < 0);
    same += ok;
  }
  EXPECT_GE(same, compared - compared / 1000) << same << " of " << compared;
}
