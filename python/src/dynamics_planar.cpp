// odyn._core: the planar model's assembly and dynamic analysis (every integrator, in both
// coordinates), the largest unit of the module.

#include <odyn/python/analyses.hpp>

#include "bindings.hpp"

namespace odyn::python {

void bind_planar_dynamics(py::module_& m) {
  analysis::bind_dynamics<PlanarBox>(m);
}

}  // namespace odyn::python
