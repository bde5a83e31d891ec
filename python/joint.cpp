// The Python Joint: a Session (session/session.hpp) as the CLI builds it, its options from the option table.
#include <omp.h>

#include <chrono>
#include <cmath>
#include <limits>

#include "bindings.hpp"
#include "impinge/clinical/rom.hpp"
#include "impinge/core/error.hpp"
#include "impinge/session/morphology_run.hpp"
#include "impinge/session/outputs.hpp"
#include "impinge/session/plan_run.hpp"
#include "impinge/session/runs.hpp"

namespace impinge::python {

namespace {



PyJoint make_joint(const py::object& ball, const py::object& socket, const py::kwargs& kw) {
  RunOptions run = RunOptions::clinical();
  py::dict given(kw);
  if (given.contains("ball") || given.contains("socket")) throw Error("Joint: give ball and socket once");
  given["ball"] = ball;
  given["socket"] = socket;
  set_options(run, given, use_joint, "Joint");
  PyJoint j;
  run_interruptible([&] { j.session = std::make_shared<const Session>(run.session); });
  for (const std::string& w : j.session->warnings())
    if (PyErr_WarnEx(PyExc_UserWarning, ("impinge: " + w).c_str(), 1) != 0) throw py::error_already_set();
  return j;
}

// The Joint `impinge view` serves: its options the CLI's tokens, read through the option table as the CLI reads them.
py::tuple joint_from_cli(const std::vector<std::string>& args) {
  RunOptions run = RunOptions::clinical();
  set_cli_options(run, args, use_view, "impinge view");
  PyJoint j;
  run_interruptible([&] { j.session = std::make_shared<const Session>(run.session); });
  py::dict command;
  command["motion"] = run.command.motion.empty() ? py::object(py::none()) : py::object(py::str(run.command.motion));
  return py::make_tuple(j, command);
}

// Both scans as Python: the gaps and statuses as numpy arrays (owning the C++ buffers), and each
// scan's summary as summary.json records it (scan_record).
py::dict result_dict(const Session& session, PoseResult&& r) {
  py::dict d;
  const auto nb = static_cast<py::ssize_t>(r.ball_gaps.gap_mm.size());
  const auto ns = static_cast<py::ssize_t>(r.socket_gaps.gap_mm.size());
  const ImpingementLevels& levels = session.joint_options().levels;
  // The impingement level of each vertex (0 none .. count-1 deepest; 255 untested), as the PLY files give it; taken
  // before the gaps move into their arrays.
  const LevelQuantity on = session.joint_options().level_quantity();
  std::vector<std::uint8_t> femur_level = vertex_levels(r.ball_gaps, levels, on);
  std::vector<std::uint8_t> pelvis_level = vertex_levels(r.socket_gaps, levels, on);
  py::dict summary;
  summary["femur"] = from_json(scan_record(session.joint().ball(), r.ball, r.ball_detection_ms, levels, nullptr));
  summary["pelvis"] =
      from_json(scan_record(session.joint().socket(), r.socket, r.socket_detection_ms, levels, nullptr));
  summary["femur_detection_ms"] = r.ball_detection_ms;
  summary["pelvis_detection_ms"] = r.socket_detection_ms;
  if (session.joint_options().distances) {
    summary["femur_distance_ms"] = r.ball_distance_ms;
    summary["pelvis_distance_ms"] = r.socket_distance_ms;
  }
  d["femur_gap_mm"] = own(std::move(r.ball_gaps.gap_mm), {nb});
  d["pelvis_gap_mm"] = own(std::move(r.socket_gaps.gap_mm), {ns});
  if (!r.ball_gaps.distance_mm.empty()) {
    d["femur_distance_mm"] = own(std::move(r.ball_gaps.distance_mm), {nb});
    d["pelvis_distance_mm"] = own(std::move(r.socket_gaps.distance_mm), {ns});
  }
  d["femur_level"] = own(std::move(femur_level), {nb});
  d["pelvis_level"] = own(std::move(pelvis_level), {ns});
  d["femur_status"] = own(std::move(r.ball_gaps.status), {nb});
  d["pelvis_status"] = own(std::move(r.socket_gaps.status), {ns});
  d["summary"] = summary;
  return d;
}

// Both scans at every pose: the motion table's columns (frames.csv's), one C++ loop without the GIL.
py::dict motion(const PyJoint& j, const py::handle& angles_obj) {
  const std::vector<PoseAngles> poses = to_angles(angles_obj);
  Table t;
  t.columns = motion_columns(j.session->joint_options().levels);
  t.rows.reserve(poses.size());
  run_interruptible(
      [&] { run_motion(*j.session, poses, {}, [&](const MotionFrame& f) { t.rows.push_back(motion_row(f)); }); });
  py::dict d = table_columns(t);
  d["pelvis_penetrating_area_mm2"] = d["penetrating_area_mm2"];
  return d;
}

std::string joint_doc() {
  std::string names;
  for (const OptionRow& r : option_table())
    if (r.uses & use_joint) names += (names.empty() ? "" : ", ") + r.key;
  return "Joint(ball=None, socket=None, **options): a hip set up as `impinge distance` sets it up (the session "
         "layer): femur (ball) and pelvis (socket) from a subject.json, mesh files or (V, F) arrays, in their input "
         "frame (frame='LPS' or 'RAS', mm); both maps built once (the GIL is released), then any number of poses. "
         "Options, the rows of impinge.options() with 'joint' in their uses (the CLI's names with underscores; "
         "None or absent: the clinical preset's default): " + names +
         ". cor: the femoral head centre, 'auto' or (x, y, z) mm in the input frame; head_region: (x, y, z, r) mm; "
         "landmarks: dict name -> (x, y, z) mm; levels: thresholds in mm, decreasing; maps: (ball_path, "
         "socket_path) saved by save_maps(); preset: 'clinical' or 'thesis'. Positions, rotations and frames given "
         "or returned are in the input frame. Raises impinge.Error naming the option, array or file on bad input; "
         "warnings (e.g. an overlap at the scan pose) as UserWarning.";
}

// The ROM request of rom_limits or rom_map (`use`): the clinical preset and the keywords given. The distance
// metric needs the Joint's distances.
RomRequest rom_request(const PyJoint& j, const py::dict& given, unsigned use, const std::string& caller) {
  RunOptions run = RunOptions::clinical();
  set_options(run, given, use, caller);
  require(run.rom.search.metric == RomMetric::radial || j.session->joint_options().distances,
          caller + ": metric 'distance' needs a Joint with distances=True (the default); give metric='radial' for "
                   "the thesis' radial gap");
  return run.rom;
}

py::dict rom_limits(const PyJoint& j, const py::kwargs& given) {
  RomRequest q = rom_request(j, given, use_rom_limits, "rom_limits");
  q.map = false;
  RomRun run;
  run_interruptible([&] { run = run_rom(*j.session, q); });
  const Table t = rom_limits_table(*j.session, run);
  py::dict d;
  for (std::size_t k = 0; k < t.rows.size(); ++k) {
    py::dict e;
    for (std::size_t c = 1; c < t.columns.size(); ++c) {
      const nlohmann::json& x = t.rows[k][c];
      e[py::str(t.columns[c])] = x.is_null() ? py::object(py::float_(std::nan(""))) : from_json(x);
    }
    e["contact_mm"] = Eigen::Vector3d(j.session->to_input(run.limits[k].contact_mm));
    const PoseAngles& start = run.motions[k].start;
    e["start_deg"] = py::make_tuple(start.flexion_deg, start.adduction_deg, start.internal_rotation_deg);
    // The pose at the limit (degrees, ISB): the motion's angles there; None without a limit.
    const double limit = run.limits[k].limit_deg;
    if (std::isfinite(limit)) {
      const PoseAngles p = run.motions[k].angles(limit);
      e["pose_at_limit_deg"] = py::make_tuple(p.flexion_deg, p.adduction_deg, p.internal_rotation_deg);
    } else {
      e["pose_at_limit_deg"] = py::none();
    }
    d[py::str(run.motions[k].name)] = e;
  }
  d["excluded_vertices"] = run.baseline.excluded_vertices;
  return d;
}

// Joint.plan: a resection plan on this Joint's inputs and settings (run_plan), its check, its record as a dict with
// the resected meshes (input frame) and each vertex's depth.
py::dict plan(const PyJoint& j, const py::kwargs& given) {
  RunOptions run = RunOptions::clinical();
  set_options(run, given, use_joint_plan, "plan");
  PlanRun p;
  run_interruptible([&] { p = run_plan(j.session->options(), run.rom, run.plan); });
  require(p.all_met || run.plan.allow_partial,
          "plan: a target is missed (give allow_partial=True to get the plan anyway): " + [&] {
            std::string s;
            for (std::size_t k = 0; k < p.targets.size(); ++k)
              if (!p.targets[k].met)
                s += (s.empty() ? "" : "; ") + p.targets[k].name +
                     (p.plan.targets[k].note.empty() ? std::string() : ": " + p.plan.targets[k].note);
            return s;
          }());
  py::dict d = py::reinterpret_borrow<py::dict>(from_json(plan_record(p)));
  if (p.plan.femur.allowed) {
    d["femur_resected"] = py::make_tuple(p.femur_resected.V, p.femur_resected.F);
    d["femur_resection_mm"] = Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(p.plan.femur.depth_mm.data(), static_cast<Eigen::Index>(p.plan.femur.depth_mm.size())));
  }
  if (p.plan.pelvis.allowed) {
    d["pelvis_resected"] = py::make_tuple(p.pelvis_resected.V, p.pelvis_resected.F);
    d["pelvis_resection_mm"] = Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(p.plan.pelvis.depth_mm.data(), static_cast<Eigen::Index>(p.plan.pelvis.depth_mm.size())));
  }
  return d;
}

