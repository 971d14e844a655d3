// odyn._core: model building. Bodies and elements are added by type name with their parameters
// in a dict whose keys are the C++ parameter names; the Python layer (python/odyn/model.py)
// checks types and shapes first, so these functions assume well-formed values and let the
// library's own checks (ModelError) speak for the physics.

#include <Python.h>

#include <cmath>
#include <span>
#include <sstream>
#include <string>

#include "bindings.hpp"
#include "catalogue.hpp"

namespace odyn::python {

// --- Python callables ------------------------------------------------------------------------

namespace {
bool read_flat(PyObject* value, double* out, int count, int& filled) {
  // Fast path: tuples and lists of Python numbers (nested for several bodies).
  if (PyFloat_Check(value) || PyLong_Check(value)) {
    if (filled >= count) return false;
    out[filled++] = PyFloat_AsDouble(value);
    return !PyErr_Occurred();
  }
  if (PyTuple_Check(value) || PyList_Check(value)) {
    const Py_ssize_t n = PySequence_Fast_GET_SIZE(value);
    PyObject** items = PySequence_Fast_ITEMS(value);
    for (Py_ssize_t i = 0; i < n; ++i)
      if (!read_flat(items[i], out, count, filled)) return false;
    return true;
  }
  // Anything else that numpy reads as numbers (arrays, numpy scalars).
  auto array = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
  if (!array) {
    PyErr_Clear();
    return false;
  }
  if (filled + array.size() > count) return false;
  std::copy(array.data(), array.data() + array.size(), out + filled);
  filled += static_cast<int>(array.size());
  return true;
}
}  // namespace

void read_numbers(py::handle value, double* out, int count, const std::string& what) {
  int filled = 0;
  if (!read_flat(value.ptr(), out, count, filled) || filled != count) {
    if (PyErr_Occurred()) throw py::error_already_set();
    throw py::type_error(what + ": the function must return " + std::to_string(count) +
                         (count == 1 ? " number" : " numbers") + ", got " +
                         std::string(py::repr(value)));
  }
  for (int i = 0; i < count; ++i)
    if (!std::isfinite(out[i]))
      throw py::value_error(what + ": the function returned a non-finite value (" +
                            std::string(py::repr(value)) + ")");
}

FrameView<Spatial>::FrameView() {
  data_ = new double[size]();
  py::capsule owner(data_, [](void* p) { delete[] static_cast<double*>(p); });
  auto view = [&](std::vector<py::ssize_t> shape, int offset) {
    py::array_t<double> array(shape, data_ + offset, owner);
    array.attr("flags").attr("writeable") = false;
    return array;
  };
  object_ = py::module_::import("types").attr("SimpleNamespace")(
      py::arg("position") = view({3}, position), py::arg("rotation") = view({3, 3}, rotation),
      py::arg("linear_velocity") = view({3}, linear_velocity),
      py::arg("angular_velocity") = view({3}, angular_velocity));
}

void FrameView<Spatial>::load(const Spatial::Frame& frame) {
  for (int i = 0; i < 3; ++i) {
    data_[position + i] = frame.position[i];
    for (int j = 0; j < 3; ++j) data_[rotation + 3 * i + j] = frame.rotation(i, j);  // by rows
    data_[linear_velocity + i] = frame.linear_velocity[i];
    data_[angular_velocity + i] = frame.angular_velocity[i];
  }
}

FrameView<Planar>::FrameView() {
  data_ = new double[size]();
  py::capsule owner(data_, [](void* p) { delete[] static_cast<double*>(p); });
  auto view = [&](std::vector<py::ssize_t> shape, int offset) {
    py::array_t<double> array(shape, data_ + offset, owner);
    array.attr("flags").attr("writeable") = false;
    return array;
  };
  object_ = py::module_::import("types").attr("SimpleNamespace")(
      py::arg("position") = view({2}, position), py::arg("angle") = 0.0,
      py::arg("rotation") = view({2, 2}, rotation),
      py::arg("linear_velocity") = view({2}, linear_velocity), py::arg("angular_velocity") = 0.0);
}

void FrameView<Planar>::load(const Planar::Frame& frame) {
  for (int i = 0; i < 2; ++i) {
    data_[position + i] = frame.position[i];
    for (int j = 0; j < 2; ++j) data_[rotation + 2 * i + j] = frame.rotation(i, j);  // by rows
    data_[linear_velocity + i] = frame.linear_velocity[i];
  }
  // Scalars are attributes of the namespace (Python floats: the cheapest for user code).
  const auto set = [&](const char* name, double value) {
    const py::object number = py::reinterpret_steal<py::object>(PyFloat_FromDouble(value));
    if (!number || PyObject_SetAttrString(object_.ptr(), name, number.ptr()) != 0)
      throw py::error_already_set();
  };
  set("angle", frame.angle);
  set("angular_velocity", frame.omega());
}

template <class Space>
Callable<Space>::Callable(py::object function, int num_frames, std::string what)
    : function_(std::move(function)),
      views_(static_cast<std::size_t>(num_frames)),
      what_(std::move(what)) {}

template <class Space>
Callable<Space>::~Callable() {
  py::gil_scoped_acquire gil;
  function_ = py::object();
  views_.clear();
}

template <class Space>
py::object Callable<Space>::call_with_frames(double t, const typename Space::Frame* const* frames) {
  // Vectorcall with the argument slots on the stack: no tuple is built.
  std::array<PyObject*, 4> args{};  // slot 0 is scratch (PY_VECTORCALL_ARGUMENTS_OFFSET)
  py::object time = py::reinterpret_steal<py::object>(PyFloat_FromDouble(t));
  args[1] = time.ptr();
  for (std::size_t k = 0; k < views_.size(); ++k) {
    views_[k].load(*frames[k]);
    args[2 + k] = views_[k].object().ptr();
  }
  PyObject* result =
      PyObject_Vectorcall(function_.ptr(), args.data() + 1,
                          (1 + views_.size()) | PY_VECTORCALL_ARGUMENTS_OFFSET, nullptr);
  if (!result) throw py::error_already_set();
  return py::reinterpret_steal<py::object>(result);
}

template <class Space>
py::object Callable<Space>::call_with_numbers(std::initializer_list<double> numbers) {
  std::array<PyObject*, 4> args{};
  std::array<py::object, 3> owned;
  std::size_t n = 0;
  for (const double x : numbers) {
    owned[n] = py::reinterpret_steal<py::object>(PyFloat_FromDouble(x));
    args[1 + n] = owned[n].ptr();
    ++n;
  }
  PyObject* result = PyObject_Vectorcall(function_.ptr(), args.data() + 1,
                                         n | PY_VECTORCALL_ARGUMENTS_OFFSET, nullptr);
  if (!result) throw py::error_already_set();
  return py::reinterpret_steal<py::object>(result);
}

template <class Space>
py::object Callable<Space>::call_with_vectors(double t, const double* x, const double* y, int n) {
  const auto array = [n](const double* values) {
    py::array_t<double> out(n);
    std::copy(values, values + n, out.mutable_data());
    return out;
  };
  return function_(t, array(x), array(y));
}

template class Callable<Spatial>;
template class Callable<Planar>;

// --- Parameters from the Python layer's dict (shared with planar.cpp) ------------------------

double number(const py::dict& d, const char* key) {
  return d[key].cast<double>();
}
std::string text(const py::dict& d, const char* key) {
  return d[key].cast<std::string>();
}

namespace {
/// A scalar function of one or three numbers from a Python callable.
template <class... Args>
std::function<double(Args...)> scalar_function(py::object f, const std::string& what) {
  auto callable = std::make_shared<Callable<Spatial>>(std::move(f), 0, what);
  return [callable](Args... args) {
    py::gil_scoped_acquire gil;
    double value = 0.0;
    read_numbers(callable->call_with_numbers({static_cast<double>(args)...}), &value, 1,
                 callable->what());
    return value;
  };
}
}  // namespace

std::function<double(double, double, double)> scalar_function3(py::object f,
                                                               const std::string& what) {
  return scalar_function<double, double, double>(std::move(f), what);
}

Motion motion(const py::dict& d, const std::string& what) {
  const py::dict m = d["motion"].cast<py::dict>();
  const std::string type = text(m, "type");
  if (type == "constant_velocity")
    return Motion::constant_velocity(number(m, "rate"), number(m, "start"));
  if (type == "polynomial")
    return Motion::polynomial(m["coefficients"].cast<std::vector<double>>());
  if (type == "harmonic")
    return Motion::harmonic(number(m, "amplitude"), number(m, "frequency"), number(m, "phase"),
                            number(m, "offset"));
  if (type == "function")
    return {scalar_function<double>(m["position"], what + " motion position"),
            scalar_function<double>(m["velocity"], what + " motion velocity"),
            scalar_function<double>(m["acceleration"], what + " motion acceleration")};
  throw ModelError(what, "unknown motion type '" + type + "'");
}

namespace {

// --- Parameters from the Python layer's dict -------------------------------------------------

using Eigen::Vector3d;

Vector3d vec3(const py::dict& d, const char* key) {
  return d[key].cast<Vector3d>();
}
void add_body(SpatialBox& box, const py::dict& d) {
  if (box.running) throw ModelError("model", "cannot change a model while an analysis runs");
  sp::Body body;
  body.name = text(d, "name");
  body.mass = number(d, "mass");
  body.inertia = d["inertia"].cast<Eigen::Matrix3d>();
  body.position = vec3(d, "position");
  const Eigen::Vector4d q = d["orientation"].cast<Eigen::Vector4d>();  // w, x, y, z
  body.orientation = Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
  body.linear_velocity = vec3(d, "linear_velocity");
  body.angular_velocity = vec3(d, "angular_velocity");
  if (d.contains("velocity_given") && !d["velocity_given"].is_none())
    body.velocity_given = d["velocity_given"].cast<std::array<bool, 6>>();
  box.assembled = {};  // the model changes: assemble again
  box.model.add_body(std::move(body));
}

template <class Box, class AddBody, class AddElement>
void bind_model(py::module_& m, const char* name, const char* doc, AddBody add_body_function,
                AddElement add_element_function) {
  py::class_<Box>(m, name, doc)
      .def(py::init<>())
      .def("add_body", add_body_function, py::arg("parameters"))
      .def("add_element", add_element_function, py::arg("type"), py::arg("parameters"))
      .def_property_readonly("space", [](const Box&) { return std::string(Box::space_name); })
      .def_property_readonly("num_bodies", [](const Box& b) { return b.model.num_bodies(); })
      .def_property_readonly("num_equations", [](const Box& b) { return b.model.num_equations(); })
      .def("body_index",
           [](const Box& b, const std::string& body) { return b.model.body(body).index; })
      .def("element_type", [](const Box& b, const std::string& element) {
        using M = typename Box::ModelType;
        return std::string(Catalogue<M>::type_names[b.model.locate(element).type]);
      });
}

template <class M>
py::object type_names() {
  const auto& names = Catalogue<M>::type_names;
  return py::cast(std::vector<std::string>(names.begin(), names.end()));
}

/// The descriptions of the element types a model type can add, as plain Python values: a list
/// of {type, category, summary, parameters: [{name, kind, default (JSON text or None), unit,
/// doc}], outputs and state_fields: [{name, unit, doc}], joints: [the types `joint` may name]}.
template <class M>
py::list catalogue() {
  py::list out;
  for (const ElementDescription* d : Catalogue<M>::descriptions()) {
    py::list parameters;
    for (const Parameter& p : d->parameters) {
      py::dict entry;
      entry["name"] = p.name;
      entry["kind"] = p.kind;
      entry["default"] =
          p.fallback == nullptr ? py::object(py::none()) : py::object(py::str(p.fallback));
      entry["unit"] = p.unit;
      entry["doc"] = p.doc;
      parameters.append(entry);
    }
    const auto listed = [](std::span<const Output> fields) {
      py::list out;
      for (const Output& o : fields) {
        py::dict entry;
        entry["name"] = o.name;
        entry["unit"] = o.unit;
        entry["doc"] = o.doc;
        out.append(entry);
      }
      return out;
    };
    py::dict element;
    element["type"] = d->type;
    element["category"] = d->category;
    element["summary"] = d->summary;
    element["parameters"] = parameters;
    element["outputs"] = listed(d->outputs);
    element["state_fields"] = listed(d->state_fields);
    py::list joints;
    for (const char* joint : d->joints) joints.append(joint);
    element["joints"] = joints;
    out.append(element);
  }
  return out;
}

py::list kinds() {
  py::list out;
  for (const ParameterKind& kind : parameter_kinds) out.append(py::make_tuple(kind.name, kind.doc));
  return out;
}

/// {"turning_joint": [types], "sliding_joint": [types], "coupled_joint": [types],
/// "optional_coupled_joint": [types]}: what those kinds may name in a space.
template <class Kinds>
py::dict joint_kinds() {
  py::dict out;
  py::list turning, sliding, coupled;
  for (const char* type : Kinds::turning_joint_types) turning.append(type);
  for (const char* type : Kinds::sliding_joint_types) sliding.append(type);
  for (const char* type : Kinds::coupled_joint_types) coupled.append(type);
  out["turning_joint"] = turning;
  out["sliding_joint"] = sliding;
  out["coupled_joint"] = coupled;
  out["optional_coupled_joint"] = coupled;
  return out;
}

struct SpatialJointKinds {
  static constexpr auto turning_joint_types = odyn::spatial::turning_joint_types;
  static constexpr auto sliding_joint_types = odyn::spatial::sliding_joint_types;
  static constexpr auto coupled_joint_types = odyn::spatial::coupled_joint_types;
};
struct PlanarJointKinds {
  static constexpr auto turning_joint_types = odyn::planar::turning_joint_types;
  static constexpr auto sliding_joint_types = odyn::planar::sliding_joint_types;
  static constexpr auto coupled_joint_types = odyn::planar::coupled_joint_types;
};

}  // namespace

}  // namespace odyn::python

