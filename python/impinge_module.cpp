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

#include <omp.h>

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
#include "impinge/io/motion.hpp"
#include "impinge/io/subject.hpp"
#include "impinge/maps/map_io.hpp"
#include "impinge/sampling/sampling.hpp"
#include "impinge/schemes/sampling_scheme.hpp"
#include "impinge/session/records.hpp"
#include "impinge/session/runs.hpp"
#include "impinge/session/session.hpp"
#include <functional>

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


// A map's view for Python: values as a read-only numpy view kept alive by the joint.
struct MapView {
  std::shared_ptr<const HipJoint> owner;
  const RadialDistanceMap* map;
};

// The Python Joint: a Session (impinge/session/session.hpp), as the CLI builds it.
struct PyJoint {
  std::shared_ptr<const Session> session;
  const HipJoint& hip() const { return session->hip(); }
};

// ---- Joint's options: one table, the same names as the CLI's (dashes as underscores, "_mm" where a
// length), so that Joint(...) takes every option `impinge distance` takes.

std::string as_string(const py::handle& v, const std::string& name) {
  if (!py::isinstance<py::str>(v)) throw Error(name + ": expected a string, got " + std::string(py::str(v.get_type())));
  return v.cast<std::string>();
}
double as_double(const py::handle& v, const std::string& name) {
  try {
    return py::float_(py::reinterpret_borrow<py::object>(v)).cast<double>();
  } catch (const py::error_already_set&) {
    throw Error(name + ": expected a number, got " + std::string(py::str(v.get_type())));
  }
}
int as_int(const py::handle& v, const std::string& name) {
  const double x = as_double(v, name);
  if (x != std::floor(x) || std::fabs(x) > 1e9) throw Error(name + ": expected a whole number, got " + std::to_string(x));
  return static_cast<int>(x);
}
bool as_bool(const py::handle& v, const std::string& name) {
  if (!py::isinstance<py::bool_>(v)) throw Error(name + ": expected True or False");
  return v.cast<bool>();
}
std::vector<double> as_numbers(const py::handle& v, const std::string& name, std::size_t count) {
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(v);
  if (!a || a.ndim() != 1 || (count > 0 && static_cast<std::size_t>(a.size()) != count))
    throw Error(name + ": expected " + (count ? std::to_string(count) + " numbers" : std::string("a list of numbers")));
  std::vector<double> out(a.data(), a.data() + a.size());
  for (double x : out)
    if (!std::isfinite(x)) throw Error(name + ": not finite");
  return out;
}

// A mesh option: a file path or a pair (V, F) of arrays.
void set_mesh(const py::handle& v, const std::string& name, std::string& path, std::optional<TriangleMesh>& mesh) {
  if (py::isinstance<py::str>(v) || py::hasattr(v, "__fspath__"))
    path = py::str(py::module_::import("os").attr("fspath")(v)).cast<std::string>();
  else
    mesh = to_mesh(v, name);
}

using OptionSetter = std::function<void(SessionOptions&, const py::handle&, const std::string&)>;

