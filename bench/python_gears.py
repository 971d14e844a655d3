"""Speed against error on gears and screws, for each integrator and tolerance, against closed
forms:

- gearbox: a pinion (J = 1e-3 kg m^2) driving a wheel (J = 0.016 kg m^2) at ratio -1/4 on
  spatial hinges, under a motor torque of 0.2 N m for 2 s (the pinion turns about 10 times);
  the pinion's angle against T t^2 / (2 (J_p + J_w / 16));
- lead screw: a 0.4 kg nut (J = 2e-5 kg m^2 about the screw) on a cylindrical joint with a
  pitch of 10 mm, sinking under gravity for 0.5 s; its slide against g m t^2 / (2 (m + J (2 pi
  / p)^2)).

For each: the relative error, the steps and the median wall time of 5 runs.

    .venv/bin/python bench/python_gears.py
"""

import math

import odyn
from speed_error_table import COMMON_CASES, print_table

G = 9.81
TORQUE, J_PINION, J_WHEEL, RATIO = 0.2, 1e-3, 0.016, -0.25
MASS, J_NUT, PITCH = 0.4, 2e-5, 0.01


def gearbox():
    m = odyn.Model()
    m.add_body("pinion", 0.2, [J_PINION / 2, J_PINION / 2, J_PINION])
    m.add_body("wheel", 1.0, [J_WHEEL / 2, J_WHEEL / 2, J_WHEEL], position=[0.1, 0, 0])
    m.add_revolute("input", "ground", body_b="pinion")
    m.add_revolute("output", "ground", on_a={"point": [0.1, 0, 0]}, body_b="wheel")
    m.add_gear("mesh", joint_a="input", joint_b="output", ratio=RATIO)
    m.add_point_torque("motor", "pinion", [0, 0, TORQUE])
    return m


def lead_screw():
    m = odyn.Model()
    m.add_body("nut", MASS, [1e-5, 1e-5, J_NUT])
    m.add_cylindrical("shaft", "ground", body_b="nut")
    m.add_screw("thread", joint="shaft", pitch=PITCH)
    m.add_gravity("gravity", [0, 0, -G])
    return m


def gearbox_error(r):
    expected = TORQUE * 2.0 ** 2 / (2 * (J_PINION + RATIO ** 2 * J_WHEEL))
    return abs(r.output("mesh", "angle_a")[-1] / expected - 1.0)


def lead_screw_error(r):
    lead = 2 * math.pi / PITCH
    expected = -G * MASS * 0.5 ** 2 / (2 * (MASS + J_NUT * lead ** 2))
    return abs(r.output("thread", "slide")[-1] / expected - 1.0)


CASES = COMMON_CASES + [
    ("generalized-alpha, h = 1e-3 s", {"integrator": "generalized-alpha", "step": 1e-3}),
    ("dop853, 1e-9, joint coordinates",
     {"integrator": "dop853", "rtol": 1e-9, "atol": 1e-9, "coordinates": "joint"}),
]

print_table([("gearbox: error of the angle", gearbox, 2.0, gearbox_error),
             ("lead screw: error of the slide", lead_screw, 0.5, lead_screw_error)], CASES)
