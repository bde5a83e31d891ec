#pragma once
// The Python module's shared parts: numpy conversions (convert.cpp), the option table's keywords
// (options.cpp), the Joint class (joint.cpp); impinge_module.cpp binds the module.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <functional>
#include <memory>
#include <typeinfo>
#include <string>
#include <vector>

#include "impinge/anatomy/sphere_fit.hpp"
#include "impinge/clinical/hip_joint.hpp"
#include "impinge/core/mesh.hpp"
#include "impinge/session/option_table.hpp"
#include "impinge/session/records.hpp"
#include "impinge/session/session.hpp"

namespace impinge::python {

namespace py = pybind11;

// A numpy array owning `v` (moved to the heap; freed with the array).
template <typename T>
py::array_t<T> own(std::vector<T>&& v, std::vector<py::ssize_t> shape) {
  auto* p = new std::vector<T>(std::move(v));
  py::capsule free(p, [](void* q) { delete static_cast<std::vector<T>*>(q); });
  return py::array_t<T>(shape, p->data(), free);
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

// ---- Uninitialised instances (issue 80) ----
// T.__new__(T) makes an instance whose C++ value was never constructed; pybind11 would hand a method an
// unconstructed object (a crash on first use). Throws TypeError naming the class when `src` is an instance of
// the bound type `type` without its value (`origin`: where such objects come from, for the message); does
// nothing for any other object. Every bound type's caster runs it (InitialisedCaster below), so every method and
// property is guarded.
void require_initialised(py::handle src, const std::type_info& type, const char* origin);

// ---- convert.cpp: numpy and JSON ----
// A numpy array's kind and shape checked: n x 3 (n >= min_rows); kind 'f' (float32/64) or 'i' (integers).
py::array checked(const py::handle& obj, const std::string& what, char kind, py::ssize_t min_rows);
Vertices to_vertices(const py::handle& obj, const std::string& what);
// A pair (V, F) of arrays as a checked mesh named `what`.
TriangleMesh to_mesh(const py::handle& pair, const std::string& what);
// (V, F) arrays of a mesh.
py::tuple mesh_arrays(const TriangleMesh& mesh);
Eigen::Matrix3d to_rotation(const py::handle& obj);
Eigen::Vector3d to_point(const py::handle& obj, const std::string& what);
py::dict sphere_dict(const SphereFitResult& s);
// A JSON record (records.hpp) as Python objects (dicts, lists, numbers, strings; null as None).
py::object from_json(const nlohmann::json& j);
// A table's columns as a dict of arrays: float64 for numbers (None as NaN), lists for text.
py::dict table_columns(const Table& t);
// Checked clinical angles (k x 3, degrees) from a numpy array.
std::vector<PoseAngles> to_angles(const py::handle& angles_obj);

// ---- options.cpp: the option table (session/option_table.hpp) in Python ----
// A Python value as the row's value (None: nothing); `as` names it in errors.
OptionValue to_value(const OptionRow& row, const py::handle& value, const std::string& as);
// A value as Python (nothing: None; integers as int; path pairs as tuples).
py::object to_python(const OptionRow& row, const OptionValue& value);
// The table row `key` (Python's name); throws when none.
const OptionRow& option_row(const std::string& key);
// The clinical preset's default of `key` as Python.
py::object default_of(const std::string& key);
// Every row (uses & use) given in `given` (key -> value; None: the default) set on `run`, in the table's order
// (preset first); a key no row of `use` takes is an error naming `caller` and the known keys.
void set_options(RunOptions& run, const py::dict& given, unsigned use, const std::string& caller);
// The CLI's tokens (--name VALUE, --name=VALUE, --flag) of the rows with `use`, parsed as the CLI parses them
// (parse_option_text) and set on `run` in the table's order; an unknown or repeated option, or one without its value,
// is an error naming `caller`; a former name warns (DeprecationWarning).
void set_cli_options(RunOptions& run, const std::vector<std::string>& args, unsigned use, const std::string& caller);
void bind_options(py::module_& m);
// "Keywords (...): a, b, c.": the keys of the rows with `use`, for a docstring.
std::string keywords_doc(unsigned use);
// A docstring kept for the module's lifetime (pybind11 keeps the pointer it is given).
const char* keep_doc(std::string doc);

// ---- interrupt.cpp: Ctrl-C in long calls (issue 80) ----
// Runs `work` with the GIL released, the library's loops asking Python whether a signal arrived (InterruptScope,
// core/interrupt.hpp: PyErr_CheckSignals with the GIL taken back, at most every 50 ms, on this thread). A signal's
// exception (KeyboardInterrupt for Ctrl-C) stops the loops and is raised here, whatever `work` threw or returned
// meanwhile; else `work`'s own error, if any. Only on Python's main thread (the one signal handlers run on);
// elsewhere `work` runs without the GIL and without polling.
void run_interruptible(const std::function<void()>& work);

// ---- joint.cpp ----
void bind_joint(py::module_& m);

}  // namespace impinge::python

namespace pybind11::detail {
// The caster of a bound type that refuses an instance made by __new__ without __init__ (require_initialised)
// before pybind11 would hand its unconstructed value to a method.
// `origin` names where the type's objects come from.
template <typename T, const char* origin>
class InitialisedCaster : public type_caster_base<T> {
 public:
  bool load(handle src, bool convert) {
    impinge::python::require_initialised(src, typeid(T), origin);
    return type_caster_base<T>::load(src, convert);
  }
};
// Every type the module binds (py::class_): Joint, Map, SphereFit.
inline constexpr char kJointOrigin[] = "impinge.Joint(...)";
inline constexpr char kMapOrigin[] = "Joint.femur_map or Joint.pelvis_map";
inline constexpr char kSphereFitOrigin[] = "impinge.locate_femoral_head(...)";
template <>
class type_caster<impinge::python::PyJoint> : public InitialisedCaster<impinge::python::PyJoint, kJointOrigin> {};
template <>
class type_caster<impinge::python::MapView> : public InitialisedCaster<impinge::python::MapView, kMapOrigin> {};
template <>
class type_caster<impinge::SphereFitResult> : public InitialisedCaster<impinge::SphereFitResult, kSphereFitOrigin> {};
}  // namespace pybind11::detail