PYBIND11_MODULE(_core, m) {
  using namespace odyn::python;
  m.doc() = "odyn's compiled core: model building and analyses (use the odyn package instead)";

  static py::exception<odyn::Error> error(m, "Error", PyExc_RuntimeError);
  static py::exception<odyn::ModelError> model_error(m, "ModelError", error.ptr());
  static py::exception<odyn::AssemblyError> assembly_error(m, "AssemblyError", error.ptr());
  static py::exception<odyn::SolverError> solver_error(m, "SolverError", error.ptr());
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const odyn::ModelError& e) {
      py::set_error(model_error, e.what());
    } catch (const odyn::AssemblyError& e) {
      py::set_error(assembly_error, e.what());
    } catch (const odyn::SolverError& e) {
      py::set_error(solver_error, e.what());
    } catch (const odyn::Error& e) {
      py::set_error(error, e.what());
    }
  });

  bind_model<SpatialBox>(m, "Model", "The C++ spatial model (odyn.Model wraps it).", &add_body,
                         &add_element<SpatialBox>);
  bind_model<PlanarBox>(m, "PlanarModel", "The C++ planar model (odyn.PlanarModel wraps it).",
                        &add_planar_body, &add_element<PlanarBox>);
  m.attr("element_types") = type_names<Model>();
  m.attr("planar_element_types") = type_names<PlanarModel>();
  m.attr("element_catalogue") = catalogue<Model>();
  m.attr("planar_element_catalogue") = catalogue<PlanarModel>();
  m.attr("parameter_kinds") = kinds();
  m.attr("joint_kinds") = joint_kinds<SpatialJointKinds>();
  m.attr("planar_joint_kinds") = joint_kinds<PlanarJointKinds>();
  bind_integrators(m);
  bind_spatial_analyses(m);
  bind_planar_analyses(m);
}