py::array_t<double> rom_map(const PyJoint& j, const py::kwargs& given) {
  RomRequest q = rom_request(j, given, use_rom_map, "rom_map");
  q.limits = false;
  RomRun run;
  run_interruptible([&] { run = run_rom(*j.session, q); });
  std::vector<double> ir(run.map.size());
  for (std::size_t k = 0; k < run.map.size(); ++k) ir[k] = run.map[k].max_internal_rotation_deg;
  return own(std::move(ir), {py::ssize_t(run.map_flexion_deg.size()), py::ssize_t(run.map_adduction_deg.size())});
}

void add_joint_queries(py::class_<PyJoint>& c) {
  c.def(
       "detect",
       [](const PyJoint& j, const py::handle& R, const py::handle& t) {
         const Eigen::Matrix3d Rin = to_rotation(R);
         const Eigen::Vector3d tin = t.is_none() ? Eigen::Vector3d::Zero() : to_point(t, "t");
         const auto [Rj, tj] = j.session->joint_motion(Rin, tin);
         PoseResult r;
         {
           py::gil_scoped_release release;
           j.session->joint().detect(Rj, tj, r);
         }
         return result_dict(*j.session, std::move(r));
       },
       py::arg("R") = py::none(), py::arg("t") = py::none(),
       "Both scans with the femur rotated by R (3, 3; input frame) about its head centre (`cor`), then translated by t (3,) "
       "mm -> dict(femur_gap_mm, pelvis_gap_mm: float32 (n,) in the input's vertex order, NaN where not "
       "tested; femur_distance_mm, pelvis_distance_mm: float32 (n,), the signed Euclidean distance to the other "
       "bone, NaN beyond the reach (with distances on); femur_status, pelvis_status: uint8 (0 tested, 1 no "
       "surface, 2 beyond reach); femur_level, pelvis_level: uint8 (n,), the impingement level (0 none .. "
       "len(levels) deepest, 255 untested; level_colours() gives the PLY files' colours); summary).")
      .def(
          "detect_pose",
          [](const PyJoint& j, double flexion, double adduction, double internal_rotation) {
            PoseResult r;
            FemurPose p;
            ClosestPoint femur_closest, pelvis_closest;
            {
              py::gil_scoped_release release;
              p = j.hip().femur_pose(PoseAngles{flexion, adduction, internal_rotation});
              j.hip().joint().detect(p.R, p.t, r);
              femur_closest = closest_point(*j.session, true, r.ball_gaps, p);
              pelvis_closest = closest_point(*j.session, false, r.socket_gaps, p);
            }
            py::dict d = result_dict(*j.session, std::move(r));
            // Where each scan comes closest, classed as summary.json's closest_contact_class.
            d["summary"]["femur"]["closest_contact_class"] = to_string(femur_closest.contact_class);
            d["summary"]["pelvis"]["closest_contact_class"] = to_string(pelvis_closest.contact_class);
            d["joint_translation_mm"] = Eigen::Vector3d(j.session->to_input(j.hip().femur_translation(p.t)));
            return d;
          },
          py::arg("flexion") = 0.0, py::arg("adduction") = 0.0, py::arg("internal_rotation") = 0.0,
          "Both scans at clinical angles (degrees, ISB joint coordinate system: flexion, adduction and internal "
          "rotation positive; zero per `neutral`), the femur placed by the joint-centre method (option "
          "joint_centre) -> the same dict as detect(), with joint_translation_mm (3,): the femur's translation "
          "(input frame, mm) after its rotation about the COR, and each scan's summary with closest_contact_class "
          "(where it comes closest: articular, intra-articular or extra-articular impingement, as summary.json).")
      .def("motion", &motion, py::arg("angles"),
           "Both scans at every row of angles (k, 3): flexion, adduction, internal rotation in degrees -> dict of "
           "(k,) arrays, the columns of the CLI's frames.csv (femur_min_gap_mm, pelvis_min_gap_mm, "
           "penetrating_area_mm2 = pelvis_penetrating_area_mm2, femur_penetrating_area_mm2, pelvis_levelN_area_mm2, "
           "closest clock hours and point, detection_ms). One C++ loop, frames in blocks on impinge.get_threads() "
           "threads (rows in order); the GIL is released.")
      .def("rom_limits", &rom_limits,
           keep_doc("ROM limits from neutral for the standard motions (flexion, extension, abduction, adduction, "
                    "internal and "
           "external rotation, both rotations at 90 deg flexion, FADIR) -> dict motion -> the CLI's rom_limits.csv "
           "row (limit_deg (NaN: none within max_deg), first_contact_deg (where the bones first touch: limit_deg "
           "at contact_depth_mm 0, the default), limited_by, contact_class, pelvis_clock_h, femur_clock_h, "
           "min_gap_at_limit_mm, monotone, contact_at_start, evaluations, limit_isb_deg and limit_app_deg (the "
           "motion about each pelvic frame's axes; NaN with neutral='scan'), normal_deg and normal_source (active "
           "ranges of living subjects), bony_normal_deg and bony_normal_source (published simulated bony ROM)), "
           "contact_mm (input frame) and "
           "pose_at_limit_deg ((flexion, adduction, internal rotation) at the limit; None without one), start_deg (where "
           "the motion starts); and "
           "excluded_vertices (in contact at neutral, not counted). The keywords are the option table's "
           "(impinge.options(): `impinge rom`'s --threshold, --contact-depth, --metric, --contacts, --step, --max), "
           "with its defaults. metric 'distance' needs the Joint's distances (the default). " +
            keywords_doc(use_rom_limits)))
      .def("plan", &plan,
           keep_doc("Resection plan (the CLI's `impinge plan`, plan.json as a dict): the least bone to remove so "
                    "that the "
           "targets run free of impingement (target: 'MOTION=DEG,...' and/or 'normal'; target_motion: a motion "
           "file), shaped for a spherical burr, within the safety depth, never the head inside the labrum line or "
           "the lunate surface; checked on the resected bones in their own placement (the ROM search and the "
           "clearance at every target pose; further passes where one is missed). Adds femur_resected (V, F: input "
           "frame, the input's faces) and femur_resection_mm (per vertex), and the pelvis' with resect 'pelvis' or "
           "'both'. labrum=True targets the labral limits: the femur is cut to clear the pelvis and the labrum (never "
           "cut; not with resect 'pelvis'). Raises impinge.Error when a target is missed, unless allow_partial. "
           "Keywords and defaults: the "
            "option table's (impinge.options()). " + keywords_doc(use_joint_plan)))
      .def("rom_map", &rom_map,
           keep_doc("ROM map: the largest internal rotation (deg) before contact for every flexion x adduction "
                    "(deg; default "
           "`impinge rom`'s grid) -> float64 (len(flexion), len(adduction)); NaN where in contact already without "
           "rotation or free up to 150 deg. The same search as `impinge rom`'s rom_map.csv (run_rom). " +
            keywords_doc(use_rom_map)))
      .def(
          "morphology",
          [](const PyJoint& j) {
            MorphologyRun run;
            run_interruptible([&] { run = run_morphology(j.session->options()); });
            return from_json(morphology_record(run));
          },
          "The hip's morphology (the CLI's morphology.json as a dict: femur and acetabulum, each measure's value, unit, "
          "definition, source, frame and where it was obtained; notes): head radius and sphericity, neck-shaft "
          "angle, femoral version (across the shaft and across the mechanical axis), alpha angle per clock hour, head-neck offset; acetabular sphere, version and inclination (Murray 1993, "
          "anterior pelvic plane), lateral and anterior centre-edge angles, coverage. Measured on this Joint's inputs "
          "and frames, without its maps.")
      .def(
          "femur_rotation",
          [](const PyJoint& j, double flexion, double adduction, double internal_rotation) {
            return j.session->input_rotation(j.hip().femur_rotation({flexion, adduction, internal_rotation}));
          },
          py::arg("flexion") = 0.0, py::arg("adduction") = 0.0, py::arg("internal_rotation") = 0.0,
          "Rotation (3, 3; input frame) of the femur about the COR at the clinical angles.")
      .def(
          "femur_pose",
          [](const PyJoint& j, double flexion, double adduction, double internal_rotation) {
            const FemurPose p = j.hip().femur_pose({flexion, adduction, internal_rotation});
            return std::pair{Eigen::Matrix3d(j.session->input_rotation(p.R)), Eigen::Vector3d(j.session->input_translation(p))};
          },
          py::arg("flexion") = 0.0, py::arg("adduction") = 0.0, py::arg("internal_rotation") = 0.0,
          "(R, t): the femur as scanned, rotated by R (3, 3; input frame) about the COR (`cor`) and then translated "
          "by t (3,; mm, input frame), at the clinical angles with the joint-centre method's translation: posed "
          "vertices = (V - cor) R^T + cor + t; detect(R, t) scans that pose.")
      .def(
          "save_maps", [](const PyJoint& j, const std::string& ball, const std::string& socket) {
            j.hip().save_maps(ball, socket);
          },
          py::arg("ball_path"), py::arg("socket_path"),
          "Save both maps (impinge map files with scheme, resolution, COR and checksum) for Joint(..., maps=...).");
}

