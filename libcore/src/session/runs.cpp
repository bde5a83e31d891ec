#include "impinge/session/runs.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <limits>
#include <thread>

#include <omp.h>

#include "impinge/clinical/published_rom.hpp"
#include "impinge/core/error.hpp"
#include "impinge/core/interrupt.hpp"
#include "impinge/core/timing.hpp"
#include "impinge/session/records.hpp"
#include "labrum_run.hpp"

namespace impinge {

std::vector<std::string> motion_columns(const ImpingementLevels& levels) {
  std::vector<std::string> c = {"frame",           "time_s",          "flexion_deg",          "adduction_deg",
                                "internal_rotation_deg", "femur_min_gap_mm", "pelvis_min_gap_mm",
                                "femur_min_distance_mm", "pelvis_min_distance_mm",
                                "penetrating_area_mm2",  "femur_penetrating_area_mm2"};
  for (int k = 0; k < levels.count(); ++k) c.push_back("pelvis_level" + std::to_string(k) + "_area_mm2");
  for (const char* name : {"pelvis_closest_clock_h", "femur_closest_clock_h", "pelvis_closest_x_mm",
                           "pelvis_closest_y_mm", "pelvis_closest_z_mm", "pelvis_closest_class",
                           "joint_translation_x_mm", "joint_translation_y_mm", "joint_translation_z_mm", "detection_ms"})
    c.emplace_back(name);
  return c;
}

nlohmann::json motion_row(const MotionFrame& f) {
  const PoseResult& r = *f.result;
  nlohmann::json row = {f.index,
                        f.time_s,
                        f.angles.flexion_deg,
                        f.angles.adduction_deg,
                        f.angles.internal_rotation_deg,
                        number_or_null(r.ball.min_gap_mm),
                        number_or_null(r.socket.min_gap_mm),
                        number_or_null(r.ball.min_distance_mm),
                        number_or_null(r.socket.min_distance_mm),
                        r.socket.area_penetrating_mm2,
                        r.ball.area_penetrating_mm2};
  for (double area : r.socket.level_area_mm2) row.push_back(area);
  row.push_back(number_or_null(f.socket_clock.closest_hour));
  row.push_back(number_or_null(f.ball_clock.closest_hour));
  for (int c = 0; c < 3; ++c) row.push_back(number_or_null(f.socket_closest[c]));
  row.push_back(to_string(f.socket_closest_class));
  for (int c = 0; c < 3; ++c) row.push_back(f.joint_translation[c]);
  row.push_back(f.detection_ms);
  return row;
}

namespace {
// One frame of a motion into f (its result into res): the pose, both scans, the closest socket point
// and the clock summaries.
void scan_frame(const Session& s, std::size_t k, const PoseAngles& angles, double time_s, MotionFrame& f,
                PoseResult& res) {
  interruption_point();  // a front end's stop (Ctrl-C in Python): this frame's error, which ends the hand-overs
  f.result = &res;
  f.index = k;
  f.time_s = time_s;
  f.angles = angles;
  const auto t0 = Clock::now();
  f.pose = s.hip().femur_pose(angles);  // with the joint-centre method's translation (counted here)
  // What this thread's scans learnt at the frames before (the distance scans' seeds and empty balls:
  // the same results at less cost along a motion; Joint::detect's memory).
  thread_local DetectionMemory memory;
  s.joint().detect(f.pose.R, f.pose.t, res, &memory);
  f.detection_ms = ms_since(t0);
  f.joint_translation = s.to_input(s.hip().femur_translation(f.pose.t));
  const ClosestPoint c = closest_point(s, false, res.socket_gaps, f.pose);
  f.socket_closest = c.vertex >= 0 ? s.report_point(c.p_joint) : c.p_joint;
  f.socket_closest_class = c.contact_class;
  f.ball_clock.closest_hour = f.socket_clock.closest_hour = std::nan("");
  s.hip().clocks(res, f.ball_clock, f.socket_clock);
}
}  // namespace

double run_motion(const Session& s, const std::vector<PoseAngles>& angles, const std::vector<double>& time_s,
                  const std::function<void(const MotionFrame&)>& on_frame) {
  require(time_s.empty() || time_s.size() == angles.size(),
          "motion: " + std::to_string(time_s.size()) + " times for " + std::to_string(angles.size()) + " poses");
  // Frames are independent, and are scanned on every OpenMP thread, each taking the next frames as soon
  // as it is free (no block waits for its slowest frame; a worker takes a run of consecutive frames).
  // They go through a ring of slots, each keeping its PoseResult (after the first lap no pose
  // allocates): frame k is scanned into slot k % ring once frame k - ring has been handed over. The calling thread (OpenMP's master) hands the frames to
  // on_frame in order as they become ready (writing a VTP file then hides behind the other threads'
  // scans), and scans a frame itself whenever the next one to hand over is not ready yet.
  const auto n = static_cast<std::int64_t>(angles.size());
  if (n == 0) return 0;
  const int threads = std::max(1, omp_get_max_threads());
  const auto ring = static_cast<std::int64_t>(std::min<std::size_t>(angles.size(), 16 * static_cast<std::size_t>(threads)));
  constexpr std::int64_t kRun = 8;  // frames a worker takes at once (the master takes one at a time)
  std::vector<PoseResult> results(static_cast<std::size_t>(ring));
  std::vector<MotionFrame> frames(static_cast<std::size_t>(ring));
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(ring));  // a frame's scan error, in its slot
  std::vector<std::atomic<std::int64_t>> scanned(static_cast<std::size_t>(ring));  // the frame in the slot
  for (auto& k : scanned) k = -1;
  std::atomic<std::int64_t> next{0};       // the next frame to scan
  std::atomic<std::int64_t> handed{0};     // frames handed over (frame k may use its slot once k < handed + ring)
  std::atomic<bool> stop{false};           // the hand-overs ended (done, or an error): scan no more
  std::exception_ptr error;                // rethrown after the threads end: on_frame's, or the first frame's scan error
  auto scan = [&](std::int64_t k) {
    const auto slot = static_cast<std::size_t>(k % ring);
    errors[slot] = nullptr;
    try {
      scan_frame(s, static_cast<std::size_t>(k), angles[static_cast<std::size_t>(k)],
                 time_s.empty() ? static_cast<double>(k) : time_s[static_cast<std::size_t>(k)], frames[slot], results[slot]);
    } catch (...) {
      errors[slot] = std::current_exception();
    }
    scanned[slot].store(k, std::memory_order_release);
  };
  const auto t0 = Clock::now();
#pragma omp parallel num_threads(threads)
  {
    if (omp_get_thread_num() == 0) {
      for (std::int64_t d = 0; d < n;) {
        if (interruption_requested()) {  // polled here too: the master may only hand frames over
          error = std::make_exception_ptr(Interrupted());
          break;
        }
        const auto slot = static_cast<std::size_t>(d % ring);
        if (scanned[slot].load(std::memory_order_acquire) == d) {
          try {  // the frame's scan error, or on_frame's, ends the hand-overs
            if (errors[slot]) std::rethrow_exception(errors[slot]);
            on_frame(frames[slot]);
          } catch (...) {
            error = std::current_exception();
            break;
          }
          handed.store(++d, std::memory_order_release);
          continue;
        }
        std::int64_t k = next.load();  // help: scan the next frame if its slot is free
        if (k < n && k < d + ring && next.compare_exchange_strong(k, k + 1))
          scan(k);
        else
          std::this_thread::yield();
      }
      stop = true;
    } else {
      // Runs of kRun consecutive frames: a thread's distance memory then meets each vertex a frame
      // later, not several, and its facts (seeds, nearby triangles) hold more often.
      for (bool more = true; more && !stop;) {
        const std::int64_t first = next.fetch_add(kRun);
        more = first < n;
        for (std::int64_t k = first; k < std::min(first + kRun, n) && !stop; ++k) {
          while (k >= handed.load(std::memory_order_acquire) + ring && !stop) std::this_thread::yield();
          if (!stop) scan(k);
        }
      }
    }
  }
  const double detect_ms = ms_since(t0);
  if (error) std::rethrow_exception(error);
  return detect_ms;
}