// Every option of Joint(...) by name (sorted as the CLI's help lists them).
const std::vector<std::pair<std::string, OptionSetter>>& joint_options() {
  static const std::vector<std::pair<std::string, OptionSetter>> t = {
      {"subject", [](SessionOptions& o, const py::handle& v, const std::string& n) {
         o.input.subject = py::str(py::module_::import("os").attr("fspath")(v)).cast<std::string>();
         (void)n;
       }},
      {"ball", [](SessionOptions& o, const py::handle& v, const std::string& n) {
         set_mesh(v, n, o.input.ball, o.input.ball_mesh);
       }},
      {"socket", [](SessionOptions& o, const py::handle& v, const std::string& n) {
         set_mesh(v, n, o.input.socket, o.input.socket_mesh);
       }},
      {"side", [](SessionOptions& o, const py::handle& v, const std::string& n) { o.input.side = as_string(v, n); }},
      {"frame", [](SessionOptions& o, const py::handle& v, const std::string& n) { o.input.frame = as_string(v, n); }},
      {"cor", [](SessionOptions& o, const py::handle& v, const std::string& n) {
         if (py::isinstance<py::str>(v)) {
           o.cor.given = parse_cor(v.cast<std::string>(), n);
         } else {
           const auto x = as_numbers(v, n, 3);
           o.cor.given = Eigen::Vector3d(x[0], x[1], x[2]);
         }
       }},
      {"allow_any_cor", [](SessionOptions& o, const py::handle& v, const std::string& n) { o.cor.allow_any = as_bool(v, n); }},
      {"head_region", [](SessionOptions& o, const py::handle& v, const std::string& n) {
         const auto x = as_numbers(v, n, 4);
         if (!(x[3] > 0)) throw Error(n + ": the radius R must be > 0 mm");
         o.cor.head_region = Eigen::Vector4d(x[0], x[1], x[2], x[3]);
       }},
      {"landmarks", [](SessionOptions& o, const py::handle& v, const std::string& n) {
         if (!py::isinstance<py::dict>(v)) throw Error(n + ": expected a dict name -> (x, y, z) mm");
         for (const auto& [k, p] : py::reinterpret_borrow<py::dict>(v)) {
           const auto x = as_numbers(p, n + "['" + py::str(k).cast<std::string>() + "']", 3);
           o.input.landmarks[py::str(k).cast<std::string>()] = Eigen::Vector3d(x[0], x[1], x[2]);
         }
       }},
      {"scheme", [](SessionOptions& o, const py::handle& v, const std::string& n) { o.maps.scheme = as_string(v, n); }},
      {"resolution", [](SessionOptions& o, const py::handle& v, const std::string& n) { o.maps.resolution = as_double(v, n); }},
      {"precision", [](SessionOptions& o, const py::handle& v, const std::string& n) { o.maps.precision = as_double(v, n); }},
      {"turns", [](SessionOptions& o, const py::handle& v, const std::string& n) { o.maps.turns = as_double(v, n); }},
      {"spacing", [](SessionOptions& o, const py::handle& v, const std::string& n) { o.maps.spacing = as_double(v, n); }},
      {"sampling", [](SessionOptions& o, const py::handle& v, const std::string& n) { o.maps.sampling = as_string(v, n); }},
      {"mode", [](SessionOptions& o, const py::handle& v, const std::string& n) { o.maps.mode = as_string(v, n); }},
      {"levels", [](SessionOptions& o, const py::handle& v, const std::string& n) { o.maps.levels = as_numbers(v, n, 0); }},
      {"occlusion_tolerance_mm", [](SessionOptions& o, const py::handle& v, const std::string& n) {
         o.maps.occlusion_tolerance_mm = as_double(v, n);
       }},
      {"max_radius_mm", [](SessionOptions& o, const py::handle& v, const std::string& n) { o.maps.max_radius_mm = as_double(v, n); }},
      {"sparse", [](SessionOptions& o, const py::handle& v, const std::string& n) { o.maps.sparse_mm = as_double(v, n); }},
      {"discontinuity_tolerance_mm", [](SessionOptions& o, const py::handle& v, const std::string& n) {
         o.maps.discontinuity_tolerance_mm = as_double(v, n);
       }},
      {"layers", [](SessionOptions& o, const py::handle& v, const std::string& n) { o.maps.layers = as_int(v, n); }},
      {"extra_articular_radius_mm", [](SessionOptions& o, const py::handle& v, const std::string& n) {
         o.maps.extra_articular_radius_mm = as_double(v, n);
       }},
      {"layered_spacing", [](SessionOptions& o, const py::handle& v, const std::string& n) {
         o.maps.layered_spacing_deg = as_double(v, n);
       }},
      {"distances", [](SessionOptions& o, const py::handle& v, const std::string& n) { o.maps.distances = as_bool(v, n); }},
      {"levels_on", [](SessionOptions& o, const py::handle& v, const std::string& n) { o.maps.levels_on = as_string(v, n); }},
      {"distance_reach_mm", [](SessionOptions& o, const py::handle& v, const std::string& n) {
         o.maps.distance_reach_mm = as_double(v, n);
       }},
      {"maps_only", [](SessionOptions& o, const py::handle& v, const std::string& n) { o.maps.maps_only = as_bool(v, n); }},
      {"maps", [](SessionOptions& o, const py::handle& v, const std::string& n) {
         const auto p = py::cast<std::pair<std::string, std::string>>(v);
         (void)n;
         o.maps.ball_map_file = p.first, o.maps.socket_map_file = p.second;
       }},
      {"neutral", [](SessionOptions& o, const py::handle& v, const std::string& n) { o.frames.neutral = as_string(v, n); }},
      {"pelvis_frame", [](SessionOptions& o, const py::handle& v, const std::string& n) { o.frames.pelvis_frame = as_string(v, n); }},
      {"joint_centre", [](SessionOptions& o, const py::handle& v, const std::string& n) { o.frames.joint_centre = as_string(v, n); }},
      {"femur_frame", [](SessionOptions& o, const py::handle& v, const std::string& n) { o.frames.femur_frame = as_string(v, n); }},
  };
  return t;
}