void add_joint_properties(py::class_<PyJoint>& c) {
  c.def_property_readonly("cor", [](const PyJoint& j) { return j.session->head_centre_input(); },
                          "The femoral head centre, the centre of rotation (3,), mm, input frame: the `cor` given, "
                          "else the fitted one; detect(R, t) rotates the femur about it.")
      .def_property_readonly("map_centre", [](const PyJoint& j) { return j.session->map_centre_input(); },
                             "The maps' centre, where the rays of the radial gaps start (3,), mm, input frame: the "
                             "head centre, or the acetabular centre where a fitted head was seated before sampling "
                             "(the combined and equidistant joint centres).")
      .def_property_readonly(
          "acetabular_centre",
          [](const PyJoint& j) -> py::object {
            const auto a = j.session->acetabular_centre_input();
            return a ? py::cast(Eigen::Vector3d(*a)) : py::none();
          },
          "The acetabular centre (the sphere fitted to the acetabulum) (3,), mm, input frame; None with scan "
          "neutral.")
      .def_property_readonly(
          "pivot",
          [](const PyJoint& j) -> py::object {
            const auto p = pivot_input(*j.session);
            return p ? py::cast(Eigen::Vector3d(*p)) : py::none();
          },
          "The point the femur turns about under the joint-centre method (3,), mm, input frame, the pelvis fixed: "
          "the head centre (femoral-head), the acetabular centre (acetabular, combined); None for equidistant (its "
          "centre moves with each pose) and without an acetabular centre. summary.json's pivot_mm.")
      .def_property_readonly("femur_map",
                             [](const PyJoint& j) { return MapView{j.session->shared_hip(), &j.hip().joint().ball().map}; })
      .def_property_readonly(
          "pelvis_map", [](const PyJoint& j) { return MapView{j.session->shared_hip(), &j.hip().joint().socket().map}; })
      .def_property_readonly(
          "meshes",
          [](const PyJoint& j) {
            const Session& s = *j.session;
            py::dict d;
            d["femur"] = py::make_tuple(Vertices(s.femur_input(s.hip().scan_pose())), s.joint().ball().mesh.F);
            d["pelvis"] = py::make_tuple(Vertices(s.pelvis_input()), s.joint().socket().mesh.F);
            return d;
          },
          "Both bones as given, in the input frame at the scan pose -> dict(femur=(V (n, 3) float64 mm, F (m, 3) "
          "int), pelvis=(V, F)): the vertex order of every per-vertex result.")
      .def_property_readonly(
          "frames",
          [](const PyJoint& j) -> py::object {
            const nlohmann::json r = setup_record(*j.session);
            return r.contains("frames") ? from_json(r["frames"]) : py::none();
          },
          "Anatomical frames as summary.json's \"frames\" records them (anatomical neutral; None with scan neutral), "
          "input frame: per bone origin_mm, x_axis, y_axis, z_axis (ISB: x anterior, y superior, z right), "
          "landmarks with their sources; scan_pose_deg, the acetabulum, seat_mm.")
      .def_property_readonly(
          "setup", [](const PyJoint& j) { return from_json(setup_record(*j.session)); },
          "The set-up as the CLI's summary.json reports it (inputs, input frame, COR and its method, scheme, maps, "
          "frames and acetabulum in the input frame, warnings) -> dict.")
      .def_property_readonly("warnings", [](const PyJoint& j) { return j.session->warnings(); },
                             "Warnings about the input, one line each (also raised as UserWarning).");
}

