// 08_distance_maps -- thesis Fig. 31, 40-42, 50: distance maps and gap statistics on real
// joints, RSID (equiangular) and USID (helix at the matched number of turns) side by side.
//
// Inputs: every subject under --data (real hips) and the generated 3k hip model.
// Outputs: OUT/08_distance_maps/
//   gap_statistics.csv  one row per subject x precision x mode x scan (ball / socket); the scan's
//                       vertices are tested against the other body's map, while map_* and
//                       sampling_ms describe the scanned body's own map; COR in the RAS frame; sampling_ms and
//                       detection_ms are medians, *_q25_ms and *_q75_ms their quartiles, over timing_runs rounds
//                       (both bodies' samplings alternated, both scans alternated)
//   vertex_gaps.csv     per-vertex gaps within 45 mm of the COR at the finest precision, exact mode
//   map_<subject>_<body>.png  the maps at 0.5 deg (theta across, phi down); *_helix.png at k = 458,
//                       *_<scheme>.png for the other registered schemes (drawn in their own way)
//   map_images.csv    each map image's grey scale (grey 40 = nearest_mm, 255 = farthest_mm), for colour bars
//   render_<subject>_<body>.ply  both bones within 60 mm of the COR at the scan pose, in the pelvic
//                       frame (ISB; generated models: the scan's anatomical axes), with gaps, levels
//                       and colours, at 0.25 deg exact mode (HipJoint), for the shaded renders
//   clock_faces.csv     one row per subject: the acetabular clock face and orientation in that frame
//   poses_<subject>_<pose>.ply  (first real subject) the femur within 250 mm of the COR, posed by the
//                       clinical angles of poses.csv, and the pelvis within 150 mm, in the pelvic frame:
//                       the README's figure of the ISB angles
//   poses.csv           pose, flexion_deg, adduction_deg, internal_rotation_deg
//   radial_vs_distance.csv  (issue 26) one row per subject x pose x scan: the radial gap of the thesis
//                       beside the Euclidean distance (the CLI's defaults: layers 4, distances within
//                       6 mm), where they differ by more than 1 mm and in which contact class, and what
//                       the penetrating area and the thesis' levels become under each
//   radial_vs_distance_vertices.csv  per vertex within 6 mm of the other bone: gap and distance (every
//                       k-th vertex, at most 4000 per row of the table above), for the scatter figure
//   meta.json
// Command: build/experiments/exp_08_distance_maps --out results --data ../shared/data/hips [--quick]
// Precisions 1, 0.5 and (outside quick mode) 0.1 and 0.05 deg, each with the helix of matched turns
// k = round(720 / (pi p)) (thesis Table 6); modes linear and exact; scan pose (identity). Every
// other registered scheme (scheme_names) at the coarsest resolution whose node spacing is at most p,
// for p >= 0.1 deg, exact mode, with its gaps' difference from the equiangular ones (the vs_*
// columns) and its map images (map_<subject>_<body>_<scheme>.png). Sampling
// and detection times are medians over the repetitions. Helix rows also give the difference of
// their gaps from the equiangular ones at the same precision and mode (thesis Fig. 50).
#include <algorithm>
#include <filesystem>
#include <map>

#include "experiment_support.hpp"
#include "impinge/anatomy/clock_face.hpp"
#include "impinge/anatomy/sphere_fit.hpp"
#include "impinge/clinical/hip_joint.hpp"
#include "impinge/clinical/rom.hpp"
#include "impinge/core/error.hpp"
#include "impinge/core/spherical_frame.hpp"
#include "impinge/session/option_table.hpp"
#include "impinge/detection/joint.hpp"
#include "impinge/io/mesh_io.hpp"
#include "impinge/maps/map_image.hpp"
#include "impinge/sampling/sampling.hpp"
#include "impinge/schemes/helix_scheme.hpp"

using namespace impinge;
using namespace impinge::experiment;

