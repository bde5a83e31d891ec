// The option table's rows: every option of the CLI, Python and the study files (option_table.hpp).
#include <algorithm>
#include <limits>

#include "impinge/detection/impingement_levels.hpp"
#include "impinge/schemes/sampling_scheme.hpp"
#include "impinge/session/session.hpp"
#include "option_builders.hpp"

namespace impinge {

namespace {

using namespace detail;

constexpr unsigned kJointCommands = use_distance | use_motion | use_rom | use_plan;
constexpr unsigned kInput = kJointCommands | use_joint | use_morphology | use_view;
constexpr unsigned kSetting = kJointCommands | use_joint | use_study | use_view;

// A length's range with 0 added, for a row whose 0 means "no such length" (every vertex, dense maps).
Range with_zero(Range r) {
  r.min_open = false;
  return r;
}

std::vector<std::string> registered_schemes() {
  std::vector<std::string> v;
  for (const auto& [name, res] : scheme_names()) v.push_back(name);
  return v;
}

std::string scheme_help() {
  std::string s;
  for (const auto& [name, res] : scheme_names()) s += (s.empty() ? "" : ", ") + name + " (" + res + ")";
  return "Sampling scheme of the maps: " + s;
}

std::string levels_help() {
  std::string d;
  for (double t : ImpingementLevels{}.thresholds_mm) d += (d.empty() ? "" : ",") + shortest(t);
  return "Impingement thresholds, decreasing, e.g. 4,2.667,1.333,0 (default: " + d + ", the thesis' 4 mm cartilage "
         "offset in thirds)";
}

// The inputs' rows: the preset (applied first), the subject, the bones (ball and socket: a file, or a mesh from
// Python), side, frame and landmarks (input frame, mm).
void add_input_rows(Rows& t) {
  t.text("preset", "preset", OptionType::choice, kSetting, {"clinical", "thesis"},
         "Named defaults, applied before every other option: 'clinical' (layered maps, Euclidean distances, the ROM "
         "metric the distance, the equidistant joint centre at anatomical neutral) or 'thesis' (single-layer maps, "
         "radial gaps only, rotation about the femoral head centre, the thesis' ROM criterion)",
         [](auto& o) -> auto& { return o.preset; });
  t.rows.back().set = [](RunOptions& o, const OptionValue& v, const std::string& as) {
    const RunOptions p = RunOptions::named(value_as<std::string>(v, as, "a string"), as);
    o.preset = p.preset, o.rom = p.rom;
    take_session_settings(o.session, p.session);
  };
  t.text("subject", "subject", OptionType::path, kInput, {},
         "subject.json giving side, frame (LPS or RAS) and optional landmarks; supplies --ball/--socket",
         [](auto& o) -> auto& { return o.session.input.subject; });
  for (const bool ball : {true, false}) {
    OptionRow& r = t.add(ball ? "ball" : "socket", ball ? "ball" : "socket", OptionType::mesh, "", kInput,
                         ball ? "Ball mesh (femur): PLY, STL, OBJ, OFF, or VTK .vtp/.vtk (through VTK's Python bindings), mm "
                                     "(Python: also (V, F) arrays)"
                              : "Socket mesh (pelvis): PLY, STL, OBJ, OFF, or VTK .vtp/.vtk (through VTK's Python "
                                "bindings), mm (Python: also (V, F) arrays)");
    r.set = [ball](RunOptions& o, const OptionValue& v, const std::string& as) {
      SessionInput& in = o.session.input;
      set_mesh(o, v, as, [&](RunOptions&) -> std::string& { return ball ? in.ball : in.socket; },
               [&](RunOptions&) -> std::optional<TriangleMesh>& { return ball ? in.ball_mesh : in.socket_mesh; });
    };
    r.get = [ball](const RunOptions& o) -> OptionValue {
      const std::string& p = ball ? o.session.input.ball : o.session.input.socket;
      if (p.empty()) return std::monostate{};
      return p;
    };
  }
  t.text("side", "side", OptionType::choice, kInput, {"right", "left"},
         "right or left (default: the subject's, else right; contradicting it is an error)",
         [](auto& o) -> auto& { return o.session.input.side; });
  t.text("frame", "frame", OptionType::choice, kInput, {"LPS", "RAS"},
         "Input frame LPS or RAS (default: the subject's, else RAS; contradicting it is an error)",
         [](auto& o) -> auto& { return o.session.input.frame; });
  t.flag("strict", "strict", OptionType::flag, kInput,
         "Refuse a mesh that needs a repair: a fragment apart from the bone (over 10 mm from it) or a repeated face "
         "(a double wall); otherwise they are removed and said (docs: mesh hygiene)",
         [](auto& o) -> auto& { return o.session.input.strict; });
  OptionRow& lm = t.add("landmarks", "landmarks", OptionType::landmarks, "mm", use_joint,
                        "Landmarks, input frame, mm, named as subject.json's (over the subject's)");
  lm.set = [](RunOptions& o, const OptionValue& v, const std::string& as) {
    if (std::holds_alternative<std::monostate>(v)) return;
    for (const auto& [name, p] : value_as<Landmarks>(v, as, "a dict name -> (x, y, z) mm")) {
      require(p.allFinite(), [&] { return as + "['" + name + "']: not three finite numbers"; });
      o.session.input.landmarks[name] = p;
    }
  };
  lm.get = [](const RunOptions& o) -> OptionValue {
    if (o.session.input.landmarks.empty()) return std::monostate{};
    return o.session.input.landmarks;
  };
}

// The centre of rotation's rows: cor (the femoral head centre, input frame, mm, or auto), allow-any-cor and
// head-region (X,Y,Z,R mm: where the head sphere is fitted).
void add_cor_rows(Rows& t) {
  OptionRow& cor = t.add("cor", "cor", OptionType::point, "mm", kInput,
                         "The femoral head centre, the centre of rotation: 'auto' (a sphere fitted to the femoral head, "
                         "in any scan orientation) or X,Y,Z in the input files' frame; the radial gaps at the scan "
                         "pose are measured about it");
  cor.set = [](RunOptions& o, const OptionValue& v, const std::string& as) {
    if (std::holds_alternative<std::monostate>(v)) {
      o.session.cor.given.reset();
      return;
    }
    const std::vector<double> x = checked_numbers(v, as, 3);
    o.session.cor.given = Eigen::Vector3d(x[0], x[1], x[2]);
  };
  cor.get = [](const RunOptions& o) -> OptionValue {
    if (!o.session.cor.given) return std::monostate{};
    const Eigen::Vector3d& c = *o.session.cor.given;
    return std::vector<double>{c.x(), c.y(), c.z()};
  };
  t.flag("allow-any-cor", "allow_any_cor", OptionType::flag, kSetting | use_morphology,
         "Accept a --cor (or subject.json's landmark hip_centre) outside the femoral head (research; otherwise an "
         "error naming the COR and the fitted head centre)",
         [](auto& o) -> auto& { return o.session.cor.allow_any; });
  OptionRow& hr = t.add("head-region", "head_region", OptionType::region, "mm", kSetting | use_morphology,
                        "X,Y,Z,R: fit the head sphere to femur vertices within R mm of (X,Y,Z), input frame");
  hr.set = [](RunOptions& o, const OptionValue& v, const std::string& as) {
    if (std::holds_alternative<std::monostate>(v)) {
      o.session.cor.head_region.reset();
      return;
    }
    const std::vector<double> x = checked_numbers(v, as, 4);
    require(x[3] > 0, [&] { return as + ": the radius R = " + shortest(x[3]) + " mm must be > 0 mm"; });
    o.session.cor.head_region = Eigen::Vector4d(x[0], x[1], x[2], x[3]);
  };
  hr.get = [](const RunOptions& o) -> OptionValue {
    if (!o.session.cor.head_region) return std::monostate{};
    const Eigen::Vector4d& c = *o.session.cor.head_region;
    return std::vector<double>{c[0], c[1], c[2], c[3]};
  };
}

// The grid's rows: the sampling scheme, its resolution or the aliases precision (deg) and turns, the largest node
// spacing wanted (deg), and the sampling method.
void add_grid_rows(Rows& t) {
  t.text("scheme", "scheme", OptionType::choice, kSetting, registered_schemes(), scheme_help(),
         [](auto& o) -> auto& { return o.session.grid.scheme; });
  t.number("resolution", "resolution", "", kSetting, GridRequest::kResolutionRange,
           "Resolution of the scheme (its own unit, listed with --scheme); 0: the scheme's equivalent of 0.5 deg "
           "node spacing",
           [](auto& o) -> auto& { return o.session.grid.resolution; });
  t.number("precision", "precision", "deg", kSetting, GridRequest::kPrecisionRange,
           "Alias of --resolution for equiangular grids: precision p in degrees (0: not given)",
           [](auto& o) -> auto& { return o.session.grid.precision; });
  t.number("turns", "turns", "", kSetting, GridRequest::kTurnsRange,
           "Alias of --resolution for the helix: k turns (w = k^2 nodes; 0: not given)",
           [](auto& o) -> auto& { return o.session.grid.turns; });
  t.number("spacing", "spacing_deg", "deg", kSetting, GridRequest::kSpacingRange,
           "Largest node spacing wanted, degrees, for any scheme: the coarsest resolution that reaches it (instead "
           "of --resolution; 0: not given)",
           [](auto& o) -> auto& { return o.session.grid.spacing; })
      .old_keys = {"spacing"};
  t.choice("sampling", "sampling", kSetting, kSamplingMethodNames,
         "auto, rasterize, resample, ray-cast (naive, small meshes only) or ray-cast-bvh (exact node values for any "
         "scheme)",
         [](auto& o) -> auto& { return o.session.hip.joint.sampling; });
}

// How the radial gaps are read and classified: the distance mode, the impingement levels (mm), the occlusion
// tolerance (mm), the vertices tested (max-radius, mm), sparse maps (mm) and the discontinuity tolerance (mm).
void add_gap_rows(Rows& t) {
  t.choice("mode", "mode", kSetting, kDistanceModeNames,
         "Distance mode: 'linear' (thesis Alg. 1) or 'exact' (ray-plane)",
         [](auto& o) -> auto& { return o.session.hip.joint.mode; });
  OptionRow& levels = t.add("levels", "levels", OptionType::numbers, "mm", kSetting, levels_help());
  levels.set = [](RunOptions& o, const OptionValue& v, const std::string& as) {
    ImpingementLevels l;  // nothing: the default thresholds
    if (!std::holds_alternative<std::monostate>(v)) l.thresholds_mm = checked_numbers(v, as, 0);
    try {
      l.validate();
    } catch (const Error& e) {
      throw Error(as + ": " + e.what());
    }
    o.session.hip.joint.levels = l;
  };
  levels.get = [](const RunOptions& o) -> OptionValue {  // the default thresholds: nothing (help gives them)
    const std::vector<double>& thresholds = o.session.hip.joint.levels.thresholds_mm;
    if (thresholds == ImpingementLevels{}.thresholds_mm) return std::monostate{};
    return thresholds;
  };
  t.number("occlusion-tolerance", "occlusion_tolerance_mm", "mm", kSetting, JointOptions::kOcclusionToleranceRange,
           "Vertices farther than their own first surface plus this are skipped (beyond reach)",
           [](auto& o) -> auto& { return o.session.hip.joint.occlusion_tolerance_mm; });
  // Two rows whose 0 stands for a setting without a length (every vertex; dense maps): the field's range with 0
  // added.
  OptionRow& radius = t.number("max-radius", "max_radius_mm", "mm", kSetting, with_zero(JointOptions::kMaxRadiusRange),
                               "Test only vertices within this distance of the COR (0 = all)",
                               [](auto& o) -> auto& { return o.session.hip.joint.max_radius_mm; });
  radius.set = [spec = radius](RunOptions& o, const OptionValue& v, const std::string& as) {
    const double x = checked_number(spec, v, as);
    o.session.hip.joint.max_radius_mm = x > 0 ? x : JointOptions::kInf;
  };
  radius.get = [](const RunOptions& o) -> OptionValue {
    const double r = o.session.hip.joint.max_radius_mm;
    return std::isinf(r) ? 0.0 : r;
  };
  OptionRow& sparse = t.number("sparse", "sparse_region_mm", "mm", kSetting, with_zero(JointOptions::kSparseRegionRange),
                               "Store both maps sparse, in tiles, keeping only tiles with a surface within this "
                               "distance of the COR ('inf': any surface, the same gaps bit for bit; 0 = dense maps)",
                               [](auto& o) -> auto& { return o.session.hip.joint.sparse_region_mm; });
  sparse.old_keys = {"sparse"};
  sparse.set = [spec = sparse](RunOptions& o, const OptionValue& v, const std::string& as) {
    const double x = checked_number(spec, v, as);
    o.session.hip.joint.sparse_maps = x > 0;
    o.session.hip.joint.sparse_region_mm = x > 0 ? x : JointOptions::kInf;
  };
  sparse.get = [](const RunOptions& o) -> OptionValue {
    return o.session.hip.joint.sparse_maps ? o.session.hip.joint.sparse_region_mm : 0.0;
  };
  t.number("discontinuity-tolerance", "discontinuity_tolerance_mm", "mm", kSetting,
           JointOptions::kDiscontinuityToleranceRange,
           "Look-ups whose stencil may be off by more than this (depth discontinuities: rims, coverage edges) are "
           "resolved by an exact ray cast",
           [](auto& o) -> auto& { return o.session.hip.joint.discontinuity_tolerance_mm; });
}

// The layered maps' rows (the vertices hidden behind their own bone): layers, the query strategy (layered maps or
// exact casts), the layered maps' node spacing (deg) and the extra-articular radius (mm).
void add_layer_rows(Rows& t) {
  t.integer("layers", "layers", "", kSetting, JointOptions::kLayersRange,
            "N: also a layered map of N crossings per node for each bone, so that vertices hidden behind their own "
            "bone's nearer surface (trochanters, shaft, ilium) are tested too: extra-articular impingement (0 = off, "
            "the thesis' single-layer maps)",
            [](auto& o) -> auto& { return o.session.hip.joint.layers; });
  OptionRow& strategy = t.text("query-strategy", "query_strategy", OptionType::choice, kSetting, {"auto", "maps", "direct"},
         "What to build for the work: maps (both maps and the layered maps, for many poses), direct (no layered "
         "maps: the hidden vertices by exact ray casts; distance's distance hierarchies only over the triangles its "
         "pose can reach; a few poses; no ROM searches), auto (by the number of poses: "
         "distance and motions of fewer than " + std::to_string(kDirectQueryMaxPoses) +
             " frames direct; ROM searches, plans and longer motions maps). The "
         "distances and the first-surface gaps are the same either way; the hidden vertices' gaps are exact with "
         "direct, the maps' interpolation with maps",
         [](auto& o) -> auto& { return o.session.query_strategy; });
  strategy.old_names = {"setup"};
  strategy.old_keys = {"setup"};
  t.number("layered-spacing", "layered_spacing_deg", "deg", kSetting, JointOptions::kLayeredSpacingRange,
           "The layered maps' largest node spacing (the scheme at the coarsest resolution reaching it, never finer "
           "than the maps'; 0: the maps' own); their edges are exact ray casts",
           [](auto& o) -> auto& { return o.session.hip.joint.layered_spacing_deg; })
      .old_keys = {"layered_spacing"};
  t.number("extra-articular-radius", "extra_articular_radius_mm", "mm", kSetting,
           JointOptions::kExtraArticularRadiusRange,
           "With --layers, test hidden vertices within this distance of the COR",
           [](auto& o) -> auto& { return o.session.hip.joint.extra_articular_radius_mm; });
}

// The Euclidean distances' rows: distances on or off, what the levels classify (distance or radial gap) and the
// distance reach (mm).
void add_distance_rows(Rows& t) {
  t.flag("distances", "distances", OptionType::on_off, kSetting,
         "on|off: beside each radial gap, the signed Euclidean distance to the other bone's surface (what 3D "
         "Slicer, VTK, Open3D and libigl report; negative inside it), exact, for every vertex (hidden ones too) "
         "within --distance-reach of the other bone",
         [](auto& o) -> auto& { return o.session.hip.joint.distances; });
  t.choice("levels-on", "levels_on", kSetting, kLevelQuantityNames,
         "What the impingement levels (colours, level areas, clock sectors) classify: the Euclidean distance or the "
         "thesis' radial gap (default: the distance, or the radial gap with --distances off)",
         [](auto& o) -> auto& { return o.session.hip.joint.levels_on; });
  t.number("distance-reach", "distance_reach_mm", "mm", kSetting, JointOptions::kDistanceReachRange,
           "Vertices proven farther than this from the other bone get no distance (0: the largest --levels "
           "threshold)",
           [](auto& o) -> auto& { return o.session.hip.joint.distance_reach_mm; });
}

// The maps' remaining rows: the memory limit (GB), maps-only look-ups and saved maps to load instead of sampling.
void add_map_rows(Rows& t) {
  t.number("max-memory", "max_memory_gb", "GB", kSetting, SessionOptions::kMaxMemoryRange,
           "The most memory the maps may take; a resolution whose maps need more is refused before anything is "
           "allocated (0: three quarters of this machine's memory)",
           [](auto& o) -> auto& { return o.session.max_memory_gb; });
  t.flag("maps-only", "maps_only", OptionType::flag, kSetting,
         "No exact look-ups at depth discontinuities: the maps answer alone (the thesis' algorithm)",
         [](auto& o) -> auto& { return o.session.hip.joint.exact_at_discontinuities; }, true);
  OptionRow& mp = t.add("maps", "maps", OptionType::path_pair, "", use_joint,
                        "(ball_path, socket_path): maps saved by save_maps() to load instead of sampling");
  mp.set = [](RunOptions& o, const OptionValue& v, const std::string& as) {
    if (std::holds_alternative<std::monostate>(v)) {
      o.session.hip.ball_map_file.clear(), o.session.hip.socket_map_file.clear();
      return;
    }
    const auto& p = value_as<std::vector<std::string>>(v, as, "a pair (ball_path, socket_path)");
    require(p.size() == 2, [&] { return as + ": expected a pair (ball_path, socket_path), got " + std::to_string(p.size()) + " items"; });
    o.session.hip.ball_map_file = p[0], o.session.hip.socket_map_file = p[1];
  };
  mp.get = [](const RunOptions& o) -> OptionValue {
    if (o.session.hip.ball_map_file.empty()) return std::monostate{};
    return std::vector<std::string>{o.session.hip.ball_map_file, o.session.hip.socket_map_file};
  };
}

void add_frame_rows(Rows& t) {
  t.choice("neutral", "neutral", kSetting | use_morphology, kNeutralNames,
         "Zero pose: 'anatomical' (the femoral ISB frame parallel to the pelvic one, both found from the bones or "
         "given as landmarks in subject.json) or 'scan' (the pose in the scanner; angles about the input frame's "
         "axes: flexion about left-right, adduction about antero-posterior, rotation about superior-inferior). "
         "Default: subject.json's \"neutral\", else anatomical",
         [](auto& o) -> auto& { return o.session.hip.neutral; });
  t.choice("pelvis-frame", "pelvis_frame", kSetting | use_morphology, kPelvisFrameKindNames,
         "Pelvic axes: 'isb' (Wu et al. 2002: ASIS and PSIS) or 'app' (anterior pelvic plane: ASIS and pubic "
         "tubercles, as clinical ROM tools)",
         [](auto& o) -> auto& { return o.session.hip.frames.pelvis; });
  t.choice("joint-centre", "joint_centre", kSetting, kJointCentreMethodNames,
         "How the femur moves at each pose (Puls et al. 2010, Comput Aided Surg 15:75): 'femoral-head' (rotation "
         "about the head centre: the thesis' method), 'acetabular' (about the acetabular centre), 'combined' (the "
         "head centre placed on the acetabular centre) or 'equidistant' (at each pose the femur is also translated "
         "so that the joint space over the lunate surface is as even as possible). The translation is reported per "
         "pose and limit. Default: equidistant with anatomical neutral, femoral-head with --neutral scan (which "
         "allows no other)",
         [](auto& o) -> auto& { return o.session.hip.joint_centre; });
  t.choice("femur-frame", "femur_frame", kSetting | use_morphology, kFemurFrameKindNames,
         "Femoral medio-lateral axis: 'epicondyles' (ISB) or 'posterior-condyles' (posterior condylar axis)",
         [](auto& o) -> auto& { return o.session.hip.frames.femur; });
}

// The labrum's rows (labrum.hpp): on or off, its base width and height (defaults from cadaveric measurements).
void add_labrum_rows(Rows& t) {
  const unsigned uses = use_rom | use_rom_limits | use_plan | use_joint_plan;
  t.flag("labrum", "labrum", OptionType::flag, uses,
         "Also the acetabular labrum, a soft-tissue ring of triangular cross-section on the rim continuing the "
         "socket's sphere, with its own map: each limit's labral limit beside the bony one (rom_limits.csv's labral_* "
         "columns, labrum.ply); the ROM map stays bony. plan: target the labral limits, the femur cut to clear the "
         "pelvis and the labrum (never cut; not with --resect pelvis)",
         [](auto& o) -> auto& { return o.rom.labrum.enabled; });
  t.number("labrum-width", "labrum_width_mm", "mm", uses, LabrumOptions::kWidthRange,
           "The labrum's base width on the rim (default: the mean width of 55 cadaveric labra, Tan et al. 2001, "
           "Am J Orthop 30:809)",
           [](auto& o) -> auto& { return o.rom.labrum.width_mm; });
  t.number("labrum-height", "labrum_height_mm", "mm", uses, LabrumOptions::kHeightRange,
           "The labrum's height from its base to its free margin (default: the anterior labrum's mean height in 54 "
           "cadaveric labra, Won et al. 2003, Yonsei Med J 44:855; 4.0-6.8 mm elsewhere on the rim)",
           [](auto& o) -> auto& { return o.rom.labrum.height_mm; });
}

void add_rom_rows(Rows& t) {
  const unsigned both = use_rom | use_rom_limits | use_rom_map | use_plan | use_joint_plan;
  t.number("threshold", "threshold_mm", "mm", both, RomOptions::kThresholdRange,
           "The bones meet when the least gap (--metric) is <= this less --contact-depth (0: bone contact; a "
           "cartilage offset > 0)",
           [](auto& o) -> auto& { return o.rom.search.threshold_mm; });
  t.number("contact-depth", "contact_depth_mm", "mm", both, RomOptions::kContactDepthRange,
           "A contact must reach this far past the threshold to end a search. 0 (default): the limit is the first "
           "touch (the least exact surface-to-surface distance reaches the threshold). For noisy meshes (an MRI "
           "surface's roughness, 0.4-0.8 mm rms) a depth > 0 lets a graze shallower than the data's error pass; "
           "the limit is then a depth of overlap by the per-vertex test, and first_contact_deg still the first touch",
           [](auto& o) -> auto& { return o.rom.search.contact_depth_mm; });
  t.choice("metric", "metric", both, kRomMetricNames,
           "What --threshold is compared with: the signed Euclidean distance to the other bone (what a depth or a "
           "cartilage offset means) or the thesis' radial gap (along the ray from the COR; where the ray runs inside "
           "the other bone it reads a depth of tens of mm for a graze). The distance needs distances on: a Python "
           "Joint built with distances=False uses the radial gap unless metric is given",
           [](auto& o) -> auto& { return o.rom.search.metric; });
  t.choice("contacts", "contacts", use_rom | use_rom_limits | use_plan | use_joint_plan, kRomContactsNames,
           "Which contacts end a search: 'impingement' (the head-neck junction, neck or trochanters against the rim "
           "or the pelvis beyond it; the head's joint surface meeting the lunate surface, the joint space closing, "
           "is left out), 'articular' (only that: where the joint space closes) or 'all' (every vertex, the thesis' "
           "criterion). Anatomical neutral only (the zones need the acetabulum)",
           [](auto& o) -> auto& { return o.rom.search.contacts; });
  t.number("step", "step_deg", "deg", use_rom | use_rom_limits | use_plan | use_joint_plan, RomOptions::kStepRange,
           "Coarse search step (then bisection to --search-tolerance)",
           [](auto& o) -> auto& { return o.rom.search.step_deg; });
  t.number("search-tolerance", "tolerance_deg", "deg", use_rom | use_rom_limits | use_plan | use_joint_plan,
           RomOptions::kToleranceRange,
           "Bisect each limit's last step until the bracket is this narrow (at most --step; the default 0.1 ends "
           "at 0.0625 from the 2 deg step)",
           [](auto& o) -> auto& { return o.rom.search.tolerance_deg; });
  t.number("max", "max_deg", "deg", use_rom | use_rom_limits | use_plan | use_joint_plan, RomOptions::kMaxRange,
           "Search no farther than this from the start",
           [](auto& o) -> auto& { return o.rom.search.max_deg; });
  t.numbers("map-flexion", "flexion", "deg", use_rom | use_rom_map, "The ROM map's flexion angles",
            [](auto& o) -> auto& { return o.rom.map_flexion_deg; });
  t.numbers("map-adduction", "adduction", "deg", use_rom | use_rom_map, "The ROM map's adduction angles",
            [](auto& o) -> auto& { return o.rom.map_adduction_deg; });
  t.flag("no-map", "no_map", OptionType::flag, use_rom, "Limits only, no ROM map",
         [](auto& o) -> auto& { return o.rom.map; }, true);
  t.flag("envelope", "envelope", OptionType::flag, use_rom,
         "Also the ROM envelope: every pose of flexion -30..130 x adduction -50..40 x internal rotation -60..60 deg "
         "(1 deg steps) valid or in contact, by adaptive refinement (rom_envelope.csv: the valid runs of internal "
         "rotation)",
         [](auto& o) -> auto& { return o.rom.envelope; });
  t.integer("envelope-coarse", "envelope_coarse", "", use_rom, RomEnvelopeOptions::kCoarseStepsRange,
            "Steps between the envelope's first poses (1: scan every pose; larger is faster and can miss a region of "
            "contact smaller than a cell)",
            [](auto& o) -> auto& { return o.rom.envelope_options.coarse_steps; });
  add_labrum_rows(t);
}

void add_command_rows(Rows& t) {
  OptionRow& out = t.text("out", "out", OptionType::path, use_cli_commands, {}, "Output folder",
                          [](auto& o) -> auto& { return o.command.out; });
  out.required = true;
  t.text("pose", "pose", OptionType::text, use_distance, {},
         "FLEX,ADD,IR in degrees, ISB joint coordinate system (Wu et al. 2002): flexion about the pelvic "
         "medio-lateral axis (+ = knee forward), adduction about the floating axis (+ = knee towards the midline, "
         "negative = abduction), internal rotation about the femoral long axis (+ = front of the thigh turns "
         "inwards); mirrored for the left side so the signs mean the same. Zero is set by --neutral",
         [](auto& o) -> auto& { return o.command.pose; });
  t.flag("render", "render", OptionType::flag, use_distance | use_plan,
         "Also write shaded renders with matplotlib (distance: render.png, anterior, lateral and the socket's medial "
         "view with the acetabular clock face; plan: plan.png, the resection's depth on the head-neck clock face)",
         [](auto& o) -> auto& { return o.command.render; });
  OptionRow& motion = t.text("motion", "motion", OptionType::path, use_motion | use_view, {},
                             "Motion file: .csv, .mot or .sto (view: optional, played with a timeline)",
                             [](auto& o) -> auto& { return o.command.motion; });
  motion.required = true;
  motion.optional_for = use_view;
  t.integer("vtp-every", "vtp_every", "", use_motion, CommandArguments::kVtpEveryRange,
            "Write the posed bones (gaps/frame_N.vtp) every N frames; 0 = every frame up to 100 frames, else at most "
            "100 files",
            [](auto& o) -> auto& { return o.command.vtp_every; });
  t.flag("quiet", "quiet", OptionType::flag, use_motion, "No progress bar or final line",
         [](auto& o) -> auto& { return o.command.quiet; });
  t.integer("triangles", "triangles", "", use_generate | use_generated_hip, HipModelOptions::kTargetTrianglesRange,
            "Target triangles per model in " + HipModelOptions::kTargetTrianglesRange.text() +
                " (the generator's coarsest model has about 50; 20 million take about 2 GB of memory)",
            [](auto& o) -> auto& { return o.generate.target_triangles; });
  t.number("cam", "cam_mm", "mm", use_generate | use_generated_hip, HipModelOptions::kCamHeightRange, "Cam bump height",
           [](auto& o) -> auto& { return o.generate.cam_height_mm; });
  t.number("coverage", "coverage_deg", "deg", use_generate | use_generated_hip, HipModelOptions::kCupCoverageRange,
           "Cup coverage angle from the cup pole",
           [](auto& o) -> auto& { return o.generate.cup_coverage_deg; });
}

void add_plan_rows(Rows& t) {
  const unsigned plan = use_plan | use_joint_plan;
  t.text("target", "target", OptionType::text, plan, {},
         "Targets of a resection plan: MOTION=DEG,... (standard motions: flexion, extension, abduction, adduction, "
         "internal_rotation, external_rotation, internal_rotation_90_flexion, external_rotation_90_flexion, fadir) "
         "and/or 'normal' (each motion's published normal range: AAOS 1965, Kouyoumdjian et al. 2012); a named "
         "angle replaces normal's",
         [](auto& o) -> auto& { return o.plan.target; });
  t.text("target-motion", "target_motion", OptionType::path, plan, {},
         "A motion file (.csv, .mot, .sto) whose every frame the plan must free of impingement",
         [](auto& o) -> auto& { return o.plan.target_motion; });
  t.choice("resect", "resect", plan, kResectBonesNames,
           "Which bone the plan may resect: femur (the cam: osteochondroplasty of the head-neck junction), pelvis "
           "(a rim trim) or both (each contact shared); never the head's articular surface or the lunate surface",
           [](auto& o) -> auto& { return o.plan.resection.bones; });
  t.number("clearance", "clearance_mm", "mm", plan, ResectionOptions::kClearanceRange,
           "The least distance the bones keep at every target pose after the resection",
           [](auto& o) -> auto& { return o.plan.resection.clearance_mm; })
      .old_names = {"clearance-mm"};
  t.number("max-depth-fraction", "max_depth_fraction", "", plan, PlanRequest::kMaxDepthFractionRange,
           "Safety depth as a fraction of the femoral neck's least diameter (Mardones et al. 2005: deeper than "
           "about 30 % weakens the neck); a target that needs more is planned up to where it can be reached",
           [](auto& o) -> auto& { return o.plan.max_depth_fraction; });
  t.number("max-depth", "max_depth_mm", "mm", plan, PlanRequest::kMaxDepthRange,
           "Safety depth in mm instead of the fraction (0: the fraction of the neck's diameter)",
           [](auto& o) -> auto& { return o.plan.max_depth_mm; })
      .old_names = {"max-depth-mm"};
  t.number("burr-radius", "burr_radius_mm", "mm", plan, ResectionOptions::kBurrRadiusRange,
           "Radius of the spherical burr the removal is shaped for (arthroscopic burrs: 4-5.5 mm diameter; 0: no "
           "shaping, the least removal per vertex)",
           [](auto& o) -> auto& { return o.plan.resection.burr_radius_mm; })
      .old_names = {"burr-radius-mm"};
  t.number("plan-step", "plan_step_deg", "deg", plan, PlanRequest::kStepRange,
           "Poses along each target motion every this many degrees (with the clearance, a step small enough that "
           "no contact deeper than --contact-depth fits between two poses)",
           [](auto& o) -> auto& { return o.plan.step_deg; });
  t.flag("allow-partial", "allow_partial", OptionType::flag, plan,
         "A target the checked plan misses is reported, not an error (exit 0)",
         [](auto& o) -> auto& { return o.plan.allow_partial; });
}

// `impinge view`'s own rows (ViewOptions): where its server listens and whether it opens the page.
void add_view_rows(Rows& t) {
  t.text("host", "host", OptionType::text, use_view, {},
         "The address the viewer's server listens on (127.0.0.1: this machine only; another address serves the "
         "network, with a warning; the page's token still guards every request)",
         [](auto& o) -> auto& { return o.view.host; });
  t.integer("port", "port", "", use_view, ViewOptions::kPortRange,
            "The viewer's TCP port (0: a free one, printed with the page's address)",
            [](auto& o) -> auto& { return o.view.port; });
  t.flag("no-browser", "no_browser", OptionType::flag, use_view,
         "Print the page's address without opening it in a browser",
         [](auto& o) -> auto& { return o.view.open_browser; }, true);
  t.text("export", "export", OptionType::path, use_view, {},
         "Write one self-contained HTML file (the meshes and the --export-poses, opens from disk with no server or "
         "network) instead of serving",
         [](auto& o) -> auto& { return o.view.export_path; });
  t.text("export-poses", "export_poses", OptionType::text, use_view, {},
         "The poses an --export holds: auto (the motion's frames with --motion, else rom), rom (neutral, and 2 deg "
         "before and at each standard motion's limit), motion, or F,A,R;F,A,R;... (degrees, ISB)",
         [](auto& o) -> auto& { return o.view.export_poses; });
  t.text("plan", "plan", OptionType::path, use_view, {},
         "An impinge plan output folder: the resected bones coloured by their depth, before and after, with each "
         "target's limit before and after",
         [](auto& o) -> auto& { return o.view.plan_dir; });
  t.text("motion-folder", "motion_folder", OptionType::path, use_view, {},
         "A folder whose motion files (.csv, .mot, .sto) the page may choose from (only those, directly in it)",
         [](auto& o) -> auto& { return o.view.motion_folder; });
  t.number("export-max-mb", "export_max_mb", "MB", use_view, ViewOptions::kExportMaxMbRange,
           "The export's largest size; a motion's frames are decimated evenly to fit",
           [](auto& o) -> auto& { return o.view.export_max_mb; });
}

}  // namespace

const std::vector<OptionRow>& option_table() {
  static const std::vector<OptionRow> table = [] {
    Rows t;
    add_input_rows(t);
    add_cor_rows(t);
    add_grid_rows(t);
    add_gap_rows(t);
    add_layer_rows(t);
    add_distance_rows(t);
    add_map_rows(t);
    add_frame_rows(t);
    add_rom_rows(t);
    add_plan_rows(t);
    add_command_rows(t);
    add_view_rows(t);
    return std::move(t.rows);
  }();
  return table;
}

const OptionRow* find_option(const std::string& name) {
  for (const OptionRow& r : option_table())
    if (r.name == name || r.key == name ||
        std::find(r.old_names.begin(), r.old_names.end(), name) != r.old_names.end() ||
        std::find(r.old_keys.begin(), r.old_keys.end(), name) != r.old_keys.end())
      return &r;
  return nullptr;
}

}  // namespace impinge