void add_joint_benchmarks(py::class_<PyJoint>& c) {
  c.def(
       "_bench_detect_ns",
       [](const PyJoint& j, const py::handle& R, int repetitions) {
         // Median ns of Joint::detect (C++ loop, reused buffers): the reference for the binding's overhead.
         const auto [Rj, tj] = j.session->joint_motion(to_rotation(R), Eigen::Vector3d::Zero());
         std::vector<double> ns;
         PoseResult r;
         py::gil_scoped_release release;
         for (int k = 0; k < repetitions; ++k) {
           const auto t0 = std::chrono::steady_clock::now();
           j.hip().joint().detect(Rj, tj, r);
           ns.push_back(std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count());
         }
         std::nth_element(ns.begin(), ns.begin() + static_cast<std::ptrdiff_t>(ns.size() / 2), ns.end());
         return ns[ns.size() / 2];
       },
       py::arg("R") = py::none(), py::arg("repetitions") = 50)
      .def(
          "_bench_motion_ns",
          [](const PyJoint& j, const py::handle& angles) {
            // ns of the C++ loop motion() runs, timed inside C++: the reference for motion()'s overhead.
            const std::vector<PoseAngles> poses = to_angles(angles);
            std::vector<nlohmann::json> rows;
            rows.reserve(poses.size());
            py::gil_scoped_release release;
            const auto t0 = std::chrono::steady_clock::now();
            run_motion(*j.session, poses, {}, [&](const MotionFrame& f) { rows.push_back(motion_row(f)); });
            return std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count();
          },
          py::arg("angles"));
}

}  // namespace

