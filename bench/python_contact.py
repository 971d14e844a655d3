"""Speed against error on contact, for each integrator and tolerance, against closed forms:

- impact: a 0.3 kg ball thrown at 1.5 m/s against the ground (sphere_plane, k = 1e7 N/m^1.5,
  Hertz's exponent, d = 0.4 s/m), no gravity; the exit speed against the root of the law's
  first integral (docs/contact.md);
- rolling: a 2 kg ball of 0.1 m rolling from rest down a 0.3 rad incline (mu 0.6,
  v_s = 1e-4 m/s) for 1 s, from its static overlap delta; its mean acceleration over the last
  half second against g sin(theta) / (1 + I / (m r_c^2)), r_c = r - delta / 2 (5/7 g sin(theta)
  for a rigid ball).

For each: the relative error, the steps and the median wall time of 5 runs.

    .venv/bin/python bench/python_contact.py
"""

import math

import numpy as np

import odyn
from speed_error_table import print_table

G = 9.81


def exit_speed(d, v_in):
    target = d * v_in - math.log1p(d * v_in)
    lo, hi = 0.0, (1.0 - 1e-15) / d
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if -d * mid - math.log1p(-d * mid) < target else (lo, mid)
    return 0.5 * (lo + hi)


def impact():
    m = odyn.Model()
    m.add_body("ball", 0.3, [3e-4] * 3, position=[0, 0, 0.052], linear_velocity=[0, 0, -1.5])
    m.add_sphere_plane("floor", "ground", "ball", 0.05, stiffness=1e7, dissipation=0.4)
    return m


THETA = 0.3


# The static overlap, and the contact point's lever r - delta / 2 (docs/contact.md).
DEPTH = (2.0 * G * math.cos(THETA) / 1e7) ** (1.0 / 1.5)
LEVER = 0.1 - 0.5 * DEPTH


def rolling():
    m = odyn.Model()
    normal = np.array([-math.sin(THETA), 0.0, math.cos(THETA)])
    m.add_body("ball", 2.0, [0.4 * 2.0 * 0.01] * 3, position=(0.1 - DEPTH) * normal)
    m.add_gravity("g", [0, 0, -G])
    m.add_sphere_plane("floor", "ground", "ball", 0.1, normal=normal, stiffness=1e7,
                       dissipation=2.0, friction=0.6, slip_speed=1e-4)
    return m


def impact_error(r):
    return abs(r.body("ball").linear_velocity[-1, 2] / exit_speed(0.4, 1.5) - 1.0)


def rolling_error(r):
    downhill = np.array([math.cos(THETA), 0.0, math.sin(THETA)])
    speed = -r.body("ball").linear_velocity @ downhill
    late = r.t >= 0.5
    slope = np.polyfit(r.t[late], speed[late], 1)[0]
    return abs(slope * (1.0 + 0.4 * (0.1 / LEVER) ** 2) / (G * math.sin(THETA)) - 1.0)


CASES = [
    ("auto (defaults)", {}),
    ("dop853, rtol = atol = 1e-6", {"integrator": "dop853", "rtol": 1e-6, "atol": 1e-6}),
    ("dop853, 1e-9", {"integrator": "dop853", "rtol": 1e-9, "atol": 1e-9}),
    ("dopri5, 1e-6", {"integrator": "dopri5", "rtol": 1e-6, "atol": 1e-6}),
    ("bdf, 1e-6", {"integrator": "bdf", "rtol": 1e-6, "atol": 1e-6}),
    ("generalized-alpha, h = 1e-4 s", {"integrator": "generalized-alpha", "step": 1e-4}),
    ("generalized-alpha, h = 1e-5 s", {"integrator": "generalized-alpha", "step": 1e-5}),
]

print_table([("impact: error of v_out", impact, 0.02, impact_error),
             ("rolling: error of the acceleration", rolling, 1.0, rolling_error)], CASES)
