#pragma once
// Private to libcore/src/clinical: the exact contact test of the ROM searches (RomOptions::exact_contact,
// issue 81): whether the bones meet at a pose is the least exact distance between their counted
// triangles (MeshContact: vertex against face and edge against edge), not a vertex's gap, so that a limit
// does not depend on where the vertices lie. Included by rom.cpp and rom_exact.cpp only.

#include <memory>

#include "clinical/rom_scanner.hpp"
#include "impinge/detection/mesh_contact.hpp"

namespace impinge {
namespace rom_detail {

// Whether a search whose bones meet at `cut` (threshold less contact depth, mm) finds its contacts
// exactly: a cut >= 0 (a depth of overlap has no exact mesh-to-mesh meaning; the per-vertex depth
// serves), with the radial metric only at 0 (where the radial gap and the distance agree), every vertex
// counted (RomVertices::all).
inline bool exact_at(const RomOptions& o, double cut) {
  return o.exact_contact && o.vertices == RomVertices::all && cut >= 0 &&
         (o.metric == RomMetric::distance || cut == 0);
}
// Whether a search with these options and baseline finds its contacts exactly.
inline bool exact_search(const RomOptions& o, const RomBaseline& base) {
  return exact_at(o, cut_of(o)) && base.contact != nullptr;
}

// The baseline's contact meshes (RomBaseline::contact): the femur's and the pelvis' triangles about the
// COR (the femur moves), a triangle counted when any of its corners is (not in base's skip lists), less
// both triangles of every pair (counted or not) within `threshold` (mm) at the baseline pose (R, t): a
// pre-existing overlap, as the skip lists leave out its vertices.
std::shared_ptr<const MeshContact> baseline_contact(const Joint& joint, const RomBaseline& base,
                                                    const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                                    double threshold);

// The exact test at a pose, with the pelvis' contacts classed at the pose as CompactScanner::take does
// (a pelvis triangle counts at a pose when one of its corners counts there).
class ExactScanner {
 public:
  ExactScanner(const Joint& joint, const RomBaseline& base, double cut);
  // full = false: a Least with gap <= the cut when a counted pair lies within it (the first found), else
  // gap = +inf. full: the least distance over every counted pair and where (Least::point), with the
  // counted corner nearest it as the vertex (the femur's when the femur's triangle counts).
  Least operator()(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, bool full) const;

 private:
  MeshContact::Query query_at(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, double reach, bool first) const;
  const Joint& joint_;
  const RomBaseline& base_;
  const MeshContact& contact_;
  PelvisContacts pelvis_;
  double cut_;
};

}  // namespace rom_detail
}  // namespace impinge