void bind_joint(py::module_& m) {
  m.def(
      "femoral_head_centre",
      [](const py::object& ball, const py::object& socket, const py::kwargs& kw) {
        RunOptions run = RunOptions::clinical();
        py::dict given(kw);
        given["ball"] = ball;
        given["socket"] = socket;
        set_options(run, given, use_joint, "femoral_head_centre");
        CorResult c;
        Eigen::Matrix3d to_input;
        {
          py::gil_scoped_release release;
          const LoadedInput in = load_input(run.session.input);
          c = find_centre_of_rotation(in, run.session.cor);
          to_input = in.to_working.transpose();
        }
        py::dict d;
        d["centre"] = Eigen::Vector3d(to_input * c.head.centre);
        d["radius"] = c.head.radius;
        d["method"] = c.method;
        return d;
      },
      py::arg("ball") = py::none(), py::arg("socket") = py::none(),
      "The femoral head centre, the centre of rotation, as Joint(...) finds it from the same keywords (the "
      "session's policy: head_region, cor, the subject's hip_centre landmark, else the head fitted on the femur "
      "that sits in the acetabulum), without building maps -> dict(centre (3,) mm in the input frame, radius mm "
      "(NaN when given), method).");

  py::class_<PyJoint> c(m, "Joint", "A hip set up as the CLI sets it up (the session layer); see __init__.");
  static const std::string doc = joint_doc();  // pybind11 keeps the pointer
  c.def(py::init(&make_joint), py::arg("ball") = py::none(), py::arg("socket") = py::none(), doc.c_str());
  c.def_static("_from_cli", &joint_from_cli, py::arg("args"),
               "(Joint, dict(motion: path or None)) set up from `impinge view`'s command-line options (['--subject', "
               "'S', '--precision', '0.5', ...]: the option table's rows for view, parsed as the CLI parses them). "
               "Raises impinge.Error naming the option. For impinge.view; warnings are in .warnings.");
  add_joint_queries(c);
  add_joint_properties(c);
  add_joint_benchmarks(c);
}

}  // namespace impinge::python
