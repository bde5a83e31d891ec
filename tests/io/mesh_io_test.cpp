// Mesh loading: every bad file gives an impinge::Error naming the file and the element; a
// PLY written and read back keeps vertex order and count; degenerate triangles are counted.
#include "impinge/io/mesh_io.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <tuple>

#include "impinge/core/error.hpp"
#include "impinge/io/generated_models.hpp"
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
    EXPECT_NE(msg.find(fragment), std::string::npos) << msg << " (wanted: " << fragment << ")";
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
  ASSERT_EQ(m.F.rows(), 2);
  EXPECT_EQ(m.degenerate_faces_skipped, 1);
  EXPECT_EQ(m.V.rows(), 4);
  // The triangles after the skipped one move up, in the file's order.
  EXPECT_EQ(m.F.row(0), Eigen::RowVector3i(0, 1, 2));
  EXPECT_EQ(m.F.row(1), Eigen::RowVector3i(0, 1, 3));
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

// write_ply with per-vertex arrays (the plan's resection_mm): the file is exactly the header and the body its
// counts give (n x (3 + arrays) floats, m faces of a uchar 3 and three ints), every value where the header says,
// read back byte by byte here rather than by the library's reader; an array of the wrong length is an error.
TEST(MeshIo, PlyWithArraysHoldsEveryValueWhereItsHeaderSays) {
  const std::string d = test::temp_dir("mesh_io_arrays");
  const TriangleMesh s = make_uv_sphere(10, Eigen::Vector3d(1, 2, 3), 12, 6, Eigen::Vector3d(0.2, 0.1, 1));
  const auto n = static_cast<std::size_t>(s.V.rows()), m = static_cast<std::size_t>(s.F.rows());
  std::vector<PointArray> arrays(2);
  arrays[0].name = "resection_mm";
  arrays[1].name = "other";
  for (std::size_t i = 0; i < n; ++i) {
    arrays[0].f32.push_back(0.25f * static_cast<float>(i));
    arrays[1].f32.push_back(-static_cast<float>(i) - 0.5f);
  }
  write_ply(d + "/a.ply", s, arrays);
  std::ifstream in(d + "/a.ply", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t body = bytes.find("end_header\n") + 11;
  ASSERT_NE(bytes.find("property float resection_mm\nproperty float other\nelement face"), std::string::npos);
  ASSERT_EQ(bytes.size(), body + n * 5 * sizeof(float) + m * 13);
  auto f32 = [&](std::size_t at) {
    float v;
    std::memcpy(&v, bytes.data() + at, sizeof v);
    return v;
  };
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t at = body + i * 5 * sizeof(float);
    for (int k = 0; k < 3; ++k) ASSERT_EQ(f32(at + 4 * k), static_cast<float>(s.V(i, k))) << i;
    ASSERT_EQ(f32(at + 12), arrays[0].f32[i]) << i;
    ASSERT_EQ(f32(at + 16), arrays[1].f32[i]) << i;
  }
  for (std::size_t f = 0; f < m; ++f) {
    const std::size_t at = body + n * 5 * sizeof(float) + f * 13;
    ASSERT_EQ(bytes[at], 3) << f;
    for (int k = 0; k < 3; ++k) {
      std::int32_t v;
      std::memcpy(&v, bytes.data() + at + 1 + 4 * k, sizeof v);
      ASSERT_EQ(v, s.F(f, k)) << f;
    }
  }
  arrays[1].f32.pop_back();
  EXPECT_THROW(write_ply(d + "/b.ply", s, arrays), Error);
}