namespace {
// The standard motions' limits with their angles in the other pelvic frame than the session's (RomRun::
// other_limits): the same joint, the motions about that frame's axes from its neutral, whose own scan is their
// baseline (its overlap excluded, as the session frame's neutral is for the limits).
void other_frame_limits(const Session& s, const RomRequest& q, RomRun& run) {
  const HipJoint& hip = s.hip();
  if (!hip.pelvis_frame_kind()) {
    run.other_frame_note = hip.other_pelvis_frame_note();
    return;
  }
  const PelvisFrameKind other = *hip.pelvis_frame_kind() == PelvisFrameKind::isb
                                    ? PelvisFrameKind::anterior_pelvic_plane
                                    : PelvisFrameKind::isb;
  if (!hip.has_pelvis_frame(other)) {
    run.other_frame_note = hip.other_pelvis_frame_note();
    return;
  }
  const auto t0 = Clock::now();
  const PoseRotation rotation = [&hip, other](const PoseAngles& a) { return hip.femur_rotation(a, other); };
  const RomBaseline base = rom_baseline(hip, rotation({}), q.search);
  run.other_limits = find_rom_limits(hip, run.motions, q.search, base, rotation);
  run.other_frame = other;
  run.other_limits_ms = ms_since(t0);
}
}  // namespace

