// 09_rom_observation -- thesis sec. 5.2, Tables 11-13, Fig. 60-63: the thesis' recorded ROM
// extremities applied to our hips, ROM limits and ROM maps with where the bones meet, checked
// against an exact reference, with their sensitivity and cost.
//
// Inputs: every real subject under --data (anatomical frames found from the bones); without real
// subjects, the generated 12k hip with a 2 mm cam (scan neutral) for the limits only. The thesis'
// Table 11 and the published values compared with are read from experiments/09_*.csv.
// Outputs: OUT/09_rom_observation/
//   observation.csv   subject x patient (A, B) x motion: Table 11's extremity as a pose from anatomical
//                     neutral; both scans' minimum gap, the socket's area per level (thresholds 6, 4,
//                     2, 0 mm: thesis sec. 5.2's blue > 6 mm and red < 2 mm), the closest point's clock hour
//   observation_sectors.csv  subject x patient x motion x acetabular clock sector (hours (k, k+1]): the
//                     socket's red area there (within 2 mm or penetrating, mm^2): where the red zone lies by
//                     area, beside the closest point's hour
//   observation_<subject>_<patient>_<motion>.ply  (first real subject) the cup region with gaps, for the
//                     medial views of Tables 12-13
//   rom_limits.csv    subject x motion: limit, where limited, exact-reference check 0.5 deg either side
//   rom_map.csv       subject x flexion x adduction: the largest internal rotation
//   sensitivity.csv   subject x method x variant x motion: the thesis' femoral-head method at other
//                     resolutions, and each joint-centre method with the COR moved 1 mm along each pelvic axis
//   methods.csv       subject x joint-centre method (Puls et al. 2010: femoral-head, acetabular, combined,
//                     equidistant) x motion: the CLI's rom_limits.csv row with its defaults (layered maps,
//                     contact depth), the method first
//   methods_map.csv   subject x method x flexion x adduction: the ROM map under each method
//   timing.csv        subject: sampling, limits, map, evaluations, poses per second, FCL collide per pose and
//                     its extrapolated search time; limits, map and search (both) are medians of --repetitions
//                     searches (limits by the exact contact test, the default), search_q25_ms and search_q75_ms
//                     the search's quartiles, search_runs their number; alternated with them, the same search by the
//                     per-vertex test (RomOptions::exact_contact false: per_vertex_search_ms and quartiles, the
//                     share of its look-ups the bounds skip, share_skipped, NaN without repeated timings) and the
//                     exact search's time over it, paired round by round (exact_over_per_vertex and quartiles); sampling (both maps) the median and
//                     quartiles of at least 5 new sessions (sampling_runs); FCL per pose the median and quartiles
//                     over fcl_poses_timed poses
//   extra_articular.csv  subject x motion x counted vertices (all, hidden): with layered maps (4 crossings
//                     per node), the limit, where limited, and the exact check 0.5 deg either side (CGAL
//                     all-intersection rays for the hidden vertices, first hits for the others)
//   layered.csv       subject x body: layered map nodes, bytes and sampling time (median and quartiles of
//                     at least 5 sessions) beside the single-layer map's; hidden vertices; the nine limits' search
//                     time with and without layers (alternated, at least 5 rounds: medians and quartiles)
//   envelope.csv      subject: the ROM envelope (every pose of flexion -30..130 x adduction -50..40 x internal
//                     rotation -60..60, 1 deg; quick: 5 deg) by adaptive refinement beside the brute force that
//                     scans every pose (the refinement: at least 5 rounds, medians and quartiles; the brute force,
//                     the reference, in one run: brute_force_runs), and the poses on which they differ
//   cam.csv           thesis Fig. 60-61: the generated 12k hip without and with a 2 mm cam at the antero-superior
//                     head-neck junction (scan neutral, the thesis' femoral-head method, bone contact): each
//                     motion's limit and how high the cam stands where the bones meet (the femur's vertex
//                     nearest the contact: its distance from the head centre with the cam less without)
//   clock_faces.csv   the acetabular clock face of each real subject in its pelvic frame
//   thesis_table11.csv, published.csv   copies of the inputs the analysis compares with
//   meta.json
// --quick (CI's budget, issue 82 item 7): maps at 0.25 deg (sensitivity: 0.5), the envelope at 5 deg (the coarsest
// step dividing every range); on every subject but the first, timing.csv's sampling and search are the subject's
// first run's (sampling_runs, search_runs 1), layered.csv's sampling and limits are not timed (empty, timing_runs
// 0), and the joint-centre methods' maps and COR moves are left out (their limits stay: methods.csv). The rounds
// the paper gives as "at least 5" stay at 5 where they run.
// Command: build/experiments/exp_09_rom_observation --out results --data ../shared/data/hips [--quick]
#include <omp.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "experiment_support.hpp"
#include "impinge/anatomy/clock_face.hpp"
#include "impinge/anatomy/sphere_fit.hpp"
#include "impinge/casters/exact_reference.hpp"
#include "impinge/casters/fcl_collision.hpp"
#include "impinge/casters/first_hit_caster.hpp"
#include "impinge/clinical/hip_joint.hpp"
#include "impinge/clinical/rom.hpp"
#include "impinge/core/error.hpp"
#include "impinge/core/timing.hpp"
#include "impinge/io/generated_models.hpp"
#include "impinge/io/mesh_io.hpp"
#include "impinge/maps/layered_map.hpp"
#include "impinge/session/records.hpp"
#include "impinge/session/option_table.hpp"
#include "impinge/session/runs.hpp"