PyJoint make_joint(const py::object& ball, const py::object& socket, const py::kwargs& kw) {
  SessionOptions o;
  o.maps.layers = 4;        // as the CLI: the whole bone by default
  o.maps.distances = true;  // and the Euclidean distances beside the gaps
  const auto& table = joint_options();
  auto set = [&](const std::string& name, const py::handle& v) {
    if (v.is_none()) return;  // None: the default
    for (const auto& [n, setter] : table)
      if (n == name) {
        setter(o, v, name);
        return;
      }
    std::string known;
    for (const auto& [n, setter] : table) known += (known.empty() ? "" : ", ") + n;
    throw Error("Joint: unknown option '" + name + "' (options: " + known + ")");
  };
  set("ball", ball);
  set("socket", socket);
  for (const auto& [k, v] : kw) set(py::str(k).cast<std::string>(), v);
  PyJoint j;
  {
    py::gil_scoped_release release;
    j.session = std::make_shared<const Session>(o);
  }
  for (const std::string& w : j.session->warnings())
    if (PyErr_WarnEx(PyExc_UserWarning, ("impinge: " + w).c_str(), 1) != 0) throw py::error_already_set();
  return j;
}

// A JSON record (records.hpp) as Python objects (dicts, lists, numbers, strings; null as None),
// converted directly (no text in between: detect() returns one per call).
py::object from_json(const nlohmann::json& j) {
  switch (j.type()) {
    case nlohmann::json::value_t::object: {
      py::dict d;
      for (const auto& [k, v] : j.items()) d[py::str(k)] = from_json(v);
      return std::move(d);
    }
    case nlohmann::json::value_t::array: {
      py::list l;
      for (const auto& v : j) l.append(from_json(v));
      return std::move(l);
    }
    case nlohmann::json::value_t::string: return py::str(j.get<std::string>());
    case nlohmann::json::value_t::boolean: return py::bool_(j.get<bool>());
    case nlohmann::json::value_t::number_integer: return py::int_(j.get<std::int64_t>());
    case nlohmann::json::value_t::number_unsigned: return py::int_(j.get<std::uint64_t>());
    case nlohmann::json::value_t::number_float: return py::float_(j.get<double>());
    default: return py::none();
  }
}

// A table's columns as a dict of arrays: float64 for numbers (None as NaN), lists for text.
py::dict table_columns(const Table& t) {
  py::dict d;
  for (std::size_t c = 0; c < t.columns.size(); ++c) {
    const bool text = !t.rows.empty() && t.rows[0][c].is_string();
    if (text) {
      py::list l;
      for (const auto& r : t.rows) l.append(r[c].get<std::string>());
      d[py::str(t.columns[c])] = l;
      continue;
    }
    std::vector<double> v(t.rows.size());
    for (std::size_t k = 0; k < v.size(); ++k) {
      const auto& x = t.rows[k][c];
      v[k] = x.is_null() ? std::nan("") : x.is_boolean() ? double(x.get<bool>()) : x.get<double>();
    }
    d[py::str(t.columns[c])] = own(std::move(v), {py::ssize_t(t.rows.size())});
  }
  return d;
}

