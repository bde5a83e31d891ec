// run_plan's check and further passes (session/plan_check.hpp): the ROM limits and the clearance at every target
// pose in the placement of a new session on the resected bones.
#include "session/plan_check.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "impinge/casters/signed_distance.hpp"
#include "impinge/core/error.hpp"
#include "impinge/core/interrupt.hpp"
#include "session/plan_labrum.hpp"

namespace impinge::plan_detail {

namespace {

constexpr double kInfMm = std::numeric_limits<double>::infinity();

/// The least counted gap of `hip` at a pose (the ROM search's criterion: distance with the distance metric, else the
/// radial gap), over the vertices the baseline counts; +inf when none is near.
double counted_min_gap(const HipJoint& hip, const RomBaseline& base, const RomOptions& search, const FemurPose& P,
                       PoseResult& res) {
  hip.joint().detect(P.R, P.t, res);
  double m = std::numeric_limits<double>::infinity();
  const Vertices& socket = hip.joint().socket().relative;
  for (int b = 0; b < 2; ++b) {
    const ScanGaps& g = b == 0 ? res.ball_gaps : res.socket_gaps;
    const std::vector<std::uint8_t>& skip = b == 0 ? base.skip_ball : base.skip_socket;
    for (std::size_t i = 0; i < g.gap_mm.size(); ++i) {
      if (!skip.empty() && skip[i]) continue;
      double v = search.metric == RomMetric::distance && !g.distance_mm.empty() ? g.distance_mm[i] : g.gap_mm[i];
      if (std::isnan(v) && search.metric == RomMetric::distance && g.gap_mm[i] < 0) v = g.gap_mm[i];
      if (!(v < m)) continue;
      if (b == 1 && base.meets_head(P.R.transpose() * (socket.row(static_cast<Eigen::Index>(i)).transpose() - P.t)))
        continue;
      m = v;
    }
  }
  return m;
}

/// The frames of a motion file in contact in session `s` with baseline `base`: the bones' counted least gap at most
/// the threshold less the contact depth (the cut, mm), or with `labrum` (plan_labrum of s's hip) the femur and the
/// labrum within the cut: their exact least distance where the search's is exact (a cut >= 0 and the baseline's
/// contact meshes), else their counted least gap (the labrum split fine).
std::int64_t frames_in_contact(const Session& s, const RomBaseline& base, const PlanLabrum* labrum,
                               const RomOptions& search, const std::vector<PoseAngles>& frames) {
  std::int64_t n = 0;
  const double cut = search.threshold_mm - search.contact_depth_mm;
  const bool exact = labrum && labrum->baseline.contact && cut >= 0;
#pragma omp parallel reduction(+ : n)
  {
    PoseResult res;
#pragma omp for schedule(dynamic, 4)
    for (std::size_t k = 0; k < frames.size(); ++k) {
      if (interruption_requested()) continue;
      const FemurPose P = s.hip().femur_pose(frames[k]);
      if (counted_min_gap(s.hip(), base, search, P, res) <= cut ||
          (labrum && (exact ? labrum_exact_distance(*labrum, P, cut) <= cut
                            : counted_min_gap(*labrum->hip, labrum->baseline, search, P, res) <= cut)))
        ++n;
    }
  }
  interruption_point();  // a front end's stop (Ctrl-C in Python): the frames skipped above
  return n;
}

/// The check's session: `c.options` with the bones the plan may resect replaced by run's resected meshes, as the
/// first session (rom_session_options, the distances on, the plan's reach: which changes no limit, only which far
/// vertices get a distance).
std::unique_ptr<Session> check_session(const PlanRun& run, const PlanCheck& c) {
  SessionOptions after_options = c.options;
  if (run.plan.femur.allowed) after_options.input.ball_mesh = run.femur_resected, after_options.input.ball.clear();
  if (run.plan.pelvis.allowed)
    after_options.input.socket_mesh = run.pelvis_resected, after_options.input.socket.clear();
  SessionOptions check_options = rom_session_options(after_options, c.rom.search);
  check_options.hip.joint.distances = true;
  check_options.hip.joint.distance_reach_mm = c.distance_reach_mm;
  return std::make_unique<Session>(check_options);
}

/// Each target before and after (run.targets, run.all_met): a standard motion's limits (deg) before and on the
/// resected bones (`after`, of session `s_after`), with the labrum its labral limits too (labral_limit), its
/// targeted limit (the labral one with the labrum, else the bony one) met when free or limited within 0.1 deg of
/// the target, else its shortfall (deg); a motion file's frames in contact before and after (with the labrum: with
/// the bones or the labrum, c.labrum and `labrum_after`: plan_labrum of each session's hip), met when none is
/// after. `met` and all_met here: the limits alone (check_clearance adds the clearance).
void check_targets(PlanRun& run, const PlanCheck& c, const Session& s_after, const RomRun& after,
                   const PlanLabrum* labrum_after) {
  const RomRun& before = c.before;
  run.all_met = true;
  run.targets.clear();
  for (const ResectionTarget& target : c.targets) {
    PlanTargetCheck t;
    t.name = target.name;
    t.target_deg = target.angle_deg;
    if (!std::isnan(target.angle_deg)) {
      for (std::size_t m = 0; m < before.motions.size(); ++m)
        if (before.motions[m].name == target.name) {
          t.before = before.limits[m], t.after = after.limits[m];
          if (before.labrum && after.labrum)
            t.labral_before = labral_limit(before, m), t.labral_after = labral_limit(after, m);
        }
      const RomLimitStatus status = t.labral_after ? t.labral_after->status : t.after.status;
      const double reached = t.labral_after ? t.labral_after->limit_deg : t.after.limit_deg;
      t.met = status == RomLimitStatus::free ||
              (status == RomLimitStatus::limited && reached >= target.angle_deg - 0.1);
      if (!t.met) t.shortfall_deg = status == RomLimitStatus::limited ? target.angle_deg - reached : target.angle_deg;
    } else {
      t.frames_in_contact_before = frames_in_contact(c.s, before.baseline, c.labrum, c.rom.search, target.poses);
      t.frames_in_contact_after =
          frames_in_contact(s_after, after.baseline, labrum_after, c.rom.search, target.poses);
      t.met = t.frames_in_contact_after == 0;
    }
    t.limit_met = t.met;
    run.all_met = run.all_met && t.met;
    run.targets.push_back(t);
  }
}

/// Both bodies of `hip` (the femur and the pelvis, or a labral hip's labrum) for exact signed distances (joint frame,
/// unposed: JointBody::relative).
struct BoneQueries {
  SignedDistanceQuery femur, pelvis;
  static TriangleMesh mesh(const JointBody& b) {
    TriangleMesh m;
    m.V = b.relative, m.F = b.mesh.F, m.source = b.mesh.source;
    return m;
  }
  explicit BoneQueries(const HipJoint& hip) : femur(mesh(hip.joint().ball())), pelvis(mesh(hip.joint().socket())) {}
};

/// A pose's least signed distances (mm): over the vertices the plan follows, and over every vertex (the joint
/// surfaces too).
struct PoseClearance {
  double counted = std::numeric_limits<double>::infinity(), any = std::numeric_limits<double>::infinity();
};

/// The least signed distances (mm) at pose P of `hip` (a session's, or its labral hip: the femur and the labrum): over
/// the vertices the plan follows (RomBaseline `base`'s, as find_contacts in resection.cpp) and over every vertex; each
/// vertex's Euclidean distance to the other bone where the joint gives one (within its reach), the exact signed
/// distance (`q`) where it gives none but the radial gap says the vertex lies inside the other bone (farther inside
/// than the reach, or the radial gap's error); +inf when none is within the reach.
PoseClearance pose_clearance(const HipJoint& hip, const RomBaseline& base, const BoneQueries& q, const FemurPose& P,
                             PoseResult& res) {
  hip.joint().detect(P.R, P.t, res);
  PoseClearance m;
  for (int b = 0; b < 2; ++b) {
    const ScanGaps& g = b == 0 ? res.ball_gaps : res.socket_gaps;
    const std::vector<std::uint8_t>& skip = b == 0 ? base.skip_ball : base.skip_socket;
    const Vertices& own = b == 0 ? hip.joint().ball().relative : hip.joint().socket().relative;
    for (std::size_t i = 0; i < g.gap_mm.size(); ++i) {
      double v = g.distance_mm.empty() ? std::nan("") : double(g.distance_mm[i]);
      if (std::isnan(v) && !(g.gap_mm[i] < 0)) continue;
      const Eigen::Vector3d x = own.row(static_cast<Eigen::Index>(i)).transpose();
      if (std::isnan(v)) {
        ClosestSurfacePoint cp;
        const bool found = b == 0 ? q.pelvis.signed_distance(P.R * x + P.t, kInfMm, 0, cp)
                                  : q.femur.signed_distance(P.R.transpose() * (x - P.t), kInfMm, 0, cp);
        if (!found) continue;
        v = cp.signed_mm();
      }
      m.any = std::min(m.any, v);
      if ((!skip.empty() && skip[i]) || !(v < m.counted)) continue;
      if (b == 1 && base.meets_head(P.R.transpose() * (x - P.t))) continue;
      m.counted = v;
    }
  }
  return m;
}

/// Each pose's clearance in `hip`'s placement (pose_clearance) at pose `which[p]` (target, pose) of `planned`, in
/// parallel. Throws impinge::Error with the first pose's error.
std::vector<PoseClearance> pose_clearances(const HipJoint& hip, const RomBaseline& base,
                                    const std::vector<ResectionTarget>& planned,
                                    const std::vector<std::pair<std::size_t, std::size_t>>& which) {
  std::vector<PoseClearance> d(which.size());
  if (which.empty()) return d;
  const BoneQueries q(hip);
  std::string error;
#pragma omp parallel
  {
    PoseResult res;
#pragma omp for schedule(dynamic, 1)
    for (std::size_t p = 0; p < which.size(); ++p) {
      if (interruption_requested()) continue;
      try {
        const PoseAngles& a = planned[which[p].first].poses[which[p].second];
        d[p] = pose_clearance(hip, base, q, hip.femur_pose(a), res);
      } catch (const std::exception& e) {
#pragma omp critical(plan_clearance_error)
        if (error.empty()) error = e.what();
      }
    }
  }
  interruption_point();  // a front end's stop (Ctrl-C in Python): the poses skipped above
  require(error.empty(), "plan check: " + error);
  return d;
}

/// pose_clearances of the femur against the labrum (`labrum`: the femur and its labrum split fine), each pose's least
/// counted distance also at most the exact least distance there (labrum_exact_distance within `reach`, mm): the
/// labrum's free margin may cross the femur between vertices. Throws impinge::Error as pose_clearances does.
std::vector<PoseClearance> labrum_clearances(const PlanLabrum& labrum, const std::vector<ResectionTarget>& planned,
                                             const std::vector<std::pair<std::size_t, std::size_t>>& which,
                                             double reach) {
  std::vector<PoseClearance> d = pose_clearances(*labrum.hip, labrum.baseline, planned, which);
#pragma omp parallel for schedule(dynamic, 1)
  for (std::size_t p = 0; p < which.size(); ++p) {
    if (interruption_requested()) continue;
    const FemurPose P = labrum.hip->femur_pose(planned[which[p].first].poses[which[p].second]);
    d[p].counted = std::min(d[p].counted, labrum_exact_distance(labrum, P, reach));
  }
  interruption_point();
  return d;
}

/// The clearance each target keeps in session `s_after`'s placement (the final one when this is the last check):
/// over the poses the plan cleared (the first run.plan.targets[k].poses_cleared of `planned[k]`, the poses of the
/// last pass), the least counted signed distance (mm) and its motion angle or frame, and at the target's own pose
/// (its last, when the plan cleared it); with `labrum` (plan_labrum of s_after's hip) each pose's the lesser of the
/// bones' and the femur's to the labrum (labrum_clearances; that one alone also: clearance_least_labrum_mm); met
/// when the least is at least the clearance (less 1e-4 mm of rounding). A target is met when its limit and its
/// clearance are; sets run.clearance_met and run.all_met.
void check_clearance(PlanRun& run, const PlanCheck& c, const Session& s_after, const RomBaseline& base,
                     const PlanLabrum* labrum, const std::vector<ResectionTarget>& planned) {
  constexpr double kRoundingMm = 1e-4;
  std::vector<std::pair<std::size_t, std::size_t>> which;
  for (std::size_t k = 0; k < planned.size() && k < run.plan.targets.size(); ++k) {
    const auto cleared = static_cast<std::size_t>(std::max<std::int64_t>(0, run.plan.targets[k].poses_cleared));
    for (std::size_t i = 0; i < std::min(cleared, planned[k].poses.size()); ++i) which.emplace_back(k, i);
  }
  std::vector<PoseClearance> d = pose_clearances(s_after.hip(), base, planned, which);
  std::vector<PoseClearance> labral;
  if (labrum) labral = labrum_clearances(*labrum, planned, which, c.distance_reach_mm);
  for (std::size_t p = 0; p < labral.size(); ++p)
    d[p].counted = std::min(d[p].counted, labral[p].counted), d[p].any = std::min(d[p].any, labral[p].any);
  run.clearance_met = true;
  run.all_met = true;
  for (std::size_t k = 0; k < run.targets.size(); ++k) {
    PlanTargetCheck& t = run.targets[k];
    t.clearance_least_mm = t.clearance_least_at = t.clearance_at_target_mm = t.clearance_least_any_mm = std::nan("");
    t.clearance_least_labrum_mm = std::nan("");
    t.clearance_poses = 0;
    for (std::size_t p = 0; p < which.size(); ++p) {
      if (which[p].first != k) continue;
      ++t.clearance_poses;
      const ResectionTarget& tg = planned[k];
      if (!(d[p].counted >= t.clearance_least_mm))
        t.clearance_least_mm = d[p].counted, t.clearance_least_at = tg.theta_deg[which[p].second];
      if (!(d[p].any >= t.clearance_least_any_mm)) t.clearance_least_any_mm = d[p].any;
      if (!labral.empty() && !(labral[p].counted >= t.clearance_least_labrum_mm))
        t.clearance_least_labrum_mm = labral[p].counted;
      if (which[p].second + 1 == tg.poses.size()) t.clearance_at_target_mm = d[p].counted;
    }
    t.clearance_met = !(t.clearance_least_mm < c.ro.clearance_mm - kRoundingMm);
    t.met = t.limit_met && t.clearance_met;
    run.clearance_met = run.clearance_met && t.clearance_met;
    run.all_met = run.all_met && t.met;
  }
}

/// The largest distance (mm) between the vertices of the labrum `before` and `after` (input frame), NaN when their
/// vertex counts differ.
double labrum_moved_mm(const TriangleMesh& before, const TriangleMesh& after) {
  if (before.V.rows() != after.V.rows()) return std::nan("");
  return before.V.rows() ? (before.V - after.V).rowwise().norm().maxCoeff() : 0.0;
}

/// Adds a further pass's removal of one bone to the plan's `total` (when that bone may be resected): `mesh` (input
/// frame, mm) moved by the pass's displacement of `body_after` on session `s_after`, the depths (mm) summed, the
/// resected vertices back in the first session's joint frame (the frame of total.resected; joint_to_input: that
/// session's joint-to-input rotation), the measures summarised again under the safety depth (mm).
void add_pass_removal(BoneResection& total, const BoneResection& pass_plan, const Session& s_after,
                      const JointBody& body_after, const JointBody& body, const Vertices& scan, TriangleMesh& mesh,
                      const Eigen::Matrix3d& joint_to_input, double safety_depth_mm) {
  if (!total.allowed) return;
  mesh = resected_mesh(s_after, pass_plan, body_after, mesh.V, mesh.source.c_str());
  for (std::size_t i = 0; i < total.depth_mm.size(); ++i) total.depth_mm[i] += pass_plan.depth_mm[i];
  // In the first session's joint frame (the frame of total.resected): the input-frame displacement, rotated.
  total.resected = body.relative + (mesh.V - scan) * joint_to_input;
  summarize_resection(total, body.relative, body.mesh.F, body.vertex_area, safety_depth_mm);
  total.thin_vertices += pass_plan.thin_vertices;
}

/// Adds pass `pass`'s plan `next` (made on session `s_after`) to run.plan: both bones' removals, and the pass's
/// targets, iterations and residual (mm) in place of the earlier ones, its rounds, poses, contacts and time (ms)
/// added; run.plan.passes = pass + 1.
void add_pass(PlanRun& run, const PlanCheck& c, const Session& s_after, const ResectionPlan& next,
              const Eigen::Matrix3d& joint_to_input, int pass) {
  const Session& s = c.s;
  add_pass_removal(run.plan.femur, next.femur, s_after, s_after.joint().ball(), s.joint().ball(), c.femur_scan,
                   run.femur_resected, joint_to_input, c.ro.safety_depth_mm);
  add_pass_removal(run.plan.pelvis, next.pelvis, s_after, s_after.joint().socket(), s.joint().socket(), c.pelvis_scan,
                   run.pelvis_resected, joint_to_input, c.ro.safety_depth_mm);
  run.plan.targets = next.targets;
  run.plan.iterations = next.iterations;
  run.plan.rounds += next.rounds;
  run.plan.residual_mm = next.residual_mm;
  run.plan.poses += next.poses;
  run.plan.contacts += next.contacts;
  run.plan.ms += next.ms;
  run.plan.passes = pass + 1;
}

/// A further pass's targets: per target of the first plan (`first`), its poses there or those of plan_targets on the
/// check's limits (`again`: from 2 deg short of a limit that fell short of where the first plan began), the more.
std::vector<ResectionTarget> further_targets(const std::vector<ResectionTarget>& first,
                                             const std::vector<ResectionTarget>& again) {
  std::vector<ResectionTarget> out = first;
  for (ResectionTarget& t : out)
    for (const ResectionTarget& a : again)
      if (a.name == t.name && a.poses.size() > t.poses.size()) t = a;
  return out;
}

}  // namespace

TriangleMesh resected_mesh(const Session& session, const BoneResection& b, const JointBody& body,
                           const Vertices& scan_pose, const char* name) {
  const Eigen::Matrix3d joint_to_input = session.to_input() * session.hip().joint_to_working();
  TriangleMesh m;
  m.V = scan_pose + (b.resected - body.relative) * joint_to_input.transpose();
  m.F = body.mesh.F;
  m.source = name;
  return m;
}

double check_plan(PlanRun& run, const PlanCheck& c) {
  const Eigen::Matrix3d joint_to_input = c.s.to_input() * c.s.hip().joint_to_working();  // the first session's
  double extra_plan_ms = 0;
  std::vector<ResectionTarget> planned = c.targets;  // the last pass's targets and poses
  for (int pass = 1;; ++pass) {
    const std::unique_ptr<Session> s_after = check_session(run, c);
    const RomRun after = run_rom(*s_after, c.limits_only);
    std::optional<PlanLabrum> labrum;  // with --labrum: the labrum, split fine, on the bones after
    if (after.labrum) labrum = plan_labrum(s_after->hip(), c.rom.labrum, c.rom.search);
    check_targets(run, c, *s_after, after, labrum ? &*labrum : nullptr);
    check_clearance(run, c, *s_after, after.baseline, labrum ? &*labrum : nullptr, planned);
    run.final_head_centre_mm = s_after->head_centre_input();
    if (after.labrum) run.labrum_moved_mm = labrum_moved_mm(run.labrum_mesh, labrum_input(*s_after, after));
    if (run.all_met || pass >= kPlanPasses) break;
    // A further pass on the resected bones in their own placement, its depths added to the earlier passes'.
    const auto t_pass = Clock::now();
    ResectionOptions more = c.ro;
    more.femur_removed_mm = run.plan.femur.depth_mm;
    more.pelvis_removed_mm = run.plan.pelvis.depth_mm;
    std::vector<ResectionTarget> targets =
        further_targets(c.targets, plan_targets(*s_after, c.request, targeted_limits(after)));
    const ResectionPlan next =
        plan_targeted(s_after->hip(), after.baseline, labrum ? &*labrum : nullptr, targets, more);
    extra_plan_ms += ms_since(t_pass);
    if (next.femur.deepest_cut_mm <= kResectedDepthMm && next.pelvis.deepest_cut_mm <= kResectedDepthMm) break;
    add_pass(run, c, *s_after, next, joint_to_input, pass);
    planned = std::move(targets);
  }
  return extra_plan_ms;
}

}  // namespace impinge::plan_detail
