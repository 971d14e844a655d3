"""odyn: multibody dynamics (rigid bodies, joints, drivers, forces; assembly; dynamics with
generalized-alpha, HHT or Dormand-Prince, by name), with the C++ library's spatial and planar
elements compiled in::

    import odyn
    m = odyn.Model()
    m.add_body(name="bob", mass=1.0, inertia=[1e-3, 1e-3, 1e-3], position=[1, 0, 0])
    m.add_revolute(name="hinge", body_a="ground", on_a=odyn.frame([0, 0, 0], [0, 0, 1]),
                   body_b="bob", on_b=odyn.frame([-1, 0, 0], [0, 0, 1]))
    m.add_gravity(name="gravity", acceleration=[0, -9.81, 0])
    r = odyn.simulate(m, t_end=2.0, step=1e-3, output_interval=0.01)
    r.reaction("hinge").force      # (n, 3), on the bob, global axes

    p = odyn.PlanarModel()         # x, y, phi per body; 2-vectors, angles, torques as numbers
    p.add_body(name="bar", mass=1.0, inertia=1 / 12, position=[0.5, 0])
    p.add_revolute(name="pivot", body_a="ground", body_b="bar", on_b=odyn.frame([-0.5, 0]))
    p.add_gravity(name="gravity", acceleration=[0, -9.81])
    r = odyn.simulate(p, t_end=1.0, integrator="dopri5", rtol=1e-8, atol=1e-8)
    r.body("bar").angle, r.statistics.steps

odyn.integrators(): the integrators by name, with what they are.
Other analyses: odyn.kinematics (a fully driven mechanism, with the drivers' efforts),
odyn.statics, odyn.quasi_statics (equilibria along a driver's motion), odyn.modes,
odyn.linearize (a state-space model for chosen inputs and outputs, about any state);
odyn.check(model) reports its degrees of freedom and redundant equations.

Scenes: odyn.load(path) -> Scene (model + analysis settings + outputs), odyn.save(scene, path).
Command line: odyn run SCENE (python -m odyn run SCENE).
Element types of one's own, compiled in a module of one's own: odyn.Model(module=...), and
odyn.cmake_dir() for its build (docs/elements.md).
"""

from . import _core
from ._core import AssemblyError, Error, ModelError, SolverError
from ._schema import SceneError
from .contact import hunt_crossley_dissipation
from .modules import cmake_dir
from .model import (BaseModel, Model, PlanarModel, constant_velocity, frame, harmonic,
                    motion_function, polynomial)
from .results import (AssemblyWarning, BodyHistory, Event, Interrupted, PlanarBodyHistory,
                      PointHistory, Reaction, RedundantConstraintsWarning, Result, Statistics,
                      ToleranceWarning, assemble, integrators, simulate)
from .scene import Scene, load, loads, save
from .kinematics import ModelReport, check, kinematics
from .statics import Modes, modes, quasi_statics, statics
from .linear import LinearModel, linearize
from .settings import (Adams, AssemblySettings, Auto, Bdf, Dop853, Dopri5, GeneralizedAlpha, Hht,
                       IntegratorSettings)

#: Every element type that Model.add accepts (and scenes, except user_force and
#: user_constraint).
element_types = tuple(t for t in dict.fromkeys(_core.element_types) if t != "signal_watch")
#: Every element type that PlanarModel.add accepts.
planar_element_types = tuple(
    t for t in dict.fromkeys(_core.planar_element_types) if t != "signal_watch")

__version__ = "0.1.0"

__all__ = [
    "Adams", "AssemblyError", "AssemblySettings", "AssemblyWarning", "Auto", "BaseModel", "Bdf",
    "BodyHistory", "Dop853", "Dopri5", "Error", "Event", "GeneralizedAlpha", "Hht",
    "IntegratorSettings", "Interrupted", "LinearModel", "Model", "ModelError", "ModelReport",
    "Modes", "PlanarBodyHistory", "PlanarModel", "PointHistory", "Reaction",
    "RedundantConstraintsWarning", "Result", "Scene", "SceneError", "SolverError", "Statistics",
    "ToleranceWarning", "assemble", "check", "cmake_dir", "constant_velocity", "element_types",
    "frame", "harmonic", "hunt_crossley_dissipation", "integrators", "kinematics", "linearize",
    "load", "loads", "modes", "motion_function", "planar_element_types", "polynomial",
    "quasi_statics", "save", "simulate", "statics",
]