// impinge's own PLY reader (mesh_readers.hpp): every encoding and type gives the same mesh; every
// structural fault is an error naming the file and where, as assimp 5.2.4 did not (it hung).
namespace {
std::string binary_ply(bool big, bool doubles, bool extra, std::size_t cut = std::string::npos) {
  const float vf[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const int faces[2][3] = {{0, 1, 2}, {0, 1, 3}};
  std::string h = std::string("ply\nformat ") + (big ? "binary_big_endian" : "binary_little_endian") + " 1.0\n" +
                  "comment written by the test\nelement vertex 4\n" + (extra ? "property uchar red\n" : "") +
                  (doubles ? "property double x\nproperty double y\nproperty double z\n"
                           : "property float x\nproperty float y\nproperty float z\n") +
                  "element face 2\nproperty list uchar int vertex_indices\n" + (extra ? "property ushort flags\n" : "") +
                  (extra ? "element edge 1\nproperty list ushort uint vertex_pair\n" : "") + "end_header\n";
  auto put = [&](const void* p, std::size_t n) {
    std::string b(static_cast<const char*>(p), n);
    if (big) std::reverse(b.begin(), b.end());
    h += b;
  };
  for (const auto& v : vf) {
    if (extra) h += '\x7f';
    for (float c : v) {
      if (doubles) {
        const double d = c;
        put(&d, 8);
      } else {
        put(&c, 4);
      }
    }
  }
  for (const auto& f : faces) {
    h += '\x03';
    for (int i : f) put(&i, 4);
    if (extra) {
      const unsigned short fl = 9;
      put(&fl, 2);
    }
  }
  if (extra) {
    const unsigned short two = 2;
    const unsigned int pair[2] = {0, 3};
    put(&two, 2);
    put(&pair[0], 4);
    put(&pair[1], 4);
  }
  return cut == std::string::npos ? h : h.substr(0, cut);
}
}  // namespace

TEST(MeshIo, PlyEncodingsAndTypesGiveTheSameMesh) {
  const std::string d = test::temp_dir("mesh_io_ply_encodings");
  test::write_text(d + "/ascii.ply", ply(kVerts, 2, "3 0 1 2\n3 0 1 3\n"));
  const TriangleMesh ref = load_mesh(d + "/ascii.ply");
  ASSERT_EQ(ref.F.rows(), 2);
  for (bool big : {false, true})
    for (bool doubles : {false, true})
      for (bool extra : {false, true}) {
        const std::string p = d + "/b" + std::to_string(big) + std::to_string(doubles) + std::to_string(extra) + ".ply";
        test::write_text(p, binary_ply(big, doubles, extra));
        const TriangleMesh m = load_mesh(p);
        EXPECT_EQ(m.V, ref.V) << p;
        EXPECT_EQ(m.F, ref.F) << p;
      }
  // An element without properties holds no data, whatever its count (no loop over two billion).
  test::write_text(d + "/empty_element.ply",
                   "ply\nformat ascii 1.0\nelement marker 2000000000\nelement vertex 4\nproperty float x\n"
                   "property float y\nproperty float z\nelement face 2\nproperty list uchar int vertex_indices\n"
                   "end_header\n" + kVerts + "3 0 1 2\n3 0 1 3\n");
  EXPECT_EQ(load_mesh(d + "/empty_element.ply").F, ref.F);
  // CRLF header lines, as Windows tools write them.
  std::string crlf = binary_ply(false, false, false);
  for (std::size_t at = crlf.find('\n'); at < crlf.find("end_header") + 11; at = crlf.find('\n', at + 2))
    crlf.insert(at, "\r");
  test::write_text(d + "/crlf.ply", crlf);
  EXPECT_EQ(load_mesh(d + "/crlf.ply").V, ref.V);
}

TEST(MeshIo, MalformedPlyIsAnErrorNamingWhere) {
  const std::string d = test::temp_dir("mesh_io_ply_faults");
  const std::string good = binary_ply(false, false, true);
  const std::size_t body = good.find("end_header\n") + 11;
  struct Case {
    std::string name, text, fragment;
  };
  const std::vector<Case> cases = {
      {"no_end_header", good.substr(0, body - 11), "no 'end_header'"},
      {"truncated_body", good.substr(0, body + 30), "truncated"},
      {"cut_in_faces", good.substr(0, good.size() - 12), "truncated"},
      {"trailing", good + "garbage", "after the last element"},
      {"bad_format", "ply\nformat binary 1.0\nend_header\n", "header line 2"},
      {"bad_type", "ply\nformat ascii 1.0\nelement vertex 1\nproperty real x\nend_header\n", "unknown type 'real'"},
      {"huge_count", "ply\nformat ascii 1.0\nelement vertex 2000000000\nproperty float x\nproperty float y\n"
                     "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n",
       "more than the rest of the file can hold"},
      {"no_z", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nelement face 1\n"
               "property list uchar int vertex_indices\nend_header\n0 0\n1 0\n0 1\n3 0 1 2\n",
       "lacks a scalar x, y or z"},
      {"faces_first", "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\nelement vertex 3\n"
                      "property float x\nproperty float y\nproperty float z\nend_header\n3 0 1 2\n0 0 0\n1 0 0\n0 1 0\n",
       "comes before"},
      {"word", ply("0 0 0\n1 zero 0\n0 1 0\n0 0 1\n", 1, "3 0 1 2\n"), "line 11: vertex 1, property 'y'"},
      {"float_index", ply(kVerts, 1, "3 0 1.5 2\n"), "not an integer"},
      {"negative_index", ply(kVerts, 1, "3 0 -1 2\n"), "face 0 has vertex index -1"},
      {"list_overflow", "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                        "element face 1\nproperty list uchar int vertex_indices\nend_header\n" + kVerts + "300 0 1 2\n",
       "not an integer of its type"},
  };
  for (const Case& c : cases) {
    const std::string p = d + "/" + c.name + ".ply";
    test::write_text(p, c.text);
    expect_error(p, c.fragment);
  }
}

TEST(MeshIo, MalformedOffIsAnErrorNamingTheLine) {
  const std::string d = test::temp_dir("mesh_io_off_faults");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 7\n", "face 0 has vertex index 7 outside [0, 4)"},
      {"OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n", "the file ends before face 1"},
      {"OFF\n4 1 0\n0 0 0\n1 0 0\n0 1\n0 0 1\n3 0 1 2\n", "line 5: vertex 2 has fewer than 3"},
      {"OFF\n400000000 1 0\n0 0 0\n", "no more than the file can hold"},
      {"OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n4 0 1 2 3\n", "face 0 has 4 vertices"},
      {"PLY\n", "does not start with 'OFF'"},
  };
  int k = 0;
  for (const auto& [text, fragment] : cases) {
    const std::string p = d + "/case" + std::to_string(k++) + ".off";
    test::write_text(p, text);
    expect_error(p, fragment);
  }
  // Counts on the OFF line, comments and colours after the indices are fine.
  test::write_text(d + "/ok.off", "OFF 4 2 0 # counts here\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2 255 0 0\n3 0 1 3\n");
  EXPECT_EQ(load_mesh(d + "/ok.off").F.rows(), 2);
}

TEST(MeshIo, RealSubjectsHaveTheTriangleCountsOfTheDataReadme) {
  // ../shared/data/README.md's table; every triangle of these closed meshes has area.
  const std::vector<std::tuple<std::string, int, int>> subjects = {
      {"lhdl-ct", 70422, 95256}, {"mc22", 34936, 61662}, {"tlem2-mri", 33036, 74586}};
  for (const auto& [name, femur, pelvis] : subjects) {
    const std::string dir = std::string(IMPINGE_SHARED_DATA) + "/" + name;
    if (!std::filesystem::exists(dir)) GTEST_SKIP() << "shared data absent: " << dir;
    const TriangleMesh f = load_mesh(dir + "/femur_r.ply"), p = load_mesh(dir + "/pelvis.ply");
    EXPECT_EQ(f.F.rows() + f.degenerate_faces_skipped, femur) << name;
    EXPECT_EQ(p.F.rows() + p.degenerate_faces_skipped, pelvis) << name;
  }
}
