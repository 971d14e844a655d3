#pragma once
// What the translation units of odyn._core share: the two model types the module compiles (the
// library's elements and elements written in Python) and the declarations that tie its units
// together. The machinery is in include/odyn/python/, which a module of one's own uses the same
// way (examples/python/odyn_engine/odyn_engine.cpp, docs/elements.md).

#include <odyn/python/models.hpp>

namespace odyn::python {

using Model = SpatialModelWith<>;
using PlanarModel = PlanarModelWith<>;
using SpatialBox = ModelBox<Model>;
using PlanarBox = ModelBox<PlanarModel>;

/// Register each model's analyses on the module, in four units that compile in parallel: assembly
/// and the dynamic analysis (dynamics.cpp, dynamics_planar.cpp) and the others (analyses.cpp,
/// analyses_planar.cpp). GCC's time for a unit grows faster than its size, so smaller units also
/// cost less in all.
void bind_spatial_dynamics(py::module_& m);
void bind_planar_dynamics(py::module_& m);
void bind_spatial_analyses(py::module_& m);
void bind_planar_analyses(py::module_& m);
/// Registers `integrators`, the integrators the library knows by name (analyses.cpp).
void bind_integrators(py::module_& m);

}  // namespace odyn::python