using namespace impinge;
using namespace impinge::experiment;
namespace fs = std::filesystem;

namespace {

struct Table11Row {
  std::string patient, hip, motion;
  double angle = 0;
};
std::vector<Table11Row> read_table11(const std::string& path) {
  std::ifstream in(path);
  require(in.good(), path + ": cannot open");
  std::string line;
  std::getline(in, line);
  std::vector<Table11Row> rows;
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    Table11Row r;
    std::string angle;
    std::getline(ss, r.patient, ',');
    std::getline(ss, r.hip, ',');
    std::getline(ss, r.motion, ',');
    std::getline(ss, angle, ',');
    r.angle = std::stod(angle);
    rows.push_back(r);
  }
  return rows;
}

PoseAngles extremity(const std::string& motion, double a) {
  if (motion == "abduction") return {0, -a, 0};
  if (motion == "adduction") return {0, a, 0};
  if (motion == "external_rotation") return {0, 0, -a};
  if (motion == "internal_rotation") return {0, 0, a};
  if (motion == "extension") return {-a, 0, 0};
  if (motion == "flexion") return {a, 0, 0};
  throw Error("09: unknown motion " + motion);
}

// Exact least gap (CGAL ray casts from the COR) over the counted first-surface vertices of both bodies
// at femur rotation R (joint frame): ball vertices against the pelvis, pelvis vertices against the
// posed femur.
double exact_least_gap(const Joint& j, const ExactReference& pelvis, const ExactReference& femur,
                       const RomBaseline& base, const Eigen::Matrix3d& R) {
  double least = std::numeric_limits<double>::infinity();
  const ScanSet& b = j.ball().scan_set;
  for (std::int64_t k = 0; k < b.size(); ++k) {
    if (base.skip_ball[static_cast<std::size_t>(b.index[k])]) continue;
    const Eigen::Vector3d q = R * Eigen::Vector3d(b.x[k], b.y[k], b.z[k]);
    const auto hit = pelvis.first_hit(Eigen::Vector3d::Zero(), q.normalized());
    if (hit) least = std::min(least, *hit - q.norm());
  }
  const ScanSet& s = j.socket().scan_set;
  for (std::int64_t k = 0; k < s.size(); ++k) {
    if (base.skip_socket[static_cast<std::size_t>(s.index[k])]) continue;
    const Eigen::Vector3d p(s.x[k], s.y[k], s.z[k]);
    const auto hit = femur.first_hit(Eigen::Vector3d::Zero(), (R.transpose() * p).normalized());
    if (hit) least = std::min(least, p.norm() - *hit);
  }
  return least;
}

// Exact least signed distance (CGAL all-intersection rays from the COR) over the counted hidden vertices
// of both bodies at femur rotation R: ball hidden vertices against the pelvis, pelvis hidden vertices
// against the posed femur (issue 14's oracle for the layered maps).
double exact_least_hidden(const Joint& j, const ExactReference& pelvis, const ExactReference& femur,
                          const RomBaseline& base, const Eigen::Matrix3d& R) {
  double least = std::numeric_limits<double>::infinity();
  auto signed_distance = [](const ExactReference& ref, int orientation, const Eigen::Vector3d& q) {
    const std::vector<RayCrossing> c = crossings_from_hits(ref.all_hits(Eigen::Vector3d::Zero(), q.normalized()), orientation);
    return signed_radial_distance(c.data(), static_cast<int>(c.size()), true, q.norm());
  };
  const ScanSet& b = j.ball().hidden_set;
  for (std::int64_t k = 0; k < b.size(); ++k) {
    if (base.skip_ball[static_cast<std::size_t>(b.index[k])]) continue;
    const double d = signed_distance(pelvis, j.socket().caster->orientation(), R * Eigen::Vector3d(b.x[k], b.y[k], b.z[k]));
    if (!std::isnan(d)) least = std::min(least, d);
  }
  const ScanSet& s = j.socket().hidden_set;
  for (std::int64_t k = 0; k < s.size(); ++k) {
    if (base.skip_socket[static_cast<std::size_t>(s.index[k])]) continue;
    const double d =
        signed_distance(femur, j.ball().caster->orientation(), R.transpose() * Eigen::Vector3d(s.x[k], s.y[k], s.z[k]));
    if (!std::isnan(d)) least = std::min(least, d);
  }
  return least;
}

// Motions searched for extra-articular contacts beside the standard ones: abduction and extension from
// neutral with external rotation growing at half their rate (the trochanter towards the ilium, the
// neck and lesser trochanter towards the ischium).
std::vector<StandardMotion> extra_articular_motions() {
  std::vector<StandardMotion> m = standard_motions();
  m.push_back({"abduction_external_rotation", [](double t) { return PoseAngles{0, -t, -t / 2}; }});
  m.push_back({"extension_external_rotation", [](double t) { return PoseAngles{-t, 0, -t / 2}; }});
  return m;
}
// What every step reads: the experiment's settings.
struct Settings {
  std::string dir;
  bool quick = false;
  double resolution = 0.1;                 // deg, the maps of the limits, map and envelope
  std::vector<double> sens_resolutions;    // deg, the sensitivity's other resolutions
  RomOptions ro;
  ImpingementLevels observation_levels;    // thesis sec. 5.2: blue > 6 mm, red < 2 mm
  std::vector<Table11Row> table11;
  int threads = 1;
  int reps = 5;  // the search's timing runs (--repetitions)
};

