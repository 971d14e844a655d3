"""Stick-slip: a block on a belt that runs at a constant speed, held back by a spring to the
ground, with friction in the block's slide on the belt (joint_friction, docs/friction.md).

The block rides with the belt while the spring's pull stays below mu_s N. Then it slips back,
swings about the point where the spring balances mu_k N, and catches the belt again: a limit
cycle. With Coulomb's law (mu falling from mu_s to mu_k at once), the period is

    T = (pi + 2 atan(V / (omega D))) / omega + 2 D / V,   D = (mu_s - mu_k) N / k,

with omega = sqrt(k / m). The regularized law approaches it as the Stribeck velocity falls.

    python examples/python/stick_slip.py [--stribeck-velocity V] [--plot FILE]
"""

import argparse
import math

import numpy as np

import odyn

G = 9.81


def belt_and_block(belt_speed=0.05, stiffness=100.0, mass=1.0, mu=0.4, mu_s=0.6,
                   stribeck_velocity=1e-3, transition_velocity=1e-5):
    """The planar model: a belt driven along x, a block sliding on it, a spring from the ground
    to the block (unstretched at x = 0), gravity pressing the block on the belt."""
    m = odyn.PlanarModel()
    m.add_body("belt", 1.0, 0.1, linear_velocity=[belt_speed, 0])
    m.add_body("block", mass, 0.01, linear_velocity=[belt_speed, 0])
    m.add_translational("track", "ground", on_a={"axis": [1, 0]}, body_b="belt",
                        on_b={"axis": [1, 0]})
    m.add_translational_driver("drive", {"type": "constant_velocity", "rate": belt_speed},
                               joint="track")
    m.add_translational("slide", "belt", on_a={"axis": [1, 0]}, body_b="block",
                        on_b={"axis": [1, 0]})
    m.add_joint_friction("friction", joint="slide", coefficient=mu, static_coefficient=mu_s,
                         stribeck_velocity=stribeck_velocity,
                         transition_velocity=transition_velocity)
    m.add_tsda("spring", "ground", point_a=[-1.0, 0], body_b="block", stiffness=stiffness,
               free_length=1.0)
    m.add_gravity("gravity", [0, -G])
    return m


def coulomb_period(belt_speed=0.05, stiffness=100.0, mass=1.0, mu=0.4, mu_s=0.6):
    """The limit cycle's period under Coulomb's law (see the top of this file)."""
    omega = math.sqrt(stiffness / mass)
    gap = (mu_s - mu) * mass * G / stiffness
    return ((math.pi + 2 * math.atan(belt_speed / (omega * gap))) / omega
            + 2 * gap / belt_speed)


def slip_onsets(result, belt_speed=0.05):
    """The times at which the block starts to slip back (its speed relative to the belt falls
    through -belt_speed / 2), interpolated between outputs."""
    slip = result.body("block").linear_velocity[:, 0] - belt_speed
    level = -belt_speed / 2
    i = np.where((slip[:-1] > level) & (slip[1:] <= level))[0]
    return result.t[i] + (level - slip[i]) / (slip[i + 1] - slip[i]) * (result.t[i + 1]
                                                                          - result.t[i])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--stribeck-velocity", type=float, default=1e-3)
    parser.add_argument("--plot", help="write a figure of the cycle to this file (PNG)")
    args = parser.parse_args()
    model = belt_and_block(stribeck_velocity=args.stribeck_velocity,
                           transition_velocity=args.stribeck_velocity / 100)
    r = odyn.simulate(model, t_end=6.0, output_interval=1e-3, rtol=1e-9, atol=1e-11)
    period = np.diff(slip_onsets(r))[-1]
    print(f"{r.statistics.steps} steps, {1e3 * r.statistics.wall_seconds:.1f} ms "
          f"({r.summary['integrator_choice']})")
    print(f"period {period:.5f} s; Coulomb's law: {coulomb_period():.5f} s "
          f"({100 * (period / coulomb_period() - 1):+.2f} %)")
    if args.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(7, 5))
        top.plot(r.t, r.body("block").linear_velocity[:, 0] - 0.05)
        top.set_ylabel("slip speed on the belt (m/s)")
        bottom.plot(r.t, r.output("friction", "force"), label="friction on the block")
        bottom.plot(r.t, -r.output("spring", "tension"), label="spring on the block")
        bottom.set_ylabel("force along the belt (N)")
        bottom.set_xlabel("t (s)")
        bottom.legend()
        fig.tight_layout()
        fig.savefig(args.plot, dpi=120)
        print(f"wrote {args.plot}")


if __name__ == "__main__":
    main()
