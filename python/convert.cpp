// numpy arrays and JSON records to and from the library's types (bindings.hpp).
#include <cmath>

#include "bindings.hpp"
#include "impinge/core/error.hpp"

namespace impinge::python {

void require_initialised(py::handle src, const std::type_info& type, const char* origin) {
  py::detail::type_info* info = py::detail::get_type_info(type);
  if (info == nullptr || src.ptr() == nullptr || !PyObject_TypeCheck(src.ptr(), info->type)) return;
  auto* inst = reinterpret_cast<py::detail::instance*>(src.ptr());
  const py::detail::value_and_holder v = inst->get_value_and_holder(info, false);
  // Constructed: a value, and a holder wherever pybind11 owns the value (a reference it was handed has none).
  if (v && v.value_ptr() != nullptr && (v.holder_constructed() || !inst->owned)) return;
  const std::string name = py::str(py::handle(reinterpret_cast<PyObject*>(info->type)).attr("__name__"));
  throw py::type_error("impinge." + name + " object is not initialised (made by " + name +
                       ".__new__ without __init__); " + name + " objects come from " + origin);
}

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

py::tuple mesh_arrays(const TriangleMesh& t) {
  py::array_t<double> V({t.V.rows(), Eigen::Index(3)});
  std::copy(t.V.data(), t.V.data() + t.V.size(), V.mutable_data());
  py::array_t<std::int32_t> F({t.F.rows(), Eigen::Index(3)});
  std::copy(t.F.data(), t.F.data() + t.F.size(), F.mutable_data());
  return py::make_tuple(V, F);
}

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

}  // namespace impinge::python
