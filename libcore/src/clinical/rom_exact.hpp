#pragma once
// Private to libcore/src/clinical: the exact contact test of the ROM searches (RomOptions::exact_contact,
// issue 81): whether the bones meet at a pose is the least exact distance between their counted
// triangles (MeshContact: vertex against face and edge against edge), not a vertex's gap, so that a limit
// does not depend on where the vertices lie. Included by rom.cpp and rom_exact.cpp only.

#include <cstdint>
#include <memory>
#include <vector>

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
// COR (the femur moves). A pair of triangles is classed by where it comes nearest: by the femur's closest
// point, unposed, against the head up to its head-neck junction (base.meets_head; at a touch the pelvis'
// point carried onto the femur is the same point), so that a triangle across the junction counts on its
// neck side only and the class does not depend on where the vertices lie (issue 81). A femur triangle wholly
// on one side (head_side_of_face) is decided once; one the junction or the head's reach may cross is classed
// pair by pair (MeshContact's 2). With RomContacts::all or no head zone (scan neutral) every pair counts.
// Left out: every femur triangle with a corner in `skip_ball_pre` (the vertices within the threshold at the
// baseline, before any articular class) or in a pair within `threshold` (mm) at the baseline pose (R, t): a
// pre-existing overlap, as the skip lists leave out its vertices.
std::shared_ptr<const MeshContact> baseline_contact(const Joint& joint, const RomBaseline& base,
                                                    const std::vector<std::uint8_t>& skip_ball_pre,
                                                    const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                                    double threshold);

// Where the triangle (a, b, c) (mm, the zone's frame) lies against `zone`: 1 wholly inside it (FemoralHeadZone::
// contains at every point), 0 wholly outside, -1 either (the junction or the reach may cross it). Conservative:
// the triangle's angular extent seen from the head centre widens its range of angles from the neck and of
// azimuths, and the junction's least and largest angle over those azimuths decide.
int head_side_of_face(const FemoralHeadZone& zone, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                      const Eigen::Vector3d& c);

// The exact test at a pose, each pair classed at the pose by where it comes nearest (baseline_contact).
class ExactScanner {
 public:
  ExactScanner(const Joint& joint, const RomBaseline& base, double cut);
  // full = false: a Least with gap <= the cut when a counted pair lies within it (the first found), else
  // gap = +inf. full: the least distance over every counted pair and where (Least::point), with the
  // femur's corner nearest it as the vertex.
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