// Both scans as Python: the gaps and statuses as numpy arrays (owning the C++ buffers), and each
// scan's summary as summary.json records it (scan_record).
py::dict result_dict(const Session& session, PoseResult&& r) {
  py::dict d;
  const auto nb = static_cast<py::ssize_t>(r.ball_gaps.gap_mm.size());
  const auto ns = static_cast<py::ssize_t>(r.socket_gaps.gap_mm.size());
  const ImpingementLevels& levels = session.joint_options().levels;
  py::dict summary;
  summary["ball"] = from_json(scan_record(session.joint().ball(), r.ball, r.ball_detection_ms, levels, nullptr));
  summary["socket"] =
      from_json(scan_record(session.joint().socket(), r.socket, r.socket_detection_ms, levels, nullptr));
  summary["ball_detection_ms"] = r.ball_detection_ms;
  summary["socket_detection_ms"] = r.socket_detection_ms;
  if (session.joint_options().distances) {
    summary["ball_distance_ms"] = r.ball_distance_ms;
    summary["socket_distance_ms"] = r.socket_distance_ms;
  }
  d["ball_gap_mm"] = own(std::move(r.ball_gaps.gap_mm), {nb});
  d["socket_gap_mm"] = own(std::move(r.socket_gaps.gap_mm), {ns});
  if (!r.ball_gaps.distance_mm.empty()) {
    d["ball_distance_mm"] = own(std::move(r.ball_gaps.distance_mm), {nb});
    d["socket_distance_mm"] = own(std::move(r.socket_gaps.distance_mm), {ns});
  }
  d["ball_status"] = own(std::move(r.ball_gaps.status), {nb});
  d["socket_status"] = own(std::move(r.socket_gaps.status), {ns});
  d["summary"] = summary;
  return d;
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

// Both scans at every pose: the motion table's columns (frames.csv's), one C++ loop without the GIL.
py::dict motion(const PyJoint& j, const py::handle& angles_obj) {
  const std::vector<PoseAngles> poses = to_angles(angles_obj);
  Table t;
  t.columns = motion_columns(j.session->joint_options().levels);
  t.rows.reserve(poses.size());
  {
    py::gil_scoped_release release;
    run_motion(*j.session, poses, {}, [&](const MotionFrame& f) { t.rows.push_back(motion_row(f)); });
  }
  py::dict d = table_columns(t);
  d["socket_penetrating_area_mm2"] = d["penetrating_area_mm2"];
  return d;
}

void bind_functions(py::module_& m) {
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
      "set_threads",
      [](int n) {
        if (n < 1) throw Error("set_threads: n = " + std::to_string(n) + ": must be >= 1");
        omp_set_num_threads(n);
      },
      py::arg("n"),
      "Threads (OpenMP) of the calling thread's later calls: ROM searches and maps, sampling. Default: one per "
      "core (or OMP_NUM_THREADS). Studies give each task one thread (impinge.study).");
  m.def("get_threads", []() { return omp_get_max_threads(); },
        "Threads (OpenMP) the calling thread's next parallel call would use.");

  m.def(
      "load_motion",
      [](const std::string& path, const std::string& side) {
        Motion motion;
        {
          const Side s = parse_side(side, "side");
          py::gil_scoped_release release;
          motion = load_motion(path, s);
        }
        std::vector<double> angles(motion.frames() * 3);
        for (std::size_t k = 0; k < motion.frames(); ++k) {
          angles[3 * k] = motion.angles[k].flexion_deg;
          angles[3 * k + 1] = motion.angles[k].adduction_deg;
          angles[3 * k + 2] = motion.angles[k].internal_rotation_deg;
        }
        py::dict d;
        d["time_s"] = own(std::move(motion.time_s), {py::ssize_t(motion.frames())});
        d["angles"] = own(std::move(angles), {py::ssize_t(motion.frames()), py::ssize_t(3)});
        d["format"] = motion.format;
        return d;
      },
      py::arg("path"), py::arg("side") = "right",
      "Read a motion file as impinge motion reads it (io/motion.hpp): CSV with time_s, flexion_deg, adduction_deg, "
      "internal_rotation_deg, or OpenSim .mot/.sto with hip_flexion_r|l, hip_adduction_r|l, hip_rotation_r|l "
      "(side: 'right' or 'left'; radians converted) -> dict(time_s: float64 (k,) s, angles: float64 (k, 3) degrees "
      "(flexion, adduction, internal rotation; ISB), format: 'csv' or 'opensim'). Raises impinge.Error naming the "
      "file, line and column.");

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
      [](const py::handle& V, const py::handle& F, const py::handle& pelvis) {
        const TriangleMesh mesh = to_mesh(py::make_tuple(V, F), "femur");
        if (pelvis.is_none()) {
          py::gil_scoped_release release;
          return locate_femoral_head(mesh);
        }
        const TriangleMesh p = to_mesh(pelvis, "pelvis");
        py::gil_scoped_release release;
        return locate_femoral_head(mesh, p);
      },
      py::arg("V"), py::arg("F"), py::arg("pelvis") = py::none(),
      "Femoral head sphere of a femur in any orientation (long axis, RANSAC and geometric fit at each end) -> "
      "SphereFit. pelvis: (V, F) in the same frame: the head is the end that sits in the acetabulum, as the "
      "CLI finds it (whole or proximal femur, either side); without it, the end with the better sphere. Raises "
      "impinge.Error when it cannot tell which end is proximal.");

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

}

