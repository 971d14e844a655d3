// odyn._core: the spatial model's analyses other than the dynamic one (dynamics.cpp), and the
// integrators the library knows by name.

#include <odyn/python/analyses.hpp>

#include "bindings.hpp"

namespace odyn::python {

void bind_spatial_analyses(py::module_& m) {
  analysis::bind_kinematics<SpatialBox>(m);
  analysis::bind_statics<SpatialBox>(m);
}

void bind_integrators(py::module_& m) {
  m.def(
      "integrators",
      [] {
        std::vector<std::pair<std::string, std::string>> out;
        for (const auto& [name, what] : odyn::integrator_names()) out.emplace_back(name, what);
        return out;
      },
      "The integrators that simulate knows by name: a list of (name, description), from the "
      "C++ library's odyn::integrator_names().");
}

}  // namespace odyn::python