namespace {
// With impingement contacts and articular zones, the motions again counting every contact: the contact each limit
// set aside (RomRun::all_contact_limits; issue 81).
void every_contact_limits(const HipJoint& hip, const RomRequest& q, RomRun& run) {
  if (q.search.contacts != RomContacts::impingement || !hip.articular()) return;
  RomOptions every = q.search;
  every.contacts = RomContacts::all;
  run.all_contact_limits = find_rom_limits(hip, run.motions, every, rom_baseline(hip, hip.femur_rotation({}), every));
}
}  // namespace

RomRun run_rom(const Session& s, const RomRequest& q) {
  // Only the articular zones tell the joint surfaces apart; without them (scan neutral) 'articular' would
  // count every vertex under its name.
  require(q.search.contacts != RomContacts::articular || s.hip().articular(),
          "contacts articular: needs anatomical neutral (the lunate surface and the head's joint surface); with "
          "scan neutral every vertex counts (contacts all)");
  RomRun run;
  run.search = q.search;
  const HipJoint& hip = s.hip();
  // Pre-existing overlap at neutral (a segmentation's) is excluded, not taken for a limit. The
  // baseline's scan and the search bounds it builds count with the limits' time.
  auto t0 = Clock::now();
  run.frame = hip.pelvis_frame_kind();
  run.baseline = rom_baseline(hip, hip.femur_rotation({}), q.search);  // with its joint translation
  if (q.limits) {
    run.motions = standard_motions();
    run.limits = find_rom_limits(hip, run.motions, q.search, run.baseline);
  }
  run.limits_ms = ms_since(t0);
  if (q.limits && q.both_frames) other_frame_limits(s, q, run);
  if (q.limits) every_contact_limits(hip, q, run);
  if (q.limits && q.labrum.enabled) detail::run_labrum(s, q, run);
  auto count = [&run](const auto& x) {  // a limit's, a cell's or the envelope's look-ups
    run.vertices_looked_up += x.vertices_looked_up;
    run.vertices_skipped += x.vertices_skipped;
  };
  for (const RomLimit& l : run.limits) count(l), run.limit_evaluations += l.evaluations;
  if (q.map) {
    run.map_flexion_deg = q.map_flexion_deg;
    run.map_adduction_deg = q.map_adduction_deg;
    if (run.map_flexion_deg.empty()) run.map_flexion_deg = RomRequest{}.map_flexion_deg;
    if (run.map_adduction_deg.empty()) run.map_adduction_deg = RomRequest{}.map_adduction_deg;
    t0 = Clock::now();
    run.map = rom_map(hip, run.map_flexion_deg, run.map_adduction_deg, q.search, run.baseline);
    run.map_ms = ms_since(t0);
    for (const RomMapCell& c : run.map) count(c), run.map_evaluations += c.evaluations;
  }
  if (q.envelope) {
    run.envelope_options = q.envelope_options;
    t0 = Clock::now();
    run.envelope = rom_envelope(hip, q.envelope_options, q.search, run.baseline);
    run.envelope_ms = ms_since(t0);
    count(*run.envelope);
  }
  return run;
}

