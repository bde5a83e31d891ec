// The plan against the labrum (session/plan_labrum.hpp; issue 81 item 4): the labral limits as the plan's targets,
// and the femoral cut that clears the pelvis and the labrum both.
#include "session/plan_labrum.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "impinge/core/error.hpp"
#include "impinge/detection/mesh_contact.hpp"

namespace impinge::plan_detail {

namespace {

/// `targets` with each one's poses cut back to the first `cleared[k]` (the poses a plan cleared: a prefix).
std::vector<ResectionTarget> cut_back(std::vector<ResectionTarget> targets, const std::vector<std::int64_t>& cleared) {
  for (std::size_t k = 0; k < targets.size(); ++k) {
    const auto n = static_cast<std::size_t>(std::max<std::int64_t>(0, cleared[k]));
    if (n >= targets[k].poses.size()) continue;
    targets[k].poses.resize(n);
    targets[k].theta_deg.resize(n);
  }
  return targets;
}

/// Per target, the poses plan `p` cleared.
std::vector<std::int64_t> cleared(const ResectionPlan& p) {
  std::vector<std::int64_t> out;
  for (const ResectionTargetResult& r : p.targets) out.push_back(r.poses_cleared);
  return out;
}

/// Whether plan `p` cleared fewer poses of some target than `than` asks.
bool clears_fewer(const ResectionPlan& p, const std::vector<std::int64_t>& than) {
  for (std::size_t k = 0; k < than.size(); ++k)
    if (p.targets[k].poses_cleared < than[k]) return true;
  return false;
}

/// Target k's result of the two plans on `targets` (the poses asked for; the plans may have seen fewer).
ResectionTargetResult combined_target(const ResectionTarget& target, const ResectionTargetResult& bony,
                                      const ResectionTargetResult& labral) {
  ResectionTargetResult r = bony;
  r.poses = static_cast<std::int64_t>(target.poses.size());
  r.poses_cleared = std::min(bony.poses_cleared, labral.poses_cleared);
  r.reachable = bony.reachable && labral.reachable && r.poses_cleared == r.poses;
  if (r.reachable) return r;
  r.reachable_deg = std::nan("");
  if (!std::isnan(r.angle_deg))
    for (std::int64_t i = 0; i < r.poses_cleared; ++i)
      if (!std::isnan(target.theta_deg[static_cast<std::size_t>(i)]))
        r.reachable_deg = target.theta_deg[static_cast<std::size_t>(i)];
  const bool labrum_first = labral.poses_cleared <= bony.poses_cleared && !labral.note.empty();
  r.note = labrum_first ? "against the labrum: " + labral.note : bony.note;
  return r;
}

/// The bony plan `bony` with the labral plan's femoral depths: per vertex the deeper (header).
ResectionPlan combined(const HipJoint& hip, const std::vector<ResectionTarget>& targets, ResectionPlan bony,
                       const ResectionPlan& labral) {
  BoneResection& f = bony.femur;
  const JointBody& femur = hip.joint().ball();
  for (std::size_t i = 0; i < f.depth_mm.size(); ++i) {
    f.depth_mm[i] = std::max(f.depth_mm[i], labral.femur.depth_mm[i]);
    const auto v = static_cast<Eigen::Index>(i);
    f.resected.row(v) = femur.relative.row(v) - f.depth_mm[i] * f.normals.row(v);
  }
  summarize_resection(f, femur.relative, femur.mesh.F, femur.vertex_area, bony.options.safety_depth_mm);
  f.thin_vertices = std::max(f.thin_vertices, labral.femur.thin_vertices);
  for (std::size_t k = 0; k < targets.size(); ++k)
    bony.targets[k] = combined_target(targets[k], bony.targets[k], labral.targets[k]);
  bony.iterations = std::max(bony.iterations, labral.iterations);
  bony.rounds += labral.rounds;
  bony.residual_mm = std::max(bony.residual_mm, labral.residual_mm);
  bony.poses += labral.poses;
  bony.contacts += labral.contacts;
  bony.ms += labral.ms;
  return bony;
}

}  // namespace

RomRun targeted_limits(const RomRun& run) {
  RomRun out = run;
  if (!run.labrum) return out;
  for (std::size_t k = 0; k < out.limits.size(); ++k) {
    const LabralLimit l = labral_limit(run, k);
    RomLimit& t = out.limits[k];
    t.limit_deg = l.limit_deg;
    t.status = l.status;
    t.contact_class = l.contact_class;
  }
  return out;
}

PlanLabrum plan_labrum(const HipJoint& hip, const LabrumOptions& labrum, const RomOptions& search) {
  PlanLabrum out;
  try {
    out.hip = hip.with_labrum(labrum.width_mm, labrum.height_mm, kPlanLabrumSplits);
  } catch (const Error& e) {
    throw Error(std::string("--labrum: ") + e.what());
  }
  out.baseline = rom_baseline(*out.hip, out.hip->femur_rotation({}), search);
  return out;
}

double labrum_exact_distance(const PlanLabrum& labrum, const FemurPose& P, double reach) {
  const RomBaseline& base = labrum.baseline;
  if (!base.contact) return std::numeric_limits<double>::infinity();
  MeshContact::Query q;
  q.reach = reach;
  if (base.head_zone)  // a pair across the junction is classed by the femur's closest point, as the search classes it
    q.pair_counts = [&base, Rt = Eigen::Matrix3d(P.R.transpose()), t = P.t](
                        std::int64_t, const Eigen::Vector3d& on_a, const Eigen::Vector3d&) {
      return base.meets_head(Rt * (on_a - t)) == (base.contacts == RomContacts::articular);
    };
  return base.contact->least(P.R, P.t, q).distance;
}

ResectionPlan plan_targeted(const HipJoint& hip, const RomBaseline& baseline, const PlanLabrum* labrum,
                            const std::vector<ResectionTarget>& targets, const ResectionOptions& options) {
  if (!labrum) return plan_resection(hip, targets, baseline, options);
  ResectionOptions femur_only = options;
  femur_only.bones = ResectBones::femur;
  femur_only.pelvis_removed_mm.clear();  // the labral hip's socket is the labrum: nothing was removed from it
  ResectionPlan labral = plan_resection(*labrum->hip, targets, labrum->baseline, femur_only);
  std::vector<ResectionTarget> planned = cut_back(targets, cleared(labral));
  const ResectionPlan bony = plan_resection(hip, planned, baseline, options);
  if (clears_fewer(bony, cleared(labral))) {
    // No femur is cut for the labrum at a pose the bones cannot be cleared at: the labral plan again on the poses
    // the bony plan cleared (a subset of those it cleared, so it clears them all).
    planned = cut_back(planned, cleared(bony));
    const ResectionPlan first = std::move(labral);
    labral = plan_resection(*labrum->hip, planned, labrum->baseline, femur_only);
    labral.targets = first.targets;  // what the labrum allows: the first labral plan's (poses cleared, notes)
    labral.ms += first.ms, labral.rounds += first.rounds, labral.poses += first.poses;
  }
  return combined(hip, targets, bony, labral);
}

}  // namespace impinge::plan_detail
