#pragma once
// Shared fixtures and oracles for the tests.
#include <Eigen/Core>
#include <functional>
#include <optional>
#include <random>
#include <string>

#include "impinge/casters/exact_reference.hpp"
#include "impinge/core/mesh.hpp"
#include "impinge/session/session.hpp"

namespace impinge::test {

/// A random rotation from a seeded RNG.
Eigen::Matrix3d random_rotation(std::mt19937_64& rng);
/// Apply x -> R x + t to every vertex.
TriangleMesh transformed(const TriangleMesh& m, const Eigen::Matrix3d& R, const Eigen::Vector3d& t);
/// The same mesh with its vertices and faces in a random order (seeded) and each face's corners turned.
TriangleMesh renumbered(const TriangleMesh& m, unsigned seed);
/// A fresh temporary directory for a test.
std::string temp_dir(const std::string& name);
/// Whether `q` (mm) is inside the closed mesh behind `ref` by CGAL: the majority of three fixed rays' crossing
/// parities (ExactReference::all_hits). The ray-parity oracle of the distance and resection tests.
bool inside_by_parity(const ExactReference& ref, const Eigen::Vector3d& q);
/// Write text to a file.
void write_text(const std::string& path, const std::string& text);
/// The message of the impinge::Error that f throws, or "(no error)" when it throws none (any other exception
/// passes through).
std::string error_of(const std::function<void()>& f);
/// A real subject of ../shared/data/hips in the anatomical frame with its automatic COR, or
/// nullopt when the shared data folder is absent (the caller skips).
struct RealJoint {
  TriangleMesh femur, pelvis;
  Eigen::Vector3d cor;
};
std::optional<RealJoint> load_real_joint(const std::string& name);
/// One mesh of both meshes' triangles (a body of several closed parts).
TriangleMesh concatenated(const TriangleMesh& a, const TriangleMesh& b);
/// Closed axis-aligned box [lo, hi] (mm), 12 triangles wound outward.
TriangleMesh make_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi);
/// The session of a generated hip (2,000 triangles, 2 mm cam; scan neutral, its true COR given, 1 deg maps,
/// distances within 6 mm) with its meshes given in `frame` ("RAS" or "LPS"); built once per frame.
const Session& generated_session(const std::string& frame);
/// Analytic oracle: distance from origin o along unit u to the sphere (c, r), far root.
double ray_sphere_far(const Eigen::Vector3d& o, const Eigen::Vector3d& u, const Eigen::Vector3d& c, double r);

/// Hip joint options of scan neutral on equiangular maps of `precision_deg` (deg): the generated hips' ROM tests.
inline HipJointOptions scan_options(double precision_deg) {
  HipJointOptions o;
  o.neutral = Neutral::scan;
  o.joint.scheme = make_scheme("equiangular", precision_deg);
  return o;
}

}  // namespace impinge::test
