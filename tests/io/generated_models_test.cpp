// Generated models: closed (every edge shared by exactly two triangles), triangle counts near
// the target, the head sphere and cup concentric about the true COR.
#include "impinge/io/generated_models.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

using namespace impinge;

namespace {
bool closed(const TriangleMesh& m) {
  std::map<std::pair<int, int>, int> edges;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = m.F(f, k), b = m.F(f, (k + 1) % 3);
      ++edges[{std::min(a, b), std::max(a, b)}];
    }
  for (const auto& [e, n] : edges)
    if (n != 2) return false;
  return true;
}
}  // namespace

TEST(GeneratedModels, ClosedAtThesisTriangleLevels) {
  for (int t : {300, 1000, 3000, 12000}) {
    HipModelOptions o;
    o.target_triangles = t;
    const HipModel h = make_hip_model(o);
    EXPECT_TRUE(closed(h.ball)) << t;
    EXPECT_TRUE(closed(h.socket)) << t;
    EXPECT_NEAR(double(h.ball.F.rows()), t, 0.2 * t);
    EXPECT_NEAR(double(h.socket.F.rows()), t, 0.2 * t);
    // cup inner shell vertices at head radius + gap from the COR
    double min_socket = 1e9;
    for (Eigen::Index i = 0; i < h.socket.V.rows(); ++i)
      min_socket = std::min(min_socket, (h.socket.V.row(i).transpose() - h.cor).norm());
    EXPECT_NEAR(min_socket, o.head_radius_mm + o.cartilage_gap_mm, 1e-9);
  }
}

TEST(GeneratedModels, SlicedSphereAndConchoidAreClosedAndStarShaped) {
  const TriangleMesh st = make_sliced_sphere(22, 1.25, Eigen::Vector3d(1, 2, 3), 96);
  EXPECT_TRUE(closed(st));
  // a staircase stays within one slice thickness of the sphere, and its rings lie on slice
  // boundaries z = c.z + k * 1.25
  for (Eigen::Index i = 0; i < st.V.rows(); ++i) {
    const Eigen::Vector3d d = st.V.row(i).transpose() - Eigen::Vector3d(1, 2, 3);
    EXPECT_LE(std::abs(d.norm() - 22), 1.25);
    EXPECT_NEAR(d.z() / 1.25, std::round(d.z() / 1.25), 1e-9);
  }
  const TriangleMesh c = make_conchoid_surface(20.501, 17.843, Eigen::Vector3d::Zero(), 64, 32);
  EXPECT_TRUE(closed(c));
}
