#include "impinge/session/plan_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <map>
#include <memory>
#include <sstream>

#include "impinge/clinical/clock_summary.hpp"
#include "impinge/clinical/published_rom.hpp"
#include "impinge/core/error.hpp"
#include "impinge/core/interrupt.hpp"
#include "impinge/core/parse.hpp"
#include "impinge/io/mesh_io.hpp"
#include "impinge/io/motion.hpp"
#include "impinge/session/morphology_run.hpp"
#include "impinge/session/records.hpp"

namespace impinge {

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

/// "name=deg,name=deg" and "normal" into motion -> angle (a named angle replaces normal's).
std::map<std::string, double> parse_targets(const std::string& text, const std::vector<StandardMotion>& motions) {
  std::map<std::string, double> out;
  std::string names;
  for (const StandardMotion& m : motions) names += (names.empty() ? "" : ", ") + m.name;
  std::stringstream ss(text);
  std::string item;
  std::map<std::string, double> named;
  bool normal = false;
  while (std::getline(ss, item, ',')) {
    item.erase(0, item.find_first_not_of(" \t"));
    item.erase(item.find_last_not_of(" \t") + 1);
    if (item.empty()) continue;
    if (item == "normal") {
      normal = true;
      continue;
    }
    const auto eq = item.find('=');
    require(eq != std::string::npos, "--target: '" + item + "' is not MOTION=DEG or 'normal'; motions: " + names);
    const std::string name = item.substr(0, eq);
    require(std::any_of(motions.begin(), motions.end(), [&](const StandardMotion& m) { return m.name == name; }),
            "--target: '" + name + "' is not a standard motion; valid: " + names + ", or 'normal'");
    const double deg = parse_number_list(item.substr(eq + 1), "--target " + name, 1)[0];
    require(std::isfinite(deg) && deg > 0 && deg <= 150,
            "--target " + name + "=" + item.substr(eq + 1) + ": the angle must lie in (0, 150] deg");
    require(named.count(name) == 0, [&] {
      return "--target: " + name + " given twice (" + name + "=" + shortest_decimal(named[name]) + " and " + item +
             "): give each motion once";
    });
    named[name] = deg;
  }
  if (normal)
    for (const StandardMotion& m : motions) {
      const PublishedRange r = published_normal_range(m.name);
      if (std::isfinite(r.normal_deg)) out[m.name] = r.normal_deg;
    }
  for (const auto& [k, v] : named) out[k] = v;
  return out;
}

/// The least counted gap at a pose (the ROM search's criterion: distance with the distance metric, else the
/// radial gap), over the vertices the baseline counts; +inf when none is near.
double counted_min_gap(const Session& s, const RomBaseline& base, const RomOptions& search, const FemurPose& P,
                       PoseResult& res) {
  s.joint().detect(P.R, P.t, res);
  double m = std::numeric_limits<double>::infinity();
  const Vertices& socket = s.joint().socket().relative;
  for (int b = 0; b < 2; ++b) {
    const ScanGaps& g = b == 0 ? res.ball_gaps : res.socket_gaps;
    const std::vector<std::uint8_t>& skip = b == 0 ? base.skip_ball : base.skip_socket;
    for (std::size_t i = 0; i < g.gap_mm.size(); ++i) {
      if (!skip.empty() && skip[i]) continue;
      double v = search.metric == RomMetric::distance && !g.distance_mm.empty() ? g.distance_mm[i] : g.gap_mm[i];
      if (std::isnan(v) && search.metric == RomMetric::distance && g.gap_mm[i] < 0) v = g.gap_mm[i];
      if (!(v < m)) continue;
      if (b == 1 && std::isfinite(base.head_sphere_reach_mm)) {
        const Eigen::Vector3d u = socket.row(static_cast<Eigen::Index>(i)).transpose();
        if ((P.R.transpose() * (u - P.t) - base.head_centre).norm() <= base.head_sphere_reach_mm) continue;
      }
      m = v;
    }
  }
  return m;
}

std::int64_t frames_in_contact(const Session& s, const RomBaseline& base, const RomOptions& search,
                               const std::vector<PoseAngles>& frames) {
  std::int64_t n = 0;
  const double cut = search.threshold_mm - search.contact_depth_mm;
#pragma omp parallel reduction(+ : n)
  {
    PoseResult res;
#pragma omp for schedule(dynamic, 4)
    for (std::size_t k = 0; k < frames.size(); ++k)
      if (!interruption_requested() && counted_min_gap(s, base, search, s.hip().femur_pose(frames[k]), res) <= cut) ++n;
  }
  interruption_point();  // a front end's stop (Ctrl-C in Python): the frames skipped above
  return n;
}

/// The extent (from, to hours) of the smallest clock arc holding every resected vertex.
void clock_extent(const std::vector<double>& hours, const std::vector<double>& depth, double& from, double& to) {
  std::vector<double> h;
  for (std::size_t i = 0; i < hours.size() && i < depth.size(); ++i)
    if (depth[i] > kResectedDepthMm && std::isfinite(hours[i])) h.push_back(std::fmod(hours[i], 12.0));
  if (h.empty()) return;
  std::sort(h.begin(), h.end());
  double gap = h.front() + 12 - h.back();
  std::size_t after = 0;
  for (std::size_t i = 1; i < h.size(); ++i)
    if (h[i] - h[i - 1] > gap) gap = h[i] - h[i - 1], after = i;
  auto hour = [](double x) { return x <= 0 ? x + 12 : x; };
  from = hour(h[after]);
  to = hour(h[(after + h.size() - 1) % h.size()]);
}

std::optional<Morphology> try_morphology(const SessionOptions& so, std::vector<std::string>& notes, const char* what) {
  try {
    return run_morphology(so).morphology;
  } catch (const std::exception& e) {
    notes.push_back(std::string("morphology ") + what + " not measured: " + e.what());
    return std::nullopt;
  }
}

}  // namespace

