// 08_distance_maps -- thesis Fig. 31, 40-42, 50: distance maps and gap statistics on real
// joints, RSID (equiangular) and USID (helix at the matched number of turns) side by side.
//
// Inputs: every subject under --data (real hips) and the generated 3k hip model.
// Outputs: OUT/08_distance_maps/
//   gap_statistics.csv  one row per subject x precision x mode x scan (ball / socket); the scan's
//                       vertices are tested against the other body's map, while map_* and
//                       sampling_ms describe the scanned body's own map; COR in the RAS frame
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
#include "impinge/core/error.hpp"
#include "impinge/core/spherical_frame.hpp"
#include "impinge/detection/joint.hpp"
#include "impinge/io/mesh_io.hpp"
#include "impinge/maps/map_image.hpp"
#include "impinge/sampling/sampling.hpp"
#include "impinge/schemes/helix_scheme.hpp"

using namespace impinge;
using namespace impinge::experiment;

int main(int argc, char** argv) {
  const Args args = parse_args(argc, argv, "08_distance_maps: gap statistics and maps on real joints");
  const std::string dir = experiment_dir(args, "08_distance_maps");
  std::vector<Subject> subjects = load_subjects(args, {3000});
  // Quick runs check the pipeline at 1 and 0.5 deg; full runs add 0.1 and 0.05 deg.
  const std::vector<double> precisions = args.quick ? std::vector<double>{1, 0.5} : std::vector<double>{1, 0.5, 0.1, 0.05};
  const double finest = precisions.back();

  CsvWriter stats(dir + "/gap_statistics.csv", {"subject",
                                                "generated",
                                                "scheme",
                                                "resolution",
                                                "precision_deg",
                                                "mode",
                                                "scan",
                                                "cor_ras_x_mm",
                                                "cor_ras_y_mm",
                                                "cor_ras_z_mm",
                                                "head_radius_mm",
                                                "sphere_fit_rms_mm",
                                                "cor_error_mm",
                                                "vertices",
                                                "vertices_tested",
                                                "vertices_no_surface",
                                                "vertices_beyond_reach",
                                                "min_gap_mm",
                                                "vertices_penetrating",
                                                "area_penetrating_mm2",
                                                "level_none",
                                                "level_yellow",
                                                "level_orange",
                                                "level_red",
                                                "level_purple",
                                                "map_nodes",
                                                "map_nodes_covered",
                                                "map_bytes",
                                                "sampling_ms",
                                                "detection_ms",
                                                "detection_ns_per_lookup",
                                                "linear_vs_exact_p95_abs_mm",
                                                "vs_equiangular_p95_abs_mm",
                                                "vs_equiangular_max_abs_mm",
                                                "vs_equiangular_compared"});
  CsvWriter map_images(dir + "/map_images.csv",
                       {"subject", "body", "scheme", "resolution", "file", "nearest_mm", "farthest_mm"});
  CsvWriter vertices(dir + "/vertex_gaps.csv", {"subject", "scan", "vertex", "x_mm", "y_mm", "z_mm", "gap_mm"});

  const auto others = static_cast<int>(scheme_names().size()) - 2;  // registered beyond the thesis' two
  const auto coarse = std::count_if(precisions.begin(), precisions.end(), [](double p) { return p >= 0.1; });
  const int total = static_cast<int>(subjects.size()) * (static_cast<int>(precisions.size()) * 4 + static_cast<int>(coarse) * others);
  auto abs_diff = [](const std::vector<float>& a, const std::vector<float>& b) {
    std::vector<double> d;
    for (std::size_t i = 0; i < a.size() && i < b.size(); ++i)
      if (std::isfinite(a[i]) && std::isfinite(b[i])) d.push_back(std::abs(double(a[i]) - b[i]));
    std::sort(d.begin(), d.end());
    return d;
  };
  auto quantile = [](const std::vector<double>& d, double q) {
    return d.empty() ? std::nan("") : d[static_cast<std::size_t>(q * double(d.size() - 1))];
  };
  int done = 0;
  for (const Subject& s : subjects) {
    const SphereFitResult fit = fit_femoral_head(s.femur);
    const double cor_error = s.generated ? (fit.centre - s.true_cor).norm() : std::nan("");
    for (double p : precisions) {
      std::map<DistanceMode, std::vector<float>> rsid_ball;  // equiangular ball gaps per mode
      const double k = matched_helix_turns(p);
      std::vector<std::shared_ptr<const SamplingScheme>> schemes{make_scheme("equiangular", p), make_scheme("helix", k)};
      // Every other registered scheme (issue 12: without touching this driver), exact mode, at the
      // coarsest resolution whose node spacing is at most p, for p >= 0.1 deg.
      if (p >= 0.1)
        for (const auto& [name, unit] : scheme_names()) {
          (void)unit;
          if (name == "equiangular" || name == "helix") continue;
          try {
            schemes.push_back(make_scheme(name, resolution_for_spacing(name, p)));
          } catch (const Error&) {
            // a resolution this scheme does not take at this spacing (e.g. conchoid needs 90/p integral)
          }
        }
      for (const auto& scheme : schemes) {
        const bool helix = scheme->name() != "equiangular";  // compared with the equiangular gaps below
        const bool thesis_scheme = scheme->name() == "equiangular" || scheme->name() == "helix";
        std::vector<float> exact_ball;  // exact-mode gaps, for the linear-vs-exact difference
        for (DistanceMode mode : {DistanceMode::exact, DistanceMode::linear}) {
          if (!thesis_scheme && mode == DistanceMode::linear) continue;
          progress("08_distance_maps", ++done, total,
                   s.name + " " + scheme->name() + " " + std::to_string(scheme->resolution()) + " " + to_string(mode));
          JointOptions o;
          o.scheme = scheme;
          o.mode = mode;
          const Joint joint(s.femur, s.pelvis, fit.centre, o);
          const PoseResult res = joint.detect(Eigen::Matrix3d::Identity());
          // Timings: rasterisation of each body and each scan, medians.
          const int reps = p <= 0.05 ? std::max(1, args.repetitions / 2) : args.repetitions;
          double sample_ms[2], detect_ms[2];
          const JointBody* bodies[2] = {&joint.ball(), &joint.socket()};
          for (int b = 0; b < 2; ++b) {
            RadialDistanceMap scratch{scheme};
            SamplingOptions so;
            so.mode = mode;
            sample_ms[b] = median_ms(
                [&] {
                  std::fill(scratch.data(), scratch.data() + scratch.num_nodes(), RadialDistanceMap::no_surface());
                  sample_surface(bodies[b]->mesh, fit.centre, so, scratch);
                },
                reps);
          }
          ScanGaps scratch_gaps;
          detect_ms[0] = median_ms(
              [&] {
                scan_gaps(joint.ball().relative, Eigen::Matrix3d::Identity(), joint.ball().mask, joint.socket().map,
                          ScanSide::inside, scratch_gaps);
              },
              args.repetitions);
          detect_ms[1] = median_ms(
              [&] {
                scan_gaps(joint.socket().relative, Eigen::Matrix3d::Identity(), joint.socket().mask, joint.ball().map,
                          ScanSide::outside, scratch_gaps);
              },
              args.repetitions);
          double p95 = std::nan(""), vs_p95 = std::nan(""), vs_max = std::nan("");
          std::int64_t vs_n = 0;
          if (mode == DistanceMode::exact)
            exact_ball = res.ball_gaps.gap_mm;
          else
            p95 = quantile(abs_diff(exact_ball, res.ball_gaps.gap_mm), 0.95);
          if (!helix) {
            rsid_ball[mode] = res.ball_gaps.gap_mm;
          } else {
            const std::vector<double> d = abs_diff(rsid_ball[mode], res.ball_gaps.gap_mm);
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
            const double ns = lookups > 0 ? detect_ms[b] * 1e6 / double(lookups) : std::nan("");
            stats.row(s.name, int(s.generated), scheme->name(), scheme->resolution(), p, to_string(mode),
                      b == 0 ? "ball" : "socket", fit.centre.x(), fit.centre.y(), fit.centre.z(), fit.radius,
                      fit.rms_residual, cor_error, sm.vertices, sm.vertices_tested, sm.vertices_no_surface,
                      sm.vertices_beyond_reach, sm.min_gap_mm, sm.vertices_penetrating, sm.area_penetrating_mm2,
                      sm.level_vertices[0], sm.level_vertices[1], sm.level_vertices[2], sm.level_vertices[3],
                      sm.level_vertices[4], body.map.num_nodes(), body.sampling.nodes_covered,
                      std::int64_t(body.map.bytes()), sample_ms[b], detect_ms[b], ns, b == 0 ? p95 : std::nan(""),
                      b == 0 ? vs_p95 : std::nan(""), b == 0 ? vs_max : std::nan(""), b == 0 ? vs_n : std::int64_t(0));
          }
          if (p == 0.5 && mode == DistanceMode::exact) {
            const std::string suffix = helix ? "_" + scheme->name() + ".png" : ".png";
            for (int b = 0; b < 2; ++b) {
              const std::string body = b == 0 ? "ball" : "socket";
              const std::string file = "map_" + s.name + "_" + body + suffix;
              const MapImageScale sc = write_map_png(dir + "/" + file, b == 0 ? joint.ball().map : joint.socket().map);
              map_images.row(s.name, body, scheme->name(), scheme->resolution(), file, sc.nearest_mm, sc.farthest_mm);
            }
          }
          if (p == finest && mode == DistanceMode::exact && !helix) {
            const ScanGaps* gaps[2] = {&res.ball_gaps, &res.socket_gaps};
            for (int b = 0; b < 2; ++b)
              for (Eigen::Index i = 0; i < bodies[b]->relative.rows(); ++i) {
                if (bodies[b]->relative.row(i).norm() > 45) continue;
                const Eigen::Vector3d v = bodies[b]->mesh.V.row(i).transpose();
                vertices.row(s.name, b == 0 ? "ball" : "socket", std::int64_t(i), v.x(), v.y(), v.z(),
                             double(gaps[b]->gap_mm[static_cast<std::size_t>(i)]));
              }
          }
        }
      }
    }
  }
  // Shaded-render data: the hip region of both bones at the scan pose, in the pelvic frame.
  CsvWriter clocks(dir + "/clock_faces.csv",
                   {"subject", "side", "neutral", "centre_x_mm", "centre_y_mm", "centre_z_mm", "twelve_x", "twelve_y",
                    "twelve_z", "three_x", "three_y", "three_z", "rim_radius_mm", "rim_plane_rms_mm", "inclination_deg",
                    "anteversion_deg", "head_radius_mm", "acetabular_radius_mm", "scan_flexion_deg",
                    "scan_adduction_deg", "scan_internal_rotation_deg"});
  const double render_precision = 0.25, render_radius = 60;
  CsvWriter poses(dir + "/poses.csv", {"pose", "flexion_deg", "adduction_deg", "internal_rotation_deg"});
  const std::vector<std::pair<std::string, PoseAngles>> figure_poses{
      {"neutral", {0, 0, 0}}, {"flexion90", {90, 0, 0}}, {"adduction30", {0, 30, 0}}, {"internal30", {0, 0, 30}}};
  bool wrote_poses = false;
  for (const Subject& s : subjects) {
    MapSettings maps;
    maps.precision = render_precision;
    maps.mode = "exact";
    const Session session(session_options(s, maps));  // as the CLI sets a subject up
    const HipJoint& hip = session.hip();
    const HipJointOptions& ho = session.hip_options();
    const PoseResult res = hip.joint().detect(Eigen::Matrix3d::Identity());
    // Joint frame -> pelvic frame: p_pelvic = S^T p_joint (S = scan_axes()).
    const Eigen::Matrix3d to_pelvic = scan_axes().transpose();
    const JointBody* bodies[2] = {&hip.joint().ball(), &hip.joint().socket()};
    const ScanGaps* gaps[2] = {&res.ball_gaps, &res.socket_gaps};
    for (int b = 0; b < 2; ++b)
      write_region_ply(dir + "/render_" + s.name + (b == 0 ? "_ball.ply" : "_socket.ply"), *bodies[b], to_pelvic,
                   render_radius, gaps[b], ho.joint.levels, b == 0);
    if (!s.generated && !wrote_poses) {  // the README's figure of the clinical angles
      wrote_poses = true;
      for (const auto& [name, a] : figure_poses) {
        write_region_ply(dir + "/poses_" + s.name + "_" + name + ".ply", hip.joint().ball(),
                     to_pelvic * hip.femur_rotation(a), 250, nullptr, ho.joint.levels, true);
        poses.row(name, a.flexion_deg, a.adduction_deg, a.internal_rotation_deg);
      }
      write_region_ply(dir + "/poses_" + s.name + "_pelvis.ply", hip.joint().socket(), to_pelvic, 150, nullptr,
                   ho.joint.levels, false);
    }
    if (hip.socket_clock()) {
      const ClockFace c = hip.socket_clock()->transformed(to_pelvic, Eigen::Vector3d::Zero());
      const Acetabulum& A = *hip.acetabulum();
      const AcetabularOrientation orientation = radiographic_orientation(A, hip.frames()->pelvis, s.side);
      const PoseAngles& sp = hip.frames()->scan_pose;
      clocks.row(s.name, s.side == Side::right ? "right" : "left", "anatomical", c.centre.x(), c.centre.y(),
                 c.centre.z(), c.twelve.x(), c.twelve.y(), c.twelve.z(), c.three.x(), c.three.y(), c.three.z(),
                 A.rim_radius_mm, A.rim_plane_rms_mm, orientation.inclination_deg,
                 orientation.anteversion_deg, hip.head_radius_mm(), A.sphere.radius,
                 sp.flexion_deg, sp.adduction_deg, sp.internal_rotation_deg);
    } else {
      const double nan = std::nan("");
      clocks.row(s.name, s.side == Side::right ? "right" : "left", "scan", nan, nan, nan, nan, nan, nan, nan, nan,
                 nan, nan, nan, nan, nan, hip.head_radius_mm(), nan, 0.0, 0.0, 0.0);
    }
  }

  nlohmann::json subj = nlohmann::json::array();
  for (const Subject& s : subjects) subj.push_back({{"name", s.name}, {"source", s.source}});
  write_meta(dir, args,
             {{"precisions_deg", precisions},
              {"helix_turns", "round(720 / (pi p)) for each precision p"},
              {"modes", {"exact", "linear"}},
              {"pose_deg", {0, 0, 0}},
              {"subjects", subj},
              {"cor", "fit_femoral_head defaults (RANSAC + geometric sphere fit)"},
              {"vertex_gaps_region_mm", 45},
              {"render", {{"precision_deg", render_precision}, {"mode", "exact"}, {"region_mm", render_radius},
                          {"frame", "pelvic (ISB, Wu et al. 2002) for real subjects; scan axes for generated"},
                          {"pose", "scan pose"}}},
              {"occlusion_tolerance_mm", JointOptions{}.occlusion_tolerance_mm},
              {"levels_thresholds_mm", ImpingementLevels{}.thresholds_mm}});
  return 0;
}
