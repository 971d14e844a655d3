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

/// Registers the analyses (assembly, dynamics) of each model on the module (analyses.cpp,
/// analyses_planar.cpp: the two models' integrators compile in parallel).
void bind_spatial_analyses(py::module_& m);
void bind_planar_analyses(py::module_& m);
/// Registers `integrators`, the integrators the library knows by name (analyses.cpp).
void bind_integrators(py::module_& m);

}  // namespace odyn::python
