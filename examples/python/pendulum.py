"""A pendulum with air drag: the Python twin of README's first program
(tests/downstream/main.cpp). The drag is a new force written in the script itself, as a Python
function of the bob's state, where the C++ program writes a new element type.
"""

import numpy as np

import odyn


def air_drag(coefficient):
    """A user force: -c v at the centre of mass (global force, then global torque)."""
    def force(t, body):
        v = body.linear_velocity
        return (-coefficient * v[0], -coefficient * v[1], -coefficient * v[2], 0.0, 0.0, 0.0)
    return force


def main():
    m = odyn.Model()
    m.add_body(name="bob", mass=1.0, inertia=[1e-3, 1e-3, 1e-3], position=[1.0, 0.0, 0.0])
    m.add_revolute(name="hinge", body_a="ground", on_a=odyn.frame([0, 0, 0], [0, 0, 1]),
                   body_b="bob", on_b=odyn.frame([-1, 0, 0], [0, 0, 1]))
    m.add_gravity(name="gravity", acceleration=[0.0, -9.81, 0.0])
    m.add_user_force(name="drag", bodies=["bob"], function=air_drag(0.05))
    res = odyn.simulate(m, step=1e-3, t_end=2.0, output_interval=0.5)
    force = res.reaction("hinge").force  # on the bob, global axes
    position = res.body("bob").position
    angle = np.arctan2(position[:, 1], position[:, 0])
    for t, a, f in zip(res.t, angle, force):
        print(f"t = {t:.1f} s  angle = {a:+.4f} rad  hinge force = ({f[0]:+.3f}, {f[1]:+.3f}) N")


if __name__ == "__main__":
    main()
