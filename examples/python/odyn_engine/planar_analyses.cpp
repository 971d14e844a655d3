// odyn_engine: the planar model's analyses, in a unit of their own (see odyn_engine.cpp).

#include <odyn/python/analyses.hpp>

#include "engine_models.hpp"

void engine_module::bind_planar_analyses(pybind11::module_& m) {
  using PlanarBox = odyn::python::ModelBox<Planar>;
  odyn::python::analysis::bind_dynamics<PlanarBox>(m);
  odyn::python::analysis::bind_kinematics<PlanarBox>(m);
}