namespace {
// Whether soft tissue usually ends `motion` before the bones meet at its limit `l`: judged for a limit or a free
// motion; a motion not reached, or in contact at its start, has no bony limit to judge.
bool soft_tissue_ends_first(const std::string& motion, const RomLimit& l) {
  const bool judged = l.status == RomLimitStatus::limited || l.status == RomLimitStatus::free;
  return judged && soft_tissue_first(motion, l.limit_deg);
}
}  // namespace

namespace {
// The limit of motion k with its angles in pelvic frame `frame` (the run's limits or the other frame's), or
// nullptr when the run has none there (scan neutral, or the other frame not searched).
const RomLimit* limit_in_frame(const RomRun& run, std::size_t k, PelvisFrameKind frame) {
  if (run.frame == frame && k < run.limits.size()) return &run.limits[k];
  if (run.other_frame == frame && k < run.other_limits.size()) return &run.other_limits[k];
  return nullptr;
}
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// The contact the every-contact search (RomRun::all_contact_limits) met before motion k's limit (or where the
// motion is free), or nullptr: a contact the limit set aside, the joint surfaces meeting (issue 81, item 1).
const RomLimit* contact_set_aside(const RomRun& run, std::size_t k) {
  if (k >= run.all_contact_limits.size()) return nullptr;
  const RomLimit& a = run.all_contact_limits[k];
  const RomLimit& l = run.limits[k];
  return std::isfinite(a.limit_deg) && !(l.limit_deg <= a.limit_deg) ? &a : nullptr;
}
nlohmann::json set_aside_record(const RomLimit* a) {
  if (!a) return nullptr;
  return {{"angle_deg", number_or_null(a->limit_deg)}, {"contact_class", to_string(a->contact_class)},
          {"femoral_zone", to_string(a->femoral_zone)}, {"pelvic_zone", to_string(a->pelvic_zone)},
          {"pelvis_clock_h", number_or_null(a->socket_clock_h)}, {"femur_clock_h", number_or_null(a->femur_clock_h)},
          {"why", "the first contact of every vertex (--contacts all) comes before the limit: the head's joint "
                  "surface meeting the lunate surface, not counted as impingement"}};
}
nlohmann::json limit_of(const RomLimit* x) { return x ? number_or_null(x->limit_deg) : nlohmann::json(); }
nlohmann::json status_of(const RomLimit* x) { return x ? nlohmann::json(to_string(x->status)) : nlohmann::json(); }
}  // namespace

Table rom_limits_table(const Session& s, const RomRun& run) {
  Table t;
  t.columns = {"motion",      "limit_deg",        "first_contact_deg", "status",       "limited_by",     "contact_class", "pelvis_clock_h",
               "femur_clock_h", "min_gap_at_limit_mm", "monotone", "contact_at_start", "contact_x_mm", "contact_y_mm",
               "contact_z_mm", "joint_translation_x_mm", "joint_translation_y_mm", "joint_translation_z_mm",
               "evaluations", "normal_deg", "normal_source", "soft_tissue_first", "pelvic_frame", "limit_isb_deg",
               "status_isb", "limit_app_deg", "status_app", "bony_normal_deg", "bony_normal_frame",
               "bony_normal_source", "femoral_zone", "pelvic_zone", "set_aside_contact_deg",
               "set_aside_contact_class", "set_aside_femoral_zone", "set_aside_pelvic_zone", "note"};
  const std::string frame = pelvic_frame_name(s);
  for (std::size_t k = 0; k < run.motions.size(); ++k) {
    const RomLimit& l = run.limits[k];
    const std::string& name = run.motions[k].name;
    const Eigen::Vector3d c = s.to_input(l.contact_mm), tr = s.to_input(l.joint_translation_mm);
    const PublishedRange normal = published_normal_range(name);
    const BonyRange bony = published_bony_range(name);
    const RomLimit* isb = limit_in_frame(run, k, PelvisFrameKind::isb);
    const RomLimit* app = limit_in_frame(run, k, PelvisFrameKind::anterior_pelvic_plane);
    const RomLimit* set_aside = contact_set_aside(run, k);
    t.add({name, number_or_null(l.limit_deg), number_or_null(l.first_contact_deg), to_string(l.status), to_string(l.limited_by), to_string(l.contact_class),
           number_or_null(l.socket_clock_h),
           number_or_null(l.femur_clock_h), number_or_null(l.min_gap_at_limit_mm), l.monotone, l.contact_at_start,
           number_or_null(c.x()), number_or_null(c.y()), number_or_null(c.z()), number_or_null(tr.x()),
           number_or_null(tr.y()), number_or_null(tr.z()), l.evaluations, number_or_null(normal.normal_deg),
           normal.source, soft_tissue_ends_first(name, l), frame, limit_of(isb), status_of(isb), limit_of(app),
           status_of(app), number_or_null(bony.bony_deg), bony.frame, bony.source, to_string(l.femoral_zone),
           to_string(l.pelvic_zone), number_or_null(set_aside ? set_aside->limit_deg : kNaN),
           set_aside ? to_string(set_aside->contact_class) : "", set_aside ? to_string(set_aside->femoral_zone) : "", set_aside ? to_string(set_aside->pelvic_zone) : "",
           l.note});
  }
  if (run.labrum) detail::add_labral_columns(t, run);
  return t;
}