// The experiment's outputs, one writer or table each (see the file comment).
struct Outputs {
  explicit Outputs(const std::string& dir)
      : obs(dir + "/observation.csv",
            {"subject", "patient", "motion", "angle_deg", "flexion_deg", "adduction_deg", "internal_rotation_deg",
             "ball_min_gap_mm", "socket_min_gap_mm", "socket_closest_clock_h", "socket_area_over6_mm2",
             "socket_area_4to6_mm2", "socket_area_2to4_mm2", "socket_area_0to2_mm2", "socket_area_penetrating_mm2"}),
        sectors(dir + "/observation_sectors.csv", {"subject", "patient", "motion", "sector", "hours", "red_area_mm2"}),
        clocks(dir + "/clock_faces.csv", {"subject", "side", "centre_x_mm", "centre_y_mm", "centre_z_mm", "twelve_x",
                                          "twelve_y", "twelve_z", "three_x", "three_y", "three_z", "rim_radius_mm"}),
        extra(dir + "/extra_articular.csv",
              {"subject", "motion", "counted", "limit_deg", "limited_by", "hidden_vertex", "ball_vertex",
               "socket_clock_h", "contact_radius_mm", "min_gap_at_limit_mm", "contact_at_start",
               "exact_gap_before_mm", "exact_gap_after_mm", "validated"}),
        layered(dir + "/layered.csv",
                {"subject", "body", "layers", "nodes", "layered_bytes", "single_bytes", "layered_sampling_ms",
                 "layered_sampling_q25_ms", "layered_sampling_q75_ms", "single_sampling_ms", "nodes_covered",
                 "nodes_truncated", "nodes_not_alternating", "max_crossings", "hidden_vertices", "limits_ms_single",
                 "limits_ms_layered", "limits_single_q25_ms", "limits_single_q75_ms", "limits_layered_q25_ms",
                 "limits_layered_q75_ms", "timing_runs"}),
        env(dir + "/envelope.csv",
            {"subject", "resolution_deg", "step_deg", "coarse_steps", "threads", "poses", "poses_scanned",
             "poses_valid", "envelope_ms", "envelope_q25_ms", "envelope_q75_ms", "poses_per_second",
             "poses_per_core_second", "brute_force_ms", "brute_force_q25_ms", "brute_force_q75_ms",
             "brute_force_poses_valid", "poses_differ", "timing_runs", "brute_force_runs"}),
        sens(dir + "/sensitivity.csv", {"subject", "method", "variant", "motion", "limit_deg", "delta_deg"}),
        tim(dir + "/timing.csv",
            {"subject", "resolution_deg", "threads", "sampling_ms", "sampling_q25_ms", "sampling_q75_ms",
             "sampling_runs", "limits_ms", "map_ms", "search_ms", "search_q25_ms", "search_q75_ms", "search_runs",
             "evaluations", "poses_per_second", "share_skipped", "per_vertex_search_ms", "per_vertex_search_q25_ms",
             "per_vertex_search_q75_ms", "exact_over_per_vertex", "exact_over_per_vertex_q25", "exact_over_per_vertex_q75",
             "fcl_collide_ms_per_pose", "fcl_collide_q25_ms",
             "fcl_collide_q75_ms", "fcl_poses_timed",
             "fcl_search_ms_extrapolated", "fcl_over_ours", "excluded_vertices", "neutral_min_gap_mm"}),
        bony(dir + "/bony.csv",
             {"subject", "side", "head_radius_mm", "head_fit_rms_mm", "acetabular_radius_mm", "acetabular_fit_rms_mm",
              "inclination_deg", "anteversion_deg", "median_coverage_deg", "notch_coverage_deg", "scan_pose_min_gap_mm",
              "neutral_min_gap_mm"}) {}
  CsvWriter obs, sectors, clocks, extra, layered, env, sens, tim;
  CsvWriter bony;  // each hip's bony measures beside its limits (left against right: issue 29)
  // rom_limits.csv and rom_map.csv: the CLI's tables (session layer) with the subject first; the
  // limits also with their exact check. methods.csv, methods_map.csv: the same per joint-centre method.
  Table lim, map, meth, meth_map;
  bool wrote_renders = false;
};

// One subject set up as the CLI sets it up, its ROM run (`impinge rom`: limits, then the map) and
// the exact references of both bones.
struct SubjectRun {
  SubjectRun(const Subject& s, const Settings& st)
      : subject(s), options(options_of(s, st)), session(options), run(run_rom(session, request(st))),
        ex_pelvis(session.joint().socket().mesh), ex_femur(session.joint().ball().mesh) {}
  static SessionOptions options_of(const Subject& s, const Settings& st) {
    SessionOptions o;
    o.grid.precision = st.resolution;
    o.hip.joint.levels = st.observation_levels;
    return session_options(s, o);
  }
  static RomRequest request(const Settings& st) {
    RomRequest q;
    q.search = st.ro;
    return q;
  }
  const Subject& subject;
  const SessionOptions options;
  const Session session;
  const RomRun run;
  const ExactReference ex_pelvis, ex_femur;
};

