// submesh: the triangles whose corners are all kept, vertices renumbered in order of first use;
// checked against a hand-built two-triangle square and brute-force counts on a generated hip.
#include "impinge/core/mesh.hpp"

#include <gtest/gtest.h>

#include <functional>
#include <map>

#include "impinge/anatomy/femur_frame.hpp"
#include "impinge/casters/embree_ray_caster.hpp"
#include "impinge/casters/exact_reference.hpp"
#include "impinge/casters/fcl_collision.hpp"
#include "impinge/core/error.hpp"
#include "impinge/core/spherical_frame.hpp"
#include "impinge/detection/joint.hpp"
#include "impinge/io/generated_models.hpp"
#include "impinge/io/mesh_io.hpp"
#include "impinge/sampling/naive_sampling.hpp"
#include "impinge/sampling/raster_plan.hpp"
#include "impinge/sampling/sampling.hpp"
#include "test_support.hpp"

using namespace impinge;

TEST(Mesh, SubmeshKeepsTrianglesWhoseCornersAreAllKept) {
  TriangleMesh sq;
  sq.source = "square";
  sq.V.resize(4, 3);
  sq.V << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
  sq.F.resize(2, 3);
  sq.F << 0, 1, 2, 0, 2, 3;
  std::vector<Eigen::Index> kept;
  const TriangleMesh a = submesh(sq, {1, 0, 1, 1}, &kept);  // drops vertex 1 and so triangle 0
  ASSERT_EQ(a.F.rows(), 1);
  EXPECT_EQ(kept, (std::vector<Eigen::Index>{0, 2, 3}));
  for (int c = 0; c < 3; ++c) EXPECT_EQ(a.V.row(a.F(0, c)), sq.V.row(sq.F(1, c)));
  EXPECT_EQ(submesh(sq, {0, 0, 0, 0}).F.rows(), 0);
  EXPECT_THROW(submesh(sq, {1, 1}), Error);

  const HipModel h = make_hip_model({});
  std::vector<std::uint8_t> keep(static_cast<std::size_t>(h.ball.V.rows()));
  for (Eigen::Index i = 0; i < h.ball.V.rows(); ++i) keep[static_cast<std::size_t>(i)] = h.ball.V(i, 2) > h.cor.z();
  Eigen::Index expect = 0;
  for (Eigen::Index f = 0; f < h.ball.F.rows(); ++f)
    expect += keep[h.ball.F(f, 0)] && keep[h.ball.F(f, 1)] && keep[h.ball.F(f, 2)];
  const TriangleMesh b = submesh(h.ball, keep);
  EXPECT_EQ(b.F.rows(), expect);
  EXPECT_NO_THROW(validate_mesh(b));
  EXPECT_GT(b.V.col(2).minCoeff(), h.cor.z());
}

// orient_consistently: a closed, consistently wound mesh is left as it is (its fast path); with some triangles
// flipped it flips exactly those back (the general path), and a non-orientable strip reports conflicts. The
// oracle is the mesh before the flips.
TEST(Mesh, OrientConsistentlyRestoresTheWindingAndLeavesAConsistentMeshAlone) {
  const TriangleMesh sphere = make_uv_sphere(10, Eigen::Vector3d(1, 2, 3), 40, 20);
  TriangleMesh m = sphere;
  std::int64_t conflicts = -1;
  EXPECT_EQ(orient_consistently(m, &conflicts), 0);
  EXPECT_EQ(conflicts, 0);
  EXPECT_EQ(m.F, sphere.F);
  for (Eigen::Index f = 0; f < m.F.rows(); f += 7) std::swap(m.F(f, 1), m.F(f, 2));
  const Eigen::Index flipped = (m.F.rows() + 6) / 7;
  EXPECT_EQ(orient_consistently(m, &conflicts), flipped);
  EXPECT_EQ(conflicts, 0);
  EXPECT_EQ(m.F, sphere.F);
  // A Moebius strip of 8 quads: one shared edge no winding can agree across.
  TriangleMesh strip;
  const int n = 8;
  strip.V.resize(2 * n, 3);
  for (int k = 0; k < n; ++k) {
    const double a = 2 * kPi * k / n, w = kPi * k / n;
    const Eigen::Vector3d c(20 * std::cos(a), 20 * std::sin(a), 0), r(std::cos(a), std::sin(a), 0);
    const Eigen::Vector3d d = std::cos(w) * r + std::sin(w) * Eigen::Vector3d::UnitZ();
    strip.V.row(2 * k) = (c - 3 * d).transpose();
    strip.V.row(2 * k + 1) = (c + 3 * d).transpose();
  }
  strip.F.resize(2 * n, 3);
  for (int k = 0; k < n; ++k) {
    const int a = 2 * k, b = 2 * k + 1;
    const int c = k + 1 < n ? 2 * (k + 1) : 1, d = k + 1 < n ? 2 * (k + 1) + 1 : 0;  // the half twist
    strip.F.row(2 * k) << a, c, b;
    strip.F.row(2 * k + 1) << b, c, d;
  }
  orient_consistently(strip, &conflicts);
  EXPECT_GT(conflicts, 0);
}

