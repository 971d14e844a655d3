"""Speed against error for a constraint written in Python (user_constraint), against the same
constraint in C++ and a closed form.

A conical pendulum: a 2 kg bob on a massless rod of length 1.5 m from the origin, at 0.6 rad
from the downward vertical, started on its circle at Omega = sqrt(g / (L cos theta)), stays
on the circle. The rod is:

- C++: the `distance` element;
- Python, given: phi = (|x|^2 - L^2) / 2 with its gradient (x) and gamma (-|x'|^2);
- Python, differences: the same phi, its gradient and gamma from differences of phi.

For each integrator setting: the bob's distance from its place on the circle at 2 s, relative
to the circle's radius, the steps and the median wall time of 5 runs.

    .venv/bin/python bench/python_user_constraint.py
"""

import math

import numpy as np

import odyn
from speed_error_table import COMMON_CASES, print_table

G, LENGTH, THETA, MASS, T_END = 9.81, 1.5, 0.6, 2.0, 2.0
RADIUS, DEPTH = LENGTH * math.sin(THETA), LENGTH * math.cos(THETA)
OMEGA = math.sqrt(G / DEPTH)


def pendulum(rod):
    def build():
        m = odyn.Model()
        m.add_body("bob", MASS, [1e-3] * 3, position=[RADIUS, 0, -DEPTH],
                   linear_velocity=[0, OMEGA * RADIUS, 0])
        if rod == "C++":
            m.add_distance("rod", "ground", body_b="bob")
        else:
            extra = {}
            if rod == "given":
                extra = {"jacobian": lambda t, b: [*b.position, 0, 0, 0, 0],
                         "gamma": lambda t, b: -float(b.linear_velocity @ b.linear_velocity)}
            m.add_user_constraint("rod", ["bob"],
                                  lambda t, b: 0.5 * (float(b.position @ b.position) - LENGTH**2),
                                  **extra)
        m.add_gravity("gravity", [0, 0, -G])
        return m
    return build


def circle_error(r):
    expected = np.array([RADIUS * math.cos(OMEGA * T_END), RADIUS * math.sin(OMEGA * T_END),
                         -DEPTH])
    return float(np.linalg.norm(r.body("bob").position[-1] - expected)) / RADIUS


CASES = COMMON_CASES + [
    ("generalized-alpha, h = 1e-3 s", {"integrator": "generalized-alpha", "step": 1e-3}),
]

print_table([(f"{rod}: error", pendulum(rod), T_END, circle_error)
             for rod in ("C++", "given", "differences")], CASES)
