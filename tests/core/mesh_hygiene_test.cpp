// clean_bone_mesh (mesh_hygiene.hpp) against shapes whose answer is known: spheres apart by a set distance, faces
// stored twice, a soup, caps cut out of a sphere (holes whose boundary and solid angle are analytic).
#include "impinge/core/mesh_hygiene.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <set>

#include "impinge/core/error.hpp"
#include "impinge/io/generated_models.hpp"

namespace impinge {
namespace {

// Meshes side by side in one (vertices and faces appended).
TriangleMesh join(const std::vector<TriangleMesh>& parts) {
  TriangleMesh m;
  Eigen::Index nv = 0, nf = 0;
  for (const TriangleMesh& p : parts) nv += p.V.rows(), nf += p.F.rows();
  m.V.resize(nv, 3);
  m.F.resize(nf, 3);
  nv = nf = 0;
  for (const TriangleMesh& p : parts) {
    m.V.middleRows(nv, p.V.rows()) = p.V;
    m.F.middleRows(nf, p.F.rows()) = p.F.array() + static_cast<int>(nv);
    nv += p.V.rows(), nf += p.F.rows();
  }
  return m;
}

// The triangles as sets of corner positions (order- and numbering-free), for comparing geometry.
std::multiset<std::vector<double>> triangles_of(const TriangleMesh& m) {
  std::multiset<std::vector<double>> out;
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    std::vector<std::vector<double>> c;
    for (int k = 0; k < 3; ++k) c.push_back({m.V(m.F(f, k), 0), m.V(m.F(f, k), 1), m.V(m.F(f, k), 2)});
    std::sort(c.begin(), c.end());
    std::vector<double> key;
    for (const auto& x : c) key.insert(key.end(), x.begin(), x.end());
    out.insert(key);
  }
  return out;
}

// The least vertex-to-vertex distance between two meshes, brute force.
double vertex_gap(const TriangleMesh& a, const TriangleMesh& b) {
  double best = INFINITY;
  for (Eigen::Index i = 0; i < a.V.rows(); ++i)
    for (Eigen::Index j = 0; j < b.V.rows(); ++j) best = std::min(best, (a.V.row(i) - b.V.row(j)).norm());
  return best;
}

TEST(MeshHygiene, BoneKeepsNearPartsAndDropsAFarFragment) {
  const TriangleMesh left = make_uv_sphere(40, {0, 0, 0}, 32, 16);
  const TriangleMesh right = make_uv_sphere(38, {82, 0, 0}, 32, 16);    // 4 mm from the left: the bone
  const TriangleMesh speck = make_uv_sphere(1, {0, 0, 48}, 8, 4);       // 7 mm above the left: the bone's
  const TriangleMesh marker = make_uv_sphere(2, {0, 0, -242}, 8, 4);    // 200 mm below: a fragment
  TriangleMesh m = join({marker, left, speck, right});
  const MeshHygiene h = clean_bone_mesh(m, "test.ply");
  EXPECT_EQ(h.components, 4);
  EXPECT_EQ(h.components_kept, 3);
  ASSERT_EQ(h.dropped.size(), 1u);
  EXPECT_EQ(h.dropped[0].triangles, marker.F.rows());
  EXPECT_NEAR(h.dropped[0].distance_mm, vertex_gap(marker, left), 1e-9);
  EXPECT_NEAR(h.dropped[0].extent_mm, 4.0, 0.1);
  EXPECT_NEAR(h.dropped[0].centre.z(), -242, 1e-9);
  EXPECT_EQ(triangles_of(m), triangles_of(join({left, speck, right})));
  EXPECT_EQ(m.V.rows(), left.V.rows() + speck.V.rows() + right.V.rows());  // the marker's vertices gone
  ASSERT_EQ(h.warnings("test.ply").size(), 1u);
  EXPECT_NE(h.warnings("test.ply")[0].find("1 fragment apart from the bone"), std::string::npos);
  TriangleMesh strict = join({marker, left, speck, right});
  EXPECT_THROW(clean_bone_mesh(strict, "test.ply", true), Error);
}

TEST(MeshHygiene, TheAnswerDoesNotDependOnTheFilesOrder) {
  const TriangleMesh a = make_uv_sphere(40, {0, 0, 0}, 24, 12), b = make_uv_sphere(3, {0, 0, 200}, 8, 4);
  TriangleMesh m = join({a, b});
  std::mt19937 rng(5);
  std::vector<int> p(static_cast<std::size_t>(m.V.rows()));
  std::iota(p.begin(), p.end(), 0);
  std::shuffle(p.begin(), p.end(), rng);
  TriangleMesh shuffled = m;
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) shuffled.V.row(p[static_cast<std::size_t>(i)]) = m.V.row(i);
  for (Eigen::Index f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) shuffled.F(m.F.rows() - 1 - f, k) = p[static_cast<std::size_t>(m.F(f, k))];
  clean_bone_mesh(m, "m");
  clean_bone_mesh(shuffled, "s");
  EXPECT_EQ(triangles_of(m), triangles_of(shuffled));
  EXPECT_EQ(triangles_of(m), triangles_of(a));
}