void bind_types(py::module_& m) {
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

}

std::string joint_doc() {
  std::string names;
  for (const auto& [n, setter] : joint_options()) names += (names.empty() ? "" : ", ") + n;
  return "Joint(ball=None, socket=None, **options): a hip set up as `impinge distance` sets it up (the session "
         "layer): femur (ball) and pelvis (socket) from a subject.json, mesh files or (V, F) arrays, in their input "
         "frame (frame='LPS' or 'RAS', mm); both maps built once (the GIL is released), then any number of poses. "
         "Options, named as the CLI's with underscores (None or absent: the default): " + names +
         ". cor: 'auto', or (x, y, z) mm in the input frame; head_region: (x, y, z, r) mm; landmarks: dict name -> "
         "(x, y, z) mm; levels: thresholds in mm, decreasing; maps: (ball_path, socket_path) saved by save_maps(). "
         "Positions, rotations and frames given or returned are in the input frame. Raises impinge.Error naming "
         "the option, array or file on bad input; warnings (e.g. an overlap at the scan pose) as UserWarning.";
}

// The ROM metric by name; "" (the default): the distance where the joint has distances on, else the radial gap.
RomMetric metric_of(const PyJoint& j, const std::string& metric) {
  if (metric.empty()) return j.session->joint().options().distances ? RomMetric::distance : RomMetric::radial;
  return parse_rom_metric(metric, "metric");
}