// Table 11's extremities as clinical poses from anatomical neutral (real subjects), and the cup
// regions of the first subject for the medial views of Tables 12-13.
void observe_table11(const SubjectRun& r, const Settings& st, Outputs& out) {
  const Subject& s = r.subject;
  const HipJoint& hip = r.session.hip();
  const ClockFace c = hip.socket_clock()->transformed(scan_axes().transpose(), Eigen::Vector3d::Zero());
  out.clocks.row(s.name, s.side == Side::right ? "right" : "left", c.centre.x(), c.centre.y(), c.centre.z(),
                 c.twelve.x(), c.twelve.y(), c.twelve.z(), c.three.x(), c.three.y(), c.three.z(),
                 hip.acetabulum()->rim_radius_mm);
  for (const Table11Row& t : st.table11) {
    const PoseAngles a = extremity(t.motion, t.angle);
    const PoseResult res = hip.detect(a);
    ClockSummary bc, sc;
    hip.clocks(res, bc, sc);
    const auto& L = res.socket.level_area_mm2;
    out.obs.row(s.name, t.patient, t.motion, t.angle, a.flexion_deg, a.adduction_deg, a.internal_rotation_deg,
                res.ball.min_gap_mm, res.socket.min_gap_mm, sc.closest_hour, L[0], L[1], L[2], L[3], L[4]);
    // The red area (the last two levels: 0-2 mm and penetrating) per clock sector.
    const std::size_t levels = L.size();
    for (std::size_t k = 0; k < 12 && sc.sector_level_area_mm2.size() == 12 * levels; ++k)
      out.sectors.row(s.name, t.patient, t.motion, static_cast<int>(k),
                      std::to_string(k) + "-" + std::to_string(k + 1),
                      sc.sector_level_area_mm2[k * levels + levels - 2] + sc.sector_level_area_mm2[k * levels + levels - 1]);
    if (!out.wrote_renders)  // the cup region (within the rim radius + 3 mm of the COR), pelvic frame, with gaps
      write_region_ply(st.dir + "/observation_" + s.name + "_" + t.patient + "_" + t.motion + ".ply",
                       hip.joint().socket(), scan_axes().transpose(), hip.acetabulum()->rim_radius_mm + 3,
                       &res.socket_gaps, st.observation_levels, false);
  }
  out.wrote_renders = true;
}

// rom_limits.csv and rom_map.csv rows, each limit checked exactly 0.5 deg either side (CGAL ray casts).
void record_limits(const SubjectRun& r, const Settings& st, Outputs& out) {
  const Table limits_table = rom_limits_table(r.session, r.run), map_table = rom_map_table(r.run);
  if (out.map.columns.empty()) {
    out.map.columns = {"subject"};
    out.map.columns.insert(out.map.columns.end(), map_table.columns.begin(), map_table.columns.end());
    out.lim.columns = {"subject"};
    out.lim.columns.insert(out.lim.columns.end(), limits_table.columns.begin(), limits_table.columns.end());
    for (const char* c : {"exact_gap_before_mm", "exact_gap_after_mm", "validated"}) out.lim.columns.emplace_back(c);
  }
  for (const nlohmann::json& m : map_table.rows) {
    nlohmann::json row = {r.subject.name};
    row.insert(row.end(), m.begin(), m.end());
    out.map.add(row);
  }
  const HipJoint& hip = r.session.hip();
  for (std::size_t k = 0; k < r.run.motions.size(); ++k) {
    const RomLimit& l = r.run.limits[k];
    double before = std::nan(""), after = std::nan("");
    std::string validated = "no_limit";
    if (!std::isnan(l.limit_deg) && !l.contact_at_start) {
      auto exact = [&](double t) {
        return exact_least_gap(hip.joint(), r.ex_pelvis, r.ex_femur, r.run.baseline,
                               hip.femur_rotation(r.run.motions[k].angles(t)));
      };
      before = exact(std::max(0.0, l.limit_deg - 0.5));
      after = exact(l.limit_deg + 0.5);
      validated = before > st.ro.threshold_mm && after <= st.ro.threshold_mm ? "yes" : "no";
    }
    nlohmann::json row = {r.subject.name};
    row.insert(row.end(), limits_table.rows[k].begin(), limits_table.rows[k].end());
    for (const nlohmann::json& x : {number_or_null(before), number_or_null(after), nlohmann::json(validated)})
      row.push_back(x);
    out.lim.add(row);
  }
}

