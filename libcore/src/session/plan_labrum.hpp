#pragma once
// The plan against the labrum (`impinge plan --labrum`, issue 81 item 4), private to the session layer: the limits
// the plan targets, and the femoral cut that clears both the pelvis and the labrum at every target pose.
#include <memory>
#include <vector>

#include "impinge/clinical/resection.hpp"
#include "impinge/session/runs.hpp"

namespace impinge::plan_detail {

/// The limits a plan targets, from the ROM run `run`: without its labrum (RomRun::labrum) `run` itself (the bony
/// limits); with it, a copy whose limits[k] are motion k's labral limits (labral_limit: the first of the bony limit
/// and the labrum's first contact, deg; its status and contact class), the rest as in `run`. What plan_targets reads
/// (motions, limits). Never throws. Source: impinge (issue 81).
RomRun targeted_limits(const RomRun& run);

/// The labrum a plan works against: the labral hip of a session's hip with its triangles split kPlanLabrumSplits
/// times (HipJoint::with_labrum: the same surface as `impinge rom --labrum`'s, whose exact search checks the plan),
/// and its baseline at neutral (rom_baseline with the ROM search's options).
struct PlanLabrum {
  std::shared_ptr<const HipJoint> hip;
  RomBaseline baseline;
};
/// How often a plan's labrum is split in four. The plan's contacts are per vertex (resection.hpp); the labrum's free
/// margin is a sharp edge with a vertex per rim point (5 deg apart: 2-3 mm), so that the femur crossing it between
/// two of them went unseen (on a generated hip the plan kept 0.31 mm at every vertex where the margin crossed the
/// femur: exact distance 0). Split 3 times: a vertex every 0.3 mm along the margin, 64 x 432 triangles; what the
/// margin still comes nearer between those (0.005 mm on tlem2-mri) the labral plan makes up against the exact
/// distance (plan_targeted). Split 4 times it needs no making up there, but the plan takes 2-3 times as long.
inline constexpr int kPlanLabrumSplits = 3;
/// PlanLabrum of `hip` (a session's, bony) with the labrum `labrum` (width, height, mm) and the ROM search's
/// `search`. Throws impinge::Error as HipJoint::with_labrum does, prefixed "--labrum: ".
PlanLabrum plan_labrum(const HipJoint& hip, const LabrumOptions& labrum, const RomOptions& search);
/// The exact least distance (mm; 0 where they cross) between the femur at pose P and the labrum of `labrum`, over
/// the pairs of triangles the ROM search counts (RomBaseline::contact: the head's joint surface left out), or
/// +inf without such meshes (RomOptions::exact_contact not applicable) or when none is within `reach` (mm).
double labrum_exact_distance(const PlanLabrum& labrum, const FemurPose& P, double reach);

/// The plan (plan_resection) of `hip` for `targets`, and with `labrum` (plan_labrum of that hip: the femur against the
/// labrum alone in the same joint frame, and its baseline) the femur's cut that also clears the labrum. The labrum is
/// soft tissue: it is never cut, and only the femur is cut to clear it (the pelvis is not trimmed away from it). So:
/// the plan of the labral hip with ResectBones::femur (the femur's removed depths of `options`, none of the pelvis'),
/// made again (at most twice) for the clearance plus the shortfall and the tolerance where the exact mesh-to-mesh
/// distance of its resected femur to the labrum falls short of the clearance at a pose it cleared (the per-vertex
/// contacts' error at the labrum's sharp margin), each target cut back to the poses it cleared; the plan of the bony
/// hip with `options` on those poses (cut back again, and the labral plan made again on them, when the bony plan clears
/// fewer); per femur vertex the deeper of the two depths (mm; each within the safety depth and off the protected
/// surfaces, so their largest is too: both plans share the femur's vertices, normals, protection and limits), the
/// resected femur that depth along its normal, and its measures again (summarize_resection; thin vertices: the larger
/// of the two plans' counts); the pelvis as the bony plan trims it. Per target: the poses both plans cleared, reachable
/// when both reach it, the labral plan's note (prefixed "against the labrum: ") where it stops first, else the bony
/// one's. Iterations and residual (mm): the larger; rounds, poses, contacts and time: summed. Without `labrum`:
/// plan_resection(hip, targets, baseline, options). The check (check_plan) verifies the result against both bodies.
/// Throws impinge::Error as plan_resection does. Source: impinge (issue 81).
ResectionPlan plan_targeted(const HipJoint& hip, const RomBaseline& baseline, const PlanLabrum* labrum,
                            const std::vector<ResectionTarget>& targets, const ResectionOptions& options);

}  // namespace impinge::plan_detail
