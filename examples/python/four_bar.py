"""A crank-rocker four-bar linkage under gravity, its crank driven at one turn per second: the
Python twin of examples/four_bar.cpp (model: examples/four_bar_model.hpp). It writes the
rocker's motion, the motor torque and the pin forces over two turns.

Ground pivots O2 = (0, 0) and O4 = (ground, 0); links crank O2-A, coupler A-B, rocker O4-B,
each a uniform bar whose body x axis runs from its first point to its second.

    python examples/python/four_bar.py [--h STEP] [--t-end T] [--dt-out DT] [--out FILE]
                                       [--integrator NAME] [--rho-inf R]
"""

import argparse
import math
import sys

import numpy as np

import odyn

GROUND, CRANK, COUPLER, ROCKER = 0.40, 0.10, 0.35, 0.30  # link lengths, m
MASSES = {"crank": 0.5, "coupler": 1.2, "rocker": 1.0}   # kg
SPEED = 2 * math.pi                                      # crank, rad/s
G = 9.81                                                 # m/s^2, along -y
COLUMNS = ("t", "crank_angle", "rocker_angle", "rocker_rate", "motor_torque", "F_O2", "F_A",
           "F_B", "F_O4")


def point_b(crank_angle):
    """Point B of the open (upper) assembly for a crank angle: the circles about A (coupler)
    and about O4 (rocker) meet there."""
    a = CRANK * np.array([math.cos(crank_angle), math.sin(crank_angle)])
    d = np.array([GROUND, 0.0]) - a
    distance = float(np.linalg.norm(d))
    along = (distance**2 + COUPLER**2 - ROCKER**2) / (2 * distance)
    across = math.sqrt(COUPLER**2 - along**2)
    unit = d / distance
    return a + along * unit + across * np.array([-unit[1], unit[0]])


def build():
    """The linkage with the crank at angle 0, at rest; the motor then turns it."""
    o2, o4, a, b = np.zeros(2), np.array([GROUND, 0.0]), np.array([CRANK, 0.0]), point_b(0.0)
    m = odyn.PlanarModel()

    def bar(name, start, end):
        d = end - start
        m.add_body(name=name, mass=MASSES[name], inertia=MASSES[name] * float(d @ d) / 12,
                   position=(start + end) / 2, angle=math.atan2(d[1], d[0]))

    bar("crank", o2, a)
    bar("coupler", a, b)
    bar("rocker", o4, b)
    half = {"crank": CRANK / 2, "coupler": COUPLER / 2, "rocker": ROCKER / 2}
    m.add_revolute(name="O2", body_a="ground", on_a=odyn.frame(o2), body_b="crank",
                   on_b=odyn.frame([-half["crank"], 0]))
    m.add_revolute(name="A", body_a="crank", on_a=odyn.frame([half["crank"], 0]),
                   body_b="coupler", on_b=odyn.frame([-half["coupler"], 0]))
    m.add_revolute(name="B", body_a="coupler", on_a=odyn.frame([half["coupler"], 0]),
                   body_b="rocker", on_b=odyn.frame([half["rocker"], 0]))
    m.add_revolute(name="O4", body_a="ground", on_a=odyn.frame(o4), body_b="rocker",
                   on_b=odyn.frame([-half["rocker"], 0]))
    m.add_revolute_driver(name="motor", joint="O2", motion=odyn.constant_velocity(SPEED))
    m.add_gravity(name="gravity", acceleration=[0, -G])
    return m


def table(res):
    """The C++ example's columns: body angles, the motor's torque on the crank and the
    magnitude of each pin's force on its body b."""
    out = {"t": res.t, "crank_angle": res.body("crank").angle,
           "rocker_angle": res.body("rocker").angle,
           "rocker_rate": res.body("rocker").angular_velocity,
           "motor_torque": res.reaction("motor", side="b").torque}
    for pin in ("O2", "A", "B", "O4"):
        out[f"F_{pin}"] = np.linalg.norm(res.reaction(pin, side="b").force, axis=1)
    return out


def main(argv=None):
    p = argparse.ArgumentParser(prog="four_bar", description=__doc__.splitlines()[0])
    p.add_argument("--h", type=float, default=1e-3)
    p.add_argument("--t-end", type=float, default=2.0)
    p.add_argument("--dt-out", type=float, default=1e-2)
    p.add_argument("--out", default="four_bar.csv")
    p.add_argument("--integrator", default="generalized-alpha", choices=list(odyn.integrators()))
    # Joint forces are an output here: rho_inf = 0.5 damps the step-to-step ripple that
    # index-3 multipliers carry at the default 0.9.
    p.add_argument("--rho-inf", type=float, default=0.5)
    args = p.parse_args(argv)
    try:
        res = odyn.simulate(build(), step=args.h, t_end=args.t_end, output_interval=args.dt_out,
                            integrator=args.integrator, rho_inf=args.rho_inf)
    except odyn.Error as e:
        print(f"four_bar: {e}", file=sys.stderr)
        return 1
    columns = table(res)
    odyn.scene.write_table(columns, args.out)
    s = res.statistics
    print(f"four_bar: h = {args.h:g} s, t_end = {args.t_end:g} s -> {args.out} "
          f"({len(res)} rows)")
    print(f"  steps {s.steps}, Newton iterations {s.newton_iterations}, "
          f"wall time {s.wall_seconds:.3f} s")
    print(f"  peak motor torque {np.max(np.abs(columns['motor_torque'])):.4f} N m, "
          f"largest |Phi| {s.max_position_residual:.2e}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
