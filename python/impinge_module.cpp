// The Python module `impinge` (pybind11): meshes, sphere fits, a hip joint posed by clinical
// angles or rotations, motions, and the radial distance maps as numpy arrays.
//
// Arrays: vertices are float64 (or float32) n x 3 in mm, faces integer m x 3 (0-based); results
// are numpy arrays that own the C++ buffers they were computed in (no copy). Errors are raised as
// impinge.Error (a ValueError) with the library's one-line messages; running out of memory as MemoryError naming
// what was being built. Long calls release the GIL and stop on Ctrl-C (run_interruptible: KeyboardInterrupt).
#include <omp.h>

#include "bindings.hpp"
#include "impinge/detection/impingement_levels.hpp"
#include "impinge/core/error.hpp"
#include "impinge/core/kernels.hpp"
#include "impinge/core/provenance.hpp"
#include "impinge/io/generated_models.hpp"
#include "impinge/io/mesh_io.hpp"
#include "impinge/io/motion.hpp"
#include "impinge/io/subject.hpp"

namespace py = pybind11;
using namespace impinge;
using namespace impinge::python;

namespace {

void bind_functions(py::module_& m) {
  m.def(
      "load_mesh",
      [](const std::string& path) {
        TriangleMesh mesh;
        {
          py::gil_scoped_release release;
          mesh = load_mesh(path);
        }
        return mesh_arrays(mesh);
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
  m.def(
      "level_colours",
      [](int count) {
        if (count < 2 || count > 255) throw Error("level_colours: count " + std::to_string(count) + ": must be 2-255");
        py::dict d;
        for (const bool femur : {true, false}) {
          py::list l;
          for (int k = 0; k < count; ++k) {
            const auto c = level_colour(static_cast<std::uint8_t>(k), count, femur);
            l.append(py::make_tuple(c[0], c[1], c[2]));
          }
          d[femur ? "femur" : "pelvis"] = l;
        }
        const auto u = level_colour(255, count, true);
        d["untested"] = py::make_tuple(u[0], u[1], u[2]);
        return d;
      },
      py::arg("count"),
      "The impingement levels' colours (thesis sec. 3.4, Figure 41), as the PLY files give them, for `count` levels "
      "(len(levels) + 1) -> dict(femur=[(r, g, b) per level 0..count-1], pelvis=[...], untested=(r, g, b)), 0-255; "
      "level 0 (none) is green on the femur and blue on the pelvis. Raises impinge.Error outside 2-255.");
  m.def("get_threads", []() { return omp_get_max_threads(); },
        "Threads (OpenMP) the calling thread's next parallel call would use.");
  m.def(
      "build_info",
      []() {
        py::dict d;
        d["version"] = IMPINGE_VERSION;
        d["compiler"] = compiler_description();
        d["kernels"] = kernel_description();
        return d;
      },
      "The build's provenance -> dict(version, compiler (e.g. 'GNU 12.2.0'), kernels (the dispatched kernels "
      "in use, IMPINGE_KERNELS)); what every experiment's meta.json records.");
  m.def(
      "machine_info",
      []() {
        py::dict d;
        for (const auto& [key, value] : machine_description()) d[py::str(key)] = value;
        return d;
      },
      "What this machine exposes about itself -> dict of str: cpu_model, cpu_family, cpu_model_number, "
      "cpu_stepping, cpu_mhz, l2_cache, l3_cache, logical_cpus, sockets, physical_cores, smt ('yes' when a core "
      "runs two logical CPUs), thread_siblings, memory_gib, hypervisor, os_kernel ('unknown' "
      "where the machine does not say; provenance.hpp).");

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
      [](const py::kwargs& given) {
        RunOptions run = RunOptions::clinical();
        set_options(run, given, use_generated_hip, "generated_hip");
        HipModel h;
        {
          py::gil_scoped_release release;
          h = make_hip_model(run.generate);
        }
        py::dict d;
        d["femur"] = mesh_arrays(h.ball);
        d["pelvis"] = mesh_arrays(h.socket);
        d["cor"] = h.cor;
        d["head_radius_mm"] = run.generate.head_radius_mm;
        return d;
      },
      keep_doc("A generated hip (sphere head with neck, optional cam bump, cup with rim; scan frame RAS, mm) -> "
       "dict(femur=(V, F), pelvis=(V, F), cor, head_radius_mm). Use it with neutral='scan'. The keywords are "
       "`impinge generate`'s (impinge.options()), checked against their ranges. " +
       keywords_doc(use_generated_hip)));
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
    } catch (const OutOfMemory& e) {  // what was being built and how to build less: Python's MemoryError
      PyErr_SetString(PyExc_MemoryError, e.what());
    } catch (const Error& e) {
      error(e.what());
    }
  });
  bind_functions(m);
  bind_types(m);
  bind_options(m);
  bind_joint(m);
}