py::dict rom_limits(const PyJoint& j, double threshold_mm, double step_deg, double max_deg, const std::string& contacts,
                    double contact_depth_mm, const std::string& metric) {
  RomRequest q;
  q.search.metric = metric_of(j, metric);
  q.search.contact_depth_mm = contact_depth_mm;
  q.search.contacts = parse_rom_contacts(contacts, "contacts");
  q.search.threshold_mm = threshold_mm;
  q.search.step_deg = step_deg;
  q.search.max_deg = max_deg;
  q.map = false;
  RomRun run;
  {
    py::gil_scoped_release release;
    run = run_rom(*j.session, q);
  }
  const Table t = rom_limits_table(*j.session, run);
  py::dict d;
  for (std::size_t k = 0; k < t.rows.size(); ++k) {
    py::dict e;
    for (std::size_t c = 1; c < t.columns.size(); ++c) {
      const nlohmann::json& x = t.rows[k][c];
      e[py::str(t.columns[c])] = x.is_null() ? py::object(py::float_(std::nan(""))) : from_json(x);
    }
    e["contact_mm"] = Eigen::Vector3d(j.session->to_input(run.limits[k].contact_mm));
    d[py::str(run.motions[k].name)] = e;
  }
  d["excluded_vertices"] = run.baseline.excluded_vertices;
  return d;
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
       "Both scans with the femur rotated by R (3, 3; input frame) about the COR, then translated by t (3,) "
       "mm -> dict(ball_gap_mm, socket_gap_mm: float32 (n,) in the input's vertex order, NaN where not "
       "tested; ball_distance_mm, socket_distance_mm: float32 (n,), the signed Euclidean distance to the other "
       "bone, NaN beyond the reach (with distances on); ball_status, socket_status: uint8 (0 tested, 1 no "
       "surface, 2 beyond reach); summary).")
      .def(
          "detect_pose",
          [](const PyJoint& j, double flexion, double adduction, double internal_rotation) {
            PoseResult r;
            FemurPose p;
            {
              py::gil_scoped_release release;
              p = j.hip().femur_pose(PoseAngles{flexion, adduction, internal_rotation});
              j.hip().joint().detect(p.R, p.t, r);
            }
            py::dict d = result_dict(*j.session, std::move(r));
            d["joint_translation_mm"] = Eigen::Vector3d(j.session->to_input(j.hip().femur_translation(p.t)));
            return d;
          },
          py::arg("flexion") = 0.0, py::arg("adduction") = 0.0, py::arg("internal_rotation") = 0.0,
          "Both scans at clinical angles (degrees, ISB joint coordinate system: flexion, adduction and internal "
          "rotation positive; zero per `neutral`), the femur placed by the joint-centre method (option "
          "joint_centre) -> the same dict as detect(), with joint_translation_mm (3,): the femur's translation "
          "(input frame, mm) after its rotation about the COR.")
      .def("motion", &motion, py::arg("angles"),
           "Both scans at every row of angles (k, 3): flexion, adduction, internal rotation in degrees -> dict of "
           "(k,) arrays, the columns of the CLI's frames.csv (ball_min_gap_mm, socket_min_gap_mm, "
           "penetrating_area_mm2 = socket_penetrating_area_mm2, ball_penetrating_area_mm2, socket_levelN_area_mm2, "
           "closest clock hours and point, detection_ms). One C++ loop, frames in blocks on impinge.get_threads() "
           "threads (rows in order); the GIL is released.")
      .def("rom_limits", &rom_limits, py::arg("threshold_mm") = 0.0, py::arg("step_deg") = 2.0,
           py::arg("max_deg") = 150.0, py::arg("contacts") = "impingement",
           py::arg("contact_depth_mm") = RomOptions{}.contact_depth_mm, py::arg("metric") = "",
           "ROM limits from neutral for the standard motions (flexion, extension, abduction, adduction, internal and "
           "external rotation, both rotations at 90 deg flexion, FADIR) -> dict motion -> the CLI's rom_limits.csv "
           "row (limit_deg (NaN: none within max_deg), limited_by, contact_class, socket_clock_h, femur_clock_h, "
           "min_gap_at_limit_mm, monotone, contact_at_start, evaluations) and contact_mm (input frame); and "
           "excluded_vertices (in contact at neutral, not counted). contacts: 'impingement' (the joint surfaces left out), "
           "'articular' (only they: where the joint space closes) or 'all'. contact_depth_mm: how far past the "
           "threshold a contact must reach to end a search (CLI --contact-depth; 0: the first touch). metric: 'radial' (the "
           "thesis' radial gap) or 'distance' (the signed Euclidean distance, the CLI's default; needs distances on "
           "with a distance_reach_mm of at least the threshold; min_gap_at_limit_mm is then a distance); default: "
           "'distance' when the joint has distances on, else 'radial'.")
      .def(
          "rom_map",
          [](const PyJoint& j, const std::vector<double>& flexion, const std::vector<double>& adduction,
             double threshold_mm, double contact_depth_mm, const std::string& metric) {
            RomOptions o;
            o.metric = metric_of(j, metric);
            o.threshold_mm = threshold_mm;
            o.contact_depth_mm = contact_depth_mm;
            std::vector<RomMapCell> cells;
            {
              py::gil_scoped_release release;
              const RomBaseline base = rom_baseline(j.hip(), j.hip().femur_rotation({}), o);
              cells = rom_map(j.hip(), flexion, adduction, o, base);
            }
            std::vector<double> ir(cells.size());
            for (std::size_t k = 0; k < cells.size(); ++k) ir[k] = cells[k].max_internal_rotation_deg;
            return own(std::move(ir), {py::ssize_t(flexion.size()), py::ssize_t(adduction.size())});
          },
          py::arg("flexion"), py::arg("adduction"), py::arg("threshold_mm") = 0.0,
          py::arg("contact_depth_mm") = RomOptions{}.contact_depth_mm, py::arg("metric") = "",
          "ROM map: the largest internal rotation (deg) before contact for every flexion x adduction (deg) -> "
          "float64 (len(flexion), len(adduction)); NaN where in contact already without rotation or free up to "
          "150 deg. metric: as rom_limits'.")
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

