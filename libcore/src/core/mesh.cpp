#include "impinge/core/mesh.hpp"

#include <cmath>
#include <sstream>

#include "impinge/core/error.hpp"

namespace impinge {

void validate_mesh(const TriangleMesh& mesh) {
  const std::string& src = mesh.source.empty() ? std::string("<mesh>") : mesh.source;
  require(mesh.V.rows() > 0, src + ": mesh has no vertices");
  require(mesh.F.rows() > 0, src + ": mesh has no triangles");
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i) {
    for (int k = 0; k < 3; ++k) {
      if (!std::isfinite(mesh.V(i, k))) {
        std::ostringstream os;
        os << src << ": vertex " << i << " has a non-finite coordinate (" << mesh.V(i, 0) << ", " << mesh.V(i, 1)
           << ", " << mesh.V(i, 2) << ")";
        throw Error(os.str());
      }
    }
  }
  const Eigen::Index n = mesh.V.rows();
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int idx = mesh.F(f, k);
      if (idx < 0 || idx >= n) {
        std::ostringstream os;
        os << src << ": face " << f << " has vertex index " << idx << " outside [0, " << n << ")";
        throw Error(os.str());
      }
    }
  }
}

int remove_degenerate_faces(TriangleMesh& mesh, double min_area_mm2) {
  validate_mesh(mesh);
  Faces kept(mesh.F.rows(), 3);
  Eigen::Index k = 0;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const int a = mesh.F(f, 0), b = mesh.F(f, 1), c = mesh.F(f, 2);
    if (a == b || b == c || a == c) continue;
    const Eigen::Vector3d pa = mesh.V.row(a), pb = mesh.V.row(b), pc = mesh.V.row(c);
    const double area = 0.5 * (pb - pa).cross(pc - pa).norm();
    if (!(area > min_area_mm2)) continue;
    kept.row(k++) = mesh.F.row(f);
  }
  const int removed = static_cast<int>(mesh.F.rows() - k);
  mesh.F = kept.topRows(k).eval();
  mesh.degenerate_faces_skipped += removed;
  return removed;
}

Eigen::VectorXd vertex_areas(const TriangleMesh& mesh) {
  validate_mesh(mesh);
  Eigen::VectorXd area = Eigen::VectorXd::Zero(mesh.V.rows());
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    const Eigen::Vector3d pa = mesh.V.row(mesh.F(f, 0)), pb = mesh.V.row(mesh.F(f, 1)), pc = mesh.V.row(mesh.F(f, 2));
    const double third = (pb - pa).cross(pc - pa).norm() / 6.0;
    for (int k = 0; k < 3; ++k) area[mesh.F(f, k)] += third;
  }
  return area;
}

TriangleMesh submesh(const TriangleMesh& mesh, const std::vector<std::uint8_t>& keep_vertex,
                     std::vector<Eigen::Index>* kept) {
  validate_mesh(mesh);
  require(keep_vertex.size() == static_cast<std::size_t>(mesh.V.rows()),
          mesh.source + ": submesh: the vertex selection has " + std::to_string(keep_vertex.size()) +
              " entries for " + std::to_string(mesh.V.rows()) + " vertices");
  std::vector<int> index(keep_vertex.size(), -1);
  std::vector<Eigen::Index> used;
  std::vector<Eigen::Vector3i> faces;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    bool in = true;
    for (int c = 0; c < 3; ++c) in = in && keep_vertex[static_cast<std::size_t>(mesh.F(f, c))] != 0;
    if (!in) continue;
    Eigen::Vector3i idx;
    for (int c = 0; c < 3; ++c) {
      int& k = index[static_cast<std::size_t>(mesh.F(f, c))];
      if (k < 0) k = static_cast<int>(used.size()), used.push_back(mesh.F(f, c));
      idx[c] = k;
    }
    faces.push_back(idx);
  }
  TriangleMesh out;
  out.source = mesh.source;
  out.V.resize(static_cast<Eigen::Index>(used.size()), 3);
  for (std::size_t k = 0; k < used.size(); ++k) out.V.row(static_cast<Eigen::Index>(k)) = mesh.V.row(used[k]);
  out.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (std::size_t k = 0; k < faces.size(); ++k) out.F.row(static_cast<Eigen::Index>(k)) = faces[k].transpose();
  if (kept != nullptr) *kept = std::move(used);
  return out;
}

}  // namespace impinge
