#pragma once
/// @file pelvis_frame.hpp
/// Pelvic landmarks found on a whole pelvis mesh (both hip bones), and the pelvic frames built
/// from them: the ISB frame (Wu et al. 2002) and the anterior pelvic plane (APP) frame of
/// clinical ROM tools (Tannast et al. 2007, Kubiak-Langer et al. 2007, Puls et al. 2011).

#include <Eigen/Core>
#include <string>

#include "impinge/anatomy/anatomical_frame.hpp"
#include "impinge/anatomy/pose.hpp"
#include "impinge/core/mesh.hpp"
#include "impinge/core/enum_names.hpp"

namespace impinge {

/// Which pelvic frame defines the axes (the origin is always the hip centre).
enum class PelvisFrameKind {
  isb,                     ///< Z through both ASIS (right), X in the plane of both ASIS and the PSIS midpoint (anterior)
  anterior_pelvic_plane,   ///< Z through both ASIS, X normal to the plane of both ASIS and the pubic tubercles
};
/// The names of the pelvic frames: "isb", "app" (the option table's choices, parse_pelvis_frame_kind).
inline constexpr EnumNames<PelvisFrameKind, 2> kPelvisFrameKindNames{
    {{PelvisFrameKind::isb, "isb"}, {PelvisFrameKind::anterior_pelvic_plane, "app"}}};
/// "isb" or "app".
inline const char* to_string(PelvisFrameKind kind) { return enum_name(kPelvisFrameKindNames, kind); }

/// The six pelvic landmarks (mm, working frame) and how they were obtained.
struct PelvisLandmarks {
  Eigen::Vector3d asis_right, asis_left;                    ///< anterior superior iliac spines
  Eigen::Vector3d psis_right, psis_left;                    ///< posterior superior iliac spines
  Eigen::Vector3d pubic_tubercle_right, pubic_tubercle_left;///< most anterior points of each pubis
  Landmarks as_map() const;                                 ///< the six under their snake_case names
  std::map<std::string, std::string> source;                ///< per name: "found" or "given"
  double app_out_of_plane_mm = 0;  ///< distance of the far pubic tubercle from the plane of both ASIS and
                                   ///< the near one: 0 when the four APP landmarks are coplanar
};

/// Names accepted in subject.json's "landmarks" for the pelvis.
inline const char* const kPelvisLandmarkNames[] = {"asis_right",           "asis_left",          "psis_right",
                                                   "psis_left",            "pubic_tubercle_right", "pubic_tubercle_left"};

/// Find the pelvic landmarks on `pelvis` (a whole pelvis, both hip bones, working frame, mm),
/// independently of how it lies in the scanner (only rigid-invariant constructions):
/// 1. convex hull (CGAL); the anterior pelvic plane touches it at both ASIS and the pubis, so
///    the hull triangle with the largest area x longest edge is taken as that plane (its longest
///    edge joins the two ASIS, its third corner is on the pubis);
/// 2. the ASIS nearer `hip_centre` (mm) is on `side`;
/// 3. pubic tubercles: on each side of the midline and below the hip centre, the hull vertex
///    first touched by the plane through both ASIS rotated posteriorly about their line;
/// 4. PSIS: on each side, above the hip centre, the most posterior hull vertex in the APP frame.
/// Landmarks in `given` (same names, mm, working frame) replace found ones; with all six given
/// no hull is needed. Throws impinge::Error naming the mesh when the hull is degenerate, the
/// build has no CGAL and landmarks are missing, or the hull's largest face is not consistent
/// with an anterior pelvic plane (e.g. a single hip bone: give the landmarks instead).
PelvisLandmarks find_pelvis_landmarks(const TriangleMesh& pelvis, const Eigen::Vector3d& hip_centre, Side side,
                                      const Landmarks& given = {});

/// The pelvic frame of `kind` with origin at `hip_centre` (mm, working frame; ISB's hip
/// joint convention). quality_mm is the landmarks' app_out_of_plane_mm. Throws
/// impinge::Error when the landmarks are collinear.
AnatomicalFrame pelvis_frame(const PelvisLandmarks& landmarks, const Eigen::Vector3d& hip_centre,
                             PelvisFrameKind kind = PelvisFrameKind::isb);

/// Parse "isb" / "app"; throws impinge::Error naming `context` otherwise.
PelvisFrameKind parse_pelvis_frame_kind(const std::string& text, const std::string& context);

}  // namespace impinge
