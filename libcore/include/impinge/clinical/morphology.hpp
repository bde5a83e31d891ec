#pragma once
/// @file morphology.hpp
/// The hip's shape as clinicians measure it, on the bones themselves (3D, in the working frame): the femoral
/// head's size and sphericity, the neck axis and neck-shaft angle, the femoral version, the alpha angle at every
/// hour of the head-neck junction and the head-neck offset; the acetabulum's sphere, radiographic version and
/// inclination, lateral and anterior centre-edge angles and coverage of the head. A cam shows as a large alpha
/// angle and a small offset ratio, a pincer as large centre-edge angles and coverage, a retroverted socket as a
/// small or negative version; the ROM limits are read beside them.
///
/// Definitions (each value's source is also in morphology_record's output):
/// - head: the sphere fitted to the femoral head (HipFrames::head, thesis sec. 3.4); sphericity: rms and largest
///   |distance - r| of the femur's vertices on the head's cap away from the neck (angle from the neck axis over
///   100 deg), where cartilage-bearing bone lies;
/// - neck axis: through the head centre and the centre of the neck's narrowest cross-section, the sections normal to
///   the axis (Reikeras et al. 1983; femoral_neck_axis, seeded at the centroid of the femur's surface 4-12 mm outside
///   the head sphere: femoral_clock_face); shaft axis: the principal axis of the femur's surface between 35 % and 65 % of
///   the head-to-knee length (the diaphysis), pointing proximal; neck-shaft angle: between the neck axis and the
///   shaft axis pointing distal (normal 125-135 deg);
/// - femoral version: the angle between the neck axis and a condylar axis (the line through the two posterior
///   condyle landmarks, or through the two epicondyles), both projected on a plane, positive when the neck points
///   anterior (anteversion), in two conventions:
///   - across the shaft (version_*_shaft_deg): the plane normal to the shaft axis, as on the axial slices of a CT
///     of a femur lying along the scanner's axis: the CT convention of Reikeras et al. 1983 (Acta Orthop Scand
///     54:18; their neck axis: the head centre and the neck's centre, as impinge's) and Murphy et al. 1987 (J Bone
///     Joint Surg Am 69:1169; the posterior condylar tangent as the distal reference); normal 10-20 deg against
///     the posterior condylar axis;
///   - across the mechanical axis (version_posterior_condylar_deg, version_transepicondylar_deg): the plane normal
///     to the femur's mechanical axis (the ISB femur frame's y: the epicondyles' midpoint to the head centre; Wu
///     et al. 2002), as 3D studies in the femoral frame take it;
/// - alpha angle (Noetzli et al. 2002, J Bone Joint Surg Br 84:556, measured radially as 3D CT studies do):
///   in the plane through the neck axis at each clock hour of the head-neck clock (12 superior, 3 anterior on
///   both sides), the angle at the head centre between the neck axis and the first point, coming from the head,
///   where the bone's surface lies farther from the centre than the head's radius plus a tolerance (twice the head
///   fit's rms, at least 0.5 mm); normal under 50-55 deg, a cam above;
/// - head-neck offset (Eijer et al. 2001, Hip Int 11:37) at 3 o'clock (anterior): the head's radius less the
///   least distance of the anterior neck surface from the neck axis; ratio: offset / head diameter (normal over
///   0.15-0.17);
/// - acetabulum: the sphere of its whole lunate surface (find_acetabulum); radiographic inclination and version
///   (Murray 1993, J Bone Joint Surg Br 75:228) of the rim plane's normal in the anterior pelvic plane (supine
///   radiographs; the ISB frame's values beside them); normal inclination 40-50, version 10-25 deg;
/// - lateral centre-edge angle (Wiberg 1939): in the coronal plane of the anterior pelvic plane frame through the
///   head centre, between the superior axis and the line from the head centre to the rim above it, positive
///   lateral: the median over the rim points within 5 mm of that plane (an MRI rim has notches) (normal 25-39 deg;
///   under 20 dysplasia, over 39-40 over-coverage); anterior centre-edge angle (Lequesne and de Seze 1961): the
///   same in the sagittal plane, in front of the head, towards anterior (normal over 20-25 deg). Both from the
///   bony rim in 3D, not the sourcil on a radiograph;
/// - coverage: the share of the head sphere's surface that the acetabulum covers seen from the head centre (the
///   cap inside the rim: 0.5 is a hemisphere), and the rim's angle from the acetabular pole per acetabular clock
///   hour (deg).
/// Without landmarks (`frames` from scan neutral: a generated hip, a proximal femur in a cup) the frames' axes stand
/// for the anatomical ones and the neck-shaft angle and femoral versions are NaN, with a note; without a shaft axis
/// (fewer than 30 vertices on the diaphysis: a proximal femur) the versions across the shaft are NaN, with a note.
/// Every direction is taken from the bone's own axes and its side (lateral is right for a right hip, left for a
/// left one), so a mirrored hip gives the same values and a rigidly moved hip the same values.

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "impinge/anatomy/clock_face.hpp"
#include "impinge/anatomy/hip_frames.hpp"
#include "impinge/core/mesh.hpp"