std::vector<ResectionTarget> plan_targets(const Session& s, const PlanRequest& request, const RomRun& before) {
  std::vector<ResectionTarget> out;
  const double step = request.step_deg;
  check_in_range("plan-step", step, PlanRequest::kStepRange, "deg");
  const std::map<std::string, double> wanted = parse_targets(request.target, before.motions);
  for (std::size_t m = 0; m < before.motions.size(); ++m) {
    const StandardMotion& motion = before.motions[m];
    const auto it = wanted.find(motion.name);
    if (it == wanted.end()) continue;
    const RomLimit& limit = before.limits[m];
    ResectionTarget t;
    t.name = motion.name;
    t.angle_deg = it->second;
    double from = 0;
    if (limit.status == RomLimitStatus::limited) {
      if (limit.limit_deg >= t.angle_deg) {
        out.push_back(t);  // met already: no poses
        continue;
      }
      from = std::max(0.0, limit.limit_deg - 2);
    } else if (limit.status == RomLimitStatus::free) {
      out.push_back(t);
      continue;
    } else if (limit.status == RomLimitStatus::not_reachable) {
      // The straight way from neutral to the start, parameterised by its largest angle (as find_rom_limits).
      const PoseAngles& a = motion.start;
      const double way =
          std::max({std::abs(a.flexion_deg), std::abs(a.adduction_deg), std::abs(a.internal_rotation_deg)});
      for (double x = 0; x < way; x += step) {
        const double f = x / way;
        t.poses.push_back({f * a.flexion_deg, f * a.adduction_deg, f * a.internal_rotation_deg});
        t.theta_deg.push_back(std::nan(""));
      }
    }
    for (double th = from;; th += step) {
      const double x = std::min(th, t.angle_deg);
      t.poses.push_back(motion.angles(x));
      t.theta_deg.push_back(x);
      if (x >= t.angle_deg) break;
    }
    out.push_back(t);
  }
  if (!request.target_motion.empty()) {
    const Motion motion = load_motion(request.target_motion, s.side());
    ResectionTarget t;
    t.name = request.target_motion;
    t.poses = motion.angles;
    for (std::size_t k = 0; k < motion.angles.size(); ++k) t.theta_deg.push_back(static_cast<double>(k));
    out.push_back(t);
  }
  require(!out.empty(), "plan: no target: give --target (MOTION=DEG,... or normal) or --target-motion");
  return out;
}

