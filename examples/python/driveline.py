"""A bent driveline: two shafts in bearings whose axes cross at an angle beta, joined where they
cross by a constant-velocity joint (cv_joint) or by a Cardan cross (universal).

The input shaft turns at a constant rate omega. Through the constant-velocity joint the output
turns at omega too, and a load torque T on it needs T from the motor. Through the cross the
output angle follows tan psi = tan phi / cos beta, so its speed swings twice a turn between
omega cos beta and omega / cos beta:

    psi' = omega cos(beta) / (1 - sin^2(beta) cos^2(phi)).

    python examples/python/driveline.py [--bend DEGREES] [--plot FILE]
"""

import argparse
import math

import numpy as np

import odyn


def bent_driveline(joint="cv_joint", bend=0.5, omega=3.0, load=2.5):
    """Shaft a turns about z at `omega` (a driver on its bearing); shaft b's axis d is z tilted
    by `bend` about y (a parallel-axes primitive to the ground, so that nothing is constrained
    twice); `joint` ("cv_joint" or "universal") joins them where the axes cross, and a torque
    `load` resists b's turning."""
    d = np.array([math.sin(bend), 0.0, math.cos(bend)])
    z, x, y = [0, 0, 1], [1, 0, 0], [0, 1, 0]
    m = odyn.Model()
    m.add_body("a", 1.0, [0.02, 0.02, 0.01], position=[0, 0, -0.5])
    m.add_body("b", 1.0, [0.02, 0.02, 0.01], position=0.5 * d,
               orientation=[math.cos(bend / 2), 0, math.sin(bend / 2), 0])
    m.add_revolute("bearing", "ground", on_a=odyn.frame([0, 0, -0.5], z), body_b="a",
                   on_b=odyn.frame([0, 0, 0], z))
    m.add_parallel_axes("guide", "ground", on_a=odyn.frame(0.5 * d, d), body_b="b")
    if joint == "cv_joint":
        m.add_cv_joint("joint", "a", on_a=odyn.frame([0, 0, 0.5], z), body_b="b",
                       on_b=odyn.frame([0, 0, -0.5], z))
    else:  # the cross's arms: along x on a, along y on b
        m.add_universal("joint", "a", on_a=odyn.frame([0, 0, 0.5], x), body_b="b",
                        on_b=odyn.frame([0, 0, -0.5], y))
    m.add_revolute_driver("motor", odyn.constant_velocity(omega), joint="bearing")
    m.add_point_torque("load", "b", -load * d)
    return m


def cardan_speed(t, bend=0.5, omega=3.0):
    """The output speed through the cross (see the top of this file)."""
    c = np.cos(omega * np.asarray(t))
    return omega * math.cos(bend) / (1 - math.sin(bend) ** 2 * c**2)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--bend", type=float, default=30.0, help="degrees")
    parser.add_argument("--plot", help="write a figure of the output speeds to this file (PNG)")
    args = parser.parse_args()
    bend, omega = math.radians(args.bend), 3.0
    runs = {joint: odyn.simulate(bent_driveline(joint, bend, omega), t_end=2 * math.pi / omega,
                                 output_interval=0.01, rtol=1e-10, atol=1e-10)
            for joint in ("cv_joint", "universal")}
    for joint, r in runs.items():
        speed = r.body("b").angular_velocity[:, 2]
        reference = np.full_like(r.t, omega) if joint == "cv_joint" else cardan_speed(
            r.t, bend, omega)
        print(f"{joint:9s}: output speed {speed.min():.4f} to {speed.max():.4f} rad/s, "
              f"largest error against the closed form {np.abs(speed - reference).max():.1e}; "
              f"motor torque {r.reaction('motor').torque[:, 2].min():.4f} to "
              f"{r.reaction('motor').torque[:, 2].max():.4f} N m")
    if args.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(7, 4))
        for joint, label in (("cv_joint", "constant-velocity joint"),
                             ("universal", "universal (Cardan) joint")):
            r = runs[joint]
            ax.plot(np.degrees(omega * r.t), r.body("b").angular_velocity[:, 2] / omega,
                    label=label)
        r = runs["universal"]
        ax.plot(np.degrees(omega * r.t)[::8], cardan_speed(r.t, bend, omega)[::8] / omega, "k.",
                label="cos(beta) / (1 - sin^2(beta) cos^2(phi))")
        ax.set_xlabel("input shaft angle phi (degrees)")
        ax.set_ylabel("output speed / input speed")
        ax.set_title(f"a driveline bent by {args.bend:g} degrees")
        ax.legend(fontsize=8, ncol=3, loc="upper center", bbox_to_anchor=(0.5, -0.2))
        fig.tight_layout()
        fig.savefig(args.plot, dpi=120)
        print(f"wrote {args.plot}")


if __name__ == "__main__":
    main()
