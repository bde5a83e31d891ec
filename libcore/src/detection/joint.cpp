#include "impinge/detection/joint.hpp"
#include "impinge/core/concurrent.hpp"

#include <omp.h>

#include <chrono>
#include <cmath>
#include <exception>
#include <future>

#include "impinge/core/error.hpp"
#include "impinge/core/timing.hpp"
#include "impinge/maps/depth_discontinuity.hpp"
#include "impinge/sampling/layered_sampling.hpp"

namespace impinge {

namespace {
const JointOptions& checked(const JointOptions& o, const Eigen::Vector3d& cor) {
  o.validate();
  // What this build can do (the options themselves are valid: a session that builds no joint, impinge morphology,
  // checks them without these).
  require(o.layers == 0 || FirstHitCaster::available(),
          "joint: layered maps need a ray caster (Embree or CGAL), and this build has neither");
  require(!o.distances || SignedDistanceQuery::available(),
          "joint: distances need a closest-point engine (Embree or CGAL), and this build has neither");
  require(cor.allFinite(), "joint: centre of rotation is not finite");
  return o;
}
}  // namespace

void JointOptions::validate() const {
  require(scheme != nullptr, "JointOptions::scheme: no sampling scheme given");
  check_in_range("JointOptions::occlusion_tolerance_mm", occlusion_tolerance_mm, kOcclusionToleranceRange, "mm");
  if (max_radius_mm != kInf) check_in_range("JointOptions::max_radius_mm", max_radius_mm, kMaxRadiusRange, "mm");
  if (sparse_maps) check_in_range("JointOptions::sparse_region_mm", sparse_region_mm, kSparseRegionRange, "mm");
  if (exact_at_discontinuities)
    check_in_range("JointOptions::discontinuity_tolerance_mm", discontinuity_tolerance_mm, kDiscontinuityToleranceRange,
                   "mm");
  check_in_range("JointOptions::layers", layers, kLayersRange);
  check_in_range("JointOptions::extra_articular_radius_mm", extra_articular_radius_mm, kExtraArticularRadiusRange,
                 "mm");
  check_in_range("JointOptions::layered_spacing_deg", layered_spacing_deg, kLayeredSpacingRange, "deg");
  levels.validate();
  check_in_range("JointOptions::distance_reach_mm", distance_reach_mm, kDistanceReachRange, "mm");
  const LevelQuantity q = level_quantity();
  require(q == LevelQuantity::radial_gap || distances,
          "levels-on distance (levels_on): needs the distances on (--distances on, distances=True)");
  require(q == LevelQuantity::radial_gap || reach_mm() >= levels.thresholds_mm.front(), [&] {
    return "levels-on distance (levels_on): the distance reach (--distance-reach, distance_reach_mm) " +
           shortest_decimal(reach_mm()) +
           " mm is below the largest level threshold (" + shortest_decimal(levels.thresholds_mm.front()) + " mm)";
  });
}

Joint::Joint(TriangleMesh ball, TriangleMesh socket, const Eigen::Vector3d& cor, const JointOptions& options)
    : Joint(cor, options, build_bodies(cor, options, std::move(ball), std::move(socket), std::nullopt, std::nullopt)) {}

Joint::Joint(TriangleMesh ball, TriangleMesh socket, const Eigen::Vector3d& cor, const JointOptions& options,
             RadialDistanceMap ball_map, RadialDistanceMap socket_map)
    : Joint(
          cor, options,
          build_bodies(cor, options, std::move(ball), std::move(socket), std::move(ball_map), std::move(socket_map))) {}

Joint::Joint(const Eigen::Vector3d& cor, const JointOptions& options, std::pair<JointBody, JointBody> bodies)
    : cor_(cor), options_(options), ball_(std::move(bodies.first)), socket_(std::move(bodies.second)) {}

namespace {
/// What one body's build parts hand on to its later ones (add_parts).
struct BuildParts {
  std::optional<RadialDistanceMap> given;  ///< the map given instead of sampled
  double marking_ms = 0, caster_ms = 0;    ///< the marks' and the ray caster's build times, ms
};

// A body's first part: its mesh checked, its vertices about the COR (b.relative: n x 3, mm), a given map
// (p.given) checked against the joint's scheme. Throws impinge::Error naming the mesh.
void prepare_body(JointBody& b, const BuildParts& p, const Eigen::Vector3d& cor, const JointOptions& options) {
  validate_mesh(b.mesh);
  b.relative = b.mesh.V.rowwise() - cor.transpose();
  if (!p.given) return;
  const SamplingScheme& want = *options.scheme;
  const SamplingScheme& have = p.given->scheme();
  require(want.conformable(have), b.mesh.source + ": the given map is " + have.name() + " at " +
                                      std::to_string(have.resolution()) + ", the joint's scheme is " +
                                      want.name() + " at " + std::to_string(want.resolution()));
}

// A body's map (sampled about the COR, with its time b.sampling_ms; or the given one, moved from p.given) and
// its depth-discontinuity marks when exact (their time p.marking_ms, ms; else any marks cleared).
void sample_map(JointBody& b, BuildParts& p, const Eigen::Vector3d& cor, const JointOptions& options, bool exact) {
  if (p.given) {
    b.map = std::move(*p.given);
    b.sampling.nodes_covered = b.map.nodes_covered();
  } else {
    SamplingOptions so;
    so.mode = options.mode;
    so.method = options.sampling;
    const auto t0 = std::chrono::steady_clock::now();
    b.sampling = sample_surface(b.mesh, cor, so, b.map);
    b.sampling_ms = ms_since(t0);
  }
  if (exact) {
    const auto t0 = std::chrono::steady_clock::now();
    b.nodes_marked = mark_depth_discontinuities(b.map, options.discontinuity_tolerance_mm);
    p.marking_ms = ms_since(t0);
  } else {
    clear_depth_discontinuities(b.map);  // a given map may carry marks
  }
}

// A body's ray caster about the COR (its hierarchy built as `tree` says): b.exact when exact (its build time
// p.caster_ms, ms), b.caster when layers > 0.
void build_caster(JointBody& b, BuildParts& p, const Eigen::Vector3d& cor, const JointOptions& options, bool exact,
                  HierarchyBuild tree) {
  const auto t0 = std::chrono::steady_clock::now();
  auto c = std::make_shared<const FirstHitCaster>(b.mesh, cor, tree);
  if (exact) {
    b.exact = c;
    p.caster_ms = ms_since(t0);
  }
  if (options.layers > 0) b.caster = std::move(c);
}

// A body's layered map (options.layers layers over layered_scheme), filled by its ray caster b.caster.
void build_layered_map(JointBody& b, const JointOptions& options,
                       const std::shared_ptr<const SamplingScheme>& layered_scheme) {
  auto layered = std::make_shared<LayeredMap>(layered_scheme, options.layers);
  b.layered_sampling = sample_layered_map(*layered, *b.caster);
  b.layered = std::move(layered);
}

// With layers > 0: a body's hidden vertices (not on the first surface, within the extra-articular radius and
// max_radius_mm of the COR) as b.hidden_set, in boxes of 32, and their clusters of 32 (b.hidden_clusters).
void hidden_vertices(JointBody& b, const JointOptions& options) {
  std::vector<std::uint8_t> hidden(b.mask.size(), 0);
  for (std::size_t i = 0; i < hidden.size(); ++i) {
    const double r = b.relative.row(static_cast<Eigen::Index>(i)).norm();
    // max_radius_mm bounds every vertex tested, the hidden ones too.
    hidden[i] = !b.mask[i] && r > 0 && r <= std::min(options.extra_articular_radius_mm, options.max_radius_mm);
  }
  // In boxes of 32 (order_in_boxes), each run of the clusters below compact in space.
  b.hidden_set = order_in_boxes(make_scan_set(b.relative, hidden), {32});
  b.hidden_clusters = cluster_scan_set(b.hidden_set, 32);
}

// A body's first-surface mask (b.mask: n, 1 on the first surface; through the exact caster when exact) and scan
// set, the map made sparse after the mask has read it, and with layers > 0 the hidden vertices (hidden_vertices).
// b.marking_ms: the marks' and the caster's times together (ms).
void mask_and_scan_sets(JointBody& b, const BuildParts& p, const JointOptions& options, bool exact) {
  b.marking_ms = p.marking_ms + p.caster_ms;
  b.mask = exact ? first_surface_mask(b.relative, b.map, options.occlusion_tolerance_mm, options.max_radius_mm,
                                      *b.exact)
                 : first_surface_mask(b.relative, b.map, options.occlusion_tolerance_mm, options.max_radius_mm);
  if (options.sparse_maps) b.map.make_sparse(options.sparse_region_mm);
  b.scan_set = make_scan_set(b.relative, b.mask);
  if (options.layers == 0) return;
  hidden_vertices(b, options);
}

// A body's vertex areas (b.vertex_area: n, mm^2) and, with distances, its distance scan set (the vertices within
// max_radius_mm of the COR).
void areas_and_distance_set(JointBody& b, const JointOptions& options) {
  b.vertex_area = vertex_areas(b.mesh);
  if (options.distances) b.distance_set = make_distance_scan_set(b.relative, options.max_radius_mm);
}

/// The parts of building both bodies (ball, socket), for run_task_graph: each body's checks, map and marks,
/// ray caster, layered map, first-surface mask and scan sets, closest-point hierarchy, and vertex areas with
/// distance scan set; the socket's before the ball's, the long parts first. The bodies and parts must outlive
/// the run.
void add_parts(const Eigen::Vector3d& cor, const JointOptions& options,
               const std::shared_ptr<const SamplingScheme>& layered_scheme, JointBody& ball,
               std::optional<RadialDistanceMap> ball_map, BuildParts& ball_parts, JointBody& socket,
               std::optional<RadialDistanceMap> socket_map, BuildParts& socket_parts,
               std::vector<GraphTask>& tasks) {
  JointBody* body[2] = {&ball, &socket};
  BuildParts* parts[2] = {&ball_parts, &socket_parts};
  parts[0]->given = std::move(ball_map);
  parts[1]->given = std::move(socket_map);
  const bool exact = options.exact_at_discontinuities && FirstHitCaster::available();
  // A few poses (no layered maps: the direct set-up) cast few rays: the casters' trees are built fast (Morton)
  // rather than well (SAH); the same hits either way.
  const HierarchyBuild tree = options.layered_maps ? HierarchyBuild::quality : HierarchyBuild::fast;
  auto add = [&](std::function<void()> run, std::vector<std::size_t> after, int rank) {
    tasks.push_back({std::move(run), std::move(after), rank});
    return tasks.size() - 1;
  };
  constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  std::size_t prepare[2], sample[2], caster[2] = {kNone, kNone};
  // The mesh checked, its vertices about the COR, a given map checked against the scheme.
  for (int k = 0; k < 2; ++k) {
    JointBody& b = *body[k];
    BuildParts& p = *parts[k];
    prepare[k] = add([&b, &p, &cor, &options] { prepare_body(b, p, cor, options); }, {}, k);
  }
  for (int k = 1; k >= 0; --k) {  // the socket's first
    JointBody& b = *body[k];
    BuildParts& p = *parts[k];
    // The map (sampled, or the given one) and its depth-discontinuity marks.
    sample[k] = add([&b, &p, &cor, &options, exact] { sample_map(b, p, cor, options, exact); }, {prepare[k]}, k);
    // The ray caster: exact look-ups at the marks, the layered maps, the hidden vertices' casts.
    if (exact || options.layers > 0)
      caster[k] = add([&b, &p, &cor, &options, exact, tree] { build_caster(b, p, cor, options, exact, tree); },
                      {prepare[k]}, k);
  }
  if (options.layers > 0 && options.layered_maps)
    for (int k = 1; k >= 0; --k) {
      JointBody& b = *body[k];
      add([&b, &options, layered_scheme] { build_layered_map(b, options, layered_scheme); }, {caster[k]}, k);
    }
  for (int k = 1; k >= 0; --k) {
    JointBody& b = *body[k];
    BuildParts& p = *parts[k];
    // The first-surface mask and the scan sets (the map made sparse after the mask has read it).
    std::vector<std::size_t> after{sample[k]};
    if (caster[k] != kNone) after.push_back(caster[k]);
    add([&b, &p, &options, exact] { mask_and_scan_sets(b, p, options, exact); }, std::move(after), k);
  }
  // The closest-point hierarchy needs the mesh alone (a one-pose joint builds it later, cropped:
  // crop_distance_queries).
  if (options.needs_distance_queries() && !options.cropped_distance_queries)
    for (int k = 1; k >= 0; --k) {
      JointBody& b = *body[k];
      add([&b] { b.distance_query = std::make_shared<const SignedDistanceQuery>(b.mesh); }, {prepare[k]}, k);
    }
  for (int k = 1; k >= 0; --k) {
    JointBody& b = *body[k];
    add([&b, &options] { areas_and_distance_set(b, options); }, {prepare[k]}, k);
  }
}
}  // namespace

std::pair<JointBody, JointBody> Joint::build_bodies(const Eigen::Vector3d& cor, const JointOptions& options,
                                                    TriangleMesh ball, TriangleMesh socket,
                                                    std::optional<RadialDistanceMap> ball_map,
                                                    std::optional<RadialDistanceMap> socket_map) {
  checked(options, cor);
  // The two bodies are built as their parts (add_parts), on two threads: a free thread takes the first part in
  // the list that is ready. The socket's parts come first (the pelvis is the larger mesh), and a body's own
  // parts run as soon as the core the other leaves idle can take them (lhdl-ct subdivided 4x, one pose: the
  // ball's chain ended some 100 ms before the socket's when each body was built on a thread of its own). Each
  // part writes its own members of its body, so the bodies are the same whichever thread builds which part. A
  // failure is rethrown after the running parts have ended: the ball's before the socket's (error_rank).
  JointBody b(std::move(ball), options.scheme), s(std::move(socket), options.scheme);
  BuildParts pb, ps;
  std::vector<GraphTask> tasks;
  add_parts(cor, options, layered_scheme(options), b, std::move(ball_map), pb, s, std::move(socket_map), ps, tasks);
  run_task_graph(tasks);
  return {std::move(b), std::move(s)};
}

std::shared_ptr<const SamplingScheme> Joint::layered_scheme() const { return layered_scheme(options_); }

std::shared_ptr<const SamplingScheme> Joint::layered_scheme(const JointOptions& options) {
  const auto& s = options.scheme;
  const double want = options.layered_spacing_deg;
  if (want <= 0 || s->max_node_spacing() * 180 / M_PI >= want) return s;
  return make_scheme(s->name(), resolution_for_spacing(s->name(), want));
}

void Joint::crop_distance_queries(const std::vector<std::pair<Eigen::Matrix3d, Eigen::Vector3d>>& poses) {
  if (!options_.needs_distance_queries()) return;  // no distance hierarchy to build
  for (std::size_t i = 0; i < poses.size(); ++i)
    require(poses[i].first.allFinite() && poses[i].second.allFinite(),
            "crop distance queries: pose " + std::to_string(i) + " is not finite");
  const double reach = options_.reach_mm();
  // The balls `own`'s searches reach at pose (Rq, tq), in the other body's frame: those of scan_distances (its
  // clusters grown by the reach, which hold its vertices' balls of the reach) and of the layered scans' pruning
  // (cluster_apart).
  auto region = [&](const JointBody& own, const Eigen::Matrix3d& Rq, const Eigen::Vector3d& tq,
                    std::vector<Eigen::Vector4d>& out) {
    const Eigen::Vector3d shift = cor_ + tq;
    auto add = [&](const Eigen::Vector3d& c, double r) { out.emplace_back(c.x(), c.y(), c.z(), r); };
    const DistanceScanSet& d = own.distance_set;
    for (std::size_t c = 0; c < d.centre.size(); ++c) add(Rq * d.centre[c] + shift, d.radius[c] + reach);
    const ScanClusters& h = own.hidden_clusters;
    for (std::size_t c = 0; c < h.centre.size(); ++c) add(Rq * h.centre[c] + shift, h.radius[c] + reach);
  };
  std::vector<Eigen::Vector4d> near_socket, near_ball;  // the ball's searches reach the socket, and back
  for (const auto& [R, t] : poses) {
    region(ball_, R, t, near_socket);
    const Eigen::Matrix3d Rt = R.transpose();
    region(socket_, Rt, -(Rt * t), near_ball);
  }
  run_both([&] { ball_.distance_query = std::make_shared<const SignedDistanceQuery>(ball_.mesh, near_ball); },
           [&] { socket_.distance_query = std::make_shared<const SignedDistanceQuery>(socket_.mesh, near_socket); });
}

PoseResult Joint::detect(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) const {
  PoseResult res;
  detect(R, t, res);
  return res;
}

void Joint::detect(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, PoseResult& res) const {
  detect(R, t, res, nullptr);
}

namespace {
// One body's signed distances at a pose into `out` (distance_mm, the undecided signs and the counts): scan_distances.
void measure_distances(const DistanceScanSet& set, const Eigen::Matrix3d& Rq, const Eigen::Vector3d& tq,
                       const Eigen::Vector3d& cor, const SignedDistanceQuery& other, double reach_mm,
                       DistanceScanMemory* mem, ScanGaps& out) {
  const DistanceScanStats ds =
      scan_distances(set, Rq, tq, cor, other, reach_mm, out.gap_mm, out.distance_mm, mem, &out.distance_sign_undecided);
  out.distance_winding = ds.winding;
  out.distance_undecided = ds.undecided;
}
}  // namespace

void Joint::detect(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, PoseResult& res, DetectionMemory* memory) const {
  require(!options_.needs_distance_queries() || (ball_.distance_query && socket_.distance_query),
          "joint: cropped_distance_queries is on and crop_distance_queries was not called before detect");
  // The ball's scans (its vertices against the socket's maps and surface) and the socket's (in the ball's frame:
  // R^T (p - t)) share nothing but the pose: on their own threads when this call is not already on one of
  // several (a motion's or a ROM search's frames are), each with its own scratch. Same results either way.
  const Eigen::Matrix3d Rt = R.transpose();
  const Eigen::Vector3d tt = -(Rt * t);
  // One body's scans: its first-surface vertices against the other's map, its hidden ones against the other's
  // layered map (or exact casts without one), then its distances to the other's surface. The pose (Rq, tq) takes
  // this body's vertices into the other's frame.
  auto scans = [&](const JointBody& own, const JointBody& other, const Eigen::Matrix3d& Rq, const Eigen::Vector3d& tq,
                   ScanSide side, ScanGaps& out, ScanSummary& summary, std::vector<float>& gaps,
                   DistanceScanMemory* mem, double& detection_ms, double& distance_ms) {
    gaps.resize(static_cast<std::size_t>(std::max(own.scan_set.size(), own.hidden_set.size())));
    auto t0 = std::chrono::steady_clock::now();
    const std::int64_t refined =
        scan_gaps_compact(own.scan_set, Rq, tq, other.map, side, gaps.data(), other.exact.get());
    expand_scan(own.scan_set, gaps.data(), out);  // resets the scan's counts
    out.refined = refined;
    if (other.layered) {
      out.refined += scan_layered_near(own.hidden_set, own.hidden_clusters, Rq, tq, *other.layered, cor_,
                                       *other.distance_query, options_.reach_mm(), gaps.data(), other.caster.get())
                         .refined;
      expand_layered_scan(own.hidden_set, gaps.data(), out);
    } else if (options_.layers > 0 && other.caster) {  // no layered maps: exact casts (layered_maps off)
      out.refined += scan_layered_near_exact(own.hidden_set, own.hidden_clusters, Rq, tq, *other.caster, cor_,
                                             *other.distance_query, options_.reach_mm(), gaps.data())
                         .refined;
      expand_layered_scan(own.hidden_set, gaps.data(), out);
    }
    detection_ms = ms_since(t0);
    distance_ms = 0;
    if (options_.distances) {
      t0 = std::chrono::steady_clock::now();
      measure_distances(own.distance_set, Rq, tq, cor_, *other.distance_query, options_.reach_mm(), mem, out);
      distance_ms = ms_since(t0);
    } else {
      out.distance_mm.clear();
      out.distance_sign_undecided.clear();
      out.distance_winding = out.distance_undecided = 0;
    }
    // On the body's own thread too: a pass over all its vertices (some 0.07 ms per body on lhdl-ct).
    summarize_scan(out, own.vertex_area, options_.levels, summary, options_.level_quantity());
  };
  auto ball_scans = [&] {
    scans(ball_, socket_, R, t, ScanSide::inside, res.ball_gaps, res.ball, res.compact_gaps,
          memory != nullptr ? &memory->ball : nullptr, res.ball_detection_ms, res.ball_distance_ms);
  };
  auto socket_scans = [&] {
    scans(socket_, ball_, Rt, tt, ScanSide::outside, res.socket_gaps, res.socket, res.compact_gaps_socket,
          memory != nullptr ? &memory->socket : nullptr, res.socket_detection_ms, res.socket_distance_ms);
  };
  const bool two_threads = !omp_in_parallel() && omp_get_max_threads() > 1;
  if (two_threads && options_.cropped_distance_queries) {
    // A one-pose joint (cropped hierarchies) detects once or twice: a plain second thread, which ends with the
    // scans. An OpenMP team's worker would spin-wait for the next region after them (libgomp's default), taking
    // a core from the output that follows (lhdl-ct, one pose: some 10 ms of CPU and 4-5 ms of the whole run).
    run_both(ball_scans, socket_scans);
  } else if (two_threads) {
    // Many poses (a motion, a ROM search): the team's threads stay warm from one pose to the next.
    std::exception_ptr error[2];
#pragma omp parallel num_threads(2)
    {
      const int k = omp_get_thread_num();
      try {
        if (k == 0) ball_scans();
        if (k == 1 || omp_get_num_threads() == 1) socket_scans();
      } catch (...) {
        error[k] = std::current_exception();
      }
    }
    for (const std::exception_ptr& e : error)
      if (e) std::rethrow_exception(e);
  } else {
    ball_scans();
    socket_scans();
  }
}

}  // namespace impinge
