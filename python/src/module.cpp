// odyn._core: the module the odyn package wraps. Its model types (python/src/bindings.hpp) and
// the pieces that bind them (include/odyn/python/module.hpp); the Python layer
// (python/odyn/model.py) checks types and shapes first, so these functions assume well-formed
// values and let the library's own checks (ModelError) speak for the physics.

#include <odyn/python/module.hpp>

#include "bindings.hpp"
#include "parts.hpp"

PYBIND11_MODULE(_core, m) {
  using namespace odyn::python;
  m.doc() = "odyn's compiled core: model building and analyses (use the odyn package instead)";
  bind_errors(m);
  bind_model_types<Model, PlanarModel>(m);
  m.attr("parameter_kinds") = parameter_kind_list();
  bind_integrators(m);
  m.def("combined_body", &combined_body, py::arg("body"), py::arg("space"),
        "A body dict with parts, combined by odyn's Composite (odyn.composite).");
  bind_spatial_dynamics(m);
  bind_planar_dynamics(m);
  bind_spatial_analyses(m);
  bind_planar_analyses(m);
}
