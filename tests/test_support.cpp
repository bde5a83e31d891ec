#include "test_support.hpp"

#include <unistd.h>

#include <cstdlib>
#include <algorithm>
#include <random>
#include <numeric>
#include <map>
#include <vector>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "impinge/anatomy/sphere_fit.hpp"
#include "impinge/core/error.hpp"
#include "impinge/io/generated_models.hpp"
#include "impinge/io/mesh_io.hpp"
#include "impinge/io/subject.hpp"

namespace impinge::test {

std::optional<RealJoint> load_real_joint(const std::string& name) {
  const std::string dir = std::string(IMPINGE_SHARED_DATA) + "/" + name;
  if (!std::filesystem::exists(dir + "/subject.json")) return std::nullopt;
  const SubjectInfo info = load_subject(dir + "/subject.json");
  RealJoint j{load_mesh(info.femur_path), load_mesh(info.pelvis_path), Eigen::Vector3d::Zero()};
  transform_vertices(j.femur.V, to_working_frame(info.frame));
  transform_vertices(j.pelvis.V, to_working_frame(info.frame));
  j.cor = fit_femoral_head(j.femur).centre;
  return j;
}

Eigen::Matrix3d random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0, 1);
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  q.normalize();
  return q.toRotationMatrix();
}

TriangleMesh transformed(const TriangleMesh& m, const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  TriangleMesh out = m;
  for (Eigen::Index i = 0; i < out.V.rows(); ++i) out.V.row(i) = (R * m.V.row(i).transpose() + t).transpose();
  return out;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

bool inside_by_parity(const ExactReference& ref, const Eigen::Vector3d& q) {
  static const Eigen::Vector3d dirs[3] = {Eigen::Vector3d(0.5377, 0.1834, -0.8229).normalized(),
                                          Eigen::Vector3d(-0.4336, 0.8622, 0.3188).normalized(),
                                          Eigen::Vector3d(0.3426, -0.7254, 0.5972).normalized()};
  int votes = 0;
  for (const auto& d : dirs) votes += ref.all_hits(q, d).size() % 2;
  return votes >= 2;
}

std::string temp_dir(const std::string& name) {
  // One folder per process (two test runs on one machine must not clear each other's files), removed at exit.
  static std::vector<std::filesystem::path> made;
  static const bool cleanup = [] {
    std::atexit([] {
      std::error_code ec;
      for (const auto& q : made) std::filesystem::remove_all(q, ec);
    });
    return true;
  }();
  (void)cleanup;
  const auto p = std::filesystem::temp_directory_path() / ("impinge_test_" + name + "_" + std::to_string(getpid()));
  std::filesystem::remove_all(p);
  std::filesystem::create_directories(p);
  made.push_back(p);
  return p.string();
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream os(path, std::ios::binary);
  os << text;
}

double ray_sphere_far(const Eigen::Vector3d& o, const Eigen::Vector3d& u, const Eigen::Vector3d& c, double r) {
  const Eigen::Vector3d oc = o - c;
  const double b = oc.dot(u), cc = oc.squaredNorm() - r * r;
  return -b + std::sqrt(b * b - cc);
}

TriangleMesh concatenated(const TriangleMesh& a, const TriangleMesh& b) {
  TriangleMesh m;
  m.source = a.source + " + " + b.source;
  m.V.resize(a.V.rows() + b.V.rows(), 3);
  m.V << a.V, b.V;
  m.F.resize(a.F.rows() + b.F.rows(), 3);
  m.F << a.F, (b.F.array() + static_cast<int>(a.V.rows())).matrix();
  return m;
}

TriangleMesh make_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  TriangleMesh m;
  m.source = "box";
  m.V.resize(8, 3);
  for (int k = 0; k < 8; ++k)
    m.V.row(k) << ((k & 1) ? hi.x() : lo.x()), ((k & 2) ? hi.y() : lo.y()), ((k & 4) ? hi.z() : lo.z());
  m.F.resize(12, 3);
  // Faces x = lo, x = hi, y = lo, y = hi, z = lo, z = hi, each as two triangles wound outward.
  m.F << 0, 4, 6, 0, 6, 2,  //
      1, 3, 7, 1, 7, 5,     //
      0, 1, 5, 0, 5, 4,     //
      2, 6, 7, 2, 7, 3,     //
      0, 2, 3, 0, 3, 1,     //
      4, 5, 7, 4, 7, 6;
  return m;
}

const Session& generated_session(const std::string& frame) {
  auto make = [](FrameConvention f) {
    HipModelOptions g;
    g.target_triangles = 2000;
    g.cam_height_mm = 2;
    const HipModel h = make_hip_model(g);
    const Eigen::Matrix3d M = to_working_frame(f);  // RAS -> f (its own inverse)
    SessionOptions o;
    o.input.ball_mesh = h.ball;
    o.input.socket_mesh = h.socket;
    transform_vertices(o.input.ball_mesh->V, M);
    transform_vertices(o.input.socket_mesh->V, M);
    o.input.frame = f == FrameConvention::LPS ? "LPS" : "RAS";
    o.cor.given = M * h.cor;
    o.hip.neutral = Neutral::scan;
    o.grid.precision = 1;
    o.hip.joint.distances = true;
    o.hip.joint.distance_reach_mm = 6;
    return Session(o);
  };
  if (frame == "LPS") {
    static const Session lps = make(FrameConvention::LPS);
    return lps;
  }
  static const Session ras = make(FrameConvention::RAS);
  return ras;
}

// The same mesh with its vertices and faces in a random order and each face's corners turned.
TriangleMesh renumbered(const TriangleMesh& m, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<int> to(static_cast<std::size_t>(m.V.rows())), faces(static_cast<std::size_t>(m.F.rows()));
  std::iota(to.begin(), to.end(), 0), std::iota(faces.begin(), faces.end(), 0);
  std::shuffle(to.begin(), to.end(), rng), std::shuffle(faces.begin(), faces.end(), rng);
  TriangleMesh out;
  out.V.resize(m.V.rows(), 3), out.F.resize(m.F.rows(), 3);
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) out.V.row(to[static_cast<std::size_t>(i)]) = m.V.row(i);
  for (std::size_t k = 0; k < faces.size(); ++k) {
    const auto f = static_cast<Eigen::Index>(faces[k]);
    const int turn = static_cast<int>(k % 3);
    for (int c = 0; c < 3; ++c) out.F(static_cast<Eigen::Index>(k), c) = to[static_cast<std::size_t>(m.F(f, (c + turn) % 3))];
  }
  out.source = m.source + " renumbered";
  return out;
}

}  // namespace impinge::test
