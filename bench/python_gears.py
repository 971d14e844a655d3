"""Speed against error on gears and screws, for each integrator and tolerance, against closed
forms:

- gearbox: a pinion (J = 1e-3 kg m^2) driving a wheel (J = 0.016 kg m^2) at ratio -1/4 on
  spatial hinges, under a motor torque of 0.2 N m for 2 s (the pinion turns about 10 times);
  the pinion's angle against T t^2 / (2 (J_p + J_w / 16));
- lead screw: a 0.4 kg nut (J = 2e-5 kg m^2 about the screw) on a cylindrical joint with a
  pitch of 10 mm, sinking under gravity for 0.5 s; its slide against g m t^2 / (2 (m + J (2 pi
  / p)^2));
- planetary set: sun (24 teeth, J = 2e-3), planet (18, J = 8e-4, 0.4 kg at 42 mm on the
  carrier), ring (60, J = 0.03) and carrier (J = 0.01) on coaxial spatial hinges, the meshes
  two three-joint couplers, 0.05 N m on the sun and -0.03 N m on the carrier for 1.5 s (the sun
  turns 2.4 times); the sun's angle against the Lagrangian in the sun's and the ring's angles.

For each: the relative error, the steps and the median wall time of 5 runs.

    .venv/bin/python bench/python_gears.py
"""

import math

import numpy as np

import odyn
from speed_error_table import COMMON_CASES, print_table

G = 9.81
TORQUE, J_PINION, J_WHEEL, RATIO = 0.2, 1e-3, 0.016, -0.25
MASS, J_NUT, PITCH = 0.4, 2e-5, 0.01
TEETH = {"sun": 24, "planet": 18, "ring": 60}
J_SET = {"sun": 2e-3, "ring": 0.03, "carrier": 0.01, "planet": 8e-4}
PLANET_MASS, PLANET_AT = 0.4, 0.042
T_SUN, T_CARRIER = 0.05, -0.03


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


def planetary():
    m = odyn.Model()
    for name, j in J_SET.items():
        at = [0, PLANET_AT, 0] if name == "planet" else [0, 0, 0]
        m.add_body(name, PLANET_MASS if name == "planet" else 0.5, [j, j, j], position=at)
        if name != "planet":
            m.add_revolute(f"{name} hinge", "ground", body_b=name)
    m.add_revolute("planet pin", "carrier", on_a={"point": [0, PLANET_AT, 0]}, body_b="planet")
    z_s, z_p, z_r = TEETH["sun"], TEETH["planet"], TEETH["ring"]
    m.add_coupler("sun mesh", joint_1="planet pin", scale_1=z_p, joint_2="sun hinge",
                  scale_2=z_s, joint_3="carrier hinge", scale_3=-z_s)
    m.add_coupler("ring mesh", joint_1="planet pin", scale_1=z_p, joint_2="ring hinge",
                  scale_2=-z_r, joint_3="carrier hinge", scale_3=z_r)
    m.add_point_torque("motor", "sun", [0, 0, T_SUN])
    m.add_point_torque("load", "carrier", [0, 0, T_CARRIER])
    return m


def planetary_error(r):
    """Velocities (sun, ring, carrier, planet, planet on the carrier) = A (sun', ring')."""
    z_s, z_p, z_r = TEETH["sun"], TEETH["planet"], TEETH["ring"]
    a = np.zeros((5, 2))
    a[0], a[1], a[2] = [1, 0], [0, 1], [z_s / (z_s + z_r), z_r / (z_s + z_r)]
    a[4] = -z_s / z_p * (a[0] - a[2])
    a[3] = a[2] + a[4]
    carrier = J_SET["carrier"] + PLANET_MASS * PLANET_AT ** 2
    inertia = np.diag([J_SET["sun"], J_SET["ring"], carrier, J_SET["planet"], 0.0])
    accel = np.linalg.solve(a.T @ inertia @ a, a.T @ [T_SUN, 0, T_CARRIER, 0, 0])
    expected = 0.5 * accel[0] * 1.5 ** 2
    return abs(r.output("sun mesh", "coordinate_2")[-1] / expected - 1.0)


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
             ("lead screw: error of the slide", lead_screw, 0.5, lead_screw_error),
             ("planetary set: error of the sun's angle", planetary, 1.5, planetary_error)],
            CASES)
