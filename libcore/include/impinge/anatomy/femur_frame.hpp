#pragma once
/// @file femur_frame.hpp
/// Femoral landmarks found on a whole femur mesh (head centre, epicondyles, posterior condyles)
/// and the femoral ISB frame (Wu et al. 2002) built from them.

#include <Eigen/Core>
#include <string>

#include "impinge/anatomy/anatomical_frame.hpp"
#include "impinge/anatomy/pose.hpp"
#include "impinge/anatomy/sphere_fit.hpp"
#include "impinge/core/mesh.hpp"
#include "impinge/core/enum_names.hpp"

namespace impinge {

/// Which line sets the femur's medio-lateral direction (z); y always runs from the epicondyles'
/// midpoint to the head centre.
enum class FemurFrameKind {
  epicondyles,         ///< ISB: z in the plane of the head centre and both epicondyles
  posterior_condyles,  ///< z parallel to the posterior condylar axis (the tangent to both posterior condyles)
};
/// The names of the femoral frames: "epicondyles", "posterior-condyles" (the option table's choices).
inline constexpr EnumNames<FemurFrameKind, 2> kFemurFrameKindNames{
    {{FemurFrameKind::epicondyles, "epicondyles"}, {FemurFrameKind::posterior_condyles, "posterior-condyles"}}};
/// "epicondyles" or "posterior-condyles".
inline const char* to_string(FemurFrameKind kind) { return enum_name(kFemurFrameKindNames, kind); }

/// Femoral landmarks, mm, working frame.
struct FemurLandmarks {
  Eigen::Vector3d head_centre;                                        ///< centre of the fitted head sphere
  Eigen::Vector3d epicondyle_lateral, epicondyle_medial;              ///< most prominent points of the distal femur
  Eigen::Vector3d posterior_condyle_lateral, posterior_condyle_medial;///< the posterior condylar axis' contact points
  Landmarks as_map() const;                                           ///< the five under their snake_case names
  std::map<std::string, std::string> source;                          ///< per name: "found" or "given"
};

/// Names accepted in subject.json's "landmarks" for the femur (besides "hip_centre", which
/// replaces the head fit).
inline const char* const kFemurLandmarkNames[] = {"epicondyle_lateral", "epicondyle_medial", "posterior_condyle_lateral",
                                                  "posterior_condyle_medial"};

/// Long axis of a femur: the principal axis of largest variance of its vertices (n x 3, mm),
/// unit, pointing towards `proximal_hint` (mm; for example the head centre) when it is finite.
Eigen::Vector3d femur_long_axis(PointsRef V, const Eigen::Vector3d& proximal_hint);

/// The extents of the points `V` (n x 3) along their principal axes (the eigenvectors of their covariance), the axis
/// of the largest variance first, in V's units: a whole femur's length and then its widths (the shared femurs:
/// 412-456 mm long, 4.3-5.3 times their next extent). Zeros for fewer than 4 points. Source: impinge.
Eigen::Vector3d principal_extents(PointsRef V);

/// Femoral head sphere on a whole femur in any orientation: the long axis (principal axis), then
/// fit_femoral_head with each end in turn taken as proximal; the end whose sphere has more
/// inliers is the head. Independent of how the femur lay in the scanner. Throws impinge::Error
/// naming the mesh when neither end gives a plausible sphere.
SphereFitResult locate_femoral_head(const TriangleMesh& femur, const HeadFitOptions& options = {});

/// The femoral head of a femur (whole or proximal only, right or left, any orientation) beside its
/// pelvis in the same frame (mm): the sphere of each end of the long axis (fit_femoral_head), and
/// the head is the one that sits in the acetabulum (two spheres within 2 mm of each other are one),
/// its nearest pelvis vertex within
/// kHeadInAcetabulumMm of its surface (the joint space; the shared hips: 0.4-1.1 mm). A distal
/// condyle or a cut shaft can out-fit the head; it cannot lie in the acetabulum. An end whose sphere
/// after the refinement rounds lies more than 20 mm beyond that limit is not refined to its fixed
/// point (fit_femoral_head's last stage, which moves a sphere by at most 1.4 mm on the shared hips and
/// lhdl-ct subdivided 4x); the head itself is refined to its fixed point, as without the pelvis. Throws
/// impinge::Error naming both meshes when neither end's sphere, or both, sit in the acetabulum (not
/// one hip in one frame?), or when no sphere is found.
SphereFitResult locate_femoral_head(const TriangleMesh& femur, const TriangleMesh& pelvis,
                                    const HeadFitOptions& options = {});

/// How far (mm) the head's surface may lie from the nearest pelvis vertex and still sit in the
/// acetabulum: the cartilage space (2-5 mm at the scan pose, shared/data/README.md) with margin for a
/// segmentation or a subluxed head.
inline constexpr double kHeadInAcetabulumMm = 12.0;

/// Find the distal landmarks of a whole femur (working frame, mm) whose head centre is
/// `head_centre` (mm): the long axis (principal axis, towards the head); the distal slab (the
/// last `distal_fraction` of the femur's length along it); the medial direction from the head's
/// offset; epicondyles as the pair of slab vertices extreme along the medio-lateral direction,
/// refined until that direction is the line through them (projected off the long axis); the
/// posterior condyles as the most posterior slab vertex of each half, refined until the
/// posterior direction is normal to the line through them (their bitangent). `side`: which
/// femur (the lateral epicondyle is on the right of a right femur). Landmarks in `given`
/// replace found ones. Throws impinge::Error naming the mesh on a femur too short or a slab
/// too small.
FemurLandmarks find_femur_landmarks(const TriangleMesh& femur, const Eigen::Vector3d& head_centre, Side side,
                                    const Landmarks& given = {}, double distal_fraction = 0.15);

/// The femoral frame (ISB: origin at the head centre; y from the epicondyles' midpoint to the
/// head centre; z perpendicular to y towards the right, in the plane of the head centre and
/// both epicondyles, or parallel to the posterior condylar axis; x = y x z anterior).
/// quality_mm is left 0 (the caller sets the head fit residual). Throws impinge::Error when
/// the landmarks are collinear.
AnatomicalFrame femur_frame(const FemurLandmarks& landmarks, Side side,
                            FemurFrameKind kind = FemurFrameKind::epicondyles);

/// Parse "epicondyles" / "posterior-condyles"; throws impinge::Error naming `context` otherwise.
FemurFrameKind parse_femur_frame_kind(const std::string& text, const std::string& context);

}  // namespace impinge