namespace {

// The tables of the gap statistics.
struct Outputs {
  explicit Outputs(const std::string& dir)
      : stats(dir + "/gap_statistics.csv",
              {"subject", "generated", "scheme", "resolution", "precision_deg", "mode", "scan", "cor_ras_x_mm",
               "cor_ras_y_mm", "cor_ras_z_mm", "head_radius_mm", "sphere_fit_rms_mm", "cor_error_mm", "vertices",
               "vertices_tested", "vertices_no_surface", "vertices_beyond_reach", "min_gap_mm",
               "vertices_penetrating", "area_penetrating_mm2", "level_none", "level_yellow", "level_orange",
               "level_red", "level_purple", "map_nodes", "map_nodes_covered", "map_bytes", "sampling_ms",
               "sampling_q25_ms", "sampling_q75_ms", "detection_ms", "detection_q25_ms", "detection_q75_ms",
               "timing_runs", "detection_ns_per_lookup", "linear_vs_exact_p95_abs_mm", "vs_equiangular_p95_abs_mm",
               "vs_equiangular_max_abs_mm", "vs_equiangular_compared"}),
        map_images(dir + "/map_images.csv",
                   {"subject", "body", "scheme", "resolution", "file", "nearest_mm", "farthest_mm"}),
        vertices(dir + "/vertex_gaps.csv", {"subject", "scan", "vertex", "x_mm", "y_mm", "z_mm", "gap_mm"}) {}
  CsvWriter stats, map_images, vertices;
};

// Sorted |a - b| over the vertices where both are finite.
std::vector<double> abs_diff(const std::vector<float>& a, const std::vector<float>& b) {
  std::vector<double> d;
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i)
    if (std::isfinite(a[i]) && std::isfinite(b[i])) d.push_back(std::abs(double(a[i]) - b[i]));
  std::sort(d.begin(), d.end());
  return d;
}
double quantile(const std::vector<double>& d, double q) {
  return d.empty() ? std::nan("") : d[static_cast<std::size_t>(q * double(d.size() - 1))];
}

// The schemes at precision p: the thesis' pair (equiangular p, the matched helix), and every other
// registered scheme (issue 12: without touching this driver), exact mode, at the coarsest resolution
// whose node spacing is at most p, for p >= 0.1 deg.
std::vector<std::shared_ptr<const SamplingScheme>> schemes_at(double p) {
  std::vector<std::shared_ptr<const SamplingScheme>> schemes{make_scheme("equiangular", p),
                                                             make_scheme("helix", matched_helix_turns(p))};
  if (p < 0.1) return schemes;
  for (const auto& [name, unit] : scheme_names()) {
    (void)unit;
    if (name == "equiangular" || name == "helix") continue;
    try {
      schemes.push_back(make_scheme(name, resolution_for_spacing(name, p)));
    } catch (const Error&) {
      // a resolution this scheme does not take at this spacing (e.g. conchoid needs 90/p integral)
    }
  }
  return schemes;
}

// One subject at one precision: what the schemes compare against.
struct Compare {
  std::map<DistanceMode, std::vector<float>> rsid_ball;  // equiangular ball gaps per mode
};

// Levels: the report's one set (kReportLevelsMm), not the thesis' Fig. 41-42 split of its 4 mm cartilage
// offset, so that the colours mean one thing in every figure of the report.