// Extra-articular impingement (issue 14): layered maps of 4 crossings per node; the standard motions
// and two with external rotation, counting every vertex (the limit) and the hidden ones only (the
// first extra-articular contact), each checked exactly 0.5 deg either side. Without `timed` (--quick, every
// subject but the first) the layered maps' sampling and the limits are not timed (layered.csv: empty times,
// timing_runs 0).
void extra_articular(const SubjectRun& r, const Settings& st, Outputs& out, bool timed) {
  SessionOptions lo = r.options;
  lo.hip.joint.layers = 4;
  const Session lsession(lo);
  const HipJoint& lhip = lsession.hip();
  const Joint& lj = lhip.joint();
  const RomBaseline lbase = rom_baseline(lhip, lhip.femur_rotation({}), st.ro);
  const std::vector<StandardMotion> xm = extra_articular_motions();
  // The nine limits without and with the layers, timed alternately (medians and quartiles of --repetitions rounds).
  const HipJoint& hip = r.session.hip();
  const int reps = timed ? std::max(5, st.reps) : 0;
  const std::vector<std::vector<double>> lim_runs =
      timed ? run_alternated({[&] { find_rom_limits(hip, r.run.motions, st.ro, r.run.baseline); },
                              [&] { find_rom_limits(lhip, r.run.motions, st.ro, lbase); }},
                             reps)
            : std::vector<std::vector<double>>(2);
  const Timing lim_single = summarize(lim_runs[0]), lim_layered = summarize(lim_runs[1]);
  // The layered maps' sampling, again `reps` times (each a new session of the same options): its spread.
  std::vector<double> layered_ms[2];
  for (int k = 0; k < reps; ++k) {
    const Session again(lo);
    layered_ms[0].push_back(again.hip().joint().ball().layered_sampling.sampling_ms);
    layered_ms[1].push_back(again.hip().joint().socket().layered_sampling.sampling_ms);
  }
  for (const RomVertices counted : {RomVertices::all, RomVertices::hidden}) {
    RomOptions xo = st.ro;
    xo.vertices = counted;
    const std::vector<RomLimit> xl = find_rom_limits(lhip, xm, xo, lbase);
    for (std::size_t k = 0; k < xm.size(); ++k) {
      const RomLimit& l = xl[k];
      double before = std::nan(""), after = std::nan("");
      std::string validated = "no_limit";
      auto exact = [&](double t) {
        const Eigen::Matrix3d R = lhip.femur_rotation(xm[k].angles(t));
        const double h = exact_least_hidden(lj, r.ex_pelvis, r.ex_femur, lbase, R);
        return counted == RomVertices::hidden ? h : std::min(h, exact_least_gap(lj, r.ex_pelvis, r.ex_femur, lbase, R));
      };
      if (!std::isnan(l.limit_deg) && !l.contact_at_start) {
        before = exact(std::max(0.0, l.limit_deg - 0.5));
        after = exact(l.limit_deg + 0.5);
        validated = before > st.ro.threshold_mm && after <= st.ro.threshold_mm ? "yes" : "no";
      }
      out.extra.row(r.subject.name, xm[k].name, counted == RomVertices::all ? "all" : "hidden", l.limit_deg,
                    to_string(l.limited_by), l.limited_by_hidden_vertex ? 1 : 0, l.limited_by_ball ? 1 : 0,
                    l.socket_clock_h,
                    l.contact_mm.allFinite() ? (l.contact_mm - lhip.to_working(Eigen::Vector3d::Zero())).norm()
                                             : std::nan(""),
                    l.min_gap_at_limit_mm, l.contact_at_start ? 1 : 0, before, after, validated);
    }
  }
  for (const JointBody* b : {&lj.ball(), &lj.socket()}) {
    const Timing ls = summarize(layered_ms[b == &lj.ball() ? 0 : 1]);
    out.layered.row(r.subject.name, b == &lj.ball() ? "femur" : "pelvis", lo.hip.joint.layers, b->layered->num_nodes(),
                    b->layered->bytes(), b->map.bytes(), ls.median_ms, ls.q25_ms, ls.q75_ms, b->sampling_ms,
                    b->layered_sampling.nodes_covered, b->layered_sampling.nodes_truncated,
                    b->layered_sampling.nodes_not_alternating, b->layered_sampling.max_crossings, b->hidden_set.size(),
                    lim_single.median_ms, lim_layered.median_ms, lim_single.q25_ms, lim_single.q75_ms,
                    lim_layered.q25_ms, lim_layered.q75_ms, reps);
  }
}

// The ROM envelope by refinement (medians and quartiles of at least 5 rounds) beside the brute force over every pose
// (one run).
void envelope(const SubjectRun& r, const Settings& st, Outputs& out) {
  const HipJoint& hip = r.session.hip();
  RomEnvelopeOptions eo;
  eo.step_deg = st.quick ? 5 : 1;  // quick: 5 deg, the coarsest step that divides every range (1/125 the poses)
  eo.coarse_steps = 4;
  RomEnvelopeOptions bo = eo;
  bo.coarse_steps = 1;
  RomEnvelope fast, all;
  const int reps = std::max(5, st.reps);
  // The brute force is the reference the envelope's poses are checked against: run once, its time a single run
  // (brute_force_runs = 1; 8-14 s a subject, which the text only bounds). Issue 82 item 7: its 5 alternated rounds
  // were most of this experiment's 7 minutes.
  const Timing tf = summarize(run_alternated({[&] { fast = rom_envelope(hip, eo, st.ro, r.run.baseline); }}, reps)[0]);
  const auto t0 = Clock::now();
  all = rom_envelope(hip, bo, st.ro, r.run.baseline);
  const Timing tb = summarize({ms_since(t0)});
  std::int64_t valid = 0, all_valid = 0, differ = 0;
  for (std::size_t p = 0; p < all.valid.size(); ++p)
    valid += fast.valid[p], all_valid += all.valid[p], differ += fast.valid[p] != all.valid[p];
  const double ms = tf.median_ms;
  out.env.row(r.subject.name, st.resolution, eo.step_deg, eo.coarse_steps, st.threads, fast.poses,
              fast.poses_evaluated, valid, ms, tf.q25_ms, tf.q75_ms, double(fast.poses) / (ms / 1000),
              double(fast.poses) / (ms / 1000) / st.threads, tb.median_ms, tb.q25_ms, tb.q75_ms, all_valid, differ,
              reps, tb.runs);
}

