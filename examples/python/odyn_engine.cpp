// odyn_engine: the engine example's models for Python, a module of one's own as a downstream
// project would write it. The engine's gas force (examples/engine_model.hpp) is no element of
// odyn's: this module compiles models with it, and the odyn package builds them with
//
//     import odyn, odyn_engine
//     m = odyn.Model(module=odyn_engine)          # or odyn.PlanarModel(module=odyn_engine)
//     m.add("engine_gas_force", name="gas force", crank="crank", piston="piston")
//
// or with "module": "odyn_engine" in a scene file. The models hold only the element types an
// engine needs (its joints, gravity, the load, and the loads and springs one adds to it; forces
// and constraints written in Python come with every module), which shortens the module's build;
// SpatialModelWith<engine::GasForce> would hold odyn's whole catalogue besides.
// python/CMakeLists.txt builds it beside odyn._core.

#include <odyn/python/module.hpp>

#include "engine_model.hpp"

namespace {

namespace sp = odyn::spatial;
namespace pl = odyn::planar;

using SpatialEngine =
    odyn::python::SpatialModelOf<sp::Revolute, sp::Spherical, sp::Universal, sp::Translational,
                                 sp::Gravity, sp::Rsda, sp::PointForce, sp::PointTorque, sp::Tsda,
                                 engine::GasForce>;
using PlanarEngine = odyn::python::PlanarModelOf<pl::Revolute, pl::Translational, pl::Gravity,
                                                 pl::Rsda, pl::PointForce, pl::PointTorque,
                                                 pl::Tsda, engine::planar::GasForce>;

}  // namespace

PYBIND11_MODULE(odyn_engine, m) {
  m.doc() =
      "The engine example's models, with its gas force (engine_gas_force), for "
      "odyn.Model(module=odyn_engine) and odyn.PlanarModel(module=odyn_engine).";
  odyn::python::bind_models<SpatialEngine, PlanarEngine>(m);
}