// Both scans at the scan pose with one scheme and mode: the statistics, the timings (fill and scan of
// each body, medians), the differences linear - exact and scheme - equiangular, the map images
// (0.5 deg) and the finest precision's per-vertex gaps.
void measure(const Subject& s, const SphereFitResult& fit, double cor_error, double p, bool finest,
             const std::shared_ptr<const SamplingScheme>& scheme, DistanceMode mode, std::vector<float>& exact_ball,
             Compare& cmp, const Args& args, const std::string& dir, Outputs& out) {
  const bool helix = scheme->name() != "equiangular";  // compared with the equiangular gaps below
  JointOptions o;
  o.scheme = scheme;
  o.mode = mode;
  o.levels.thresholds_mm = kReportLevelsMm;
  const Joint joint(s.femur, s.pelvis, fit.centre, o);
  const PoseResult res = joint.detect(Eigen::Matrix3d::Identity());
  const int reps = p <= 0.05 ? std::max(1, args.repetitions / 2) : args.repetitions;
  // Both bodies' sampling, then both scans, each pair timed alternately (run_alternated): medians and quartiles.
  Timing sample_ms[2], detect_ms[2];
  const JointBody* bodies[2] = {&joint.ball(), &joint.socket()};
  {
    RadialDistanceMap scratch[2] = {RadialDistanceMap{scheme}, RadialDistanceMap{scheme}};
    SamplingOptions so;
    so.mode = mode;
    auto sample = [&](int b) {
      return [&, b] {
        std::fill(scratch[b].data(), scratch[b].data() + scratch[b].num_nodes(), RadialDistanceMap::no_surface());
        sample_surface(bodies[b]->mesh, fit.centre, so, scratch[b]);
      };
    };
    const auto runs = run_alternated({sample(0), sample(1)}, reps);
    for (int b = 0; b < 2; ++b) sample_ms[b] = summarize(runs[std::size_t(b)]);
  }
  ScanGaps scratch_gaps;
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const auto scans = run_alternated(
      {[&] { scan_gaps(joint.ball().relative, I, joint.ball().mask, joint.socket().map, ScanSide::inside, scratch_gaps); },
       [&] {
         scan_gaps(joint.socket().relative, I, joint.socket().mask, joint.ball().map, ScanSide::outside, scratch_gaps);
       }},
      args.repetitions);
  for (int b = 0; b < 2; ++b) detect_ms[b] = summarize(scans[std::size_t(b)]);
  double p95 = std::nan(""), vs_p95 = std::nan(""), vs_max = std::nan("");
  std::int64_t vs_n = 0;
  if (mode == DistanceMode::exact)
    exact_ball = res.ball_gaps.gap_mm;
  else
    p95 = quantile(abs_diff(exact_ball, res.ball_gaps.gap_mm), 0.95);
  if (!helix) {
    cmp.rsid_ball[mode] = res.ball_gaps.gap_mm;
  } else {
    const std::vector<double> d = abs_diff(cmp.rsid_ball[mode], res.ball_gaps.gap_mm);
    vs_p95 = quantile(d, 0.95);
    vs_max = d.empty() ? std::nan("") : d.back();
    vs_n = static_cast<std::int64_t>(d.size());
  }
  const ScanSummary* sums[2] = {&res.ball, &res.socket};
  for (int b = 0; b < 2; ++b) {
    const ScanSummary& sm = *sums[b];
    const JointBody& body = *bodies[b];
    // per map look-up (tested + no surface); masked vertices cost one byte test each
    const std::int64_t lookups = sm.vertices_tested + sm.vertices_no_surface;
    const double ns = lookups > 0 ? detect_ms[b].median_ms * 1e6 / double(lookups) : std::nan("");
    out.stats.row(s.name, int(s.generated), scheme->name(), scheme->resolution(), p, to_string(mode),
                  b == 0 ? "ball" : "socket", fit.centre.x(), fit.centre.y(), fit.centre.z(), fit.radius,
                  fit.rms_residual, cor_error, sm.vertices, sm.vertices_tested, sm.vertices_no_surface,
                  sm.vertices_beyond_reach, sm.min_gap_mm, sm.vertices_penetrating, sm.area_penetrating_mm2,
                  sm.level_vertices[0], sm.level_vertices[1], sm.level_vertices[2], sm.level_vertices[3],
                  sm.level_vertices[4], body.map.num_nodes(), body.sampling.nodes_covered,
                  std::int64_t(body.map.bytes()), sample_ms[b].median_ms, sample_ms[b].q25_ms, sample_ms[b].q75_ms,
                  detect_ms[b].median_ms, detect_ms[b].q25_ms, detect_ms[b].q75_ms, detect_ms[b].runs, ns,
                  b == 0 ? p95 : std::nan(""),
                  b == 0 ? vs_p95 : std::nan(""), b == 0 ? vs_max : std::nan(""), b == 0 ? vs_n : std::int64_t(0));
  }
  if (p == 0.5 && mode == DistanceMode::exact) {
    const std::string suffix = helix ? "_" + scheme->name() + ".png" : ".png";
    for (int b = 0; b < 2; ++b) {
      const std::string body = b == 0 ? "ball" : "socket";
      const std::string file = "map_" + s.name + "_" + body + suffix;
      const MapImageScale sc = write_map_png(dir + "/" + file, b == 0 ? joint.ball().map : joint.socket().map);
      out.map_images.row(s.name, body, scheme->name(), scheme->resolution(), file, sc.nearest_mm, sc.farthest_mm);
    }
  }
  if (finest && mode == DistanceMode::exact && !helix) {
    const ScanGaps* gaps[2] = {&res.ball_gaps, &res.socket_gaps};
    for (int b = 0; b < 2; ++b)
      for (Eigen::Index i = 0; i < bodies[b]->relative.rows(); ++i) {
        if (bodies[b]->relative.row(i).norm() > 45) continue;
        const Eigen::Vector3d v = bodies[b]->mesh.V.row(i).transpose();
        out.vertices.row(s.name, b == 0 ? "ball" : "socket", std::int64_t(i), v.x(), v.y(), v.z(),
                         double(gaps[b]->gap_mm[static_cast<std::size_t>(i)]));
      }
  }
}

