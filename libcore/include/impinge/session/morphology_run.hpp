#pragma once
/// @file morphology_run.hpp
/// `impinge morphology` (and Python's impinge.morphology): a hip's morphology (clinical/morphology.hpp) from the
/// session's inputs, without maps, and its record (morphology.json) and mesh (the femur coloured by the head's
/// deviation from its sphere).

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "impinge/clinical/morphology.hpp"
#include "impinge/session/session.hpp"

namespace impinge {

/// A morphology run: the measures and what they were measured on.
struct MorphologyRun {
  nlohmann::json meshes;  ///< the bones' mesh hygiene (meshes_record)
  Morphology morphology;
  HipFrames frames;       ///< working frame (the head: the sphere the femur shows)
  std::string head_method;     ///< how the head sphere was fitted (CorResult::method, or the automatic fit's)
  std::string landmarks_file;  ///< the file the given landmarks came from (subject.json); empty: none given
  Acetabulum acetabulum;  ///< working frame
  TriangleMesh femur;     ///< working frame
  Side side = Side::right;
  Eigen::Matrix3d to_input = Eigen::Matrix3d::Identity();  ///< working -> input frame
  FrameConvention input_frame = FrameConvention::RAS;
  std::string femur_source, pelvis_source, subject;
  std::vector<std::string> warnings;
  double ms = 0;  ///< wall time of the run, loading included
};

/// Load the inputs of `options` (SessionOptions::input, cor, frames: the femur frame's condylar line), find the
/// femoral head (the sphere the femur shows, also when a COR is given), both frames (find_hip_frames) and the
/// acetabulum (find_acetabulum), and measure the morphology (measure_morphology). No maps are built. Throws
/// impinge::Error as Session's constructor does for the same inputs (naming the file, landmark or step).
/// With `reference` (a run on the same hip before a resection, its input frame the same): its head sphere, frames and
/// head-neck clock (neck axis) are taken as they are, not found again on these bones, and the acetabulum is found on
/// this pelvis about that head: a before/after comparison in which only the cut changes a value (plan_run.hpp).
MorphologyRun run_morphology(const SessionOptions& options, const MorphologyRun* reference = nullptr);

/// morphology.json: per quantity its value (points and axes in the input frame), unit, definition and source; the
/// landmarks and frames used; the notes of what could not be measured. Never throws.
nlohmann::json morphology_record(const MorphologyRun& run);

/// The femur (input frame, mm) as binary PLY with per-vertex head_deviation_mm (distance from the head centre less
/// the radius on the head's cap, NaN elsewhere) and a colour (blue inside the sphere, white on it, red outside,
/// full at 2 mm; grey off the cap). Written atomically; throws impinge::Error naming the file on I/O errors.
void write_morphology_ply(const std::string& path, const MorphologyRun& run);

}  // namespace impinge
