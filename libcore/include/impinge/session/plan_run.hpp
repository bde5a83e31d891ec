#pragma once
/// @file plan_run.hpp
/// `impinge plan` (and Python's Joint.plan): a resection plan (clinical/resection.hpp) from the session's inputs
/// and targets, checked by the ROM search on the resected bones, with its record (plan.json) and meshes
/// (femur_resected.ply, pelvis_resected.ply, and VTP for ParaView).

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "impinge/clinical/morphology.hpp"
#include "impinge/clinical/resection.hpp"
#include "impinge/session/runs.hpp"
#include "impinge/session/session.hpp"
#include "impinge/core/range.hpp"

namespace impinge {

/// What a plan asks for (the option table's plan rows).
struct PlanRequest {
  /// Targets: "MOTION=DEG,..." (standard motions: rom.hpp's names), "normal" (every standard motion's published
  /// normal range, published_rom.hpp), or both ("normal,flexion=130": a named angle replaces normal's). Empty:
  /// none (then `target_motion` must be given).
  std::string target;
  std::string target_motion;        ///< a motion file (.csv, .mot, .sto) whose every frame must be free; empty: none
  ResectionOptions resection;       ///< bones, clearance, burr (safety_depth_mm: set from the two below)
  double max_depth_fraction = 0.3;  ///< safety depth as a fraction of the neck's least diameter (Mardones 2005)
  static constexpr Range kMaxDepthFractionRange{0.01, 1};  ///< of max_depth_fraction
  double max_depth_mm = 0;          ///< safety depth, mm; 0: max_depth_fraction x the neck's diameter
  static constexpr Range kMaxDepthRange{0, 100};           ///< of max_depth_mm, mm
  bool allow_partial = false;       ///< a target missed after the check is not an error (exit 0)
  double step_deg = 0.5;            ///< poses along each target motion, deg
  static constexpr Range kStepRange{0.05, 5};               ///< of step_deg, deg
};

/// One target before and after.
struct PlanTargetCheck {
  std::string name;
  double target_deg = std::numeric_limits<double>::quiet_NaN();  ///< NaN for a motion file
  RomLimit before, after;    ///< the ROM search's (bony) limit on the input and on the resected bones (standard
                             ///< motions)
  /// With the labrum (PlanRun::labrum; standard motions): the labral limits (labral_limit: the first of the bony
  /// limit and the femur's first contact with the labrum) on the input and on the resected bones; the plan targets
  /// these. Empty without.
  std::optional<LabralLimit> labral_before, labral_after;
  bool met = false;          ///< limit_met and clearance_met
  bool limit_met = false;    ///< after: the targeted limit (labral_after with the labrum, else after) limited at or
                             ///< beyond the target (within 0.1 deg, the search's tolerance), or free; a motion
                             ///< file: no frame in contact after (with the labrum: with the bones or the labrum)
  /// The clearance (ResectionOptions::clearance_mm, what the plan promises) in the final placement: the check's
  /// session on the resected bones, whose equidistant joint centre, acetabulum and joint surfaces are found again
  /// on them. Over the poses the plan cleared (its last pass's: the whole target when it was reachable), the least
  /// counted signed distance (the vertices the plan follows, RomBaseline's; mm) and where (the motion's angle,
  /// deg, or a motion file's frame; NaN on the way to a motion's start), and at the target's own pose (its angle or
  /// last frame; NaN when not cleared). NaN and met when there was no pose to plan (a target met before the plan).
  double clearance_least_mm = std::numeric_limits<double>::quiet_NaN();
  double clearance_least_at = std::numeric_limits<double>::quiet_NaN();
  double clearance_at_target_mm = std::numeric_limits<double>::quiet_NaN();
  /// The least signed distance over the same poses and every vertex, the joint surfaces too (which the plan does
  /// not follow: a contact classed articular shows here), mm.
  double clearance_least_any_mm = std::numeric_limits<double>::quiet_NaN();
  /// With the labrum: the least counted signed distance between the femur and the labrum over the same poses, mm
  /// (clearance_least_mm is the lesser of this and the bones'); NaN without.
  double clearance_least_labrum_mm = std::numeric_limits<double>::quiet_NaN();
  std::int64_t clearance_poses = 0;  ///< the poses checked
  bool clearance_met = true;         ///< clearance_least_mm at least the clearance (less 1e-4 mm of rounding)
  double shortfall_deg = 0;  ///< target less the targeted limit after, when not met
  /// Motion files: frames in contact before and after (the ROM search's criterion), else 0.
  std::int64_t frames_in_contact_before = 0, frames_in_contact_after = 0;
};

/// A plan run: the plan, its check and what they were computed on.
struct PlanRun {
  ResectionPlan plan;
  std::vector<PlanTargetCheck> targets;
  bool all_met = false;
  bool clearance_met = false;  ///< every target's clearance_met
  /// The head centre (COR) of the final placement (the last check's session, fitted on the resected femur) and of the
  /// plan's first session (head_centre_mm), input frame, mm.
  Eigen::Vector3d final_head_centre_mm = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  /// The axes the morphology before and after share (input frame; NaN when the morphology before was not measured):
  /// the femoral head sphere and neck axis (unit, towards the head) of the femur before the resection.
  Eigen::Vector3d reference_head_centre_mm = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d reference_neck_axis = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  double reference_head_radius_mm = std::numeric_limits<double>::quiet_NaN();
  RomOptions search;  ///< the ROM search's options (the check's)
  /// With RomRequest::labrum (`impinge plan --labrum`): its width and height (mm). The plan then targets the labral
  /// limits, cutting the femur so that at every target pose it clears the pelvis and the labrum by the clearance;
  /// the labrum is never cut (plan_detail::plan_targeted). Empty: the bony limits (the plan as before issue 81).
  std::optional<LabrumOptions> labrum;
  /// With the labrum: the labrum of the plan's first session (input frame, mm; labrum.ply), and the largest distance
  /// (mm) of its vertices from those of the labrum the last check built again on the bones after (the same
  /// construction on the resected bones in their refitted placement; NaN when their vertex counts differ).
  TriangleMesh labrum_mesh;
  double labrum_moved_mm = std::numeric_limits<double>::quiet_NaN();
  double neck_diameter_mm = std::numeric_limits<double>::quiet_NaN();
  PlanRequest request;                            ///< what was asked
  double safety_depth_mm = 0;                     ///< the safety depth used (from request's cap or fraction), mm
  /// Morphology of the input and of the resected femur, the latter about the former's head sphere, neck axis and
  /// frames (run_morphology's reference): only the cut changes a value.
  std::optional<Morphology> before, after;
  std::vector<std::string> notes;                 ///< what could not be measured or checked
  TriangleMesh femur_resected, pelvis_resected;   ///< input frame, mm (the input's faces and vertex order)
  std::vector<double> femur_hours, pelvis_hours;  ///< per vertex: head-neck and acetabular clock hours (empty
                                                  ///< with scan neutral)
  double clock_from_h[2] = {NAN, NAN}, clock_to_h[2] = {NAN, NAN};  ///< femur, pelvis: the resection's extent
  std::string subject, femur_source, pelvis_source;
  Eigen::Vector3d head_centre_mm = Eigen::Vector3d::Zero();  ///< the femoral head centre at the scan pose, input frame
  FrameConvention input_frame = FrameConvention::RAS;
  std::string pelvic_frame;  ///< the frame of the targets' and limits' angles (pelvic_frame_name: isb, app or scan)
  std::string cor_method;    ///< how the head centre (the COR) was obtained (Session::cor_method)
  double setup_ms = 0, before_ms = 0, plan_ms = 0, check_ms = 0, total_ms = 0;
  std::vector<std::string> warnings;
  nlohmann::json meshes;  ///< the bones' mesh hygiene (meshes_record)
};

/// The targets of `request` for `session`'s hip (PlanRequest::target, target_motion) with the limits `before`
/// (run_rom's): each standard motion's poses from 2 deg short of its limit to the target, every
/// `step_deg` (from the start when in contact there; after the straight way from neutral to the start when
/// that is blocked); a target already met has no poses. Throws impinge::Error naming the target text, motion
/// or file.
std::vector<ResectionTarget> plan_targets(const Session& session, const PlanRequest& request, const RomRun& before);

/// Checks what can be checked before anything is built (a bad one is an error in milliseconds): the safety depth's
/// fraction and cap (mm), the targets' text, the motion file (read for `options`' side), that there is a target
/// at all, and that a plan with the labrum (`labrum`.enabled) may cut the femur (a labral contact can be cleared
/// only on the femur: --labrum with --resect pelvis is refused). Throws impinge::Error naming the option, target or
/// file. run_plan calls it first; so does Python's impinge.check_options("joint_plan", ...) (a study's plan tasks,
/// before any task runs).
void check_plan_request(const SessionOptions& options, const PlanRequest& request, const LabrumOptions& labrum = {});

/// Plan and check: the session (rom_session_options of `rom.search`, distances on with a reach of at least the
/// clearance + 1 mm), the ROM limits before, the plan (plan_resection; with `rom.labrum` the labral limits targeted,
/// the femur cut to clear the labrum too: PlanRun::labrum), the resected meshes, and the ROM limits
/// of a new session on them (the check: the same options, as `impinge rom` on the written meshes) with the
/// clearance at every pose the plan cleared in that session's placement; where a limit or a clearance is missed,
/// further passes on the resected bones (at most four passes in all); the morphology before and after (about the
/// same head sphere and neck axis) where it can be measured. Throws impinge::Error naming the option, target or
/// file; a target missed is not an error here (the CLI's exit status follows PlanRequest::allow_partial).
PlanRun run_plan(const SessionOptions& options, const RomRequest& rom, const PlanRequest& request);

/// plan.json: per bone the volume (mm^3), area (mm^2), largest and mean depth (mm), vertices, clock extent (from-
/// to hours), alpha angles before and after; per target the limit before, after, met, shortfall (with the labrum
/// also the labral limits before and after, limit_targeted "labral", and a "labrum" object); the safety depth and
/// neck diameter; method and options; notes. Never throws.
nlohmann::json plan_record(const PlanRun& run);

/// Write femur_resected.ply / .vtp (and pelvis_resected.* when the pelvis was resected; labrum.ply with the labrum,
/// PlanRun::labrum_mesh, uncut) into `dir`: input frame, the input's faces, per-vertex resection_mm (and
/// clock_hour). Atomic; throws impinge::Error naming the file.
void write_plan_meshes(const std::string& dir, const PlanRun& run);

}  // namespace impinge