// Shaded-render data: the hip region of both bones at the scan pose, in the pelvic frame, set up as
// the CLI sets a subject up; the README's figure of the clinical angles; each acetabulum's clock face.
void write_renders(const std::vector<Subject>& subjects, const std::string& dir, double render_precision,
                   double render_radius) {
  CsvWriter clocks(dir + "/clock_faces.csv",
                   {"subject", "side", "neutral", "centre_x_mm", "centre_y_mm", "centre_z_mm", "twelve_x", "twelve_y",
                    "twelve_z", "three_x", "three_y", "three_z", "rim_radius_mm", "rim_plane_rms_mm", "inclination_deg",
                    "anteversion_deg", "head_radius_mm", "acetabular_radius_mm", "scan_flexion_deg",
                    "scan_adduction_deg", "scan_internal_rotation_deg"});
  CsvWriter poses(dir + "/poses.csv", {"pose", "flexion_deg", "adduction_deg", "internal_rotation_deg"});
  const std::vector<std::pair<std::string, PoseAngles>> figure_poses{
      {"neutral", {0, 0, 0}}, {"flexion90", {90, 0, 0}}, {"adduction30", {0, 30, 0}}, {"internal30", {0, 0, 30}}};
  bool wrote_poses = false;
  for (const Subject& s : subjects) {
    SessionOptions so;
    so.grid.precision = render_precision;
    so.hip.joint.mode = DistanceMode::exact;
    so.hip.joint.levels.thresholds_mm = kReportLevelsMm;
    const Session session(session_options(s, so));
    const HipJoint& hip = session.hip();
    const ImpingementLevels& levels = session.joint_options().levels;
    const PoseResult res = hip.joint().detect(Eigen::Matrix3d::Identity());
    // Joint frame -> pelvic frame: p_pelvic = S^T p_joint (S = scan_axes()).
    const Eigen::Matrix3d to_pelvic = scan_axes().transpose();
    const JointBody* bodies[2] = {&hip.joint().ball(), &hip.joint().socket()};
    const ScanGaps* gaps[2] = {&res.ball_gaps, &res.socket_gaps};
    for (int b = 0; b < 2; ++b)
      write_region_ply(dir + "/render_" + s.name + (b == 0 ? "_ball.ply" : "_socket.ply"), *bodies[b], to_pelvic,
                       render_radius, gaps[b], levels, b == 0);
    if (!s.generated && !wrote_poses) {
      wrote_poses = true;
      for (const auto& [name, a] : figure_poses) {
        write_region_ply(dir + "/poses_" + s.name + "_" + name + ".ply", hip.joint().ball(),
                         to_pelvic * hip.femur_rotation(a), 250, nullptr, levels, true);
        poses.row(name, a.flexion_deg, a.adduction_deg, a.internal_rotation_deg);
      }
      write_region_ply(dir + "/poses_" + s.name + "_pelvis.ply", hip.joint().socket(), to_pelvic, 150, nullptr,
                       levels, false);
    }
    const char* side = s.side == Side::right ? "right" : "left";
    if (hip.socket_clock()) {
      const ClockFace c = hip.socket_clock()->transformed(to_pelvic, Eigen::Vector3d::Zero());
      const Acetabulum& A = *hip.acetabulum();
      const AcetabularOrientation o = radiographic_orientation(A, hip.frames()->pelvis, s.side);
      const PoseAngles& sp = hip.frames()->scan_pose;
      clocks.row(s.name, side, "anatomical", c.centre.x(), c.centre.y(), c.centre.z(), c.twelve.x(), c.twelve.y(),
                 c.twelve.z(), c.three.x(), c.three.y(), c.three.z(), A.rim_radius_mm, A.rim_plane_rms_mm,
                 o.inclination_deg, o.anteversion_deg, hip.head_radius_mm(), A.sphere.radius, sp.flexion_deg,
                 sp.adduction_deg, sp.internal_rotation_deg);
    } else {
      const double nan = std::nan("");
      clocks.row(s.name, side, "scan", nan, nan, nan, nan, nan, nan, nan, nan, nan, nan, nan, nan, nan,
                 hip.head_radius_mm(), nan, 0.0, 0.0, 0.0);
    }
  }
}