Table rom_map_table(const RomRun& run) {
  Table t;
  t.columns = {"flexion_deg", "adduction_deg", "max_internal_rotation_deg", "status"};
  for (const RomMapCell& c : run.map)
    t.add({c.flexion_deg, c.adduction_deg, number_or_null(c.max_internal_rotation_deg), to_string(c.status)});
  return t;
}

Table rom_envelope_table(const RomRun& run) {
  Table t;
  t.columns = {"flexion_deg", "adduction_deg", "internal_rotation_from_deg", "internal_rotation_to_deg"};
  if (!run.envelope) return t;
  const RomEnvelope& env = *run.envelope;
  const std::size_t nr = env.internal_rotation_deg.size();
  for (std::size_t i = 0; i < env.flexion_deg.size(); ++i)
    for (std::size_t j = 0; j < env.adduction_deg.size(); ++j)
      for (std::size_t k = 0; k < nr;) {
        if (!env.at(i, j, k)) {
          ++k;
          continue;
        }
        std::size_t e = k;
        while (e + 1 < nr && env.at(i, j, e + 1)) ++e;
        t.add({env.flexion_deg[i], env.adduction_deg[j], env.internal_rotation_deg[k], env.internal_rotation_deg[e]});
        k = e + 1;
      }
  return t;
}

SessionOptions rom_session_options(SessionOptions so, const RomOptions& search) {
  so.hip.joint.distances = search.metric == RomMetric::distance;
  JointOptions& jo = so.hip.joint;
  if (jo.distances && jo.distance_reach_mm == 0) jo.distance_reach_mm = std::max(search.threshold_mm, 0.0) + 1;
  so.hip.joint.levels_on = LevelQuantity::radial_gap;
  return so;
}

namespace {
// Null neutral values say why (issue 81): the metric's values are NaN beyond the distance's reach.
void add_null_reasons(const RomRun& run, nlohmann::json& j) {
  const RomOptions& o = run.search;
  const bool by_distance = o.metric == RomMetric::distance;
  if (!std::isfinite(run.baseline.min_gap_mm))
    j["neutral_min_gap_reason"] = by_distance ? "no vertex of either bone lies within the distance reach "
                                                "(distance_reach_mm) of the other at neutral: the bones are farther apart"
                                              : "no vertex's ray meets the other bone at neutral";
  if (!std::isfinite(run.baseline.joint_space_min_mm))
    j["neutral_joint_space_min_reason"] =
        by_distance ? "no lunate vertex lies within the distance reach (distance_reach_mm) of the femur at neutral: "
                      "the joint space is wider than the reach (--distance-reach widens it); or no articular zones "
                      "(scan neutral)"
                    : "no lunate vertex's ray meets the femur at neutral, or no articular zones (scan neutral)";
}
}  // namespace

