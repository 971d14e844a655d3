// odyn._core: the planar model's analyses other than the dynamic one (dynamics_planar.cpp).

#include <odyn/python/analyses.hpp>

#include "bindings.hpp"

namespace odyn::python {

void bind_planar_analyses(py::module_& m) {
  analysis::bind_kinematics<PlanarBox>(m);
  analysis::bind_statics<PlanarBox>(m);
}

}  // namespace odyn::python
