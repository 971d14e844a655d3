"""Speed against error on joint stops, for each integrator and tolerance, against closed forms:

- door: a door (8 kg, 0.8 m wide, J = 1.71 kg m^2 about its hinge) swung at 2 rad/s into a
  stop at 90 degrees (revolute_limit, k = 2e3 N m/rad, n = 1, d from
  odyn.hunt_crossley_dissipation(0.5, 2)), no gravity; its rate after the impact against
  -0.5 x 2 rad/s;
- resting: a 2 kg bar of 0.8 m hinged at one end, held out level by a stop under gravity
  (k = 400 N m/rad, n = 1, near critical damping) for 4 s from its first touch; its final
  penetration delta against the torque balance k delta = m g l / 2 cos(delta).

For each: the relative error, the steps and the median wall time of 5 runs.

    .venv/bin/python bench/python_limits.py
"""

import math

import odyn
from speed_error_table import COMMON_CASES, print_table

G = 9.81


def door():
    m = odyn.PlanarModel()
    m.add_body("door", 8.0, 8.0 * 0.8 ** 2 / 12, position=[0.4, 0], angular_velocity=2.0,
               linear_velocity=[0, 0.8])
    m.add_revolute("hinge", "ground", body_b="door", on_b={"point": [-0.4, 0]})
    m.add_revolute_limit("stop", joint="hinge", lower=0.0, upper=math.pi / 2, stiffness=2e3,
                         dissipation=odyn.hunt_crossley_dissipation(0.5, 2.0))
    return m


def resting():
    m = odyn.PlanarModel()
    m.add_body("bar", 2.0, 2.0 * 0.8 ** 2 / 12, position=[0.4, 0])
    m.add_revolute("pivot", "ground", body_b="bar", on_b={"point": [-0.4, 0]})
    m.add_gravity("gravity", [0, -G])
    m.add_revolute_limit("stop", joint="pivot", lower=0.0, stiffness=400.0, dissipation=2.5)
    return m


def door_error(r):
    return abs(r.output("stop", "rate")[-1] / -1.0 - 1.0)


def resting_error(r):
    delta = -r.output("stop", "angle")[-1]
    return abs(400.0 * delta / (2.0 * G * 0.4 * math.cos(delta)) - 1.0)


CASES = COMMON_CASES + [
    ("generalized-alpha, h = 1e-3 s", {"integrator": "generalized-alpha", "step": 1e-3}),
    ("generalized-alpha, h = 1e-4 s", {"integrator": "generalized-alpha", "step": 1e-4}),
]

print_table([("door: error of the rebound rate", door, 1.2, door_error),
             ("resting: error of the penetration", resting, 4.0, resting_error)], CASES)
