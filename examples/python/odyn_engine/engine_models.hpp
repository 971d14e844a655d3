#pragma once
// The models of the module odyn_engine (odyn_engine.cpp), which its two units share: the element
// types an engine needs (its joints, gravity, the load, and the loads and springs one adds to it;
// forces and constraints written in Python come with every module) and the gas force.

#include <odyn/python/models.hpp>

#include "engine_model.hpp"

namespace engine_module {

namespace sp = odyn::spatial;
namespace pl = odyn::planar;

using Spatial =
    odyn::python::SpatialModelOf<sp::Revolute, sp::Spherical, sp::Universal, sp::Translational,
                                 sp::Gravity, sp::Rsda, sp::PointForce, sp::PointTorque, sp::Tsda,
                                 engine::GasForce>;
using Planar = odyn::python::PlanarModelOf<pl::Revolute, pl::Translational, pl::Gravity, pl::Rsda,
                                           pl::PointForce, pl::PointTorque, pl::Tsda,
                                           engine::planar::GasForce>;

/// Registers the planar model's analyses, those odyn_engine.cpp binds for the spatial one
/// (planar_analyses.cpp).
void bind_planar_analyses(pybind11::module_& m);

}  // namespace engine_module
