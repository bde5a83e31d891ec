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

/// The exact query of the ROM search at pose P within `reach` (mm): a pair across the head-neck junction classed by
/// the femur's closest point, as rom_exact.cpp's ExactScanner classes it.
MeshContact::Query exact_query(const RomBaseline& base, const FemurPose& P, double reach) {
  MeshContact::Query q;
  q.reach = reach;
  if (base.head_zone)
    q.pair_counts = [&base, Rt = Eigen::Matrix3d(P.R.transpose()), t = P.t](
                        std::int64_t, const Eigen::Vector3d& on_a, const Eigen::Vector3d&) {
      return base.meets_head(Rt * (on_a - t)) == (base.contacts == RomContacts::articular);
    };
  return q;
}

/// What the femur resected by `plan` (its femur, joint frame) still lacks of `clearance_mm` against the labrum by the
/// exact mesh-to-mesh distance (the baseline's counted triangles, each classed pair by pair), at its worst pose of
/// those the plan cleared (the first poses_cleared of each target), mm; 0 when no pair is within the clearance or
/// without the exact meshes (RomBaseline::contact). The plan's contacts are per vertex: the labrum's free margin, a
/// sharp edge, may still come nearer the femur between its vertices.
double exact_shortfall_mm(const PlanLabrum& labrum, const ResectionPlan& plan,
                          const std::vector<ResectionTarget>& targets, double clearance_mm) {
  const RomBaseline& base = labrum.baseline;
  if (!base.contact) return 0;
  std::vector<std::uint8_t> counted(static_cast<std::size_t>(base.contact->faces_a()));
  for (std::size_t f = 0; f < counted.size(); ++f)
    counted[f] = base.contact->counted_a(static_cast<std::int64_t>(f)) ? 2 : 0;
  const JointBody& lab = labrum.hip->joint().socket();
  const MeshContact contact(plan.femur.resected, labrum.hip->joint().ball().mesh.F, lab.relative, lab.mesh.F,
                            std::move(counted),
                            std::vector<std::uint8_t>(static_cast<std::size_t>(lab.mesh.F.rows()), 0));
  std::vector<PoseAngles> poses;
  for (std::size_t k = 0; k < targets.size(); ++k)
    for (std::int64_t i = 0; i < plan.targets[k].poses_cleared; ++i)
      poses.push_back(targets[k].poses[static_cast<std::size_t>(i)]);
  double worst = 0;
#pragma omp parallel for schedule(dynamic, 1) reduction(max : worst)
  for (std::size_t p = 0; p < poses.size(); ++p) {
    const FemurPose P = labrum.hip->femur_pose(poses[p]);
    const double d = contact.least(P.R, P.t, exact_query(base, P, clearance_mm)).distance;
    if (std::isfinite(d)) worst = std::max(worst, clearance_mm - d);
  }
  return worst;
}

/// The labral plan (plan_resection of the labral hip for `targets`, `options`), asked again, at most twice, while
/// the exact distance falls short of the clearance somewhere (exact_shortfall_mm > 0), for the clearance plus that
/// shortfall and the plan's tolerance more (the per-vertex contacts' error there, made up); the candidates' margin
/// less as much, so that the same contacts are followed within the same distance reach (the increase at most what
/// the margin and the clearance's range leave).
ResectionPlan labral_plan(const PlanLabrum& labrum, const std::vector<ResectionTarget>& targets,
                          ResectionOptions options) {
  const double clearance = options.clearance_mm;
  ResectionPlan plan = plan_resection(*labrum.hip, targets, labrum.baseline, options);
  for (int again = 0; again < 2; ++again) {
    const double shortfall = exact_shortfall_mm(labrum, plan, targets, clearance);
    if (shortfall <= 0) break;
    const double more = std::min({shortfall + options.tolerance_mm, options.candidate_margin_mm,
                                  ResectionOptions::kClearanceRange.max - options.clearance_mm});
    if (more <= 0) break;
    options.clearance_mm += more;
    options.candidate_margin_mm -= more;
    const double ms = plan.ms;
    const int rounds = plan.rounds;
    plan = plan_resection(*labrum.hip, targets, labrum.baseline, options);
    plan.ms += ms, plan.rounds += rounds;
  }
  return plan;
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
  return base.contact->least(P.R, P.t, exact_query(base, P, reach)).distance;
}

ResectionPlan plan_targeted(const HipJoint& hip, const RomBaseline& baseline, const PlanLabrum* labrum,
                            const std::vector<ResectionTarget>& targets, const ResectionOptions& options) {
  if (!labrum) return plan_resection(hip, targets, baseline, options);
  ResectionOptions femur_only = options;
  femur_only.bones = ResectBones::femur;
  femur_only.pelvis_removed_mm.clear();  // the labral hip's socket is the labrum: nothing was removed from it
  ResectionPlan labral = labral_plan(*labrum, targets, femur_only);
  std::vector<ResectionTarget> planned = cut_back(targets, cleared(labral));
  const ResectionPlan bony = plan_resection(hip, planned, baseline, options);
  if (clears_fewer(bony, cleared(labral))) {
    // No femur is cut for the labrum at a pose the bones cannot be cleared at: the labral plan again on the poses
    // the bony plan cleared (a subset of those it cleared, so it clears them all).
    planned = cut_back(planned, cleared(bony));
    const ResectionPlan first = std::move(labral);
    labral = labral_plan(*labrum, planned, femur_only);
    labral.targets = first.targets;  // what the labrum allows: the first labral plan's (poses cleared, notes)
    labral.ms += first.ms, labral.rounds += first.rounds, labral.poses += first.poses;
  }
  return combined(hip, targets, bony, labral);
}

}  // namespace impinge::plan_detail