void check_plan_request(const SessionOptions& options, const PlanRequest& request) {
  check_in_range("max-depth-fraction", request.max_depth_fraction, PlanRequest::kMaxDepthFractionRange);
  check_in_range("max-depth", request.max_depth_mm, PlanRequest::kMaxDepthRange, "mm");
  parse_targets(request.target, standard_motions());
  if (!request.target_motion.empty()) load_motion(request.target_motion, input_side(options.input));
  require(!request.target.empty() || !request.target_motion.empty(),
          "plan: no target: give --target (MOTION=DEG,... or normal) or --target-motion");
}

namespace {

/// `rom` asking for the ROM limits alone (no map, no envelope): the searches before and on the resected bones.
RomRequest limits_only_request(const RomRequest& rom) {
  RomRequest limits_only = rom;
  limits_only.map = false;
  limits_only.envelope = false;
  limits_only.limits = true;
  limits_only.both_frames = false;  // the plan targets the session frame's limits only
  return limits_only;
}

/// The plan's session options: the ROM search's (rom_session_options), with the distances on and a distance
/// reach (mm) of at least the clearance plus the candidate margin (mm).
SessionOptions plan_session_options(const SessionOptions& options, const RomOptions& search,
                                    const PlanRequest& request) {
  SessionOptions so = rom_session_options(options, search);
  so.hip.joint.distances = true;
  so.hip.joint.distance_reach_mm =
      std::max(so.hip.joint.distance_reach_mm, request.resection.clearance_mm + request.resection.candidate_margin_mm);
  return so;
}

/// What the plan is computed on, from session `s`: its warnings, subject, bones' sources, input frame and the
/// head centre at the scan pose (input frame, mm).
void describe_session(PlanRun& run, const Session& s) {
  run.warnings = s.warnings();
  run.meshes = meshes_record(s.femur_hygiene(), s.pelvis_hygiene());
  run.subject = s.subject_name();
  run.femur_source = s.ball_source();
  run.pelvis_source = s.socket_source();
  run.input_frame = s.input_frame();
  run.head_centre_mm = s.head_centre_input();
  run.pelvic_frame = pelvic_frame_name(s);
  run.cor_method = s.cor_method();
}

/// The morphology before (on `options`' inputs; a note when it cannot be measured), the neck's least diameter
/// (mm, about the neck axis it found) and the safety depth (mm): the cap given, or the fraction of the neck's
/// diameter (Mardones et al. 2005). Throws impinge::Error when neither is there.
void set_safety_depth(PlanRun& run, const Session& s, const SessionOptions& options, const PlanRequest& request) {
  run.before = try_morphology(options, run.notes, "before");
  const HipJoint& hip = s.hip();
  if (run.before) {
    const Eigen::Matrix3d to_joint = hip.joint_to_working().transpose();
    const Eigen::Vector3d neck = to_joint * run.before->neck_axis;
    run.neck_diameter_mm = neck_diameter_mm(s.joint().ball().relative, s.joint().ball().mesh.F, hip.head_centre_joint(),
                                            hip.head_radius_mm(), neck);
  }
  if (request.max_depth_mm > 0) {
    run.safety_depth_mm = request.max_depth_mm;
  } else {
    require(std::isfinite(run.neck_diameter_mm),
            "plan: the neck's diameter could not be measured (" +
                (run.notes.empty() ? std::string("no neck found") : run.notes.back()) +
                "), so the safety depth is unknown: give --max-depth");
    run.safety_depth_mm = request.max_depth_fraction * run.neck_diameter_mm;
  }
}

/// A resected mesh in the input frame (mm): the scan-pose vertices `scan_pose` moved by the plan's (joint-frame)
/// displacement of `body`, b.resected - body.relative; the body's faces, named `name`. `session` is the one the
/// plan was made on; its input is the bones as they were before that plan.
TriangleMesh resected_mesh(const Session& session, const BoneResection& b, const JointBody& body,
                           const Vertices& scan_pose, const char* name) {
  const Eigen::Matrix3d joint_to_input = session.to_input() * session.hip().joint_to_working();
  TriangleMesh m;
  m.V = scan_pose + (b.resected - body.relative) * joint_to_input.transpose();
  m.F = body.mesh.F;
  m.source = name;
  return m;
}

/// What the check's passes share: the call's options and ROM request, the limits-only request, the first session's
/// distance reach (mm), the first session (the plan's joint frame) with its limits before, the targets, the
/// resection's options and the bones' scan-pose vertices (input frame, mm).
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
};

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
/// resected bones (`after`, of session `s_after`), met when free or limited within 0.1 deg of the target, else its
/// shortfall (deg); a motion file's frames in contact before and after, met when none is after.
void check_targets(PlanRun& run, const PlanCheck& c, const Session& s_after, const RomRun& after) {
  const RomRun& before = c.before;
  run.all_met = true;
  run.targets.clear();
  for (const ResectionTarget& target : c.targets) {
    PlanTargetCheck t;
    t.name = target.name;
    t.target_deg = target.angle_deg;
    if (!std::isnan(target.angle_deg)) {
      for (std::size_t m = 0; m < before.motions.size(); ++m)
        if (before.motions[m].name == target.name) t.before = before.limits[m], t.after = after.limits[m];
      t.met = t.after.status == RomLimitStatus::free ||
              (t.after.status == RomLimitStatus::limited && t.after.limit_deg >= target.angle_deg - 0.1);
      if (!t.met)
        t.shortfall_deg =
            t.after.status == RomLimitStatus::limited ? target.angle_deg - t.after.limit_deg : target.angle_deg;
    } else {
      t.frames_in_contact_before = frames_in_contact(c.s, before.baseline, c.rom.search, target.poses);
      t.frames_in_contact_after = frames_in_contact(s_after, after.baseline, c.rom.search, target.poses);
      t.met = t.frames_in_contact_after == 0;
    }
    run.all_met = run.all_met && t.met;
    run.targets.push_back(t);
  }
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

/// The check: a new session on the resected meshes, as `impinge rom` on the written files. Where it misses a
/// target, a further pass plans on those resected bones, with their own joint placement, acetabulum and joint
/// surfaces (which the resection may have moved a little: the equidistant joint centre, the rim), within what
/// the safety depth leaves of each vertex, and adds to the resection; at most kPlanPasses passes. Sets
/// run.targets and run.all_met; returns the further passes' planning time (ms).
double check_plan(PlanRun& run, const PlanCheck& c) {
  constexpr int kPlanPasses = 3;
  const Eigen::Matrix3d joint_to_input = c.s.to_input() * c.s.hip().joint_to_working();  // the first session's
  double extra_plan_ms = 0;
  std::unique_ptr<Session> s_after;
  RomRun after;
  for (int pass = 1;; ++pass) {
    s_after = check_session(run, c);
    after = run_rom(*s_after, c.limits_only);
    check_targets(run, c, *s_after, after);
    if (run.all_met || pass >= kPlanPasses) break;
    // A further pass on the resected bones, its depths added to the earlier passes'.
    const auto t_pass = Clock::now();
    ResectionOptions more = c.ro;
    more.femur_removed_mm = run.plan.femur.depth_mm;
    more.pelvis_removed_mm = run.plan.pelvis.depth_mm;
    const ResectionPlan next =
        plan_resection(s_after->hip(), plan_targets(*s_after, c.request, after), after.baseline, more);
    extra_plan_ms += ms_since(t_pass);
    if (next.femur.deepest_cut_mm <= kResectedDepthMm && next.pelvis.deepest_cut_mm <= kResectedDepthMm) break;
    add_pass(run, c, *s_after, next, joint_to_input, pass);
  }
  return extra_plan_ms;
}

/// Per vertex of each bone with a clock (anatomical neutral), its clock hour (run.femur_hours, pelvis_hours), and
/// the resection's extent on that clock (run.clock_from_h, clock_to_h: femur, pelvis; hours).
void set_clock_extents(PlanRun& run, const Session& s) {
  const HipJoint& hip = s.hip();
  if (hip.ball_clock()) {
    run.femur_hours = clock_hours(s.joint().ball().relative, *hip.ball_clock());
    clock_extent(run.femur_hours, run.plan.femur.depth_mm, run.clock_from_h[0], run.clock_to_h[0]);
  }
  if (hip.socket_clock()) {
    run.pelvis_hours = clock_hours(s.joint().socket().relative, *hip.socket_clock());
    clock_extent(run.pelvis_hours, run.plan.pelvis.depth_mm, run.clock_from_h[1], run.clock_to_h[1]);
  }
}

/// The morphology of the resected femur (run.after; a note when it cannot be measured), when the femur was
/// resected and the morphology before was measured: `options` with the resected femur.
void measure_after(PlanRun& run, const SessionOptions& options) {
  if (run.plan.femur.allowed && run.before) {
    SessionOptions mo = options;
    mo.input.ball_mesh = run.femur_resected;
    mo.input.ball.clear();
    run.after = try_morphology(mo, run.notes, "after");
  }
}

}  // namespace