// The search's cost beside FCL collide on a subset of the map's poses (flexion 45, adduction 10,
// internal rotation 0..58 step 2), extrapolated to the search's evaluations. Without `repeat` (--quick, every
// subject but the first) the sampling and the search are the subject's first run's alone (sampling_runs and
// search_runs 1).
void timing(const SubjectRun& r, const Settings& st, Outputs& out, bool repeat) {
  const HipJoint& hip = r.session.hip();
  const Joint& joint = hip.joint();
  Timing fcl;  // FCL collide per pose: median and quartiles over the poses
  int fcl_poses = 0;
  if (have_fcl()) {
    const FclJoint fj(joint.ball().mesh, joint.socket().mesh, Eigen::Vector3d::Zero());
    std::vector<double> ts;
    for (int ir = 0; ir < 60; ir += 2) {
      const Eigen::Matrix3d R = hip.femur_rotation({45, 10, double(ir)});
      const auto t1 = Clock::now();
      fj.collide(R, Eigen::Vector3d::Zero(), 1);
      ts.push_back(ms_since(t1));
    }
    fcl = summarize(ts);
    fcl_poses = static_cast<int>(ts.size());
  }
  const double fcl_ms = fcl_poses > 0 ? fcl.median_ms : std::nan("");
  // Both maps' sampling, in new sessions of the same options (at least 5): its spread (the first session's alone was
  // one run).
  std::vector<double> sampling;
  if (!repeat) sampling.push_back(joint.ball().sampling_ms + joint.socket().sampling_ms);
  for (int k = 0; repeat && k < std::max(5, st.reps); ++k) {
    const Session again(r.options);
    sampling.push_back(again.hip().joint().ball().sampling_ms + again.hip().joint().socket().sampling_ms);
  }
  const Timing tsam = summarize(sampling);
  const RomRun& run = r.run;
  const std::int64_t all_evals = run.limit_evaluations + run.map_evaluations;
  // The search (limits and map) again, `reps` rounds: the medians and quartiles of its times (the limits and the map
  // of each run as run_rom reports them), alternated with the same search by the per-vertex test (the thesis'
  // Algorithm 2 with the bounds; RomOptions::exact_contact false), whose share of look-ups the bounds skip is what
  // share_skipped gives (the exact test scans no vertices); their ratio paired round by round.
  std::vector<double> limits, map, search, per_vertex;
  RomRun vertex_run;
  if (!repeat) limits = {r.run.limits_ms}, map = {r.run.map_ms}, search = {r.run.limits_ms + r.run.map_ms};
  if (repeat) {
    RomRequest by_vertex = SubjectRun::request(st);
    by_vertex.search.exact_contact = false;
    run_alternated({[&] {
                      const RomRun again = run_rom(r.session, SubjectRun::request(st));
                      limits.push_back(again.limits_ms), map.push_back(again.map_ms);
                      search.push_back(again.limits_ms + again.map_ms);
                    },
                    [&] {
                      vertex_run = run_rom(r.session, by_vertex);
                      per_vertex.push_back(vertex_run.limits_ms + vertex_run.map_ms);
                    }},
                   std::max(1, st.reps));
    // The warm-up round's times are not the rounds'.
    limits.erase(limits.begin()), map.erase(map.begin()), search.erase(search.begin());
    per_vertex.erase(per_vertex.begin());
  }
  std::vector<double> exact_over_vertex;
  for (std::size_t k = 0; k < per_vertex.size(); ++k) exact_over_vertex.push_back(search[k] / per_vertex[k]);
  const Timing tl = summarize(limits), tm = summarize(map), ts = summarize(search), tv = summarize(per_vertex),
               tr = summarize(exact_over_vertex);
  const double search_ms = ts.median_ms;
  const std::int64_t vertex_all = vertex_run.vertices_looked_up + vertex_run.vertices_skipped;
  const double fcl_total = fcl_ms * double(all_evals);
  out.tim.row(r.subject.name, st.resolution, st.threads, tsam.median_ms, tsam.q25_ms, tsam.q75_ms, tsam.runs,
              tl.median_ms, tm.median_ms, search_ms, ts.q25_ms, ts.q75_ms, ts.runs, all_evals,
              double(all_evals) / (search_ms / 1000),
              vertex_all > 0 ? double(vertex_run.vertices_skipped) / double(vertex_all) : std::nan(""), tv.median_ms,
              tv.q25_ms, tv.q75_ms, tr.median_ms, tr.q25_ms, tr.q75_ms, fcl_ms,
              fcl_poses > 0 ? fcl.q25_ms : std::nan(""), fcl_poses > 0 ? fcl.q75_ms : std::nan(""), fcl_poses,
              fcl_total, fcl_total / search_ms, run.baseline.excluded_vertices, run.baseline.min_gap_mm);
}

// The rows of `t` with the subject and method first, into `into` (its columns set on first use).
void add_prefixed(Table& into, const Table& t, const std::string& subject, const std::string& method) {
  if (into.columns.empty()) {
    into.columns = {"subject", "method"};
    into.columns.insert(into.columns.end(), t.columns.begin(), t.columns.end());
  }
  for (const nlohmann::json& r : t.rows) {
    nlohmann::json row = {subject, method};
    row.insert(row.end(), r.begin(), r.end());
    into.add(row);
  }
}

