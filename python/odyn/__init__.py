"""odyn: multibody dynamics (rigid bodies, joints, drivers, forces; assembly; Lie-group
generalized-alpha dynamics), with the C++ library's elements compiled in.

    import odyn
    m = odyn.Model()
    m.add_body(name="bob", mass=1.0, inertia=[1e-3, 1e-3, 1e-3], position=[1, 0, 0])
    m.add_revolute(name="hinge", body_a="ground", on_a=odyn.frame([0, 0, 0], [0, 0, 1]),
                   body_b="bob", on_b=odyn.frame([-1, 0, 0], [0, 0, 1]))
    m.add_gravity(name="gravity", acceleration=[0, -9.81, 0])
    r = odyn.simulate(m, t_end=2.0, step=1e-3, output_interval=0.01)
    r.reaction("hinge").force      # (n, 3), on the bob, global axes

Scenes: odyn.load(path) -> Scene (model + analysis settings + outputs), odyn.save(scene, path).
Command line: odyn run SCENE (python -m odyn run SCENE).
"""

from . import _core
from ._core import AssemblyError, Error, ModelError, SolverError
from ._schema import SceneError
from .model import (Model, constant_velocity, frame, harmonic, motion_function,
                    polynomial)
from .results import (BodyHistory, Interrupted, Reaction, Result, assemble,
                      simulate)
from .scene import Scene, load, loads, save

#: Every element type that Model.add accepts (and scenes, except user_force).
element_types = tuple(t for t in dict.fromkeys(_core.element_types) if t != "signal_watch")

__version__ = "0.1.0"

__all__ = [
    "AssemblyError", "BodyHistory", "Error", "Interrupted", "Model", "ModelError", "Reaction",
    "Result", "Scene", "SceneError", "SolverError", "assemble", "constant_velocity",
    "element_types", "frame", "harmonic", "load", "loads", "motion_function", "polynomial",
    "save", "simulate",
]