TEST(MeshHygiene, AnotherBonesWorthApartIsRefused) {
  TriangleMesh m = join({make_uv_sphere(40, {0, 0, 0}, 24, 12), make_uv_sphere(30, {300, 0, 0}, 24, 12)});
  try {
    clean_bone_mesh(m, "femurs.ply");
    FAIL() << "two bones accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("femurs.ply: two bones in one file?"), std::string::npos) << e.what();
  }
}

TEST(MeshHygiene, DoubleWallsAndSoupsReadAsTheSurface) {
  const TriangleMesh s = make_uv_sphere(20, {1, 2, 3}, 16, 8);
  TriangleMesh doubled = s;  // every face again, reversed, interleaved
  doubled.F.resize(2 * s.F.rows(), 3);
  for (Eigen::Index f = 0; f < s.F.rows(); ++f) {
    doubled.F.row(2 * f) = s.F.row(f);
    doubled.F.row(2 * f + 1) << s.F(f, 0), s.F(f, 2), s.F(f, 1);
  }
  const MeshHygiene h = clean_bone_mesh(doubled, "d");
  EXPECT_EQ(h.duplicate_faces_removed, s.F.rows());
  EXPECT_EQ(doubled.F, s.F);  // the first of each pair kept, in order
  EXPECT_THROW(clean_bone_mesh(doubled = join({s, s}), "d", true), Error);
  TriangleMesh soup;  // every corner its own vertex
  soup.V.resize(3 * s.F.rows(), 3);
  soup.F.resize(s.F.rows(), 3);
  for (Eigen::Index f = 0; f < s.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) soup.V.row(3 * f + k) = s.V.row(s.F(f, k)), soup.F(f, k) = static_cast<int>(3 * f + k);
  const MeshHygiene g = clean_bone_mesh(soup, "soup");
  EXPECT_EQ(g.components, 1);
  EXPECT_EQ(g.boundary_edges, 0);
  EXPECT_EQ(triangles_of(soup), triangles_of(s));
}

