// The Python module `impinge` (pybind11): meshes, sphere fits, a hip joint posed by clinical
// angles or rotations, motions, and the radial distance maps as numpy arrays.
//
// Arrays: vertices are float64 (or float32) n x 3 in mm, faces integer m x 3 (0-based); results
// are numpy arrays that own the C++ buffers they were computed in (no copy). Errors are raised as
// impinge.Error (a ValueError) with the library's one-line messages. Long calls release the GIL.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "impinge/anatomy/sphere_fit.hpp"
#include "impinge/clinical/hip_joint.hpp"
#include "impinge/clinical/rom.hpp"
#include "impinge/core/error.hpp"
#include "impinge/core/mesh.hpp"
#include "impinge/io/generated_models.hpp"
#include "impinge/io/mesh_io.hpp"
#include "impinge/io/subject.hpp"
#include "impinge/maps/map_io.hpp"
#include "impinge/sampling/sampling.hpp"
#include "impinge/schemes/sampling_scheme.hpp"

namespace py = pybind11;
using namespace impinge;

namespace {

// A numpy array owning `v` (moved to the heap; freed with the array).
template <typename T>
py::array_t<T> own(std::vector<T>&& v, std::vector<py::ssize_t> shape) {
  auto* p = new std::vector<T>(std::move(v));
  py::capsule free(p, [](void* q) { delete static_cast<std::vector<T>*>(q); });
  return py::array_t<T>(shape, p->data(), free);
}

// Check a numpy array's kind and shape: n x 3 (n >= min_rows).
py::array checked(const py::handle& obj, const std::string& what, char kind, py::ssize_t min_rows) {
  if (!py::isinstance<py::array>(obj))
    throw Error(what + ": expected a numpy array of shape (n, 3), got " + std::string(py::str(obj.get_type())));
  py::array a = py::reinterpret_borrow<py::array>(obj);
  const char k = a.dtype().kind();
  const bool ok_kind = kind == 'f' ? (k == 'f' && (a.itemsize() == 4 || a.itemsize() == 8))
                                   : (k == 'i' || k == 'u');
  if (!ok_kind)
    throw Error(what + ": dtype " + std::string(py::str(a.dtype())) +
                (kind == 'f' ? " is not float32 or float64" : " is not an integer type"));
  if (a.ndim() != 2 || a.shape(1) != 3)
    throw Error(what + ": expected shape (n, 3), got " + std::string(py::str(py::tuple(py::cast(std::vector<py::ssize_t>(
                                                                  a.shape(), a.shape() + a.ndim()))))));
  if (a.shape(0) < min_rows)
    throw Error(what + ": needs at least " + std::to_string(min_rows) + " rows, got " + std::to_string(a.shape(0)));
  return a;
}

Vertices to_vertices(const py::handle& obj, const std::string& what) {
  const py::array a = checked(obj, what, 'f', 1);
  const auto d = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  Vertices V(a.shape(0), 3);
  std::copy(d.data(), d.data() + d.size(), V.data());
  for (Eigen::Index i = 0; i < V.rows(); ++i)
    if (!V.row(i).allFinite()) throw Error(what + ": vertex " + std::to_string(i) + " has a non-finite coordinate");
  return V;
}

TriangleMesh to_mesh(const py::handle& pair, const std::string& what) {
  if (!py::isinstance<py::tuple>(pair) && !py::isinstance<py::list>(pair))
    throw Error(what + ": expected a pair (V, F) of numpy arrays");
  const py::sequence s = py::reinterpret_borrow<py::sequence>(pair);
  if (s.size() != 2) throw Error(what + ": expected a pair (V, F), got " + std::to_string(s.size()) + " items");
  TriangleMesh m;
  m.source = what;
  m.V = to_vertices(s[0], what + " V");
  const py::array f = checked(s[1], what + " F", 'i', 1);
  const auto fi = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(f);
  m.F.resize(f.shape(0), 3);
  for (py::ssize_t k = 0; k < fi.size(); ++k) {
    const std::int64_t v = fi.data()[k];
    if (v < 0 || v >= m.V.rows())
      throw Error(what + " F: face " + std::to_string(k / 3) + " has vertex index " + std::to_string(v) +
                  " outside [0, " + std::to_string(m.V.rows()) + ")");
    m.F.data()[k] = static_cast<int>(v);
  }
  validate_mesh(m);
  return m;
}

Eigen::Matrix3d to_rotation(const py::handle& obj) {
  if (obj.is_none()) return Eigen::Matrix3d::Identity();
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(obj);
  if (!a || a.ndim() != 2 || a.shape(0) != 3 || a.shape(1) != 3) throw Error("R: expected a 3 x 3 rotation matrix");
  Eigen::Matrix3d R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R(r, c) = a.at(r, c);
  if (!R.allFinite() || (R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > 1e-6 || R.determinant() < 0)
    throw Error("R: not a rotation matrix (orthonormal with determinant +1, within 1e-6)");
  return R;
}

Eigen::Vector3d to_point(const py::handle& obj, const std::string& what) {
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(obj);
  if (!a || a.size() != 3) throw Error(what + ": expected three numbers (x, y, z), mm");
  const Eigen::Vector3d p(a.data()[0], a.data()[1], a.data()[2]);
  if (!p.allFinite()) throw Error(what + ": not finite");
  return p;
}

py::dict sphere_dict(const SphereFitResult& s) {
  py::dict d;
  d["centre"] = std::vector<double>{s.centre.x(), s.centre.y(), s.centre.z()};
  d["radius"] = s.radius;
  d["rms_residual"] = s.rms_residual;
  d["points_used"] = s.points_used;
  return d;
}

py::dict summary_dict(const ScanSummary& s) {
  py::dict d;
  d["vertices"] = s.vertices;
  d["vertices_tested"] = s.vertices_tested;
  d["vertices_no_surface"] = s.vertices_no_surface;
  d["vertices_beyond_reach"] = s.vertices_beyond_reach;
  d["vertices_refined"] = s.vertices_refined;
  d["vertices_tested_layered"] = s.vertices_tested_layered;
  d["min_gap_layered_mm"] = s.min_gap_layered_mm;
  d["min_gap_mm"] = s.min_gap_mm;
  d["vertices_penetrating"] = s.vertices_penetrating;
  d["area_penetrating_mm2"] = s.area_penetrating_mm2;
  d["level_area_mm2"] = s.level_area_mm2;
  d["level_vertices"] = s.level_vertices;
  return d;
}

// A map's view for Python: values as a read-only numpy view kept alive by the joint.
struct MapView {
  std::shared_ptr<const HipJoint> owner;
  const RadialDistanceMap* map;
};

// The Python Joint: a HipJoint plus its options.
struct PyJoint {
  std::shared_ptr<const HipJoint> hip;
  Side side = Side::right;
};

PyJoint make_joint(const py::handle& ball, const py::handle& socket, const py::handle& cor, const std::string& side,
                   const std::string& neutral, const std::string& scheme, double resolution, const std::string& mode,
                   const std::string& sampling, double occlusion_tolerance_mm, double max_radius_mm,
                   const std::optional<std::vector<double>>& levels, bool reseat, const std::string& pelvis_frame,
                   const std::string& femur_frame, const std::optional<std::pair<std::string, std::string>>& maps,
                   double sparse, int layers) {
  TriangleMesh b = to_mesh(ball, "ball"), s = to_mesh(socket, "socket");
  HipJointOptions o;
  o.joint.scheme = make_scheme(scheme, resolution > 0 ? resolution : default_resolution(scheme));
  o.joint.mode = parse_distance_mode(mode);
  o.joint.sampling = parse_sampling_method(sampling);
  o.joint.occlusion_tolerance_mm = occlusion_tolerance_mm;
  o.joint.max_radius_mm = max_radius_mm > 0 ? max_radius_mm : std::numeric_limits<double>::infinity();
  require(!std::isnan(sparse) && sparse >= 0, "Joint: sparse " + std::to_string(sparse) + " must be >= 0 mm or inf");
  o.joint.sparse_maps = sparse > 0;
  if (sparse > 0) o.joint.sparse_region_mm = sparse;
  o.joint.layers = layers;  // checked by Joint
  if (levels) {
    o.joint.levels.thresholds_mm = *levels;
    o.joint.levels.validate();
  }
  o.neutral = parse_neutral(neutral, "neutral");
  o.reseat = reseat;
  o.frames.pelvis = parse_pelvis_frame_kind(pelvis_frame, "pelvis_frame");
  o.frames.femur = parse_femur_frame_kind(femur_frame, "femur_frame");
  if (maps) o.ball_map_file = maps->first, o.socket_map_file = maps->second;
  PyJoint j;
  j.side = parse_side(side, "side");
  SphereFitResult head;
  if (cor.is_none()) {
    head = locate_femoral_head(b);
  } else {
    head.centre = to_point(cor, "cor");
    head.radius = std::nan("");
  }
  py::gil_scoped_release release;
  j.hip = std::make_shared<const HipJoint>(std::move(b), std::move(s), j.side, head, Landmarks{}, o);
  return j;
}

py::dict result_dict(PoseResult&& r) {
  py::dict d;
  const auto nb = static_cast<py::ssize_t>(r.ball_gaps.gap_mm.size());
  const auto ns = static_cast<py::ssize_t>(r.socket_gaps.gap_mm.size());
  py::dict summary;
  summary["ball"] = summary_dict(r.ball);
  summary["socket"] = summary_dict(r.socket);
  summary["ball_detection_ms"] = r.ball_detection_ms;
  summary["socket_detection_ms"] = r.socket_detection_ms;
  d["ball_gap_mm"] = own(std::move(r.ball_gaps.gap_mm), {nb});
  d["socket_gap_mm"] = own(std::move(r.socket_gaps.gap_mm), {ns});
  d["ball_status"] = own(std::move(r.ball_gaps.status), {nb});
  d["socket_status"] = own(std::move(r.socket_gaps.status), {ns});
  d["summary"] = summary;
  return d;
}

// Joint-frame rotation of a working-frame rotation R and translation t about the COR.
std::pair<Eigen::Matrix3d, Eigen::Vector3d> to_joint_frame(const HipJoint& h, const Eigen::Matrix3d& R,
                                                           const Eigen::Vector3d& t) {
  const Eigen::Matrix3d A = h.joint_to_working().transpose();
  return {A * R * A.transpose(), A * t};
}

// Checked clinical angles (k x 3, degrees) from a numpy array.
std::vector<PoseAngles> to_angles(const py::handle& angles_obj) {
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(angles_obj);
  if (!a || a.ndim() != 2 || a.shape(1) != 3)
    throw Error("angles: expected an array of shape (k, 3): flexion, adduction, internal rotation in degrees");
  std::vector<PoseAngles> poses(static_cast<std::size_t>(a.shape(0)));
  for (py::ssize_t f = 0; f < a.shape(0); ++f) {
    poses[static_cast<std::size_t>(f)] = {a.at(f, 0), a.at(f, 1), a.at(f, 2)};
    for (int c = 0; c < 3; ++c)
      if (!std::isfinite(a.at(f, c)))
        throw Error("angles: row " + std::to_string(f) + " column " + std::to_string(c) + " is not finite");
  }
  return poses;
}

struct MotionColumns {
  std::vector<double> ball_min, socket_min, ball_pen, socket_pen;
};

// Both scans at every pose (C++ only; the caller releases the GIL).
MotionColumns run_motion(const HipJoint& h, const std::vector<PoseAngles>& poses) {
  MotionColumns m;
  for (auto* v : {&m.ball_min, &m.socket_min, &m.ball_pen, &m.socket_pen}) v->resize(poses.size());
  PoseResult r;
  for (std::size_t f = 0; f < poses.size(); ++f) {
    h.detect(poses[f], r);
    m.ball_min[f] = r.ball.min_gap_mm;
    m.socket_min[f] = r.socket.min_gap_mm;
    m.ball_pen[f] = r.ball.area_penetrating_mm2;
    m.socket_pen[f] = r.socket.area_penetrating_mm2;
  }
  return m;
}

py::dict motion(const PyJoint& j, const py::handle& angles_obj) {
  const std::vector<PoseAngles> poses = to_angles(angles_obj);
  const auto k = static_cast<py::ssize_t>(poses.size());
  MotionColumns m;
  {
    py::gil_scoped_release release;
    m = run_motion(*j.hip, poses);
  }
  py::dict d;
  d["ball_min_gap_mm"] = own(std::move(m.ball_min), {k});
  d["socket_min_gap_mm"] = own(std::move(m.socket_min), {k});
  d["ball_penetrating_area_mm2"] = own(std::move(m.ball_pen), {k});
  d["socket_penetrating_area_mm2"] = own(std::move(m.socket_pen), {k});
  return d;
}

}  // namespace

PYBIND11_MODULE(impinge, m) {
  m.doc() =
      "impinge: impingement detection in ball-and-socket joints (the hip) by spherical radial distance maps.\n"
      "Units: mm and degrees. Vertices: float (n, 3); faces: integer (m, 3), 0-based. Gaps: positive apart,\n"
      "negative penetrating, NaN where a vertex was not tested.";
  m.attr("__version__") = IMPINGE_VERSION;
  static py::exception<Error> error(m, "Error", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const Error& e) {
      error(e.what());
    }
  });

  m.def(
      "load_mesh",
      [](const std::string& path) {
        TriangleMesh mesh;
        {
          py::gil_scoped_release release;
          mesh = load_mesh(path);
        }
        py::array_t<double> V({mesh.V.rows(), Eigen::Index(3)});
        std::copy(mesh.V.data(), mesh.V.data() + mesh.V.size(), V.mutable_data());
        py::array_t<std::int32_t> F({mesh.F.rows(), Eigen::Index(3)});
        std::copy(mesh.F.data(), mesh.F.data() + mesh.F.size(), F.mutable_data());
        return py::make_tuple(V, F);
      },
      py::arg("path"),
      "Load a triangle mesh (PLY, STL, OBJ or OFF) -> (V: float64 (n, 3) mm, F: int32 (m, 3)). Degenerate "
      "triangles are removed. Raises impinge.Error naming the file on a bad or missing file.");

  m.def(
      "fit_sphere",
      [](const py::handle& points) {
        const Vertices V = to_vertices(points, "points");
        return sphere_dict(fit_sphere_geometric(V));
      },
      py::arg("points"),
      "Geometric least-squares sphere through points (k, 3), mm (Eberly 1999; thesis sec. 3.4) -> dict(centre, "
      "radius, rms_residual, points_used). Raises impinge.Error on fewer than 4 or coplanar points.");

  m.def(
      "locate_femoral_head",
      [](const py::handle& V, const py::handle& F) {
        const TriangleMesh mesh = to_mesh(py::make_tuple(V, F), "femur");
        py::gil_scoped_release release;
        return locate_femoral_head(mesh);
      },
      py::arg("V"), py::arg("F"),
      "Femoral head sphere of a whole femur in any orientation (long axis, RANSAC and geometric fit) -> "
      "SphereFit.");

  m.def(
      "generated_hip",
      [](int triangles, double cam_mm, double coverage_deg) {
        HipModelOptions o;
        o.target_triangles = triangles;
        o.cam_height_mm = cam_mm;
        o.cup_coverage_deg = coverage_deg;
        const HipModel h = make_hip_model(o);
        auto mesh = [](const TriangleMesh& t) {
          py::array_t<double> V({t.V.rows(), Eigen::Index(3)});
          std::copy(t.V.data(), t.V.data() + t.V.size(), V.mutable_data());
          py::array_t<std::int32_t> F({t.F.rows(), Eigen::Index(3)});
          std::copy(t.F.data(), t.F.data() + t.F.size(), F.mutable_data());
          return py::make_tuple(V, F);
        };
        py::dict d;
        d["ball"] = mesh(h.ball);
        d["socket"] = mesh(h.socket);
        d["cor"] = h.cor;
        d["head_radius_mm"] = o.head_radius_mm;
        return d;
      },
      py::arg("triangles") = 3000, py::arg("cam_mm") = 0.0, py::arg("coverage_deg") = 100.0,
      "A generated hip (sphere head with neck, optional cam bump, cup with rim; scan frame RAS, mm) -> "
      "dict(ball=(V, F), socket=(V, F), cor, head_radius_mm). Use it with neutral='scan'.");

  py::class_<SphereFitResult>(m, "SphereFit", "A fitted sphere: centre (mm), radius (mm), rms_residual (mm).")
      .def_property_readonly("centre", [](const SphereFitResult& s) { return s.centre; })
      .def_readonly("radius", &SphereFitResult::radius)
      .def_readonly("rms_residual", &SphereFitResult::rms_residual)
      .def_readonly("points_used", &SphereFitResult::points_used);

  py::class_<MapView>(m, "Map", "A radial distance map (read-only): one distance (mm) per node, inf = no surface.")
      .def_property_readonly(
          "values",
          [](const MapView& v) {
            if (v.map->sparse()) {  // no dense array to view: a copy, absent tiles as inf
              py::array_t<float> a(py::ssize_t(v.map->num_nodes()));
              float* out = a.mutable_data();
              for (std::int64_t i = 0; i < v.map->num_nodes(); ++i) out[i] = v.map->at(i);
              py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
              return a;
            }
            py::array_t<float> a({py::ssize_t(v.map->num_nodes())}, {py::ssize_t(sizeof(float))}, v.map->data(),
                                 py::cast(v));
            py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
            return a;
          },
          "Node distances, float32 (num_nodes,), mm; a read-only view of the map (no copy), or a read-only copy "
          "of a sparse map.")
      .def(
          "node_directions",
          [](const MapView& v) {
            const std::int64_t n = v.map->num_nodes();
            std::vector<double> d(static_cast<std::size_t>(3 * n));
            for (std::int64_t i = 0; i < n; ++i) {
              const Eigen::Vector3d u = v.map->scheme().node_direction(i);
              for (int c = 0; c < 3; ++c) d[static_cast<std::size_t>(3 * i + c)] = u[c];
            }
            return own(std::move(d), {py::ssize_t(n), 3});
          },
          "Unit direction of every node, float64 (num_nodes, 3), in the joint frame.")
      .def_property_readonly("scheme", [](const MapView& v) { return v.map->scheme().name(); })
      .def_property_readonly("resolution", [](const MapView& v) { return v.map->scheme().resolution(); })
      .def_property_readonly("num_nodes", [](const MapView& v) { return v.map->num_nodes(); })
      .def_property_readonly("nodes_covered", [](const MapView& v) { return v.map->nodes_covered(); })
      .def_property_readonly("bytes", [](const MapView& v) { return v.map->bytes(); })
      .def_property_readonly("sparse", [](const MapView& v) { return v.map->sparse(); });

  py::class_<PyJoint>(m, "Joint",
                      "A hip: femur (ball) and pelvis (socket) in one frame (mm), both radial distance maps built "
                      "once, then any number of poses.")
      .def(py::init(&make_joint), py::arg("ball"), py::arg("socket"), py::arg("cor") = py::none(),
           py::arg("side") = "right", py::arg("neutral") = "anatomical", py::arg("scheme") = "equiangular",
           py::arg("resolution") = 0.0, py::arg("mode") = "exact", py::arg("sampling") = "auto",
           py::arg("occlusion_tolerance_mm") = 1.0, py::arg("max_radius_mm") = 0.0,
           py::arg("levels") = py::none(), py::arg("reseat") = false, py::arg("pelvis_frame") = "isb",
           py::arg("femur_frame") = "epicondyles", py::arg("maps") = py::none(), py::arg("sparse") = 0.0,
           py::arg("layers") = 0,
           "ball, socket: (V (n, 3) float, F (m, 3) int) in one frame, mm (RAS-like: x right, y anterior, z "
           "superior for neutral='scan'). cor: centre of rotation (3,), mm; None fits the femoral head. "
           "neutral: 'anatomical' (ISB frames found on whole bones) or 'scan'. scheme/resolution: sampling "
           "scheme and its resolution (0: the scheme's default, 0.5 deg equivalent). mode: 'exact' or 'linear'. "
           "levels: impingement thresholds (mm, decreasing). maps: (ball_path, socket_path) saved by save_maps() "
           "to load instead of sampling. sparse: store the maps sparse, keeping the tiles with a surface within this "
           "many mm of the COR (inf: any surface, the same gaps bit for bit; 0: dense). layers: N > 0 also tests "
           "the vertices hidden behind their own bone against the other bone's layered map of N crossings per node "
           "(extra-articular impingement; their gaps appear with the others). Builds both maps (the GIL is released). Raises impinge.Error on bad "
           "arrays, options or map files.")
      .def(
          "detect",
          [](const PyJoint& j, const py::handle& R, const py::handle& t) {
            const Eigen::Matrix3d Rw = to_rotation(R);
            const Eigen::Vector3d tw = t.is_none() ? Eigen::Vector3d::Zero() : to_point(t, "t");
            const auto [Rj, tj] = to_joint_frame(*j.hip, Rw, tw);
            PoseResult r;
            {
              py::gil_scoped_release release;
              j.hip->joint().detect(Rj, tj, r);
            }
            return result_dict(std::move(r));
          },
          py::arg("R") = py::none(), py::arg("t") = py::none(),
          "Both scans with the femur rotated by R (3, 3; input frame) about the COR, then translated by t (3,) "
          "mm -> dict(ball_gap_mm, socket_gap_mm: float32 (n,) in the input's vertex order, NaN where not "
          "tested; ball_status, socket_status: uint8 (0 tested, 1 no surface, 2 beyond reach); summary).")
      .def(
          "detect_pose",
          [](const PyJoint& j, double flexion, double adduction, double internal_rotation) {
            PoseResult r;
            {
              py::gil_scoped_release release;
              j.hip->detect(PoseAngles{flexion, adduction, internal_rotation}, r);
            }
            return result_dict(std::move(r));
          },
          py::arg("flexion") = 0.0, py::arg("adduction") = 0.0, py::arg("internal_rotation") = 0.0,
          "Both scans at clinical angles (degrees, ISB joint coordinate system: flexion, adduction and internal "
          "rotation positive; zero per `neutral`) -> the same dict as detect().")
      .def("motion", &motion, py::arg("angles"),
           "Both scans at every row of angles (k, 3): flexion, adduction, internal rotation in degrees -> "
           "dict of float64 (k,) arrays: ball_min_gap_mm, socket_min_gap_mm, ball_penetrating_area_mm2, "
           "socket_penetrating_area_mm2. One call; the GIL is released.")
      .def(
          "save_maps", [](const PyJoint& j, const std::string& ball, const std::string& socket) {
            j.hip->save_maps(ball, socket);
          },
          py::arg("ball_path"), py::arg("socket_path"),
          "Save both maps (impinge map files with scheme, resolution, COR and checksum) for Joint(..., maps=...).")
      .def(
          "rom_limits",
          [](const PyJoint& j, double threshold_mm, double step_deg, double max_deg) {
            RomOptions o;
            o.threshold_mm = threshold_mm;
            o.step_deg = step_deg;
            o.max_deg = max_deg;
            const std::vector<StandardMotion> motions = standard_motions();
            std::vector<RomLimit> limits;
            RomBaseline base;
            {
              py::gil_scoped_release release;
              base = rom_baseline(*j.hip, j.hip->femur_rotation({}), o);
              limits = find_rom_limits(*j.hip, motions, o, base);
            }
            py::dict d;
            for (std::size_t k = 0; k < motions.size(); ++k) {
              const RomLimit& l = limits[k];
              py::dict e;
              e["limit_deg"] = l.limit_deg;
              e["limited_by"] = to_string(l.limited_by);
              e["socket_clock_h"] = l.socket_clock_h;
              e["femur_clock_h"] = l.femur_clock_h;
              e["min_gap_at_limit_mm"] = l.min_gap_at_limit_mm;
              e["contact_mm"] = l.contact_mm;
              e["monotone"] = l.monotone;
              e["contact_at_start"] = l.contact_at_start;
              d[py::str(motions[k].name)] = e;
            }
            d["excluded_vertices"] = base.excluded_vertices;
            return d;
          },
          py::arg("threshold_mm") = 0.0, py::arg("step_deg") = 2.0, py::arg("max_deg") = 150.0,
          "ROM limits from neutral for the standard motions (flexion, extension, abduction, adduction, internal and "
          "external rotation, both rotations at 90 deg flexion, FADIR) -> dict motion -> dict(limit_deg (NaN: none "
          "within max_deg), limited_by, socket_clock_h, femur_clock_h, min_gap_at_limit_mm, contact_mm (input "
          "frame), monotone, contact_at_start); and excluded_vertices (in contact at neutral, not counted).")
      .def(
          "rom_map",
          [](const PyJoint& j, const std::vector<double>& flexion, const std::vector<double>& adduction,
             double threshold_mm) {
            RomOptions o;
            o.threshold_mm = threshold_mm;
            std::vector<RomMapCell> cells;
            {
              py::gil_scoped_release release;
              const RomBaseline base = rom_baseline(*j.hip, j.hip->femur_rotation({}), o);
              cells = rom_map(*j.hip, flexion, adduction, o, base);
            }
            std::vector<double> ir(cells.size());
            for (std::size_t k = 0; k < cells.size(); ++k) ir[k] = cells[k].max_internal_rotation_deg;
            return own(std::move(ir), {py::ssize_t(flexion.size()), py::ssize_t(adduction.size())});
          },
          py::arg("flexion"), py::arg("adduction"), py::arg("threshold_mm") = 0.0,
          "ROM map: the largest internal rotation (deg) before contact for every flexion x adduction (deg) -> "
          "float64 (len(flexion), len(adduction)); NaN where in contact already without rotation or free up to "
          "150 deg.")
      .def(
          "femur_rotation",
          [](const PyJoint& j, double flexion, double adduction, double internal_rotation) {
            const HipJoint& h = *j.hip;
            const Eigen::Matrix3d A = h.joint_to_working();
            return Eigen::Matrix3d(A * h.femur_rotation({flexion, adduction, internal_rotation}) * A.transpose());
          },
          py::arg("flexion") = 0.0, py::arg("adduction") = 0.0, py::arg("internal_rotation") = 0.0,
          "Rotation (3, 3; input frame) of the femur about the COR at the clinical angles.")
      .def_property_readonly("cor", [](const PyJoint& j) { return j.hip->cor(); },
                             "Centre of rotation (3,), mm, input frame.")
      .def_property_readonly("ball_map", [](const PyJoint& j) { return MapView{j.hip, &j.hip->joint().ball().map}; })
      .def_property_readonly("socket_map",
                             [](const PyJoint& j) { return MapView{j.hip, &j.hip->joint().socket().map}; })
      .def_property_readonly(
          "frames",
          [](const PyJoint& j) -> py::object {
            if (!j.hip->frames()) return py::none();
            const HipFrames& f = *j.hip->frames();
            py::dict d;
            for (const auto& [name, frame] : {std::pair{"pelvis", &f.pelvis}, std::pair{"femur", &f.femur}}) {
              py::dict fr;
              fr["origin"] = frame->origin;
              fr["axes"] = frame->axes;
              py::dict lm;
              for (const auto& [k, p] : frame->landmarks) lm[py::str(k)] = p;
              fr["landmarks"] = lm;
              d[name] = fr;
            }
            d["scan_pose"] = std::vector<double>{f.scan_pose.flexion_deg, f.scan_pose.adduction_deg,
                                                 f.scan_pose.internal_rotation_deg};
            return d;
          },
          "Anatomical frames (anatomical neutral; None with scan neutral): origin (3,), axes (3, 3; columns X "
          "anterior, Y superior, Z right), landmarks; scan_pose in degrees.")
      .def(
          "_bench_detect_ns",
          [](const PyJoint& j, const py::handle& R, int repetitions) {
            // Median ns of Joint::detect (C++ loop, reused buffers): the reference for the binding's overhead.
            const auto [Rj, tj] = to_joint_frame(*j.hip, to_rotation(R), Eigen::Vector3d::Zero());
            std::vector<double> ns;
            PoseResult r;
            py::gil_scoped_release release;
            for (int k = 0; k < repetitions; ++k) {
              const auto t0 = std::chrono::steady_clock::now();
              j.hip->joint().detect(Rj, tj, r);
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
            py::gil_scoped_release release;
            const auto t0 = std::chrono::steady_clock::now();
            const MotionColumns m = run_motion(*j.hip, poses);
            return std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count();
          },
          py::arg("angles"));
}