py::object frames_dict(const PyJoint& j) {
  if (!j.hip().frames()) return py::none();
  const HipFrames& f = *j.hip().frames();
  const Session& s = *j.session;
  py::dict d;
  for (const auto& [name, frame] : {std::pair{"pelvis", &f.pelvis}, std::pair{"femur", &f.femur}}) {
    py::dict fr;
    fr["origin"] = Eigen::Vector3d(s.to_input(frame->origin));
    fr["axes"] = Eigen::Matrix3d(s.to_input() * frame->axes);
    py::dict lm;
    for (const auto& [k, p] : frame->landmarks) lm[py::str(k)] = Eigen::Vector3d(s.to_input(p));
    fr["landmarks"] = lm;
    d[name] = fr;
  }
  d["scan_pose"] = std::vector<double>{f.scan_pose.flexion_deg, f.scan_pose.adduction_deg,
                                       f.scan_pose.internal_rotation_deg};
  return d;
}

void add_joint_properties(py::class_<PyJoint>& c) {
  c.def_property_readonly("cor", [](const PyJoint& j) { return j.session->cor_input(); },
                          "Centre of rotation (3,), mm, input frame.")
      .def_property_readonly("ball_map",
                             [](const PyJoint& j) { return MapView{j.session->shared_hip(), &j.hip().joint().ball().map}; })
      .def_property_readonly(
          "socket_map", [](const PyJoint& j) { return MapView{j.session->shared_hip(), &j.hip().joint().socket().map}; })
      .def_property_readonly("frames", &frames_dict,
                             "Anatomical frames (anatomical neutral; None with scan neutral), input frame: origin (3,), "
                             "axes (3, 3; columns X anterior, Y superior, Z right), landmarks; scan_pose in degrees.")
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

void bind_joint(py::module_& m) {
  py::class_<PyJoint> c(m, "Joint", "A hip set up as the CLI sets it up (the session layer); see __init__.");
  static const std::string doc = joint_doc();  // pybind11 keeps the pointer
  c.def(py::init(&make_joint), py::arg("ball") = py::none(), py::arg("socket") = py::none(), doc.c_str());
  add_joint_queries(c);
  add_joint_properties(c);
  add_joint_benchmarks(c);
}

}  // namespace
PYBIND11_MODULE(_impinge, m) {
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
  bind_functions(m);
  bind_types(m);
  bind_joint(m);
}