// Puls et al. 2010's four joint-centre methods side by side (issue 29), as `impinge rom` runs them by
// default (layered maps, contact depth): limits, and with `whole` (--quick: the first subject only) the maps
// (methods_map.csv) and each method's limits with the initial COR moved 1 mm along each pelvic axis.
void methods(const SubjectRun& r, Outputs& out, bool whole) {
  if (!r.session.hip().acetabulum()) return;  // scan neutral (the generated model): femoral-head only
  const std::vector<StandardMotion> motions = standard_motions();
  RomRequest q = RunOptions::clinical().rom;  // the CLI's defaults: the distance metric
  q.map = q.map && whole;
  const Eigen::Vector3d centre = r.session.head().centre;
  const Eigen::Matrix3d axes = r.session.hip().frames()->pelvis.axes;
  const char* axis_name[3] = {"x", "y", "z"};
  for (const char* method : {"femoral-head", "acetabular", "combined", "equidistant"}) {
    SessionOptions o = rom_session_options(r.options, q.search);
    o.hip.joint_centre = parse_joint_centre(method, "joint centre");
    o.hip.joint.layers = 4;
    const Session s(o);
    const RomRun run = run_rom(s, q);
    if (std::string(method) == "equidistant") {
      // The measures that can explain a difference between two hips: the fitted head and acetabulum, and
      // the joint space at the scan pose and at neutral (setup_record's values, as summary.json has them).
      const nlohmann::json j = setup_record(s);
      const nlohmann::json& a = j["frames"]["acetabulum"];
      auto num = [](const nlohmann::json& x) { return x.is_number() ? x.get<double>() : std::nan(""); };
      out.bony.row(r.subject.name, j["side"].get<std::string>(), num(j["head_radius_mm"]),
                   num(j["frames"]["femur"]["head_fit_rms_mm"]), num(a["sphere_radius_mm"]),
                   num(a["sphere_fit_rms_mm"]), num(a["radiographic_inclination_deg"]),
                   num(a["radiographic_anteversion_deg"]), num(a["median_coverage_deg"]), num(a["notch_coverage_deg"]),
                   num(j["scan_pose_min_gap_mm"]), run.baseline.min_gap_mm);
    }
    add_prefixed(out.meth, rom_limits_table(s, run), r.subject.name, method);
    add_prefixed(out.meth_map, rom_map_table(run), r.subject.name, method);
    for (int a = 0; a < 3 && whole; ++a)
      for (const double sign : {1.0, -1.0}) {
        SessionOptions m = o;
        m.cor.given = centre + sign * axes.col(a);  // the working frame is the subject's (RAS)
        m.cor.allow_any = true;
        const Session moved(m);
        const HipJoint& h = moved.hip();
        const auto v = find_rom_limits(h, motions, q.search, rom_baseline(h, h.femur_rotation({}), q.search));
        for (std::size_t k = 0; k < motions.size(); ++k)
          out.sens.row(r.subject.name, method, std::string("cor_") + (sign > 0 ? "+" : "-") + axis_name[a] + "_1mm",
                       motions[k].name, v[k].limit_deg, v[k].limit_deg - run.limits[k].limit_deg);
      }
  }
}

// Sensitivity of the thesis' femoral-head method: the COR moved 1 mm along each pelvic axis (scan
// neutral only: methods() covers anatomical neutral under every method); other resolutions.
void sensitivity(const SubjectRun& r, const Settings& st, Outputs& out) {
  const HipJoint& hip = r.session.hip();
  const std::vector<StandardMotion>& motions = r.run.motions;
  auto limits_of = [&](const Eigen::Vector3d& centre, double res) {
    SessionOptions o = r.options;
    o.grid.precision = res;
    o.cor.given = centre;  // a perturbed centre: research, not checked against the head
    o.cor.allow_any = true;
    const Session hs(o);
    const HipJoint& hj = hs.hip();
    return find_rom_limits(hj, motions, st.ro, rom_baseline(hj, hj.femur_rotation({}), st.ro));
  };
  auto record = [&](const std::string& variant, const std::vector<RomLimit>& v) {
    for (std::size_t k = 0; k < motions.size(); ++k)
      out.sens.row(r.subject.name, "femoral-head (thesis)", variant, motions[k].name, v[k].limit_deg,
                   v[k].limit_deg - r.run.limits[k].limit_deg);
  };
  const Eigen::Vector3d centre = r.session.head().centre;
  const Eigen::Matrix3d axes = hip.frames() ? hip.frames()->pelvis.axes : scan_axes();
  const char* axis_name[3] = {"x", "y", "z"};
  if (!hip.acetabulum())
    for (int a = 0; a < 3; ++a)
      for (const double sign : {1.0, -1.0})
        record(std::string("cor_") + (sign > 0 ? "+" : "-") + axis_name[a] + "_1mm",
               limits_of(centre + sign * axes.col(a), st.resolution));
  for (double res : st.sens_resolutions)
    if (res != st.resolution) record("resolution_" + std::to_string(res).substr(0, 4), limits_of(centre, res));
}

// Thesis Fig. 60-61 (sec. 5.2): the patients' cam regions, the femoral head outside its fitted sphere, "will
// most likely" be where they impinge. The patients are not available, so a generated hip without and with a
// cam tests it: do the limits shrink with the cam, and where the femur limits a motion, does its contact lie
// on the cam? Where the bones meet, the femur's surface is its vertex nearest the contact point (either bone's
// vertex); the cam's height there is that vertex's distance from the head centre with the cam less without
// (the two models share their vertices' directions). A fitted sphere would not tell the cam from the neck,
// whose surface also lies outside the head's sphere beyond the head-neck junction.
void cam_check(const Settings& st) {
  CsvWriter cam(st.dir + "/cam.csv", {"cam_mm", "motion", "limit_deg", "limited_by_femur", "cam_height_at_contact_mm",
                                      "contact_radius_mm"});
  HipModelOptions o;
  o.target_triangles = 12000;
  const HipModel without = make_hip_model(o);
  o.cam_height_mm = 2.0;
  const HipModel with_cam = make_hip_model(o);
  for (const HipModel* model : {&without, &with_cam}) {
    const HipModel& h = *model;
    const double height = model == &without ? 0.0 : o.cam_height_mm;
    SessionOptions so;
    so.grid.precision = st.resolution;
    const Session session(session_options(generated_subject(h, "generated-12k", "make_hip_model (cam check)"), so));
    RomRequest q;
    q.search = st.ro;
    q.map = false;
    const RomRun run = run_rom(session, q);
    const HipJoint& hip = session.hip();
    for (std::size_t k = 0; k < run.motions.size(); ++k) {
      const RomLimit& l = run.limits[k];
      double cam_there = std::nan(""), radius = std::nan("");
      if (!std::isnan(l.limit_deg) && !l.contact_at_start) {
        const Eigen::Matrix3d R = hip.femur_rotation(run.motions[k].angles(l.limit_deg));
        const Eigen::Vector3d c =
            hip.joint_to_working().transpose() * (l.contact_mm - hip.to_working(Eigen::Vector3d::Zero()));
        radius = c.norm();
        double best = std::numeric_limits<double>::infinity();
        for (Eigen::Index i = 0; i < h.ball.V.rows(); ++i) {
          const Eigen::Vector3d v = h.ball.V.row(i).transpose() - h.cor;  // unposed, about the head centre (the COR)
          const double d = (R * v - c).squaredNorm();
          if (d < best)
            best = d, cam_there = v.norm() - (without.ball.V.row(i).transpose() - without.cor).norm();
        }
      }
      cam.row(height, run.motions[k].name, l.limit_deg, int(l.limited_by_ball), cam_there, radius);
    }
  }
}