namespace impinge {

/// The morphology of one hip (working frame, mm and degrees; NaN where a measure could not be taken, with a
/// line in `notes`).
struct Morphology {
  // Femoral head.
  Eigen::Vector3d head_centre_mm = Eigen::Vector3d::Zero();
  double head_radius_mm = 0, head_fit_rms_mm = 0;
  double sphericity_rms_mm = 0, sphericity_max_mm = 0;  ///< |distance from the centre - radius| over the head cap
  std::int64_t sphericity_vertices = 0;
  /// Per femur vertex: distance from the head centre less the radius (mm) on the head cap, NaN elsewhere.
  std::vector<double> head_deviation_mm;
  // Neck and shaft.
  Eigen::Vector3d neck_axis = Eigen::Vector3d::Zero();   ///< unit, from the neck towards the head centre
  ClockFace head_neck_clock;  ///< the head-neck clock the alpha angles and offset were measured on (axis: neck_axis)
  Eigen::Vector3d shaft_axis = Eigen::Vector3d::Zero();  ///< unit, distal to proximal
  double neck_shaft_angle_deg = 0;
  /// Femoral anteversion against the posterior condylar axis, across the mechanical axis (knee centre to head centre).
  double version_posterior_condylar_deg = 0;
  double version_transepicondylar_deg = 0;  ///< and against the transepicondylar axis, across the mechanical axis
  /// Femoral anteversion against the posterior condylar axis, across the shaft axis (the CT convention: Reikeras et al.
  /// 1983, Murphy et al. 1987); NaN without a shaft axis.
  double version_posterior_condylar_shaft_deg = 0;
  double version_transepicondylar_shaft_deg = 0;  ///< and against the transepicondylar axis, across the shaft axis
  // Head-neck junction.
  std::array<double, 12> alpha_deg{};  ///< alpha angle at clock hours 1 ... 12 (index hour - 1)
  double alpha_max_deg = 0, alpha_max_hour = 0;
  double head_neck_offset_mm = 0, head_neck_offset_ratio = 0;  ///< at 3 o'clock (anterior)
  // Acetabulum.
  Eigen::Vector3d acetabular_centre_mm = Eigen::Vector3d::Zero();
  double acetabular_radius_mm = 0, acetabular_fit_rms_mm = 0, lunate_area_mm2 = 0;
  AcetabularOrientation orientation_app, orientation_isb;  ///< radiographic (Murray 1993)
  double lateral_centre_edge_deg = 0, anterior_centre_edge_deg = 0;
  double head_coverage = 0;               ///< share of the head sphere covered (0.5: a hemisphere)
  std::array<double, 12> coverage_deg{};  ///< rim angle from the acetabular pole per acetabular clock hour
  std::vector<std::string> notes;         ///< what could not be measured, and why
};

/// The femoral version (deg, in (-180, 180]) of the neck axis `neck` (towards the head) against the condylar axis from
/// `lateral` to `medial` (points, mm; the posterior condyles or the epicondyles), both projected on the plane normal to
/// `axis` (the shaft axis: the CT convention, Reikeras et al. 1983, Murphy et al. 1987; or the mechanical axis: the
/// ISB femoral y); positive (anteversion) when the projected neck leans towards `anterior` (any vector on the
/// anterior side of the condylar axis across `axis`). Source: those papers, in 3D (impinge).
double femoral_version_deg(const Eigen::Vector3d& neck, const Eigen::Vector3d& medial, const Eigen::Vector3d& lateral,
                           const Eigen::Vector3d& axis, const Eigen::Vector3d& anterior);

/// Measure the morphology of a hip from its whole femur and its pelvis (working frame, mm) on `side`, its frames
/// (find_hip_frames: head sphere, landmarks, ISB frames) and its acetabulum (find_acetabulum on the pelvis). The
/// anterior pelvic plane frame is built from the same landmarks. The centre-edge angles are Wiberg's edge found by
/// rays from the head centre (where the roof's bone ends, the median of five parallel planes 2 mm apart). Costs about
/// a thousand exact ray casts on the femur and up to 9,000 on the pelvis (CGAL AABB trees; ExactReference). Throws
/// impinge::Error naming the femur mesh when no neck is found (femoral_clock_face) or CGAL is missing from this build.
/// `head_neck_clock` (working frame; its axis the neck axis): measure about it instead of the femur's own
/// (femoral_clock_face): a femur after a resection measured about its neck axis before (plan_run.hpp), so that only
/// the cut changes a value, not an axis refitted on the cut bone.
Morphology measure_morphology(const TriangleMesh& femur, const TriangleMesh& pelvis, Side side, const HipFrames& frames,
                              const Acetabulum& acetabulum, const ClockFace* head_neck_clock = nullptr);

}  // namespace impinge
