#include "impinge/session/session.hpp"
#include "impinge/core/concurrent.hpp"

#include "impinge/session/option_table.hpp"

#include <unistd.h>

#include <cmath>
#include <exception>
#include <tuple>
#include <limits>
#include <new>
#include <sstream>

#include "impinge/anatomy/femur_frame.hpp"
#include "impinge/anatomy/pelvis_frame.hpp"
#include "impinge/core/error.hpp"
#include "impinge/core/parse.hpp"
#include "impinge/detection/impingement_levels.hpp"
#include "impinge/io/mesh_io.hpp"
#include "impinge/maps/layered_map.hpp"
#include "impinge/sampling/rasterize.hpp"
#include "impinge/sampling/sampling.hpp"
#include "impinge/schemes/sampling_scheme.hpp"

namespace impinge {

namespace {
std::string num(double x) { return number_text(x); }
std::string point_text(const Eigen::Vector3d& p) {
  return "(" + num(p.x()) + ", " + num(p.y()) + ", " + num(p.z()) + ")";
}
}  // namespace

// Both parse through the option table's rows, the one parser of --cor and --head-region.
std::optional<Eigen::Vector3d> parse_cor(const std::string& text, const std::string& context) {
  RunOptions o;
  const OptionRow& row = *find_option("cor");
  row.set(o, parse_option_text(row, text, context), context);
  return o.session.cor.given;
}

Eigen::Vector4d parse_head_region(const std::string& text, const std::string& context) {
  RunOptions o;
  const OptionRow& row = *find_option("head-region");
  row.set(o, parse_option_text(row, text, context), context);
  return *o.session.cor.head_region;
}

namespace {
// The side: the subject's, or the given one; both must agree.
Side checked_side(const SessionInput& input, const std::optional<Side>& subject_side) {
  if (input.side.empty()) return subject_side.value_or(Side::right);
  const Side s = parse_side(input.side, "side");
  require(!subject_side || *subject_side == s,
          "side '" + input.side + "' contradicts " + input.subject + " (its \"side\" is " +
              (*subject_side == Side::right ? "right" : "left") + ")");
  return s;
}

// The frame: the subject's (subject_frame), or the given one (input.frame, LPS or RAS; default RAS); both must agree.
FrameConvention checked_frame(const SessionInput& input, const std::optional<FrameConvention>& subject_frame) {
  FrameConvention frame = subject_frame.value_or(FrameConvention::RAS);
  if (!input.frame.empty()) {
    const FrameConvention f = parse_frame(input.frame, "frame");
    require(!subject_frame || *subject_frame == f,
            "frame '" + input.frame + "' contradicts " + input.subject + " (its \"frame\" is " +
                (*subject_frame == FrameConvention::LPS ? "LPS" : "RAS") + ")");
    frame = f;
  }
  return frame;
}

// A bone from memory (`mesh`) or from its file (`path`) into `out`, and what to call it in messages (`source`:
// the path, the mesh's own source, or `name` "(in memory)").
void take_bone(const std::optional<TriangleMesh>& mesh, const std::string& path, const char* name, TriangleMesh& out,
               std::string& source) {
  out = mesh ? *mesh : load_mesh(path);
  source = !mesh ? path : out.source.empty() ? std::string(name) + " (in memory)" : out.source;
}

// Both bones into `in` (femur, pelvis and their sources): from input's meshes or the files `ball` and `socket`
// (the subject's when not given), checked to be given once each and to be two different meshes.
void read_bones(const SessionInput& input, const std::string& ball, const std::string& socket, LoadedInput& in) {
  require(input.ball_mesh || !ball.empty(), "no femur: give ball (a mesh file or mesh) or subject");
  require(input.ball_mesh || input.socket_mesh || ball.empty() || ball != socket,
          "ball and socket are the same file (" + ball + "): give the femur and the pelvis");
  require(input.socket_mesh || !socket.empty(), "no pelvis: give socket (a mesh file or mesh) or subject");
  require(!(input.ball_mesh && !input.ball.empty()), "give ball as a file or a mesh, not both");
  require(!(input.socket_mesh && !input.socket.empty()), "give socket as a file or a mesh, not both");
  // The two files are read at once (the pelvis on a second thread); the femur's error first, as before.
  run_both([&] { take_bone(input.ball_mesh, ball, "ball", in.femur, in.femur_source); },
           [&] { take_bone(input.socket_mesh, socket, "socket", in.pelvis, in.pelvis_source); });
  require(!(in.femur.V.rows() == in.pelvis.V.rows() && in.femur.F.rows() == in.pelvis.F.rows() &&
            in.femur.V.isApprox(in.pelvis.V, 1e-12)),
          in.femur_source + " and " + in.pelvis_source + ": the femur and the pelvis are the same mesh");
}

// The given landmarks (input frame, mm) into `landmarks` (over the subject's), each name known and its point finite.
void add_given_landmarks(const SessionInput& input, Landmarks& landmarks) {
  for (const auto& [name, p] : input.landmarks) {
    bool known = name == "hip_centre";
    std::string names = "hip_centre";
    for (const char* n : kPelvisLandmarkNames) known = known || name == n, names += std::string(", ") + n;
    for (const char* n : kFemurLandmarkNames) known = known || name == n, names += std::string(", ") + n;
    require(known, [&] { return "landmarks: unknown name '" + name + "' (known: " + names + ")"; });
    require(p.allFinite(), "landmark " + name + ": not three finite numbers");
    landmarks[name] = p;
  }
}

// Winding: triangles that face against their neighbours would flip the sign of the distances around them
// (a femur 1.15 mm from the pelvis read as 123 mm inside it): both bones' flipped to agree, and said in
// in.warnings (with the edges that cannot be wound consistently). The pelvis on a second thread.
void orient_bones(LoadedInput& in) {
  std::int64_t femur_conflicts = 0, pelvis_conflicts = 0, femur_flipped = 0, pelvis_flips = 0;
  run_both([&] { femur_flipped = orient_consistently(in.femur, &femur_conflicts); },
           [&] { pelvis_flips = orient_consistently(in.pelvis, &pelvis_conflicts); });
  for (const auto& [mesh, source, flipped, conflicts] :
       {std::tuple{&in.femur, &in.femur_source, femur_flipped, femur_conflicts},
        std::tuple{&in.pelvis, &in.pelvis_source, pelvis_flips, pelvis_conflicts}}) {
    if (flipped > 0)
      in.warnings.push_back(*source + ": " + std::to_string(flipped) + " of " + std::to_string(mesh->F.rows()) +
                            " triangles were wound against their neighbours; flipped to agree with them");
    if (conflicts > 0)
      in.warnings.push_back(*source + ": " + std::to_string(conflicts) +
                            " shared edges cannot be wound consistently (a non-orientable surface): distances' signs "
                            "near them are not to be trusted");
  }
}

// Mesh hygiene (mesh_hygiene.hpp): both bones' fragments, double walls and holes, each said in in.warnings and
// kept in in.*_hygiene for the summaries. The pelvis on a second thread.
void clean_bones(LoadedInput& in, bool strict) {
  run_both([&] { in.femur_hygiene = clean_bone_mesh(in.femur, in.femur_source, strict); },
           [&] { in.pelvis_hygiene = clean_bone_mesh(in.pelvis, in.pelvis_source, strict); });
  for (const std::string& w : in.femur_hygiene.warnings(in.femur_source)) in.warnings.push_back(w);
  for (const std::string& w : in.pelvis_hygiene.warnings(in.pelvis_source)) in.warnings.push_back(w);
}

// Units: a femur or pelvis (or a part of one holding the joint) spans tens to hundreds of millimetres; a bone
// whose bounding box's diagonal is under 20 or over 3000 (file units) is an error naming the likely unit. A femur
// that shows its shaft (3 or more times as long as wide: the shared femurs 4.3-5.3) is at least 100 mm long in
// millimetres (an adult's 340-540 mm); a shorter one is a whole femur in centimetres (45 long) or inches.
void check_units(const LoadedInput& in) {
  for (const auto& [mesh, source] : {std::pair{&in.femur, &in.femur_source}, std::pair{&in.pelvis, &in.pelvis_source}}) {
    const double span = central_span(mesh->V);
    require(span >= 20 && span <= 3000, [&, span = span, source = source] {
      return *source + ": the bone spans " + num(span) + " (its bounding box's diagonal) in the file's units; a femur or "
             "pelvis in millimetres spans about 50 to 1,000: " +
             (span < 5    ? std::string("metres (scale by 1000) or inches (by 25.4)?")
              : span < 20 ? std::string("centimetres (scale by 10) or inches (by 25.4)?")
                          : std::string("micrometres?")) +
             " impinge reads millimetres";
    });
  }
  const Eigen::Vector3d e = principal_extents(in.femur.V);
  require(!(e[0] >= 3 * e[1] && e[0] < 100), [&] {
    std::string unit;
    for (const auto& [name, scale] :
         {std::pair{"centimetres (scale by 10)", 10.0}, std::pair{"inches (by 25.4)", 25.4}})
      if (e[0] * scale >= 100 && e[0] * scale <= 700) unit += (unit.empty() ? "" : " or ") + std::string(name);
    return in.femur_source + ": the femur is " + num(std::round(e[0] * 10) / 10) + " long and " +
           num(std::round(e[0] / e[1] * 10) / 10) +
           " times as long as wide (its shaft) in the file's units; a femur that shows its shaft is 100 to 700 mm "
           "long in millimetres (an adult's 340-540 mm): is the mesh in " +
           (unit.empty() ? std::string("another unit") : unit) + "? impinge reads millimetres";
  });
}

}  // namespace

Side input_side(const SessionInput& input) {
  std::optional<Side> subject_side;
  if (!input.subject.empty()) subject_side = load_subject(input.subject).side;
  return checked_side(input, subject_side);
}

LoadedInput load_input(const SessionInput& input) {
  LoadedInput in;
  std::string ball = input.ball, socket = input.socket;
  Landmarks landmarks;
  std::optional<Side> subject_side;
  std::optional<FrameConvention> subject_frame;
  if (!input.subject.empty()) {
    const SubjectInfo info = load_subject(input.subject);
    subject_side = info.side;
    subject_frame = info.frame;
    if (ball.empty() && !input.ball_mesh) ball = info.femur_path;
    if (socket.empty() && !input.socket_mesh) socket = info.pelvis_path;
    landmarks = info.landmarks;
    if (!info.landmarks.empty() && input.landmarks.empty()) in.landmarks_file = input.subject;
    in.neutral = info.neutral;
    in.name = info.name;
  }
  in.side = checked_side(input, subject_side);
  in.frame = checked_frame(input, subject_frame);
  read_bones(input, ball, socket, in);
  add_given_landmarks(input, landmarks);
  check_units(in);
  clean_bones(in, input.strict);
  orient_bones(in);
  in.to_working = to_working_frame(in.frame);
  transform_vertices(in.femur.V, in.to_working);
  transform_vertices(in.pelvis.V, in.to_working);
  for (auto& [name, p] : landmarks) in.landmarks[name] = in.to_working * p;
  return in;
}

std::string query_strategy_for_poses(const std::string& strategy, std::size_t poses) {
  require(strategy == "auto" || strategy == "maps" || strategy == "direct",
          "query strategy '" + strategy + "': must be maps, direct or auto");
  if (strategy != "auto") return strategy;
  return poses < kDirectQueryMaxPoses ? "direct" : "maps";
}

SphereFitResult located_head(const LoadedInput& in) {
  return in.pelvis.V.rows() > 0 ? locate_femoral_head(in.femur, in.pelvis) : locate_femoral_head(in.femur);
}

SphereFitResult check_cor_in_head(const std::string& what, const Eigen::Vector3d& cor, const LoadedInput& in) {
  // A given COR must lie in the femoral head: compare with the head the bone itself shows.
  const SphereFitResult head = located_head(in);
  const Eigen::Matrix3d& M = in.to_working;
  const double d = (cor - head.centre).norm();
  require(d <= head.radius, [&] {
    return what + " " + point_text(M.transpose() * cor) + " mm is " + num(d) + " mm from the fitted femoral head " +
           "centre " + point_text(M.transpose() * head.centre) + " mm, farther than the head radius " +
           num(head.radius) + " mm: the COR must lie in the head (input frame, mm); allow-any-cor accepts it";
  });
  return head;
}

CorResult find_centre_of_rotation(const LoadedInput& in, const CorOptions& cor) {
  const Eigen::Matrix3d& M = in.to_working;
  CorResult r;
  require(!(cor.given && cor.head_region), "give a COR or a head region, not both");
  if (cor.head_region) {
    const Eigen::Vector4d& v = *cor.head_region;
    r.head = fit_sphere_in_region(in.femur, M * v.head<3>(), v[3]);
    r.method = "sphere fit in region";
    return r;
  }
  if (cor.given) {
    r.head.centre = M * *cor.given;
    r.head.radius = r.head.rms_residual = std::nan("");
    r.method = "given";
    // Even a research COR (allow_any) lies at the femur: far from it, every ray misses the head.
    const Eigen::Vector3d lo = in.femur.V.colwise().minCoeff().transpose(), hi = in.femur.V.colwise().maxCoeff().transpose();
    const double outside = (r.head.centre.cwiseMax(lo).cwiseMin(hi) - r.head.centre).norm();
    require(outside <= 50, [&] {
      return "cor " + point_text(*cor.given) + " mm lies " + num(outside) + " mm outside the femur's bounding box " +
             "(input frame, mm): a COR in another frame or unit?";
    });
    if (!cor.allow_any) r.fitted_head = check_cor_in_head("cor", r.head.centre, in);
    return r;
  }
  if (in.landmarks.count("hip_centre")) {
    r.head.centre = in.landmarks.at("hip_centre");
    r.head.radius = r.head.rms_residual = std::nan("");
    r.method = "given (subject.json landmark hip_centre)";
    const std::string what = (in.landmarks_file.empty() ? "" : in.landmarks_file + ": ") + "landmark hip_centre";
    if (!cor.allow_any) r.fitted_head = check_cor_in_head(what, r.head.centre, in);
    return r;
  }
  r.head = located_head(in);
  r.method = in.pelvis.V.rows() > 0 ? "automatic sphere fit (long axis, RANSAC + geometric; the end in the acetabulum)"
                                    : "automatic sphere fit (long axis, RANSAC + geometric)";
  return r;
}

std::shared_ptr<const SamplingScheme> scheme_of(const GridRequest& g) {
  const int given = (g.resolution > 0) + (g.precision > 0) + (g.turns > 0) + (g.spacing > 0);
  require(given <= 1, "give one of resolution, precision, turns and spacing");
  check_in_range("resolution", g.resolution, GridRequest::kResolutionRange);
  check_in_range("precision", g.precision, GridRequest::kPrecisionRange, "deg");
  check_in_range("turns", g.turns, GridRequest::kTurnsRange);
  check_in_range("spacing", g.spacing, GridRequest::kSpacingRange, "deg");
  double res = default_resolution(g.scheme);
  if (g.spacing > 0) res = resolution_for_spacing(g.scheme, g.spacing);
  if (g.resolution > 0) res = g.resolution;
  if (g.precision > 0) res = g.precision;
  if (g.turns > 0) res = g.turns;
  return make_scheme(g.scheme, res);
}

namespace {
// The subject's "neutral" (`context` names it in errors) where the options leave the neutral unset.
void take_subject_neutral(HipJointOptions& o, const std::string& subject_neutral, const std::string& context) {
  if (!o.neutral && !subject_neutral.empty()) o.neutral = parse_neutral(subject_neutral, context);
}
}  // namespace

HipJointOptions resolved_hip_options(const SessionOptions& options, const std::string& subject_neutral) {
  HipJointOptions o = options.hip;
  take_subject_neutral(o, subject_neutral, "subject.json \"neutral\"");
  JointOptions& jo = o.joint;
  require(!jo.scheme || !options.grid.given(),
          "give the maps' scheme either as a grid request (scheme, resolution, precision, turns, spacing) or as "
          "HipJointOptions::joint.scheme, not both");
  if (!jo.scheme) jo.scheme = scheme_of(options.grid);
  // query_strategy_for_poses checks the value; "auto" reaching here (a library caller that did not resolve it by its
  // number of poses) builds the maps, which serve any number of poses.
  jo.layered_maps = query_strategy_for_poses(options.query_strategy, kDirectQueryMaxPoses) != "direct";
  // The levels classify the distance when there are distances, unless the radial gap is asked for.
  if (!jo.levels_on) jo.levels_on = jo.distances ? LevelQuantity::distance : LevelQuantity::radial_gap;
  jo.validate();
  require(o.ball_map_file.empty() == o.socket_map_file.empty(), "maps: give both map files (ball and socket) or none");
  return o;
}

double map_memory_bytes(const SamplingScheme& scheme) { return 2.0 * 5.0 * double(scheme.num_nodes()); }

namespace {
// Refuse maps that would not fit: before anything is allocated (a map at 0.005 deg met the kernel's OOM killer).
void check_map_memory(const SessionOptions& m, const SamplingScheme& scheme) {
  check_in_range("max-memory", m.max_memory_gb, SessionOptions::kMaxMemoryRange, "GB");
  const double machine = double(::sysconf(_SC_PHYS_PAGES)) * double(::sysconf(_SC_PAGESIZE));
  const double limit = m.max_memory_gb > 0 ? m.max_memory_gb * 1e9 : 0.75 * machine;
  const double need = map_memory_bytes(scheme);
  require(need <= limit, [&] {
    return "the maps at " + scheme.resolution_name() + " " + num(scheme.resolution()) + " (" + scheme.name() + ", " +
           num(double(scheme.num_nodes())) + " nodes each) need about " + num(std::round(need / 1e8) / 10) +
           " GB, more than " + (m.max_memory_gb > 0 ? "--max-memory " : "three quarters of this machine's ") +
           num(std::round(limit / 1e8) / 10) + " GB: coarsen the resolution or raise --max-memory";
  });
}
}  // namespace

namespace {
std::string mm1(double x) {  // x mm to 0.1 mm, rounded up (a least value to give)
  char t[32];
  std::snprintf(t, sizeof t, "%.1f", std::ceil(x * 10) / 10);
  return t;
}
double nearest_vertex_mm(const Vertices& V, const Eigen::Vector3d& centre) {
  return V.rows() == 0 ? 0.0 : std::sqrt((V.rowwise() - centre.transpose()).rowwise().squaredNorm().minCoeff());
}

// --max-radius and --sparse (issue 80) bound where contacts are tested: vertices within max-radius of the COR, maps
// holding only the tiles with a surface within sparse of it. A value below either bone's nearest vertex leaves
// that bone untested (max-radius) or its map empty (sparse): every gap untested or "no surface", every motion free.
// An error naming the option, the value and both bones' nearest vertices, before the maps are built.
void check_tested_region(const JointOptions& o, const LoadedInput& in, const Eigen::Vector3d& cor) {
  const double femur = nearest_vertex_mm(in.femur.V, cor), pelvis = nearest_vertex_mm(in.pelvis.V, cor);
  const double need = std::max(femur, pelvis);
  auto check = [&](const std::string& option, double value, const std::string& verb, const std::string& instead) {
    require(!(value < need), [&] {
      const bool both = value < femur && value < pelvis;
      const std::string bone = both || value < femur ? "femur" : "pelvis";
      return option + " " + num(value) + " mm " + verb + " the " + bone + " (its nearest vertex is " +
             mm1(bone == "femur" ? femur : pelvis) + " mm from the COR)" +
             (both ? " nor of the pelvis (" + mm1(pelvis) + " mm)" : std::string()) +
             ": no contact can be found; give at least " + mm1(need) +
             " mm (more for the acetabular rim and beyond: cam, pincer and extra-articular contacts), " + instead;
    });
  };
  if (std::isfinite(o.max_radius_mm))
    check("--max-radius", o.max_radius_mm, "reaches no vertex of", "or 0 (every vertex)");
  if (o.sparse_maps && std::isfinite(o.sparse_region_mm))
    check("--sparse", o.sparse_region_mm, "keeps no surface of", "'inf' (every surface: the same gaps) or 0 (dense maps)");
}

// A value that reaches the joint surfaces but not the acetabular rim (anatomical neutral, where the rim is found):
// contacts at the rim and beyond go untested, the gaps within it are right. A warning.
void warn_region_inside_rim(const JointOptions& o, const HipJoint& hip, std::vector<std::string>& warnings) {
  if (!hip.acetabulum()) return;
  const double rim = hip.acetabulum()->rim_radius_mm;
  const std::string where = " mm ends inside the acetabular rim (" + mm1(rim) + " mm from the centre): ";
  if (std::isfinite(o.max_radius_mm) && o.max_radius_mm < rim)
    warnings.push_back("--max-radius " + num(o.max_radius_mm) + where +
                       "contacts at the rim and beyond (cam, pincer, extra-articular) are not tested; 0 tests every vertex");
  if (o.sparse_maps && std::isfinite(o.sparse_region_mm) && o.sparse_region_mm < rim)
    warnings.push_back("--sparse " + num(o.sparse_region_mm) + where +
                       "the maps answer 'no surface' beyond it, so contacts at the rim and beyond (cam, pincer, "
                       "extra-articular) may be missed; 'inf' keeps every surface");
}
}  // namespace

namespace {
// What a hip's set-up builds, for an out-of-memory error: both maps (scheme, resolution, nodes, memory), the layered
// maps, the meshes' triangles; and how to build less.
std::string what_is_built(const HipJointOptions& o, const LoadedInput& in) {
  const SamplingScheme& s = *o.joint.scheme;
  std::string t = "the maps at " + s.resolution_name() + " " + num(s.resolution()) + " (" + s.name() + ", " +
                  std::to_string(s.num_nodes()) + " nodes each, about " +
                  num(std::ceil(map_memory_bytes(s) / 1e8) / 10) + " GB for both) of " + in.femur_source + " (" +
                  std::to_string(in.femur.F.rows()) + " triangles) and " + in.pelvis_source + " (" +
                  std::to_string(in.pelvis.F.rows()) + " triangles)";
  if (o.joint.layers > 0)
    t += ", and layered maps of " + std::to_string(o.joint.layers) + " layers at --layered-spacing " +
         (o.joint.layered_spacing_deg > 0 ? num(o.joint.layered_spacing_deg) + " deg" : std::string("the maps'"));
  return t + "; coarsen --precision (or --resolution), give fewer --layers or a larger --layered-spacing, use "
             "--query-strategy direct (no layered maps) for a few poses, or free memory";
}

// The hip built from `in` (its meshes moved in) about cor, cropped to the scan pose and `only_poses` when
// o.joint.cropped_distance_queries. Errors: memory running out (std::bad_alloc, OutOfMemory) as OutOfMemory naming
// what was built (what_is_built); any other Error as HipJoint throws it (with anatomical neutral's needs where the
// anatomy was not found).
std::shared_ptr<const HipJoint> build_hip(LoadedInput& in, Side side, const CorResult& cor, const HipJointOptions& o,
                                          const std::vector<PoseAngles>& only_poses) {
  const std::string built = what_is_built(o, in);
  try {
    auto hip = std::make_shared<HipJoint>(std::move(in.femur), std::move(in.pelvis), side, cor.head, in.landmarks, o);
    if (o.joint.cropped_distance_queries) {
      std::vector<FemurPose> poses{hip->scan_pose()};
      for (const PoseAngles& a : only_poses) poses.push_back(hip->femur_pose(a));
      hip->crop_distance_queries(poses);
    }
    return hip;
  } catch (const std::bad_alloc&) {
    throw OutOfMemory("out of memory building " + built);
  } catch (const OutOfMemory& e) {
    throw OutOfMemory(std::string(e.what()) + " while building " + built);
  }
}
}  // namespace

Session::Session(const SessionOptions& options) : options_(options) {
  // The cheap options are checked before anything is read or built.
  hip_options_ = resolved_hip_options(options);
  check_map_memory(options, *hip_options_.joint.scheme);
  LoadedInput in;
  try {
    in = load_input(options.input);
  } catch (const std::bad_alloc&) {
    throw OutOfMemory("out of memory reading the meshes (" +
                      (options.input.subject.empty() ? options.input.ball + ", " + options.input.socket
                                                     : options.input.subject) +
                      "): they need more memory than is free; decimate them or free memory");
  }
  const std::vector<std::string> load_warnings = in.warnings;
  // The naive ray cast tests every triangle for every node: refuse what would run for minutes.
  if (hip_options_.joint.sampling == SamplingMethod::ray_cast) {
    const double tests = double(hip_options_.joint.scheme->num_nodes()) * double(in.femur.F.rows() + in.pelvis.F.rows());
    require(tests <= 5e9, [&] {
      return "sampling ray-cast: " + num(double(hip_options_.joint.scheme->num_nodes())) + " nodes x " +
             num(double(in.femur.F.rows() + in.pelvis.F.rows())) + " triangles = " + num(tests) +
             " ray-triangle tests (minutes; at most 5e9): use ray-cast-bvh, the same exact node values through a BVH";
    });
  }
  take_subject_neutral(hip_options_, in.neutral, options.input.subject + ": \"neutral\"");
  const Neutral neutral = hip_options_.neutral.value_or(Neutral::anatomical);
  hip_options_.neutral = neutral;  // resolved: hip_options() tells what was built
  hip_options_.head_sphere.reset();  // the session's own (below), never a caller's
  side_ = in.side;
  frame_ = in.frame;
  to_working_ = in.to_working;
  ball_source_ = in.femur_source;
  socket_source_ = in.pelvis_source;
  subject_name_ = in.name;
  femur_hygiene_ = in.femur_hygiene;
  pelvis_hygiene_ = in.pelvis_hygiene;
  cor_ = find_centre_of_rotation(in, options.cor);
  check_side_and_frame(in, cor_, options.input);
  check_tested_region(hip_options_.joint, in, cor_.head.centre);
  hip_options_.allow_cor_outside_ball = options.cor.allow_any;
  // A COR the user gave (--cor, cor=) is the femoral head centre the radial gaps are measured about at the
  // scan pose, whatever the joint-centre method: the maps stay about it, and the combined and equidistant
  // methods move the femur by the seat at every pose instead of sampling the seated femur.
  hip_options_.seat_before_sampling = !options.cor.given;
  hip_options_.frames.landmarks_file = in.landmarks_file;
  hip_options_.to_report = in.to_working.transpose();
  hip_options_.report_frame_name = std::string("input frame, ") + (in.frame == FrameConvention::LPS ? "LPS" : "RAS");
  // A given COR (or the subject's hip_centre landmark): the zones, the acetabulum and the seat still
  // come from the head the femur shows, so that they do not move with the COR.
  if (!std::isfinite(cor_.head.radius) && neutral == Neutral::anatomical) {
    try {
      hip_options_.head_sphere = cor_.fitted_head ? *cor_.fitted_head : located_head(in);
    } catch (const Error&) {
      // No head to fit (e.g. a proximal stump): the COR's sphere, as before.
    }
  }
  // One pose's work (SessionOptions::only_poses): the distance hierarchies cropped to it and the scan pose.
  hip_options_.joint.cropped_distance_queries = !options.only_poses.empty() && options.query_strategy == "direct";
  // (With anatomical neutral, HipJoint's errors in finding the anatomy say how to do without it.)
  hip_ = build_hip(in, side_, cor_, hip_options_, options.only_poses);
  warnings_ = load_warnings;
  for (const std::string& w : hip_->warnings()) warnings_.push_back(w);
  warn_region_inside_rim(hip_options_.joint, *hip_, warnings_);
  // Segmentations that overlap as scanned (no rotation in the joint frame is the scan pose).
  const FemurPose scan_pose = hip_->scan_pose();
  auto scan_result = std::make_shared<const PoseResult>(joint().detect(scan_pose.R, scan_pose.t));
  const PoseResult& scan = *scan_result;
  scan_pose_min_gap_mm_ = std::fmin(scan.ball.min_gap_mm, scan.socket.min_gap_mm);
  if (!options.only_poses.empty()) scan_result_ = std::move(scan_result);  // a one-pose run at the scan pose
  if (scan_pose_min_gap_mm_ < 0)
    warnings_.push_back("the bones overlap by " + num(-scan_pose_min_gap_mm_) +
                        " mm at the scan pose (a segmentation overlap, not an impingement)" +
                        (hip_->joint_centre().method() == JointCentreMethod::femoral_head
                             ? std::string("; the equidistant joint centre seats the head in the acetabulum")
                             : std::string()));
}

PoseResult Session::detect(const FemurPose& pose) const {
  if (scan_result_) {
    const FemurPose scan = hip_->scan_pose();
    if (pose.R == scan.R && pose.t == scan.t) return *scan_result_;
  }
  return joint().detect(pose.R, pose.t);
}

Vertices Session::femur_input(const FemurPose& pose) const {
  return (hip_->posed_femur(pose.R, pose.t) * to_working_).eval();  // rows: v^T M = (M^T v)^T, M^T = input <- working
}

Vertices Session::pelvis_input() const { return (hip_->pelvis_vertices() * to_working_).eval(); }

std::pair<Eigen::Matrix3d, Eigen::Vector3d> Session::joint_motion(const Eigen::Matrix3d& R_in,
                                                                  const Eigen::Vector3d& t_in) const {
  // The radial gaps are measured along rays from the centre of rotation: a femur moved farther than its head's
  // radius has its head off that centre, and its gaps would read as deep penetrations of nothing.
  const double most = std::isfinite(hip_->head_radius_mm()) ? hip_->head_radius_mm() : 25.0;
  require(t_in.allFinite() && t_in.norm() <= most, [&] {
    return "t: the femur translated by " + num(t_in.norm()) + " mm; the radial gaps are measured along rays from "
           "the centre of rotation, so a translation may be at most the head radius, " + num(most) + " mm";
  });
  // joint <- working <- input: A = joint_to_working^T, M = to_working.
  const Eigen::Matrix3d B = hip_->joint_to_working().transpose() * to_working_;
  const Eigen::Matrix3d R = B * R_in * B.transpose();
  // The joint frame's femur is the seated one (its head centre at the origin) and h = cor - seat: the
  // rotation about h leaves the head centre at h, which is -seat in the joint frame.
  const Eigen::Vector3d seat = hip_->joint_to_working().transpose() * hip_->seat_mm();
  return {R, B * t_in - seat};
}

Eigen::Vector3d Session::input_translation(const FemurPose& pose) const {
  const Eigen::Matrix3d B = hip_->joint_to_working().transpose() * to_working_;
  const Eigen::Vector3d seat = hip_->joint_to_working().transpose() * hip_->seat_mm();
  return B.transpose() * (pose.t + seat);
}

Eigen::Matrix3d Session::input_rotation(const Eigen::Matrix3d& R_joint) const {
  const Eigen::Matrix3d B = hip_->joint_to_working().transpose() * to_working_;
  return B.transpose() * R_joint * B;
}

Eigen::Vector3d Session::report_point(const Eigen::Vector3d& joint_point) const {
  const Eigen::Vector3d w = hip_->to_working(joint_point);
  if (hip_->frames()) return hip_->frames()->pelvis.to_local(w);
  return to_input(w);
}

}  // namespace impinge
