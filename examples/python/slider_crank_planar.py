"""The engine of shared/specs/engine.md built from planar elements, the Python twin of
examples/slider_crank_planar.cpp: the same geometry, masses, gas force and load in the Y-Z
plane (plane x = global Y, plane y = global Z, phi = rotation about X), with the crank's and
rod's Ixx as planar moments of inertia. 9 coordinates and 8 equations instead of 18 and 17;
same options and CSV columns as engine.py. examples/slider_crank_planar.json is the same
model as a scene file. The gas force comes with the engine's models of the module odyn_engine
(examples/python/odyn_engine/odyn_engine.cpp).

    python examples/python/slider_crank_planar.py [--h STEP] [--t-end T] [--dt-out DT]
        [--out FILE] [--integrator NAME] [--rho-inf R] [--rtol R] [--atol A]
"""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import odyn  # noqa: E402
import odyn_engine  # noqa: E402
from engine import run_command_line  # noqa: E402


def build(r=0.04, L=0.14, omega0=157.08, c_load=0.1):
    """The planar engine at top dead centre (examples/engine_model.hpp, engine::planar)."""
    m = odyn.PlanarModel(module=odyn_engine)
    m.add_body(name="crank", mass=1.399, inertia=1.524, angular_velocity=omega0)
    m.add_body(name="rod", mass=0.253, inertia=0.399, position=[0, r + L / 2])
    m.add_body(name="piston", mass=0.643, inertia=0.457, position=[0, r + L])
    # Frames left out: the body's centre of mass, the axis the other body's.
    m.add_revolute(name="bearing", body_a="ground", body_b="crank")
    m.add_revolute(name="crank pin", body_a="crank", on_a=odyn.frame([0, r]), body_b="rod",
                   on_b=odyn.frame([0, -L / 2]))
    m.add_revolute(name="piston pin", body_a="rod", on_a=odyn.frame([0, L / 2]), body_b="piston")
    m.add_translational(name="cylinder", body_a="ground", on_a=odyn.frame([0, r + L], [0, 1]),
                        body_b="piston")
    m.add_gravity(name="gravity", acceleration=[0, -9.81])
    m.add_rsda(name="load", body_a="ground", body_b="crank", damping=c_load)
    m.add("engine_gas_force", name="gas force", crank="crank", piston="piston", r=r, L=L)
    return m


if __name__ == "__main__":
    sys.exit(run_command_line("slider_crank_planar", build))
