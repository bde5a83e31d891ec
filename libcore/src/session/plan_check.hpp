#pragma once
// The plan's check and its further passes (run_plan's, plan_run.hpp), private to the session layer: the ROM search
// and the clearance at every target pose, in the placement of a new session on the resected bones.
#include <chrono>
#include <vector>

#include "impinge/session/plan_run.hpp"
#include "session/plan_labrum.hpp"

namespace impinge::plan_detail {

using Clock = std::chrono::steady_clock;
/// Milliseconds since `t`.
inline double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

/// A resected mesh in the input frame (mm): the scan-pose vertices `scan_pose` moved by the plan's (joint-frame)
/// displacement of `body`, b.resected - body.relative; the body's faces, named `name`. `session` is the one the
/// plan was made on; its input is the bones as they were before that plan.
TriangleMesh resected_mesh(const Session& session, const BoneResection& b, const JointBody& body,
                           const Vertices& scan_pose, const char* name);

/// What the check's passes share: the call's options and ROM request, the limits-only request, the first session's
/// distance reach (mm), the first session (the plan's joint frame) with its limits before, the targets, the
/// resection's options and the bones' scan-pose vertices (input frame, mm); with --labrum the first session's
/// labrum (plan_labrum; else null).
struct PlanCheck {
  const SessionOptions& options;
  const RomRequest& rom;
  const PlanRequest& request;
  const RomRequest& limits_only;
  double distance_reach_mm;
  const Session& s;
  const RomRun& before;
  const std::vector<ResectionTarget>& targets;
  const ResectionOptions& ro;
  const Vertices& femur_scan;
  const Vertices& pelvis_scan;
  const PlanLabrum* labrum;
};

/// The check: a new session on the resected meshes, as `impinge rom` on the written files, its ROM limits and the
/// clearance at every pose the plan cleared (check_clearance). Where it misses a target's limit or clearance, a
/// further pass plans every target's poses again on those resected bones, in their own placement (the equidistant
/// joint centre, acetabulum and joint surfaces found on them), for the clearance plus the plan's tolerance, within
/// what the safety depth leaves of each vertex, and adds to the resection; at most kPlanPasses passes. Sets
/// run.targets, run.all_met, run.clearance_met and run.final_head_centre_mm; returns the further passes' planning
/// time (ms).
double check_plan(PlanRun& run, const PlanCheck& c);

/// Passes of plan and check, at most (run_plan).
inline constexpr int kPlanPasses = 4;

}  // namespace impinge::plan_detail
