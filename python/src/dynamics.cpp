// odyn._core: the spatial model's assembly and dynamic analysis (every integrator, in both
// coordinates), the largest unit of the module.

#include <odyn/python/analyses.hpp>

#include "bindings.hpp"

namespace odyn::python {

void bind_spatial_dynamics(py::module_& m) {
  analysis::bind_dynamics<SpatialBox>(m);
}

}  // namespace odyn::python