PlanRun run_plan(const SessionOptions& options, const RomRequest& rom, const PlanRequest& request) {
  const auto t_start = Clock::now();
  PlanRun run;
  check_plan_request(options, request);
  const RomRequest limits_only = limits_only_request(rom);
  run.search = rom.search;
  run.request = request;
  const SessionOptions so = plan_session_options(options, rom.search, request);
  const Session s(so);
  run.setup_ms = ms_since(t_start);
  describe_session(run, s);

  auto t = Clock::now();
  const RomRun before = run_rom(s, limits_only);
  run.before_ms = ms_since(t);
  const std::vector<ResectionTarget> targets = plan_targets(s, request, before);

  // The safety depth: given, or a fraction of the neck's least diameter (Mardones et al. 2005).
  set_safety_depth(run, s, options, request);
  const HipJoint& hip = s.hip();
  ResectionOptions ro = request.resection;
  ro.safety_depth_mm = run.safety_depth_mm;
  t = Clock::now();
  run.plan = plan_resection(hip, targets, before.baseline, ro);
  run.plan_ms = ms_since(t);

  // The resected meshes in the input frame: the scan-pose vertices moved by the plan's (joint-frame) displacement.
  const Vertices femur_scan = s.femur_input(hip.scan_pose()), pelvis_scan = s.pelvis_input();
  run.femur_resected = resected_mesh(s, run.plan.femur, s.joint().ball(), femur_scan, "femur_resected");
  run.pelvis_resected = resected_mesh(s, run.plan.pelvis, s.joint().socket(), pelvis_scan, "pelvis_resected");

  // The check on the resected bones, with further passes where it misses a target (check_plan).
  t = Clock::now();
  const PlanCheck check{options, rom, request,    limits_only, so.hip.joint.distance_reach_mm, s, before,
                        targets, ro,  femur_scan, pelvis_scan};
  const double extra_plan_ms = check_plan(run, check);
  run.plan_ms += extra_plan_ms;
  set_clock_extents(run, s);
  run.check_ms = ms_since(t) - extra_plan_ms;
  measure_after(run, options);
  run.total_ms = ms_since(t_start);
  return run;
}

}  // namespace impinge
