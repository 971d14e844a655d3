// odyn._core: the analyses of the planar model (a unit of its own: the two models' integrators
// compile in parallel).

#include <odyn/python/analyses.hpp>

#include "bindings.hpp"

namespace odyn::python {

void bind_planar_analyses(py::module_& m) {
  analysis::bind<PlanarBox>(m);
}

}  // namespace odyn::python
