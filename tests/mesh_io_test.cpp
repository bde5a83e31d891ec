// Mesh loading: every bad file gives an impinge::Error naming the file and the element; a
// PLY written and read back keeps vertex order and count; degenerate triangles are counted.
#include "impinge/mesh_io.hpp"

#include <gtest/gtest.h>

#include "impinge/error.hpp"
#include "impinge/generated_models.hpp"
#include "test_support.hpp"

using namespace impinge;

namespace {
const std::string kHeader =
    "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
    "element face %F\nproperty list uchar int vertex_indices\nend_header\n";
std::string ply(const std::string& verts, int faces, const std::string& face_lines) {
  std::string h = kHeader;
  h.replace(h.find("%F"), 2, std::to_string(faces));
  return h + verts + face_lines;
}
const std::string kVerts = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n";

void expect_error(const std::string& path, const std::string& fragment) {
  try {
    load_mesh(path);
    FAIL() << "no error for " << path;
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find(fragment), std::string::npos) << msg;
  }
}
}  // namespace

TEST(MeshIo, BadFilesNameFileAndElement) {
  const std::string d = test::temp_dir("mesh_io");
  expect_error(d + "/missing.ply", "does not exist");
  test::write_text(d + "/garbage.ply", "this is not a mesh");
  expect_error(d + "/garbage.ply", "cannot parse");
  test::write_text(d + "/empty.stl", "");
  expect_error(d + "/empty.stl", "cannot parse");
  test::write_text(d + "/nan.ply", ply("nan 0 0\n1 0 0\n0 1 0\n0 0 1\n", 1, "3 0 1 2\n"));
  expect_error(d + "/nan.ply", "vertex 0");
  test::write_text(d + "/index.ply", ply(kVerts, 2, "3 0 1 2\n3 0 1 9\n"));
  expect_error(d + "/index.ply", "face 1 has vertex index 9");
  test::write_text(d + "/quad.ply", ply(kVerts, 2, "3 0 1 2\n4 0 1 2 3\n"));
  expect_error(d + "/quad.ply", "face 1 has 4 vertices");
  test::write_text(d + "/allflat.ply", ply(kVerts, 1, "3 0 0 1\n"));
  expect_error(d + "/allflat.ply", "degenerate");
  test::write_text(d + "/nofaces.off", "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n");
  EXPECT_THROW(load_mesh(d + "/nofaces.off"), Error);
}

TEST(MeshIo, DegenerateTrianglesSkippedAndCounted) {
  const std::string d = test::temp_dir("mesh_io_degenerate");
  test::write_text(d + "/deg.ply", ply(kVerts, 3, "3 0 1 2\n3 1 1 2\n3 0 1 3\n"));
  const TriangleMesh m = load_mesh(d + "/deg.ply");
  EXPECT_EQ(m.F.rows(), 2);
  EXPECT_EQ(m.degenerate_faces_skipped, 1);
  EXPECT_EQ(m.V.rows(), 4);
}

TEST(MeshIo, PlyRoundTripKeepsOrderAndOtherFormatsLoad) {
  const std::string d = test::temp_dir("mesh_io_roundtrip");
  const TriangleMesh s = make_uv_sphere(10, Eigen::Vector3d(1, 2, 3), 12, 6, Eigen::Vector3d(0.2, 0.1, 1));
  write_ply(d + "/s.ply", s);
  const TriangleMesh r = load_mesh(d + "/s.ply");
  ASSERT_EQ(r.V.rows(), s.V.rows());
  ASSERT_EQ(r.F.rows(), s.F.rows());
  EXPECT_LT((r.V - s.V).cwiseAbs().maxCoeff(), 1e-5);
  EXPECT_EQ(r.F, s.F);
  test::write_text(d + "/t.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\n");
  const TriangleMesh o = load_mesh(d + "/t.obj");
  EXPECT_EQ(o.F.rows(), 2);
  EXPECT_EQ(o.V.rows(), 4);  // corners welded
  test::write_text(d + "/t.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 1 3\n");
  EXPECT_EQ(load_mesh(d + "/t.off").F.rows(), 2);
  test::write_text(d + "/t.stl",
                   "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\n"
                   "endfacet\nfacet normal 0 -1 0\nouter loop\nvertex 0 0 0\nvertex 0 0 1\nvertex 1 0 0\nendloop\n"
                   "endfacet\nendsolid t\n");
  const TriangleMesh st = load_mesh(d + "/t.stl");
  EXPECT_EQ(st.F.rows(), 2);
  EXPECT_EQ(st.V.rows(), 4);
}
