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
/// - The head: femur vertices on the head side of the head-neck junction (FemoralHeadZone: per 5 deg of
///   azimuth about the neck axis, the angle from the neck where the surface, coming from the neck, first lies
///   within the head's radius plus the alpha angle's tolerance: the same junction the alpha angle is read at,
///   morphology.hpp), never a ball radius alone (issue 81: on an MRI hip with a 3.4-6.2 mm joint space a
///   ball holding the acetabular shell reached the neck, 30.8 mm from a 25.6 mm head's centre, and hid its
///   contact with the lunate surface). Within that side, no farther from c_h than
///   max(r_h + t_h, r_a + t_a + |c_a - c_h|): an MRI head is not a sphere (the contacts that ended
///   tlem2-mri's and mc22's searches lie 1-3 mm outside the head sphere, in the cup) and its bumps on the
///   head side are still the head. The neck, a cam at the head-neck junction and the trochanters are
///   always counted.
/// - A pelvis vertex that meets the femur within that reach of the head centre and on the head side of the
///   junction meets the head's joint surface, wherever on the acetabulum it lies (the lunate surface meeting
///   the neck or a cam below the junction does not: it is impingement, counted) (the lunate surface or the rim over the head):
///   that too is the joint, not impingement, which is the head-neck junction or neck against the rim.
///   This depends on the pose, so it is applied where a contact is found (HipJoint::contact_class, the
///   ROM searches), with head_sphere_reach_mm.
/// Tolerances t_h, t_a: twice the sphere fit's rms residual (the surface's own roughness about its
/// sphere; 0.4-0.8 mm on the shared hips), at least min_tolerance_mm.

#include <array>
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

/// Azimuth bins of the head-neck junction about the neck axis (5 deg each).
inline constexpr int kJunctionBins = 72;

/// How far beyond the head sphere's radius the femur's surface counts as having left it, mm: twice the fit's
/// rms residual, at least 0.5 mm (NaN rms: 0.5). The head-neck junction's and the alpha angle's (morphology.hpp).
double head_junction_tolerance_mm(double rms_residual_mm);

/// The femoral head as a region of space about its centre, bounded by the head-neck junction (issue 81,
/// item 1). In one frame (working, or HipJoint's joint frame after transformed()).
struct FemoralHeadZone {
  ClockFace clock;   ///< centre: the head centre; axis: the neck axis towards the head; twelve and three
  double radius_mm = 0;     ///< the head sphere's radius r_h, mm
  double tolerance_mm = 0;  ///< head_junction_tolerance_mm of the fit, mm
  /// A point farther from the centre than this is not the head and does not meet it, mm (find_articular_zones:
  /// max(r_h + t_h, r_a + t_a + |c_a - c_h|), see the file comment).
  double reach_mm = 0;
  /// Per azimuth bin k (centred at 5k deg from twelve towards three about the axis): the angle, from the
  /// neck's direction (-axis), of the head-neck junction, deg; NaN where the bin had no surface within the
  /// head's reach (filled from its neighbours; every bin NaN: no femur vertex near the head sphere).
  std::array<double, kJunctionBins> junction_deg{};
  /// The junction's angle at azimuth `azimuth_deg` (deg from twelve towards three): the larger of the two
  /// nearest bins' (so a cam's edge between bins stays on the neck side). NaN when every bin is NaN.
  double junction_at(double azimuth_deg) const;
  /// p (mm, the zone's frame) lies on the head side of the junction: its angle from the neck's direction is
  /// at least junction_at(its azimuth). False on the axis' neck side within 5 deg and when the junction is NaN.
  bool on_head_side(const Eigen::Vector3d& p) const;
  /// p within reach_mm of the centre and on the head side: a pelvis point there meets the head's joint surface.
  bool contains(const Eigen::Vector3d& p) const;
  /// The same zone in another frame: points x -> R x + t (R: 3 x 3 rotation, t: mm).
  FemoralHeadZone transformed(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) const;
};

