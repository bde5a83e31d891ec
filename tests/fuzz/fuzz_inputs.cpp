#include "fuzz_inputs.hpp"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "impinge/core/error.hpp"
#include "impinge/io/mesh_io.hpp"
#include "impinge/io/motion.hpp"
#include "impinge/io/subject.hpp"

namespace impinge::fuzz {

namespace {

// One scratch folder per process, so parallel fuzzers and test shards do not share files.
std::filesystem::path scratch_dir() {
  static const std::filesystem::path dir = [] {
    std::filesystem::path d = std::filesystem::temp_directory_path() / ("impinge-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

std::string write_input(const std::string& name, const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path p = scratch_dir() / name;
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  if (!out) throw std::runtime_error("fuzz harness: cannot write " + p.string());
  return p.string();
}

template <typename Body>
Outcome guarded(Body&& body) {
  try {
    std::string broken = body();
    if (!broken.empty()) return {Outcome::bug, broken};
    return {Outcome::accepted, {}};
  } catch (const Error& e) {
    return {Outcome::refused, e.what()};
  } catch (const std::exception& e) {
    return {Outcome::bug, std::string("exception other than impinge::Error: ") + e.what()};
  } catch (...) {
    return {Outcome::bug, "non-standard exception"};
  }
}

}  // namespace

Outcome mesh_input(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return {Outcome::refused, "empty input"};
  static const char* const kExt[] = {".ply", ".stl", ".obj", ".off"};
  const std::string path = write_input(std::string("mesh") + kExt[data[0] % 4], data + 1, size - 1);
  return guarded([&]() -> std::string {
    const TriangleMesh m = load_mesh(path);
    if (m.V.rows() == 0 || m.F.rows() == 0) return "accepted an empty mesh";
    for (Eigen::Index i = 0; i < m.V.rows(); ++i)
      for (int k = 0; k < 3; ++k)
        if (!std::isfinite(m.V(i, k))) return "accepted a non-finite vertex " + std::to_string(i);
    for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
      for (int k = 0; k < 3; ++k)
        if (m.F(f, k) < 0 || m.F(f, k) >= m.V.rows()) return "accepted face " + std::to_string(f) + " out of range";
      if (m.F(f, 0) == m.F(f, 1) || m.F(f, 1) == m.F(f, 2) || m.F(f, 0) == m.F(f, 2))
        return "accepted degenerate face " + std::to_string(f);
    }
    return {};
  });
}

Outcome subject_input(const std::uint8_t* data, std::size_t size) {
  const std::string path = write_input("subject.json", data, size);
  return guarded([&]() -> std::string {
    const SubjectInfo s = load_subject(path);
    if (s.femur_path.empty() || s.pelvis_path.empty()) return "accepted a subject without mesh paths";
    for (const auto& [name, p] : s.landmarks)
      if (!p.allFinite()) return "accepted a non-finite landmark " + name;
    return {};
  });
}

Outcome motion_input(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return {Outcome::refused, "empty input"};
  static const char* const kExt[] = {".mot", ".sto", ".csv"};
  const std::string path = write_input(std::string("motion") + kExt[data[0] % 3], data + 1, size - 1);
  const Side side = (data[0] & 0x80) ? Side::left : Side::right;
  return guarded([&]() -> std::string {
    const Motion m = load_motion(path, side);
    if (m.frames() == 0) return "accepted a motion without frames";
    if (m.time_s.size() != m.angles.size()) return "times and poses differ in number";
    for (std::size_t k = 0; k < m.frames(); ++k) {
      const PoseAngles& a = m.angles[k];
      if (!std::isfinite(a.flexion_deg) || !std::isfinite(a.adduction_deg) || !std::isfinite(a.internal_rotation_deg) ||
          !std::isfinite(m.time_s[k]))
        return "accepted a non-finite value at frame " + std::to_string(k);
      if (k > 0 && m.time_s[k] < m.time_s[k - 1]) return "accepted decreasing times at frame " + std::to_string(k);
    }
    return {};
  });
}

Outcome run_input(const std::string& target, const std::uint8_t* data, std::size_t size) {
  if (target == "mesh") return mesh_input(data, size);
  if (target == "subject") return subject_input(data, size);
  if (target == "motion") return motion_input(data, size);
  throw std::invalid_argument("unknown fuzz target '" + target + "'");
}

}  // namespace impinge::fuzz