nlohmann::json rom_record(const RomRun& run) {
  nlohmann::json j;
  const RomOptions& o = run.search;
  j["threshold_mm"] = o.threshold_mm;
  j["contact_depth_mm"] = o.contact_depth_mm;
  j["metric"] = to_string(o.metric);
  j["search"] = {{"step_deg", o.step_deg}, {"max_deg", o.max_deg}, {"tolerance_deg", o.tolerance_deg}};
  j["neutral_min_gap_mm"] = number_or_null(run.baseline.min_gap_mm);
  j["neutral_joint_space_min_mm"] = number_or_null(run.baseline.joint_space_min_mm);
  add_null_reasons(run, j);
  j["excluded_vertices"] = run.baseline.excluded_vertices;
  j["contacts_counted"] = run.baseline.articular_vertices == 0 && o.contacts != RomContacts::all
                              ? "all (no articular zones: scan neutral)"
                          : o.contacts == RomContacts::impingement ? "impingement (the joint surfaces left out)"
                          : o.contacts == RomContacts::articular ? "articular (the joint surfaces only)"
                                                                 : "all";
  j["articular_vertices_left_out"] = run.baseline.articular_vertices;
  nlohmann::json limits = nlohmann::json::array();
  for (std::size_t k = 0; k < run.motions.size(); ++k) {
    const RomLimit& l = run.limits[k];
    const std::string& name = run.motions[k].name;
    const PublishedRange normal = published_normal_range(name);
    const BonyRange bony = published_bony_range(name);
    const RomLimit* isb = limit_in_frame(run, k, PelvisFrameKind::isb);
    const RomLimit* app = limit_in_frame(run, k, PelvisFrameKind::anterior_pelvic_plane);
    limits.push_back({{"motion", name},
                      {"limit_deg", number_or_null(l.limit_deg)},
                      {"first_contact_deg", number_or_null(l.first_contact_deg)},
                      {"status", to_string(l.status)},
                      {"limited_by", to_string(l.limited_by)},
                      {"monotone", l.monotone},
                      {"limit_isb_deg", limit_of(isb)},
                      {"status_isb", status_of(isb)},
                      {"limit_app_deg", limit_of(app)},
                      {"status_app", status_of(app)},
                      {"normal_deg", number_or_null(normal.normal_deg)},
                      {"normal_source", normal.source},
                      {"bony_normal_deg", number_or_null(bony.bony_deg)},
                      {"bony_normal_frame", bony.frame},
                      {"bony_normal_source", bony.source},
                      {"soft_tissue_first", soft_tissue_ends_first(name, l)},
                      {"femoral_zone", to_string(l.femoral_zone)},
                      {"pelvic_zone", to_string(l.pelvic_zone)},
                      {"set_aside_contact", set_aside_record(contact_set_aside(run, k))},
                      {"note", l.note}});
  }
  j["limits"] = limits;
  j["other_pelvic_frame"] = run.other_frame ? nlohmann::json(to_string(*run.other_frame)) : nlohmann::json();
  j["other_pelvic_frame_note"] = run.other_frame_note;
  if (run.envelope) {
    const RomEnvelope& env = *run.envelope;
    const RomEnvelopeOptions& eo = run.envelope_options;
    std::int64_t valid = 0;
    for (std::uint8_t v : env.valid) valid += v != 0;
    j["envelope"] = {
        {"poses", env.poses},
        {"poses_valid", valid},
        {"poses_scanned", env.poses_evaluated},
        {"grid",
         {{"flexion_deg", {eo.flexion_min_deg, eo.flexion_max_deg}},
          {"adduction_deg", {eo.adduction_min_deg, eo.adduction_max_deg}},
          {"internal_rotation_deg", {eo.internal_rotation_min_deg, eo.internal_rotation_max_deg}},
          {"step_deg", eo.step_deg},
          {"coarse_steps", eo.coarse_steps}}},
        {"ms", run.envelope_ms},
        {"poses_per_second", run.envelope_ms > 0 ? double(env.poses) / (run.envelope_ms / 1000) : 0.0}};
  }
  j["rom_map_cells"] = run.map.size();
  j["rom_map_evaluations"] = run.map_evaluations;
  j["limit_evaluations"] = run.limit_evaluations;
  j["vertices_looked_up"] = run.vertices_looked_up;
  j["vertices_skipped_by_bounds"] = run.vertices_skipped;
  const std::int64_t all = run.vertices_looked_up + run.vertices_skipped;
  j["share_skipped"] = all > 0 ? double(run.vertices_skipped) / double(all) : 0.0;
  if (run.labrum) j["labrum"] = detail::labrum_record(run);
  return j;
}

}  // namespace impinge