// count_unpaired_directed_edges against a brute-force count over a map of directed edges: 0 on a closed sphere,
// and the same count as the map's after a triangle is removed (a hole) or flipped (against its neighbours).
TEST(Mesh, UnpairedDirectedEdgesMatchABruteForceCount) {
  auto brute = [](const TriangleMesh& m) {
    std::map<std::pair<int, int>, int> count;
    for (Eigen::Index f = 0; f < m.F.rows(); ++f)
      for (int k = 0; k < 3; ++k) ++count[{m.F(f, k), m.F(f, (k + 1) % 3)}];
    std::int64_t unpaired = 0;
    for (const auto& [e, c] : count) {
      const auto r = count.find({e.second, e.first});
      if (c != 1 || r == count.end() || r->second != 1) unpaired += c;  // each occurrence of the edge counts
    }
    return unpaired;
  };
  const TriangleMesh sphere = make_uv_sphere(10, Eigen::Vector3d(1, 2, 3), 24, 12);
  EXPECT_EQ(count_unpaired_directed_edges(sphere), 0);
  TriangleMesh holed = sphere;
  holed.F.conservativeResize(holed.F.rows() - 1, 3);
  const std::int64_t hole = count_unpaired_directed_edges(holed);
  EXPECT_EQ(hole, brute(holed));
  EXPECT_GE(hole, 2);  // the removed triangle's neighbours' edges (2 at a pole's fan, 3 elsewhere)
  TriangleMesh flipped = sphere;
  std::swap(flipped.F(40, 1), flipped.F(40, 2));
  EXPECT_EQ(count_unpaired_directed_edges(flipped), brute(flipped));
  EXPECT_GT(count_unpaired_directed_edges(flipped), 0);
  EXPECT_EQ(count_unpaired_directed_edges(flipped, 1), 1);  // stops at the first
  TriangleMesh bad = sphere;
  bad.source = "bad-index";
  bad.F(3, 2) = -1;
  EXPECT_THROW(
      {
        try {
          count_unpaired_directed_edges(bad);
        } catch (const Error& e) {
          EXPECT_NE(std::string(e.what()).find("bad-index: triangle 3"), std::string::npos) << e.what();
          throw;
        }
      },
      Error);
}

TEST(Mesh, EveryEntryPointThatIndexesFacesRefusesABadIndex) {
  // A face index outside [0, n) is an impinge::Error naming the mesh at every entry point that reads
  // faces, never an out-of-bounds read (the sanitizer build checks the latter).
  const HipModel h = make_hip_model({});
  TriangleMesh bad = h.ball;
  bad.source = "bad-mesh";
  bad.F(bad.F.rows() / 2, 1) = static_cast<int>(bad.V.rows()) + 5;
  auto expect_error = [&](const char* what, const std::function<void()>& call) {
    try {
      call();
      ADD_FAILURE() << what << ": no error";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("bad-mesh"), std::string::npos) << what << ": " << e.what();
    }
  };
  expect_error("vertex_areas", [&] { vertex_areas(bad); });
  expect_error("remove_degenerate_faces", [&] {
    TriangleMesh m = bad;
    remove_degenerate_faces(m);
  });
  expect_error("submesh", [&] { submesh(bad, std::vector<std::uint8_t>(static_cast<std::size_t>(bad.V.rows()), 1)); });
  expect_error("write_ply", [&] { write_ply(test::temp_dir("mesh_bad") + "/m.ply", bad); });
  expect_error("sample_surface", [&] {
    RadialDistanceMap map(make_scheme("equiangular", 2.0));
    sample_surface(bad, h.cor, SamplingOptions{}, map);
  });
  expect_error("sample_naive", [&] {
    RadialDistanceMap map(make_scheme("equiangular", 10.0));
    sample_naive(bad, h.cor, map);
  });
  expect_error("cast_ray_naive", [&] { cast_ray_naive(bad, h.cor, Eigen::Vector3d::UnitX()); });
  expect_error("plan_rasterization", [&] { plan_rasterization(bad, h.cor); });
  expect_error("Joint", [&] { Joint(bad, h.socket, h.cor, JointOptions{}); });
  expect_error("locate_femoral_head", [&] { locate_femoral_head(bad); });
  if (have_exact_reference()) expect_error("ExactReference", [&] { ExactReference r(bad); });
  if (have_fcl()) expect_error("FclJoint", [&] { FclJoint f(bad, h.socket, h.cor); });
  if (have_embree()) expect_error("EmbreeRayCaster", [&] { EmbreeRayCaster e(bad, h.cor); });
}