/// The head-neck junction of `femur` (mm) about `clock` (its centre the head centre, its axis the neck axis
/// towards the head: femoral_clock_face) for a head of radius `radius_mm`: in each 5 deg azimuth bin the least
/// angle from the neck's direction (at least 5 deg) of a femur vertex within radius_mm + tolerance_mm of the
/// centre. Along a ray from the centre the first surface is the nearest, so no surface lies within that
/// distance at a smaller angle: the vertices' version of the alpha angle's sweep of rays (morphology.hpp;
/// Noetzli et al. 2002), agreeing with it to the vertex spacing (tested). reach_mm = radius_mm + reach_tolerance_mm.
/// Empty bins take their nearest non-empty neighbours' larger value. Never throws.
FemoralHeadZone find_femoral_head_zone(const TriangleMesh& femur, const ClockFace& clock, double radius_mm,
                                       double tolerance_mm, double reach_tolerance_mm);

/// Where on the femur a contact lies (femur frame): the head (on the head side of the junction), the
/// head-neck junction (within 20 deg of it on the neck side: where a cam sits), the neck (within 2 r_h of the
/// head centre along the neck and r_h of its axis), the trochanters (the rest: the greater and lesser
/// trochanters, the intertrochanteric region and the shaft). impinge's geometric reading of Ganz et al. 2003.
enum class FemoralZone { none, head, head_neck_junction, neck, trochanter };
/// "", "head", "head_neck_junction", "neck", "trochanter".
const char* to_string(FemoralZone zone);
/// The zone of p (mm, the zone's frame) about `head` (see FemoralZone). none when the junction is NaN.
FemoralZone femoral_zone(const FemoralHeadZone& head, const Eigen::Vector3d& p);

/// Where on the pelvis a contact lies: the lunate surface (in the cup, at least the rim margin below the rim
/// plane, within r_a + t_a of the acetabular centre), the fossa (in the cup, deeper), the rim (within 5 mm of
/// a rim point), else by the acetabular clock (12 superior, 3 anterior, 6 at the notch, either side) of the
/// point: the anterior inferior iliac spine at 1-3 o'clock, the pubis 3-6, the ischium 6-9, the ilium 9-1.
/// impinge's reading of the regions named by Ganz et al. 2003 and Tannast et al. 2007.
enum class PelvicZone { none, lunate, fossa, rim, aiis, pubis, ischium, ilium };
/// "", "lunate", "fossa", "rim", "aiis", "pubis", "ischium", "ilium".
const char* to_string(PelvicZone zone);

/// Tolerances of the articular zones (see the file comment).
struct ArticularZoneOptions {
  double min_tolerance_mm = 1.0;  ///< least distance from a sphere that still counts as on it, mm
  double rms_factor = 2.0;        ///< tolerance = max(min_tolerance_mm, rms_factor x the fit's rms residual)
  double rim_margin_mm = 2.0;     ///< the lunate zone ends this far below the rim plane, mm
};

/// The articular surfaces of one hip, per vertex.
struct ArticularZones {
  std::vector<std::uint8_t> femur;   ///< 1: on the femoral head's articular surface (one per femur vertex)
  FemoralHeadZone head;              ///< the head up to its junction (same frame as the meshes)
  std::vector<std::uint8_t> pelvis;  ///< 1: on the lunate surface (one per pelvis vertex)
  double head_tolerance_mm = 0, lunate_tolerance_mm = 0;
  /// r_h + t_h, mm: the head sphere with its tolerance (the equidistant joint centre's guard, JointCentre; the
  /// pelvis' contacts are classed by `head`).
  double head_sphere_reach_mm = 0;
  std::int64_t femur_vertices = 0, pelvis_vertices = 0;  ///< how many are articular
};

/// The zones of `femur` about its head sphere `head` (centre, radius; rms NaN: the minimum
/// tolerance) and head-neck clock `clock` (femoral_clock_face; its centre moved to the head centre), and of
/// `pelvis` about `acetabulum`, all in one frame (mm). Never throws.
ArticularZones find_articular_zones(const TriangleMesh& femur, const SphereFitResult& head, const ClockFace& clock,
                                    const TriangleMesh& pelvis, const Acetabulum& acetabulum,
                                    const ArticularZoneOptions& options = {});

/// The pelvic zone of p (mm, the acetabulum's frame) about `acetabulum` with `zones`' lunate tolerance and
/// `options`' rim margin (see PelvicZone).
PelvicZone pelvic_zone(const Acetabulum& acetabulum, const ArticularZones& zones, const Eigen::Vector3d& p,
                       const ArticularZoneOptions& options = {});

}  // namespace impinge