void write_meta_of(const Args& args, const Settings& st, const std::vector<Subject>& subjects, bool generated) {
  nlohmann::json subj = nlohmann::json::array();
  for (const Subject& s : subjects) subj.push_back({{"name", s.name}, {"source", s.source}});
  nlohmann::json params = {
      {"resolution_deg", st.resolution},
      {"sensitivity_resolutions_deg", st.sens_resolutions},
      {"threshold_mm", st.ro.threshold_mm},
      {"contact_depth_mm", st.ro.contact_depth_mm},
      {"methods",
       "femoral-head, acetabular, combined, equidistant (Puls et al. 2010) with the CLI's defaults: "
       "layered maps (4 crossings, 0.5 deg), contact depth 0.25 mm, impingement contacts"},
      {"step_deg", st.ro.step_deg},
      {"tolerance_deg", st.ro.tolerance_deg},
      {"observation_levels_mm", st.observation_levels.thresholds_mm},
      {"neutral", generated ? "scan (generated model)" : "anatomical (ISB frames from the bones)"},
      {"rom_map", "flexion 0..120 step 5 x adduction -20..40 step 5"},
      {"exact_check",
       "CGAL ray casts from the COR for every counted first-surface vertex, 0.5 deg "
       "before and after each limit; hidden vertices are not checked"},
      {"layers", 4},
      {"envelope",
       "flexion -30..130 x adduction -50..40 x internal rotation -60..60 deg, 1 deg (quick: 5), "
       "refined from every 4th step; time: median and quartiles of at least 5 rounds; the brute force: one run"},
      {"extra_articular_check",
       "CGAL all-intersection rays from the COR for every counted hidden vertex "
       "(signed radial distance), plus the first-hit check when all vertices count"},
      {"subjects", subj}};
  if (st.quick)
    params["quick"] =
        "maps at 0.25 deg, the envelope at 5 deg; the repeated sampling and search timings (timing.csv), the layered "
        "maps' timings (layered.csv) and the joint-centre methods' maps (methods_map.csv) and COR moves "
        "(sensitivity.csv) on the first subject only";
  write_meta(st.dir, args, params);
}

}  // namespace

int main(int argc, char** argv) {
  const Args args = parse_args(argc, argv, "09_rom_observation: thesis sec. 5.2 ROM observation, ROM limits and maps");
  Settings st;
  st.dir = experiment_dir(args, "09_rom_observation");
  st.quick = args.quick;
  const std::string src = IMPINGE_EXPERIMENTS_DIR;
  fs::copy_file(src + "/09_thesis_table11.csv", st.dir + "/thesis_table11.csv", fs::copy_options::overwrite_existing);
  fs::copy_file(src + "/09_published.csv", st.dir + "/published.csv", fs::copy_options::overwrite_existing);
  st.table11 = read_table11(src + "/09_thesis_table11.csv");
  std::vector<Subject> subjects = load_subjects(args, {});
  const bool generated = subjects.empty();
  if (generated) subjects = load_subjects(args, {12000});
  st.resolution = args.quick ? 0.25 : 0.1;
  st.sens_resolutions = args.quick ? std::vector<double>{0.5, 0.25} : std::vector<double>{0.5, 0.25, 0.1};
  st.observation_levels.thresholds_mm = kReportLevelsMm;
  st.ro.contact_depth_mm = 0;  // the thesis' criterion: the first touch (methods() uses the CLI's defaults)
  st.threads = omp_get_max_threads();
  st.reps = args.repetitions;

  Outputs out(st.dir);
  int done = 0;
  for (const Subject& s : subjects) {
    progress("09_rom_observation", ++done, static_cast<int>(subjects.size()), s.name);
    const bool first = done == 1;  // --quick: the repeated timings and the methods' COR moves and maps: this one only
    const SubjectRun r(s, st);
    if (!s.generated) observe_table11(r, st, out);
    record_limits(r, st, out);
    extra_articular(r, st, out, !st.quick || first);
    envelope(r, st, out);
    timing(r, st, out, !st.quick || first);
    sensitivity(r, st, out);
    methods(r, out, !st.quick || first);
  }
  cam_check(st);
  write_csv(st.dir + "/rom_limits.csv", out.lim);
  write_csv(st.dir + "/rom_map.csv", out.map);
  if (!out.meth.columns.empty()) {
    write_csv(st.dir + "/methods.csv", out.meth);
    write_csv(st.dir + "/methods_map.csv", out.meth_map);
  }
  write_meta_of(args, st, subjects, generated);
  return 0;
}
