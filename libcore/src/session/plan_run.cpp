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
#include "session/plan_check.hpp"
#include "session/plan_labrum.hpp"

namespace impinge {

namespace {

using plan_detail::Clock;
using plan_detail::ms_since;

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

/// run_morphology of `so` (about `reference`'s head sphere, neck axis and frames when given), or nothing with a note
/// naming `what` (before, after) and why.
std::optional<MorphologyRun> try_morphology(const SessionOptions& so, std::vector<std::string>& notes, const char* what,
                                            const MorphologyRun* reference = nullptr) {
  try {
    return run_morphology(so, reference);
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

void check_plan_request(const SessionOptions& options, const PlanRequest& request, const LabrumOptions& labrum) {
  check_in_range("max-depth-fraction", request.max_depth_fraction, PlanRequest::kMaxDepthFractionRange);
  check_in_range("max-depth", request.max_depth_mm, PlanRequest::kMaxDepthRange, "mm");
  parse_targets(request.target, standard_motions());
  if (!request.target_motion.empty()) load_motion(request.target_motion, input_side(options.input));
  require(!request.target.empty() || !request.target_motion.empty(),
          "plan: no target: give --target (MOTION=DEG,... or normal) or --target-motion");
  require(!labrum.enabled || request.resection.bones != ResectBones::pelvis,
          "plan: --labrum with --resect pelvis: a contact with the labrum can be cleared only on the femur (the "
          "labrum is soft tissue and is never cut); give --resect femur or both, or leave out --labrum");
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

/// The morphology before (`before`, on the inputs; nothing when it could not be measured) with its head sphere and
/// neck axis in the input frame (run.reference_*), the neck's least diameter (mm, about that neck axis) and the
/// safety depth (mm): the cap given, or the fraction of the neck's diameter (Mardones et al. 2005). Throws
/// impinge::Error when neither is there.
void set_safety_depth(PlanRun& run, const Session& s, const std::optional<MorphologyRun>& before,
                      const PlanRequest& request) {
  if (before) {
    run.before = before->morphology;
    run.reference_head_centre_mm = before->to_input * before->frames.head.centre;
    run.reference_head_radius_mm = before->frames.head.radius;
    run.reference_neck_axis = before->to_input * before->morphology.neck_axis;
  }
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
/// resected and the morphology before was measured: `options` with the resected femur, about the head sphere, neck
/// axis and frames before (`before`), so that only the cut changes a value.
void measure_after(PlanRun& run, const SessionOptions& options, const std::optional<MorphologyRun>& before) {
  if (run.plan.femur.allowed && before) {
    SessionOptions mo = options;
    mo.input.ball_mesh = run.femur_resected;
    mo.input.ball.clear();
    if (const std::optional<MorphologyRun> after = try_morphology(mo, run.notes, "after", &*before))
      run.after = after->morphology;
  }
}

}  // namespace

PlanRun run_plan(const SessionOptions& options, const RomRequest& rom, const PlanRequest& request) {
  const auto t_start = Clock::now();
  PlanRun run;
  check_plan_request(options, request, rom.labrum);
  const RomRequest limits_only = limits_only_request(rom);
  run.search = rom.search;
  run.request = request;
  if (rom.labrum.enabled) run.labrum = rom.labrum;
  const SessionOptions so = plan_session_options(options, rom.search, request);
  const Session s(so);
  run.setup_ms = ms_since(t_start);
  describe_session(run, s);

  auto t = Clock::now();
  const RomRun before = run_rom(s, limits_only);
  run.before_ms = ms_since(t);
  if (before.labrum) run.labrum_mesh = labrum_input(s, before);
  const std::vector<ResectionTarget> targets = plan_targets(s, request, plan_detail::targeted_limits(before));

  // The safety depth: given, or a fraction of the neck's least diameter (Mardones et al. 2005).
  const std::optional<MorphologyRun> morphology_before = try_morphology(options, run.notes, "before");
  set_safety_depth(run, s, morphology_before, request);
  const HipJoint& hip = s.hip();
  ResectionOptions ro = request.resection;
  ro.safety_depth_mm = run.safety_depth_mm;
  t = Clock::now();
  std::optional<plan_detail::PlanLabrum> labrum;  // with --labrum: the femur cut to clear the labrum too
  if (before.labrum) labrum = plan_detail::plan_labrum(hip, rom.labrum, rom.search);
  run.plan = plan_detail::plan_targeted(hip, before.baseline, labrum ? &*labrum : nullptr, targets, ro);
  run.plan_ms = ms_since(t);

  // The resected meshes in the input frame: the scan-pose vertices moved by the plan's (joint-frame) displacement.
  const Vertices femur_scan = s.femur_input(hip.scan_pose()), pelvis_scan = s.pelvis_input();
  run.femur_resected = plan_detail::resected_mesh(s, run.plan.femur, s.joint().ball(), femur_scan, "femur_resected");
  run.pelvis_resected = plan_detail::resected_mesh(s, run.plan.pelvis, s.joint().socket(), pelvis_scan, "pelvis_resected");

  // The check on the resected bones, with further passes where it misses a target (check_plan).
  t = Clock::now();
  const plan_detail::PlanCheck check{options, rom, request,    limits_only, so.hip.joint.distance_reach_mm, s, before,
                        targets, ro,  femur_scan, pelvis_scan, labrum ? &*labrum : nullptr};
  const double extra_plan_ms = plan_detail::check_plan(run, check);
  run.plan_ms += extra_plan_ms;
  set_clock_extents(run, s);
  run.check_ms = ms_since(t) - extra_plan_ms;
  measure_after(run, options, morphology_before);
  run.total_ms = ms_since(t_start);
  return run;
}

}  // namespace impinge