TEST(MeshHygiene, PartsInsideTheBoneAndUnusedVerticesAreRemoved) {
  // An inner cortical wall 1.5 mm inside (wound either way), a speck inside, and a vertex no face uses 200 mm off.
  const TriangleMesh outer = make_uv_sphere(40, {0, 0, 0}, 32, 16);
  TriangleMesh inner = make_uv_sphere(38.5, {0, 0, 0}, 32, 16);
  inner.F.col(1).swap(inner.F.col(2));
  const TriangleMesh speck = make_uv_sphere(1, {5, 5, 5}, 8, 4);
  TriangleMesh m = join({inner, outer, speck});
  m.V.conservativeResize(m.V.rows() + 1, 3);
  m.V.row(m.V.rows() - 1) << 240, 0, 0;
  const MeshHygiene h = clean_bone_mesh(m, "shells.ply");
  EXPECT_EQ(h.parts_inside_removed, 2);
  EXPECT_NEAR(h.inside_area_mm2, 4 * M_PI * 38.5 * 38.5 + 4 * M_PI, 0.05 * 4 * M_PI * 38.5 * 38.5);
  EXPECT_EQ(h.unused_vertices_removed, 1);
  EXPECT_EQ(triangles_of(m), triangles_of(outer));
  EXPECT_EQ(m.V.rows(), outer.V.rows());
  TriangleMesh strict = join({outer, speck});
  EXPECT_THROW(clean_bone_mesh(strict, "s", true), Error);
}

TEST(MeshHygiene, ACopyMovedByAMicrometreIsADoubleWall) {
  // Every face again, reversed, its corners moved 1e-6 and 1e-3 mm (a copy written with rounding): not the same
  // corners, the same wall.
  const TriangleMesh s = make_uv_sphere(20, {1, 2, 3}, 16, 8);
  for (const double shift : {1e-6, 1e-3}) {
    TriangleMesh copy = s;
    copy.V.array() += shift;
    copy.F.col(1).swap(copy.F.col(2));
    TriangleMesh m = join({s, copy});
    const MeshHygiene h = clean_bone_mesh(m, "d");
    EXPECT_EQ(h.duplicate_faces_removed, s.F.rows()) << shift;
    EXPECT_EQ(triangles_of(m), triangles_of(s)) << shift;
  }
}

TEST(MeshHygiene, HolesAndTheirWindingNumberAreAnalytic) {
  // A UV sphere's polar fans cut out: each cap is one hole whose rim is the first ring (n_theta edges).
  const int n_theta = 64, n_phi = 32;
  TriangleMesh s = make_uv_sphere(10, {0, 0, 0}, n_theta, n_phi);
  EXPECT_NEAR(winding_number(s, {0, 0, 0}), 1.0, 1e-9);
  EXPECT_NEAR(winding_number(s, {0, 0, 30}), 0.0, 1e-9);
  std::vector<std::uint8_t> keep(static_cast<std::size_t>(s.F.rows()), 1);
  for (Eigen::Index f = 0; f < s.F.rows(); ++f) {
    double z = 0;
    for (int k = 0; k < 3; ++k) z = std::max(z, s.V(s.F(f, k), 2));
    keep[static_cast<std::size_t>(f)] = z < 10 - 1e-9;  // fans touching the north pole out
  }
  TriangleMesh holed = s;
  Eigen::Index m = 0;
  for (Eigen::Index f = 0; f < s.F.rows(); ++f)
    if (keep[static_cast<std::size_t>(f)] != 0) holed.F.row(m++) = s.F.row(f);
  holed.F.conservativeResize(m, 3);
  MeshHygiene h;
  count_holes(holed, h);
  EXPECT_EQ(h.boundary_loops, 1);
  EXPECT_EQ(h.boundary_edges, n_theta);
  EXPECT_EQ(h.nonmanifold_edges, 0);
  // Seen from the centre, the hole is the cone over a regular n-gon at polar angle t: its solid angle is
  // 2 pi - sum of the n lune angles; for large n about a cap's 2 pi (1 - cos t), to (t / n)^2 relative.
  const double t = M_PI / n_phi, cap = 2 * M_PI * (1 - std::cos(t));
  EXPECT_NEAR(winding_number(holed, {0, 0, 0}), 1 - cap / (4 * M_PI), 2e-5);
  EXPECT_EQ(boundary_edges_within(holed, {0, 0, 10}, 10 * std::sin(t) + 1e-6 + 10 * (1 - std::cos(t))), n_theta);
  EXPECT_EQ(boundary_edges_within(holed, {0, 0, -10}, 5), 0);
}

}  // namespace
}  // namespace impinge
