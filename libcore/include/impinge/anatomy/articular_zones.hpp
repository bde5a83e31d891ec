#pragma once
/// @file articular_zones.hpp
/// The joint surfaces of a hip, so that a contact can be told apart: the femoral head's articular
/// surface meeting the acetabulum's lunate surface is the joint space closing, not impingement;
/// impingement is the head-neck junction or neck against the acetabular rim (intra-articular) or
/// the trochanters or neck against the ilium, the anterior inferior iliac spine or the ischium
/// (extra-articular) (Ganz et al. 2003, Clin Orthop 417:112; Tannast et al. 2007, J Orthop Res
/// 25:122).
///
/// The zones come from what impinge fits already: the femoral head sphere (centre c_h, radius
/// r_h), the acetabular sphere (c_a, r_a) and the rim plane (find_acetabulum).
/// - The lunate surface: pelvis vertices inside the cup, at least rim_margin_mm below the rim plane,
///   and no farther from c_a than r_a + t_a. The rim itself stays countable, so the rim against the
///   head-neck junction or the neck (pincer, and cam seen from the pelvis) is impingement.
/// - The head: femur vertices within the sphere about c_h that holds the acetabular shell,
///   max(r_h + t_h, r_a + t_a + |c_a - c_h|). There a femur point can only meet the lunate surface
///   or, past the rim, the rim, which is counted from the pelvis; an MRI head or cup is not a
///   sphere (the contacts that ended tlem2-mri's and mc22's searches lie 1-3 mm outside the head
///   sphere, in the cup). Farther femur vertices (a large cam, the neck, the trochanters) are counted
///   from the femur too.
/// - A pelvis vertex that meets the femur within r_h + t_h of the head centre meets the head's
///   joint surface, wherever on the acetabulum it lies (the lunate surface or the rim over the head):
///   that too is the joint, not impingement, which is the head-neck junction or neck against the rim.
///   This depends on the pose, so it is applied where a contact is found (HipJoint::contact_class, the
///   ROM searches), with head_sphere_reach_mm.
/// Tolerances t_h, t_a: twice the sphere fit's rms residual (the surface's own roughness about its
/// sphere; 0.4-0.8 mm on the shared hips), at least min_tolerance_mm.

#include <cstdint>
#include <vector>

#include "impinge/anatomy/clock_face.hpp"
#include "impinge/anatomy/sphere_fit.hpp"
#include "impinge/core/mesh.hpp"

namespace impinge {

/// How a contact (or the closest approach) of femur and pelvis is classed.
enum class ContactClass {
  none,                         ///< no contact (no limit, nothing tested)
  articular,                    ///< the head's joint surface against the lunate surface: the joint space closing
  intra_articular_impingement,  ///< head-neck junction or neck against the acetabular rim
  extra_articular_impingement,  ///< trochanters or neck against the ilium, AIIS or ischium
  labral,                       ///< the femur against the acetabular labrum (labrum.hpp), off the head's joint surface
};
/// "", "articular", "intra_articular_impingement", "extra_articular_impingement", "labral".
const char* to_string(ContactClass c);

/// Tolerances of the articular zones (see the file comment).
struct ArticularZoneOptions {
  double min_tolerance_mm = 1.0;  ///< least distance from a sphere that still counts as on it, mm
  double rms_factor = 2.0;        ///< tolerance = max(min_tolerance_mm, rms_factor x the fit's rms residual)
  double rim_margin_mm = 2.0;     ///< the lunate zone ends this far below the rim plane, mm
};

/// The articular surfaces of one hip, per vertex.
struct ArticularZones {
  std::vector<std::uint8_t> femur;   ///< 1: on the femoral head's articular surface (one per femur vertex)
  std::vector<std::uint8_t> pelvis;  ///< 1: on the lunate surface (one per pelvis vertex)
  double head_tolerance_mm = 0, lunate_tolerance_mm = 0;
  /// r_h + t_h: a pelvis vertex within this of the head centre in the femur's frame meets the head's
  /// joint surface (mm).
  double head_sphere_reach_mm = 0;
  std::int64_t femur_vertices = 0, pelvis_vertices = 0;  ///< how many are articular
};

/// The zones of `femur` about its head sphere `head` (centre, radius; rms NaN: the minimum
/// tolerance) and of `pelvis` about `acetabulum`, all in one frame (mm). Never throws.
ArticularZones find_articular_zones(const TriangleMesh& femur, const SphereFitResult& head, const TriangleMesh& pelvis,
                                    const Acetabulum& acetabulum, const ArticularZoneOptions& options = {});

}  // namespace impinge
