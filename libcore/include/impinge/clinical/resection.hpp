#pragma once
/// @file resection.hpp
/// Resection planning: the bone to remove (a femoral osteochondroplasty of a cam, a trim of a pincer rim) so that
/// target motions run free of impingement. Source: impinge (not in the thesis, which names impingement detection
/// as one step of a computer-aided surgical plan, ch. 1); the safety limit on depth after Mardones et al. 2005
/// (J Bone Joint Surg Am 87:273: a resection deeper than about 30 % of the neck's diameter weakens the neck); the
/// burr after arthroscopic practice (spherical burrs of 4-5.5 mm diameter).
///
/// Method. Let F be the femur, and P_k the pelvis seen from the femur at the target poses k (the pelvis moved by
/// the inverse of pose k). Bone that has to go is exactly F intersected with the union of the P_k grown by the
/// clearance c: any removal that leaves a point of it in place leaves the bones closer than c at some pose, and
/// any removal containing it clears every pose. That set is the least removal; the plan approximates it per
/// vertex. Each vertex i moves inwards along its (area-weighted) normal n_i by a depth d_i, so the resected mesh
/// has the input's vertices, faces and therefore its topology (closed and manifold where the input was):
/// 1. the contacts: at every target pose, every counted vertex of either bone (RomBaseline's, with the articular
///    contacts of the pose left out as the ROM search leaves them out) whose exact signed distance to the other
///    bone (HipJoint::joint().detect, JointOptions::distances) is below c + 1 mm, or which lies inside it;
/// 2. the depth each contact asks for: a vertex of the resected bone at signed distance s < c asks for c - s
///    more; a vertex u of the other bone (a rim's edge pressing into the neck) asks the three vertices of the
///    resected bone's triangle nearest to it for c - s more, s its signed distance to the resected surface;
/// 3. the burr: the required depth field r is widened into what a spherical burr of radius b cuts when its tip
///    reaches r_j below the surface at each vertex j: d_i = max_j (r_j - (b - sqrt(b^2 - |x_i - x_j|^2))) over
///    |x_i - x_j| < b, the least burr-cut surface that contains the required one on a surface flat at the
///    burr's scale; then d_i is capped at the safety depth and at half the bone's thickness under the vertex (the
///    first hit of the inward ray along -n_i with the input's surface: a thin rim or trochanter is not cut
///    through), and 0 on the protected surfaces: the femoral head's
///    articular surface inside the labrum line (ArticularZones' head surface on the inner side of the acetabular
///    rim's plane with the femur at neutral; the head-neck junction outside it, where an osteochondroplasty
///    restores the offset, may go) and the lunate surface; with scan neutral, the head sphere's surface within
///    0.5 mm and the cup's surface facing the centre within the head radius + 3 mm;
/// 4. the vertices moved, steps 2-3 are repeated on the resected bones (exact distances again) until every contact
///    is at least c apart or `max_iterations` pass: moving along n_i clears a tilted contact by less than its
///    depth, so a few rounds are needed; a contact closer than c asks (in step 2) for `tolerance_mm` more than
///    c - s, so that the rounds end with every contact at least c apart, not within a tolerance of it.
/// A contact whose depth cannot be taken (every vertex that could take it is protected or at the safety depth)
/// makes its pose unreachable: the target is planned up to the last pose before it, and the plan is made again
/// without the unreachable poses, so no bone is removed for a motion it cannot restore.
/// How far from least: (a) the burr's widening, which a user sets (burr_radius_mm = 0: none); (b) the per-vertex
/// resolution: a contact between vertices is taken by the nearest triangle's three vertices, at most about one
/// edge (1-2 mm on the shared hips) wider than the exact region; (c) moving along the normal where the contact is
/// tilted, which step 4 corrects from the excess side (it only adds). Measured in experiment 16 against cams of
/// known volume.

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "impinge/anatomy/pose.hpp"
#include "impinge/clinical/hip_joint.hpp"
#include "impinge/clinical/rom.hpp"
#include "impinge/core/mesh.hpp"
#include "impinge/core/enum_names.hpp"
#include "impinge/core/range.hpp"

