"""Speed against error on joint friction, for each integrator and tolerance, against closed
forms:

- sliding block: a 2 kg block launched at 1 m/s down a 20 degree slope on a translational joint
  with mu_k = 0.5, mu_s = 0.6 (v_s = 0.01 m/s, v_t = 1e-4 m/s); it slows at
  g (mu_k cos - sin) and sticks at 0.80 s. The error of its speed at 0.5 s against v0 minus
  that deceleration times 0.5 s, relative to v0;
- stuck block: the same run to 1.2 s, stuck since 0.80 s; the error of its creep speed against
  v_t atanh(tan / mu(v)) (where the regularized law holds gravity's pull), relative;
- braked wheel: a 3 kg wheel (J = 0.05 kg m^2) spinning at 5 rad/s on a horizontal axle with a
  rubbing pin (mu = 0.3, r = 0.02 m); its spin falls at mu r m g / J while it carries its weight.
  The error of its spin at 1 s, relative to the initial spin;
- rubbing pendulum: a 1.5 kg bar (J = 0.02 kg m^2 about its centre, 0.4 m from the pin)
  released from 1.2 rad, its pin (r = 0.05 m, mu = 0.3, v_t = 1e-3 m/s) loaded by the reaction,
  which the friction changes in turn. The error of its angle at 1.5 s against the
  one-coordinate equation J_pin theta'' = -m g L sin(theta) - r F(r |theta'|) sign(theta')
  with its normal load solved at each evaluation, integrated by classical Runge-Kutta at
  h = 1e-4 s (5e-5 s gives the same angle to 1e-12 rad).

For each: the error, the steps and the median wall time of 5 runs.

    .venv/bin/python bench/python_friction.py
"""

import math

import odyn
from speed_error_table import COMMON_CASES, print_table

G = 9.81
ANGLE, V0, MU, MU_S, V_T = math.radians(20.0), 1.0, 0.5, 0.6, 1e-4
MASS, J_WHEEL, SPIN, MU_PIN, PIN = 3.0, 0.05, 5.0, 0.3, 0.02


def block():
    m = odyn.Model()
    m.add_body("block", 2.0, [0.1, 0.2, 0.3], linear_velocity=[V0, 0, 0])
    m.add_translational("rail", "ground", on_a={"axis": [1, 0, 0]}, body_b="block",
                        on_b={"axis": [1, 0, 0]})
    m.add_joint_friction("rubbing", joint="rail", coefficient=MU, static_coefficient=MU_S,
                         transition_velocity=V_T)
    m.add_gravity("gravity", [G * math.sin(ANGLE), 0, -G * math.cos(ANGLE)])
    return m


def wheel():
    m = odyn.Model()
    m.add_body("wheel", MASS, [0.03, J_WHEEL, 0.03], angular_velocity=[0, SPIN, 0])
    m.add_revolute("axle", "ground", on_a={"axis": [0, 1, 0]}, body_b="wheel",
                   on_b={"axis": [0, 1, 0]})
    m.add_joint_friction("bearing", joint="axle", coefficient=MU_PIN, radius=PIN)
    m.add_gravity("gravity", [0, 0, -G])
    return m


def sliding_error(r):
    deceleration = G * (MU * math.cos(ANGLE) - math.sin(ANGLE))
    i = round(0.5 / 0.01)
    return abs(r.body("block").linear_velocity[i, 0] - (V0 - deceleration * 0.5)) / V0


def creep_error(r):
    creep = 0.0  # v = v_t atanh(tan / mu(v)), by a fixed point
    for _ in range(20):
        mu = MU + (MU_S - MU) * math.exp(-(creep / 0.01) ** 2)
        creep = V_T * math.atanh(math.tan(ANGLE) / mu)
    return abs(r.body("block").linear_velocity[-1, 0] / creep - 1.0)


def wheel_error(r):
    expected = SPIN - MU_PIN * PIN * MASS * G / J_WHEEL * 1.0
    return abs(r.body("wheel").angular_velocity[-1, 1] - expected) / SPIN


BOB, J_BOB, ARM, THETA0, MU_ARM, R_ARM, VT_ARM = 1.5, 0.02, 0.4, 1.2, 0.3, 0.05, 1e-3


def pendulum():
    m = odyn.Model()
    m.add_body("bob", BOB, [0.03, J_BOB, 0.01],
               position=[ARM * math.sin(THETA0), 0, -ARM * math.cos(THETA0)],
               orientation=[math.cos(THETA0 / 2), 0, -math.sin(THETA0 / 2), 0])
    m.add_revolute("pin", "ground", on_a={"axis": [0, -1, 0]}, body_b="bob",
                   on_b={"point": [0, 0, ARM], "axis": [0, -1, 0]})
    m.add_joint_friction("rubbing", joint="pin", coefficient=MU_ARM, radius=R_ARM,
                         transition_velocity=VT_ARM)
    m.add_gravity("gravity", [0, 0, -G])
    return m


def pendulum_reference(t_end=1.5, h=1e-4):
    """The angle at t_end from the one-coordinate equation (see the top of this file)."""
    pivot = J_BOB + BOB * ARM ** 2

    def rate(theta, omega):
        s, c = math.sin(theta), math.cos(theta)
        accel = -BOB * G * ARM * s / pivot
        for _ in range(12):  # the normal load holds theta'': a fixed point, 0.04 a pass
            ax = ARM * (accel * c - omega * omega * s)
            az = ARM * (accel * s + omega * omega * c)
            normal = BOB * math.hypot(ax, az + G)
            v = R_ARM * abs(omega)
            force = MU_ARM * normal * math.tanh(v / VT_ARM)
            accel = (-BOB * G * ARM * s - R_ARM * math.copysign(force, omega)) / pivot
        return omega, accel

    theta, omega = THETA0, 0.0
    for _ in range(round(t_end / h)):
        k1 = rate(theta, omega)
        k2 = rate(theta + h / 2 * k1[0], omega + h / 2 * k1[1])
        k3 = rate(theta + h / 2 * k2[0], omega + h / 2 * k2[1])
        k4 = rate(theta + h * k3[0], omega + h * k3[1])
        theta += h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        omega += h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
    return theta


PENDULUM_ANGLE = pendulum_reference()


def pendulum_error(r):
    p = r.body("bob").position[-1]
    return abs(math.atan2(p[0], -p[2]) - PENDULUM_ANGLE) / THETA0


CASES = COMMON_CASES + [
    ("generalized-alpha, h = 1e-3 s", {"integrator": "generalized-alpha", "step": 1e-3}),
]

print_table([("sliding block: error of v(0.5 s)", block, 0.5, sliding_error),
             ("stuck block: error of the creep", block, 1.2, creep_error),
             ("braked wheel: error of the spin", wheel, 1.0, wheel_error),
             ("rubbing pendulum: error of the angle", pendulum, 1.5, pendulum_error)], CASES)
