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
// SpatialModelWith<engine::GasForce> would hold odyn's whole catalogue besides. For the same
// reason it compiles only the analyses an engine is run with: assembly, the dynamic analysis, the
// kinematic analysis and the model report (bind_dynamics, bind_kinematics). The static ones
// (statics, quasi-statics, modes, linearize: bind_statics) would double its build; odyn says so
// if they are asked of its models.
// Its CMakeLists.txt builds it against the installed odyn, as a project outside odyn would, in
// two units that two cores compile side by side (odyn::python::bind_models does all in one).

#include <odyn/python/module.hpp>

#include "engine_models.hpp"

PYBIND11_MODULE(odyn_engine, m) {
  namespace python = odyn::python;
  m.doc() =
      "The engine example's models, with its gas force (engine_gas_force), for "
      "odyn.Model(module=odyn_engine) and odyn.PlanarModel(module=odyn_engine).";
  python::use_odyn_errors();
  python::bind_model_types<engine_module::Spatial, engine_module::Planar>(m);
  using SpatialBox = python::ModelBox<engine_module::Spatial>;
  python::analysis::bind_dynamics<SpatialBox>(m);
  python::analysis::bind_kinematics<SpatialBox>(m);
  engine_module::bind_planar_analyses(m);  // planar_analyses.cpp
}