// The radial gap against the Euclidean distance (issue 26, item 5), at the scan pose and two clinical
// poses, with the CLI's defaults (layered maps, the joint-centre method of the neutral) and distances within
// `reach` mm. Both quantities per vertex; their differences by contact class; and the penetrating area and
// level areas under each.
void radial_vs_distance(const std::vector<Subject>& subjects, const std::string& dir, double precision, double reach) {
  CsvWriter table(dir + "/radial_vs_distance.csv",
                  {"subject", "pose", "scan", "vertices_distance", "vertices_both", "differ_1mm", "differ_1mm_articular",
                   "differ_1mm_intra_articular", "differ_1mm_extra_articular", "max_abs_diff_mm", "p95_abs_diff_mm",
                   "distance_without_gap", "inside_by_distance", "inside_missed_by_gap", "min_gap_mm",
                   "min_distance_mm", "area_penetrating_gap_mm2", "area_penetrating_distance_mm2",
                   "area_red_gap_mm2", "area_red_distance_mm2", "signs_by_winding_number"});
  CsvWriter vertices(dir + "/radial_vs_distance_vertices.csv", {"subject", "pose", "scan", "vertex", "gap_mm", "distance_mm"});
  const std::vector<std::pair<std::string, PoseAngles>> poses{
      {"scan", {0, 0, 0}}, {"flexion90", {90, 0, 0}}, {"extension20", {-20, 5, -5}}};
  for (const Subject& s : subjects) {
    SessionOptions base = RunOptions::clinical().session;  // the CLI's: layered maps and distances
    base.grid.precision = precision;
    base.hip.joint.levels.thresholds_mm = kReportLevelsMm;
    base.hip.joint.distance_reach_mm = reach;
    SessionOptions so = session_options(s, base);
    so.hip.joint_centre.reset();  // the CLI's default for the neutral
    const Session session(so);
    const HipJoint& hip = session.hip();
    const ImpingementLevels& levels = session.joint_options().levels;
    const double red = levels.thresholds_mm[levels.thresholds_mm.size() - 2];  // the last level above contact
    for (const auto& [name, angles] : poses) {
      const FemurPose pose = name == "scan" ? hip.scan_pose() : hip.femur_pose(angles);
      const PoseResult res = hip.joint().detect(pose.R, pose.t);
      for (const bool ball : {true, false}) {
        const ScanGaps& g = ball ? res.ball_gaps : res.socket_gaps;
        const ScanSummary& sum = ball ? res.ball : res.socket;
        const Eigen::VectorXd& area = ball ? hip.joint().ball().vertex_area : hip.joint().socket().vertex_area;
        std::int64_t both = 0, differ = 0, without_gap = 0, inside = 0, missed = 0;
        std::int64_t by_class[4] = {0, 0, 0, 0};
        double area_pen_gap = 0, area_pen_dist = 0, area_red_gap = 0, area_red_dist = 0;
        std::vector<double> diffs;
        std::vector<std::size_t> within;
        for (std::size_t i = 0; i < g.distance_mm.size(); ++i) {
          const double gap = g.gap_mm[i], d = g.distance_mm[i];
          const double a = area[static_cast<Eigen::Index>(i)];
          if (std::isfinite(gap)) {
            if (gap <= 0) area_pen_gap += a;
            if (gap < red) area_red_gap += a;
          }
          if (!std::isfinite(d)) continue;
          within.push_back(i);
          if (d <= 0) area_pen_dist += a;
          if (d < red) area_red_dist += a;
          if (d < 0) {
            ++inside;
            if (!(gap < 0)) ++missed;
          }
          if (!std::isfinite(gap)) {
            ++without_gap;
            continue;
          }
          ++both;
          diffs.push_back(std::abs(gap - d));
          if (std::abs(gap - d) > 1) {
            ++differ;
            ++by_class[static_cast<int>(hip.contact_class(ball, static_cast<std::int64_t>(i), pose, kIntraArticularMarginMm))];
          }
        }
        std::sort(diffs.begin(), diffs.end());
        const double nan = std::nan("");
        table.row(s.name, name, ball ? "ball" : "socket", sum.vertices_distance, both, differ, by_class[1], by_class[2],
                  by_class[3], diffs.empty() ? nan : diffs.back(), diffs.empty() ? nan : quantile(diffs, 0.95),
                  without_gap, inside, missed, sum.min_gap_mm, sum.min_distance_mm, area_pen_gap, area_pen_dist,
                  area_red_gap, area_red_dist, sum.distance_winding);
        const std::size_t stride = std::max<std::size_t>(1, (within.size() + 3999) / 4000);
        for (std::size_t k = 0; k < within.size(); k += stride) {
          const std::size_t i = within[k];
          vertices.row(s.name, name, ball ? "ball" : "socket", static_cast<std::int64_t>(i), g.gap_mm[i], g.distance_mm[i]);
        }
      }
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  const Args args = parse_args(argc, argv, "08_distance_maps: gap statistics and maps on real joints");
  const std::string dir = experiment_dir(args, "08_distance_maps");
  std::vector<Subject> subjects = load_subjects(args, {3000});
  // Quick runs check the pipeline at 1 and 0.5 deg; full runs add 0.1 and 0.05 deg.
  const std::vector<double> precisions = args.quick ? std::vector<double>{1, 0.5} : std::vector<double>{1, 0.5, 0.1, 0.05};
  Outputs out(dir);
  int done = 0, total = 0;
  for (double p : precisions) total += 2 + static_cast<int>(schemes_at(p).size());  // the thesis' pair in two modes
  total *= static_cast<int>(subjects.size());
  for (const Subject& s : subjects) {
    // The centre as every front end finds it (the session layer); a generated hip's is fitted, so
    // that its error against the true centre is measured.
    const SphereFitResult fit = s.generated ? fit_femoral_head(s.femur) : subject_head(s);
    const double cor_error = s.generated ? (fit.centre - s.true_cor).norm() : std::nan("");
    for (double p : precisions) {
      Compare cmp;
      for (const auto& scheme : schemes_at(p)) {
        const bool thesis_scheme = scheme->name() == "equiangular" || scheme->name() == "helix";
        std::vector<float> exact_ball;  // exact-mode gaps, for the linear-vs-exact difference
        for (DistanceMode mode : {DistanceMode::exact, DistanceMode::linear}) {
          if (!thesis_scheme && mode == DistanceMode::linear) continue;
          progress("08_distance_maps", ++done, total,
                   s.name + " " + scheme->name() + " " + std::to_string(scheme->resolution()) + " " + to_string(mode));
          measure(s, fit, cor_error, p, p == precisions.back(), scheme, mode, exact_ball, cmp, args, dir, out);
        }
      }
    }
  }
  const double render_precision = 0.25, render_radius = 60;
  write_renders(subjects, dir, render_precision, render_radius);
  const double distance_precision = args.quick ? 0.5 : 0.1, distance_reach = 6;
  radial_vs_distance(subjects, dir, distance_precision, distance_reach);

  nlohmann::json subj = nlohmann::json::array();
  for (const Subject& s : subjects) subj.push_back({{"name", s.name}, {"source", s.source}});
  write_meta(dir, args,
             {{"precisions_deg", precisions},
              {"helix_turns", "round(720 / (pi p)) for each precision p"},
              {"modes", {"exact", "linear"}},
              {"pose_deg", {0, 0, 0}},
              {"subjects", subj},
              {"cor", "the session layer's automatic centre (locate_femoral_head: long axis, RANSAC + geometric "
                      "sphere fit); generated hips: fit_femoral_head, compared with the true centre"},
              {"vertex_gaps_region_mm", 45},
              {"render", {{"precision_deg", render_precision}, {"mode", "exact"}, {"region_mm", render_radius},
                          {"frame", "pelvic (ISB, Wu et al. 2002) for real subjects; scan axes for generated"},
                          {"pose", "scan pose"}}},
              {"radial_vs_distance", {{"precision_deg", distance_precision}, {"reach_mm", distance_reach},
                                      {"layers", 4}, {"joint_centre", "the CLI's default for the neutral"},
                                      {"poses", "scan pose; flexion 90; extension 20, adduction 5, rotation -5"}}},
              {"occlusion_tolerance_mm", JointOptions{}.occlusion_tolerance_mm},
              {"levels_thresholds_mm", kReportLevelsMm}});
  return 0;
}
