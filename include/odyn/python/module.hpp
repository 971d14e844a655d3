#pragma once
// The pieces of a Python module of odyn: its model classes, their bodies and elements added from
// the Python layer's dicts, the descriptions of the element types each can add, the analyses,
// and the library's exceptions. odyn._core is built from them (python/src/module.cpp), and so is
// a downstream module that compiles models with element types of its own (bind_models).

#include <Python.h>

#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include <odyn/python/analyses.hpp>
#include <odyn/python/catalogue.hpp>
#include <odyn/python/dict_values.hpp>
#include <odyn/python/errors.hpp>
#include <odyn/python/models.hpp>

namespace odyn::python {

/// Adds a body to a spatial model from the dict the Python layer checked.
template <class M>
  requires std::is_same_v<typename M::Space, Spatial>
void add_body(ModelBox<M>& box, const py::dict& d) {
  using Eigen::Vector3d;
  const auto vec3 = [&](const char* key) { return d[key].cast<Vector3d>(); };
  if (box.running) throw ModelError("model", "cannot change a model while an analysis runs");
  sp::Body body;
  body.name = text(d, "name");
  body.mass = number(d, "mass");
  body.inertia = d["inertia"].cast<Eigen::Matrix3d>();
  body.position = vec3("position");
  const Eigen::Vector4d q = d["orientation"].cast<Eigen::Vector4d>();  // w, x, y, z
  body.orientation = Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
  body.linear_velocity = vec3("linear_velocity");
  body.angular_velocity = vec3("angular_velocity");
  if (d.contains("velocity_given") && !d["velocity_given"].is_none())
    body.velocity_given = d["velocity_given"].cast<std::array<bool, 6>>();
  box.assembled = {};  // the model changes: assemble again
  box.model.add_body(std::move(body));
}

/// Adds a body to a planar model from the dict the Python layer checked.
template <class M>
  requires std::is_same_v<typename M::Space, Planar>
void add_body(ModelBox<M>& box, const py::dict& d) {
  using Eigen::Vector2d;
  const auto vec2 = [&](const char* key) { return d[key].cast<Vector2d>(); };
  if (box.running) throw ModelError("model", "cannot change a model while an analysis runs");
  pl::Body body;
  body.name = text(d, "name");
  body.mass = number(d, "mass");
  body.inertia = number(d, "inertia");
  body.position = vec2("position");
  body.angle = number(d, "angle");
  body.linear_velocity = vec2("linear_velocity");
  body.angular_velocity = number(d, "angular_velocity");
  if (d.contains("velocity_given") && !d["velocity_given"].is_none())
    body.velocity_given = d["velocity_given"].cast<std::array<bool, 3>>();
  box.assembled = {};  // the model changes: assemble again
  box.model.add_body(std::move(body));
}

/// Registers a model type's Python class: odyn.Model (or odyn.PlanarModel) wraps it.
template <class Box>
void bind_model(py::module_& m, const char* name, const char* doc) {
  py::class_<Box>(m, name, doc)
      .def(py::init<>())
      .def("add_body", &add_body<typename Box::ModelType>, py::arg("parameters"))
      .def("add_element", &add_element<Box>, py::arg("type"), py::arg("parameters"))
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

inline py::list parameter_kind_list() {
  py::list out;
  for (const ParameterKind& kind : parameter_kinds) out.append(py::make_tuple(kind.name, kind.doc));
  return out;
}

/// {"turning_joint": [types], "sliding_joint": [types], "coupled_joint": [types],
/// "optional_coupled_joint": [types]}: what those kinds may name in a space.
template <class Kinds>
py::dict joint_kind_lists() {
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

/// Registers odyn's exceptions (Error and its ModelError, AssemblyError, SolverError) on `m`
/// and translates the library's C++ exceptions into them; once per process (odyn._core does).
inline void bind_errors(py::module_& m) {
  static py::exception<odyn::Error> error(m, "Error", PyExc_RuntimeError);
  static py::exception<odyn::ModelError> model_error(m, "ModelError", error.ptr());
  static py::exception<odyn::AssemblyError> assembly_error(m, "AssemblyError", error.ptr());
  static py::exception<odyn::SolverError> solver_error(m, "SolverError", error.ptr());
  py::register_exception_translator(&translate_odyn_error);
}

/// Registers a spatial and a planar model type on `m` as the classes Model and PlanarModel, with
/// what the Python layer reads of them: element_types, element_catalogue, joint_kinds and their
/// planar_ twins. The analyses are registered apart (analysis::bind), so that a module may
/// compile each model's in a unit of its own.
template <class SpatialModelT, class PlanarModelT>
void bind_model_types(py::module_& m) {
  bind_model<ModelBox<SpatialModelT>>(m, "Model", "The C++ spatial model (odyn.Model wraps it).");
  bind_model<ModelBox<PlanarModelT>>(m, "PlanarModel",
                                     "The C++ planar model (odyn.PlanarModel wraps it).");
  m.attr("element_types") = type_names<SpatialModelT>();
  m.attr("planar_element_types") = type_names<PlanarModelT>();
  m.attr("element_catalogue") = catalogue<SpatialModelT>();
  m.attr("planar_element_catalogue") = catalogue<PlanarModelT>();
  m.attr("joint_kinds") = joint_kind_lists<SpatialJointKinds>();
  m.attr("planar_joint_kinds") = joint_kind_lists<PlanarJointKinds>();
}

/// For a module of one's own: the library's exceptions, thrown in its functions, become
/// odyn._core's (odyn.ModelError and the others), which the odyn package reports.
inline void use_odyn_errors() {
  py::module_::import("odyn._core");  // its classes exist before the first error
  py::register_local_exception_translator(&translate_odyn_error);
}

/// Everything a module of one's own needs, in one unit (examples/python/odyn_engine/): the model
/// classes of a spatial and a planar model type (each may list element types of the module's
/// own), their analyses, and odyn's exceptions. The odyn package then builds models of them:
/// odyn.Model(module=the_module), or "module" in a scene file.
template <class SpatialModelT, class PlanarModelT>
void bind_models(py::module_& m) {
  use_odyn_errors();
  bind_model_types<SpatialModelT, PlanarModelT>(m);
  analysis::bind<ModelBox<SpatialModelT>>(m);
  analysis::bind<ModelBox<PlanarModelT>>(m);
}

}  // namespace odyn::python