namespace impinge {

/// A vertex moved deeper than this counts as resected (area, vertices, mean depth, clock extent), mm.
inline constexpr double kResectedDepthMm = 0.01;

/// Which bone a plan may resect.
enum class ResectBones {
  femur,   ///< the cam: femoral osteochondroplasty (the default)
  pelvis,  ///< the rim: acetabular rim trim (a pincer)
  both,    ///< each contact's depth shared half and half where both bones can take it
};
/// The names of ResectBones (the option table's choices of --resect).
inline constexpr EnumNames<ResectBones, 3> kResectBonesNames{
    {{ResectBones::femur, "femur"}, {ResectBones::pelvis, "pelvis"}, {ResectBones::both, "both"}}};
/// "femur", "pelvis", "both".
const char* to_string(ResectBones bones);
/// Parse "femur", "pelvis" or "both". Throws impinge::Error naming `context` and the valid values otherwise.
ResectBones parse_resect_bones(const std::string& text, const std::string& context);

/// The poses one target asks to be free of impingement, in order along its motion.
struct ResectionTarget {
  std::string name;                                             ///< a standard motion's name, or a motion file
  double angle_deg = std::numeric_limits<double>::quiet_NaN();  ///< the angle to reach (NaN for a motion file)
  std::vector<PoseAngles> poses;                                ///< degrees, ISB
  std::vector<double> theta_deg;  ///< per pose: the motion's angle (NaN on a lead-in to the start), or the frame
};

/// Options of plan_resection.
struct ResectionOptions {
  ResectBones bones = ResectBones::femur;
  double clearance_mm = 0.3;  ///< c: the least distance the bones keep at every target pose, mm
  static constexpr Range kClearanceRange{0, 5};  ///< of clearance_mm, mm
  /// The safety depth, mm: no vertex is resected deeper (the caller's; run_plan sets it from PlanRequest's
  /// max_depth_mm or max_depth_fraction).
  double safety_depth_mm = std::numeric_limits<double>::infinity();
  double burr_radius_mm = 2.5;     ///< b: the spherical burr's radius, mm (0: no widening)
  static constexpr Range kBurrRadiusRange{0, 10};  ///< of burr_radius_mm, mm
  double tolerance_mm = 0.02;      ///< a contact closer than c asks for this more than it misses, mm (step 4)
  int max_iterations = 16;         ///< rounds of step 4
  double candidate_margin_mm = 1;  ///< contacts: vertices within c + this of the other bone, mm
  /// Per vertex of the femur and of the pelvis (or empty: none), the depth an earlier plan already removed, mm
  /// (a further round on its resected bones, run_plan): the safety depth caps the sum, this round's depth at
  /// safety_depth_mm less it.
  std::vector<double> femur_removed_mm, pelvis_removed_mm;
};

/// What is removed from one bone.
struct BoneResection {
  bool allowed = false;                        ///< the options let this bone be resected
  std::vector<double> depth_mm;                ///< per vertex, >= 0 (input vertex order)
  std::vector<std::uint8_t> protected_vertex;  ///< 1: never resected (articular surface)
  Vertices resected;                           ///< n x 3, joint frame, mm (the input's faces)
  Vertices normals;                            ///< n x 3 unit outward vertex normals (area-weighted), joint frame
  double volume_mm3 = 0;                       ///< the input's enclosed volume less the resected one's
  double area_mm2 = 0;                         ///< surface whose depth exceeds kResectedDepthMm (vertex areas)
  double deepest_cut_mm = 0, mean_depth_mm = 0;  ///< the largest and the mean depth (area-weighted over that surface)
  std::int64_t vertices = 0;                   ///< vertices with depth > kResectedDepthMm
  std::int64_t capped_vertices = 0;            ///< vertices held at the safety depth
  std::int64_t thin_vertices = 0;              ///< vertices held at half the bone's thickness under them
};

/// Fill `out`'s summary (volume_mm3, area_mm2, deepest_cut_mm, mean_depth_mm, vertices, capped_vertices; not
/// thin_vertices) from its depth_mm (n, mm) and resected (n x 3, mm): `original` (n x 3, mm, the same frame) and `F`
/// the bone before any resection, `vertex_area` (n, mm^2) its vertex areas, `cap_mm` the safety depth. Throws
/// impinge::Error when the sizes differ.
void summarize_resection(BoneResection& out, const Vertices& original, const Faces& F, const Eigen::VectorXd& vertex_area,
                         double cap_mm);

/// Per target: whether the plan clears it.
struct ResectionTargetResult {
  std::string name;
  double angle_deg = std::numeric_limits<double>::quiet_NaN();
  bool reachable = true;  ///< every pose cleared within the safety depth and off the protected surfaces
  /// The last motion angle cleared (the target when reachable; NaN for motion files and when not even the first
  /// pose is cleared), deg.
  double reachable_deg = std::numeric_limits<double>::quiet_NaN();
  std::int64_t poses = 0, poses_cleared = 0;
  std::string note;  ///< why a pose cannot be cleared (which surface or the safety depth), else empty
};

/// A resection plan.
struct ResectionPlan {
  ResectionOptions options;
  BoneResection femur, pelvis;  ///< pelvis.allowed false: no pelvis resection (depth all 0)
  std::vector<ResectionTargetResult> targets;
  int iterations = 0;                    ///< rounds of step 4 in the last plan
  int rounds = 0;                        ///< plans made (1 + one per round of dropping unreachable poses)
  /// Plans on the resected bones (run_plan: 1, plus one per further round after a check that missed a target)
  int passes = 1;
  double residual_mm = 0;                ///< the largest depth a kept contact still asks for (c + tolerance - s), mm
  std::int64_t poses = 0, contacts = 0;  ///< poses scanned; (pose, vertex) contacts followed
  double ms = 0;                         ///< wall time, ms
};

/// Plan the least resection (the file comment's method) of `hip`'s bones that frees every pose of `targets`:
/// each pose is femur_pose(angles) (the joint-centre method's translation), the contacts counted as the ROM
/// search counts them (`baseline`: rom_baseline with the search's contacts; JointOptions::distances must be on,
/// with a reach of at least clearance + candidate_margin_mm). Poses run on all cores (OpenMP). Throws
/// impinge::Error naming the option on a negative clearance, depth or burr radius, no distances, or a reach
/// below the clearance.
ResectionPlan plan_resection(const HipJoint& hip, const std::vector<ResectionTarget>& targets,
                             const RomBaseline& baseline, const ResectionOptions& options);

/// The volume (mm^3) a closed mesh (V: n x 3, F: m x 3) encloses: the divergence theorem's sum of signed
/// tetrahedra, its absolute value. Never throws.
double enclosed_volume(const Vertices& V, const Faces& F);

/// The femoral neck's least diameter (mm): along the neck axis (unit, towards the head centre), in 2 mm slabs from
/// half a head radius to 2.5 head radii outside the head centre, the median distance from the axis of the femur's
/// vertices (V: n x 3, F: m x 3, mm) outside the head sphere on the neck's wall (normal within 60 deg of normal to
/// the axis), twice the least over slabs whose vertices ring the axis (every 30 deg sector) and number at least
/// 12. NaN when no slab does. Source: impinge (the neck's diameter as Mardones et al. 2005 measure it, at its
/// narrowest).
double neck_diameter_mm(const Vertices& femur, const Faces& faces, const Eigen::Vector3d& head_centre,
                        double head_radius_mm, const Eigen::Vector3d& neck_axis);

}  // namespace impinge
