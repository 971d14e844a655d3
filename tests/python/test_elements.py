"""Every element type reachable from Python, each checked against a hand-computed or analytic
value; Python callables checked against the same force computed in C++."""

import math

import numpy as np
import pytest

import odyn
from conftest import python_example

G = 9.81
X, Y, Z = [1, 0, 0], [0, 1, 0], [0, 0, 1]
TESTED = set()


def covers(*types):
    TESTED.update(types)


def pendulum(joint="revolute"):
    """A 1 kg bob (inertia 1e-3) at (1, 0, 0) hinged at the origin about Z; gravity -Y."""
    m = odyn.Model()
    m.add_body(name="bob", mass=1.0, inertia=[1e-3, 1e-3, 1e-3], position=[1, 0, 0])
    if joint == "revolute":
        m.add_revolute(name="hinge", body_a="ground", on_a=odyn.frame([0, 0, 0], Z),
                       body_b="bob", on_b=odyn.frame([-1, 0, 0], Z))
    else:
        m.add_spherical(name="hinge", body_a="ground", point_a=[0, 0, 0], body_b="bob",
                        point_b=[-1, 0, 0])
    m.add_gravity(name="gravity", acceleration=[0, -G, 0])
    return m


@pytest.mark.parametrize("joint", ["revolute", "spherical"])
def test_pendulum_released_horizontal(joint):
    covers(joint, "gravity")
    a = odyn.assemble(pendulum(joint))
    alpha = -G * 1.0 / (1e-3 + 1.0)  # m g L / (J + m L^2)
    np.testing.assert_allclose(a.vdot[0], [0, alpha, 0, 0, 0, alpha], atol=1e-12)
    # Hinge force on the bob: m a - m g (global axes).
    np.testing.assert_allclose(a.reaction("hinge").force[0], [0, alpha + G, 0], atol=1e-12)
    np.testing.assert_allclose(a.reaction("hinge", side="a").force[0], [0, -(alpha + G), 0],
                               atol=1e-12)
    r = odyn.simulate(pendulum(joint), t_end=2.0, step=1e-3, output_interval=0.01)
    assert r.energy_drift() < 2e-3 * G  # mildly dissipative generalized-alpha
    np.testing.assert_allclose(np.linalg.norm(r.body("bob").position, axis=1), 1.0, atol=1e-10)


def slider(kind, axis, spin=0.0):
    m = odyn.Model()
    m.add_body(name="block", mass=2.0, inertia=[0.1, 0.1, 0.1], angular_velocity=[
        spin * a / np.linalg.norm(axis) for a in axis])
    getattr(m, f"add_{kind}")(name="guide", body_a="ground", on_a=odyn.frame([0, 0, 0], axis),
                              body_b="block", on_b=odyn.frame([0, 0, 0], axis))
    m.add_gravity(name="gravity", acceleration=[0, 0, -G])
    return m


@pytest.mark.parametrize("kind", ["translational", "cylindrical"])
def test_block_slides_down_a_45_degree_guide(kind):
    covers(kind)
    axis = [1, 0, -1]
    r = odyn.simulate(slider(kind, axis, spin=3.0 if kind == "cylindrical" else 0.0),
                      t_end=1.0, step=1e-3, output_interval=0.5)
    # Acceleration g sin 45 along the guide: s = g t^2 / (2 sqrt 2).
    s = G * r.t**2 / (2 * math.sqrt(2))
    expected = np.column_stack([s / math.sqrt(2), 0 * s, -s / math.sqrt(2)])
    np.testing.assert_allclose(r.body("block").position, expected, atol=1e-9)
    # The guide pushes perpendicular to itself: m g cos 45 along (1, 0, 1)/sqrt 2.
    np.testing.assert_allclose(r.reaction("guide").force[-1], [G, 0, G], atol=1e-8)
    if kind == "cylindrical":  # free to spin about the guide: the spin stays
        w = r.body("block").angular_velocity[-1]
        np.testing.assert_allclose(w, 3.0 * np.array(axis) / math.sqrt(2), atol=1e-9)


def test_fixed_and_universal_hold_a_body_at_rest():
    covers("fixed", "universal")
    for kind in ("fixed", "universal"):
        m = odyn.Model()
        m.add_body(name="b", mass=3.0, inertia=[0.2, 0.3, 0.4], position=[0, 0, -1])
        if kind == "fixed":
            m.add_fixed(name="j", body_a="ground", on_a=odyn.frame([0, 0, 0], Z), body_b="b",
                        on_b=odyn.frame([0, 0, 1], Z))
        else:
            m.add_universal(name="j", body_a="ground", on_a=odyn.frame([0, 0, 0], X),
                            body_b="b", on_b=odyn.frame([0, 0, 1], Y))
        m.add_gravity(name="gravity", acceleration=[0, 0, -G])
        r = odyn.simulate(m, t_end=0.5, step=1e-3, output_interval=0.25)
        np.testing.assert_allclose(r.body("b").position[-1], [0, 0, -1], atol=1e-10)
        np.testing.assert_allclose(r.reaction("j").force, np.tile([0, 0, 3.0 * G], (3, 1)),
                                   atol=1e-8)
        # In the joint frame on b the axis is w: a fixed joint carries m g along it.
        if kind == "fixed":
            np.testing.assert_allclose(r.reaction("j", axes="joint").force[-1, 2], 3.0 * G,
                                       atol=1e-8)


def test_cv_joint_turns_a_bent_output_shaft_at_the_input_speed():
    # The constant-velocity joint turns b at omega at any bend, and the motor gives the load's
    # torque (equal speeds: the power goes through). The Cardan joint's output speed swings as
    # psi' = omega cos(beta) / (1 - sin^2(beta) cos^2(omega t)).
    # The model is the driveline example's (examples/python/driveline.py).
    covers("cv_joint")
    example = python_example("driveline")
    beta, omega, load = 0.5, 3.0, 2.5
    for joint in ("cv_joint", "universal"):
        r = odyn.simulate(example.bent_driveline(joint, beta, omega, load), t_end=2.0,
                          rtol=1e-10, atol=1e-10, output_interval=0.1)
        spin = r.body("b").angular_velocity  # body axes: z is b's shaft
        if joint == "cv_joint":
            expected = np.full_like(r.t, omega)
            np.testing.assert_allclose(r.reaction("motor").torque[:, 2], load, rtol=1e-8)
            np.testing.assert_allclose(r.output("joint", "bend"), beta, atol=1e-10)
        else:  # the closed form, written here again
            c = np.cos(omega * r.t)
            expected = omega * math.cos(beta) / (1 - math.sin(beta) ** 2 * c**2)
        np.testing.assert_allclose(spin[:, 2], expected, atol=1e-8 * omega)
        np.testing.assert_allclose(spin[:, :2], 0.0, atol=1e-8 * omega)


def test_cv_joint_refuses_references_twisted_about_its_shafts():
    m = odyn.Model()
    m.add_body(name="b", mass=1.0, inertia=[0.1] * 3)
    with pytest.raises(odyn.ModelError, match=r"'j'.*twisted by -?180"):
        m.add_cv_joint(name="j", body_a="ground", on_a=odyn.frame([0, 0, 0], Z, X),
                       body_b="b", on_b=odyn.frame([0, 0, 0], Z, [-1, 0, 0]))


def test_distance_lets_a_horizontal_bob_fall_freely_at_first():
    covers("distance")
    m = odyn.Model()
    m.add_body(name="bob", mass=1.0, inertia=[1e-3] * 3, position=[1, 0, 0])
    m.add_distance(name="rod", body_a="ground", point_a=[0, 0, 0], body_b="bob",
                   point_b=[0, 0, 0])
    m.add_gravity(name="gravity", acceleration=[0, -G, 0])
    a = odyn.assemble(m)
    np.testing.assert_allclose(a.vdot[0, :3], [0, -G, 0], atol=1e-12)
    np.testing.assert_allclose(a.multipliers("rod"), [[0.0]], atol=1e-12)
    r = odyn.simulate(m, t_end=1.0, step=1e-3, output_interval=0.1)
    np.testing.assert_allclose(np.linalg.norm(r.body("bob").position, axis=1), 1.0, atol=1e-10)


def driven_pendulum(motion):
    m = pendulum()
    m.add_revolute_driver(name="motor", joint="hinge", motion=motion)
    return m


def test_revolute_driver_turns_the_bob_at_the_given_rate():
    covers("revolute_driver")
    r = odyn.simulate(driven_pendulum(odyn.constant_velocity(2.0)), t_end=1.0, step=1e-3,
                      output_interval=0.1)
    angle = 2.0 * r.t
    np.testing.assert_allclose(r.body("bob").position[:, :2],
                               np.column_stack([np.cos(angle), np.sin(angle)]), atol=1e-9)
    # At constant rate the motor's torque balances gravity's, -m g L cos(angle) (within the
    # index-3 integrator's start-up transient in lambda).
    torque = r.reaction("motor").torque[:, 2]
    np.testing.assert_allclose(torque, G * np.cos(angle), atol=2e-4)
    # The same motion from Python functions gives the same run.
    py = odyn.simulate(driven_pendulum(odyn.motion_function(
        lambda t: 2.0 * t, lambda t: 2.0, lambda t: 0.0)), t_end=1.0, step=1e-3,
        output_interval=0.1)
    np.testing.assert_allclose(py.q, r.q, atol=1e-12)


def test_translational_driver_follows_a_harmonic_motion():
    covers("translational_driver")
    m = odyn.Model()
    m.add_body(name="slide", mass=1.0, inertia=[0.1] * 3)
    m.add_translational(name="guide", body_a="ground", on_a=odyn.frame([0, 0, 0], X),
                        body_b="slide", on_b=odyn.frame([0, 0, 0], X))
    m.add_translational_driver(name="drive", joint="guide",
                               motion=odyn.harmonic(0.1, 3.0))
    r = odyn.simulate(m, t_end=1.0, step=1e-3, output_interval=0.05)
    np.testing.assert_allclose(r.body("slide").position[:, 0], 0.1 * np.sin(3.0 * r.t),
                               atol=1e-10)
    # The drive's force is m x'' = -0.9 sin(3 t) along X (after the index-3 integrator's
    # start-up transient in lambda, which has died out by the fourth output).
    force = r.reaction("drive").force[:, 0]
    np.testing.assert_allclose(force, -0.9 * np.sin(3.0 * r.t), atol=2e-3)
    np.testing.assert_allclose(force[3:], -0.9 * np.sin(3.0 * r.t[3:]), atol=1e-5)
    poly = odyn.Model()
    poly.add_body(name="slide", mass=1.0, inertia=[0.1] * 3)
    poly.add_translational_driver(name="drive", body_a="ground", on_a=odyn.frame([0, 0, 0], X),
                                  body_b="slide", on_b=odyn.frame([0, 0, 0], X),
                                  motion=odyn.polynomial([0.0, 0.5, 0.25]))
    a = odyn.assemble(poly)
    # Only the drive constrains: x' = 0.5, x'' = 0.5 (other components free, unforced).
    np.testing.assert_allclose(a.v[0, 0], 0.5, atol=1e-12)
    np.testing.assert_allclose(a.vdot[0, 0], 0.5, atol=1e-12)


def free_body(**kw):
    m = odyn.Model()
    m.add_body(name="b", mass=0.5, inertia=[0.1, 0.1, 0.2], **kw)
    return m


def test_free_fall():
    m = free_body(position=[0, 0, 10])
    m.add_gravity(name="gravity", acceleration=[0, 0, -G])
    r = odyn.simulate(m, t_end=1.0, step=1e-3, output_interval=0.25)
    np.testing.assert_allclose(r.body("b").position[:, 2], 10 - G * r.t**2 / 2, atol=1e-9)
    np.testing.assert_allclose(r.total_energy, r.total_energy[0], atol=1e-8)


def test_point_force_and_torque_constant_in_global_and_body_axes():
    covers("point_force", "point_torque")
    m = free_body()
    m.add_point_force(name="push", body="b", force=[2, 0, 0])
    m.add_point_torque(name="twist", body="b", torque=[0, 0, 0.4])
    r = odyn.simulate(m, t_end=1.0, step=1e-3, output_interval=0.5)
    np.testing.assert_allclose(r.body("b").position[:, 0], 2 * r.t**2, atol=1e-9)
    np.testing.assert_allclose(r.body("b").angular_velocity[:, 2], 2 * r.t, atol=1e-9)
    # Body turned 90 degrees about Z: body X is global Y.
    q = [math.cos(math.pi / 4), 0, 0, math.sin(math.pi / 4)]
    m = free_body(orientation=q)
    m.add_point_force(name="push", body="b", force=[2, 0, 0], axes="body")
    r = odyn.simulate(m, t_end=1.0, step=1e-3, output_interval=0.5)
    np.testing.assert_allclose(r.body("b").position[:, :2],
                               np.column_stack([0 * r.t, 2 * r.t**2]), atol=1e-9)


def spring_on_rail(kind, k=100.0, c=0.0):
    """A 1 kg block on a rail along X, pulled towards x = 1 by a spring (k, c)."""
    m = odyn.Model()
    m.add_body(name="block", mass=1.0, inertia=[0.1] * 3, position=[1.2, 0, 0])
    m.add_translational(name="rail", body_a="ground", on_a=odyn.frame([0, 0, 0], X),
                        body_b="block", on_b=odyn.frame([0, 0, 0], X))
    if kind == "tsda":
        m.add_tsda(name="spring", body_a="ground", point_a=[0, 0, 0], body_b="block",
                   point_b=[0, 0, 0], stiffness=k, damping=c, free_length=1.0)
    elif kind == "point_force":
        m.add_point_force(name="spring", body="block", force=lambda t, b: (
            -k * (b.position[0] - 1.0) - c * b.linear_velocity[0], 0.0, 0.0))
    elif kind == "user_force":
        m.add_user_force(name="spring", bodies=["block"], function=lambda t, b: (
            -k * (b.position[0] - 1.0) - c * b.linear_velocity[0], 0, 0, 0, 0, 0))
    return m


def test_tsda_oscillates_at_the_natural_frequency():
    covers("tsda")
    r = odyn.simulate(spring_on_rail("tsda"), t_end=1.0, step=1e-4, output_interval=0.01)
    np.testing.assert_allclose(r.body("block").position[:, 0], 1 + 0.2 * np.cos(10 * r.t),
                               atol=2e-5)
    np.testing.assert_allclose(r.potential_energy, 0.5 * 100 * (0.2 * np.cos(10 * r.t))**2,
                               atol=2e-3)


def test_tsda_actuator_from_python_shifts_the_equilibrium():
    m = odyn.Model()
    m.add_body(name="block", mass=1.0, inertia=[0.1] * 3, position=[1.2, 0, 0])
    m.add_translational(name="rail", body_a="ground", on_a=odyn.frame([0, 0, 0], X),
                        body_b="block", on_b=odyn.frame([0, 0, 0], X))
    m.add_tsda(name="spring", body_a="ground", point_a=[0, 0, 0], body_b="block",
               point_b=[0, 0, 0], stiffness=100.0, free_length=1.0,
               actuator=lambda t, length, rate: 10.0)  # 10 N more tension: x_eq = 0.9
    r = odyn.simulate(m, t_end=1.0, step=1e-4, output_interval=0.01)
    np.testing.assert_allclose(r.body("block").position[:, 0], 0.9 + 0.3 * np.cos(10 * r.t),
                               atol=3e-5)


@pytest.mark.parametrize("kind", ["point_force", "user_force"])
def test_python_spring_damper_matches_the_cpp_tsda(kind):
    covers("user_force")
    ref = odyn.simulate(spring_on_rail("tsda", c=2.0), t_end=1.0, step=1e-4, output_interval=0.01)
    py = odyn.simulate(spring_on_rail(kind, c=2.0), t_end=1.0, step=1e-4, output_interval=0.01)
    # Same force, same steps; the C++ element also gives Newton its stiffness, so the
    # iterates differ within Newton's tolerance only.
    np.testing.assert_allclose(py.q, ref.q, atol=1e-9)
    np.testing.assert_allclose(py.v, ref.v, atol=1e-7)


def test_python_force_gives_newton_its_stiffness_by_differences():
    # A stiff spring (k h^2 / m = 3 at h = 1e-3) written in Python: generalized-alpha's Newton
    # iteration needs its stiffness, which odyn takes by central differences of the function
    # (the default). With it the run is the C++ spring's, which gives its exact blocks.
    k = 3e6
    ref = odyn.simulate(spring_on_rail("tsda", k=k), t_end=0.05, step=1e-3,
                        output_interval=0.01, integrator="generalized-alpha")
    py = odyn.simulate(spring_on_rail("user_force", k=k), t_end=0.05, step=1e-3,
                       output_interval=0.01, integrator="generalized-alpha")
    np.testing.assert_allclose(py.q, ref.q, atol=1e-9)
    np.testing.assert_allclose(py.v, ref.v, atol=1e-6)


def test_two_body_user_force_matches_the_cpp_tsda():
    def model(python):
        m = odyn.Model()
        m.add_body(name="a", mass=1.0, inertia=[0.1] * 3, position=[-0.6, 0, 0])
        m.add_body(name="b", mass=2.0, inertia=[0.1] * 3, position=[0.6, 0, 0],
                   linear_velocity=[0, 0.5, 0])
        if python:
            def spring(t, a, b):
                d = np.asarray(b.position) - np.asarray(a.position)
                length = np.linalg.norm(d)
                f = 50.0 * (length - 1.0) * d / length  # pulls a towards b
                return [[*f, 0, 0, 0], [*(-f), 0, 0, 0]]
            m.add_user_force(name="spring", bodies=["a", "b"], function=spring)
        else:
            m.add_tsda(name="spring", body_a="a", point_a=[0, 0, 0], body_b="b",
                       point_b=[0, 0, 0], stiffness=50.0, free_length=1.0)
        return m
    ref = odyn.simulate(model(False), t_end=1.0, step=1e-3, output_interval=0.05)
    py = odyn.simulate(model(True), t_end=1.0, step=1e-3, output_interval=0.05)
    np.testing.assert_allclose(py.q, ref.q, atol=1e-9)
    # Momentum is conserved: the centre of mass moves at (0, 1/3, 0).
    com = (py.body("a").position + 2 * py.body("b").position) / 3
    np.testing.assert_allclose(com[:, 1], r_t := py.t / 3, atol=1e-9)
    assert r_t[-1] > 0


def stiff_pair(kind, k=2e6, jacobians=None):
    """Two bodies joined at their centres by a stiff spring (k h^2 / m = 2 at h = 1e-3), in C++
    (tsda) or in Python with the given jacobians function."""
    m = odyn.Model()
    m.add_body(name="a", mass=1.0, inertia=[0.1] * 3, position=[-0.6, 0, 0])
    m.add_body(name="b", mass=2.0, inertia=[0.1] * 3, position=[0.601, 0, 0],
               linear_velocity=[0, 0.5, 0])
    if kind == "tsda":
        m.add_tsda(name="spring", body_a="a", point_a=[0, 0, 0], body_b="b",
                   point_b=[0, 0, 0], stiffness=k, free_length=1.2)
        return m

    def spring(t, a, b):
        d = np.asarray(b.position) - np.asarray(a.position)
        length = np.linalg.norm(d)
        f = k * (length - 1.2) * d / length  # pulls a towards b
        return [[*f, 0, 0, 0], [*(-f), 0, 0, 0]]
    m.add_user_force(name="spring", bodies=["a", "b"], function=spring, jacobians=jacobians)
    return m


def test_python_force_supplies_its_own_stiffness_blocks():
    # The spring's exact stiffness, -dQ/dq over (a, b): S = k (n n^T + (1 - L0 / L)(I - n n^T))
    # on the centres' coordinates, +S on the diagonal blocks and -S off them.
    k = 2e6
    calls = []

    def jacobians(t, a, b):
        calls.append(t)
        d = np.asarray(b.position) - np.asarray(a.position)
        length = np.linalg.norm(d)
        n = d / length
        s = k * (np.outer(n, n) + (1 - 1.2 / length) * (np.eye(3) - np.outer(n, n)))
        stiffness = np.zeros((12, 12))
        stiffness[0:3, 0:3] = stiffness[6:9, 6:9] = s
        stiffness[0:3, 6:9] = stiffness[6:9, 0:3] = -s
        return stiffness, None

    settings = dict(t_end=0.05, step=1e-3, output_interval=0.01, integrator="generalized-alpha")
    ref = odyn.simulate(stiff_pair("tsda"), **settings)
    py = odyn.simulate(stiff_pair("user_force", jacobians=jacobians), **settings)
    assert len(calls) > 0
    np.testing.assert_allclose(py.q, ref.q, atol=1e-9)
    # The same Newton matrices: the same iterations.
    assert py.statistics.newton_iterations == ref.statistics.newton_iterations

    # Blocks that contradict the force (the sign convention turned round) are refused at the
    # first Newton matrix, naming the force and the entry.
    def wrong(t, a, b):
        stiffness, damping = jacobians(t, a, b)
        return -stiffness, damping
    with pytest.raises(odyn.ModelError, match="spring: the stiffness block from jacobians.. at "
                       r"\(0, 0\) is -2"):
        odyn.simulate(stiff_pair("user_force", jacobians=wrong), **settings)
    with pytest.raises(TypeError, match="jacobians must return .stiffness, damping."):
        odyn.simulate(stiff_pair("user_force", jacobians=lambda t, a, b: 1.0), **settings)
    with pytest.raises(TypeError, match=r"jacobians' stiffness \(12 x 12\).*144 numbers"):
        odyn.simulate(stiff_pair("user_force", jacobians=lambda t, a, b: (np.eye(6), None)),
                      **settings)


def rotor(kind, k=4.0, c=0.0, actuator=None):
    m = odyn.Model()
    m.add_body(name="rotor", mass=1.0, inertia=[0.5, 0.5, 1.0], angular_velocity=[0, 0, 1.0])
    m.add_revolute(name="axle", body_a="ground", on_a=odyn.frame([0, 0, 0], Z), body_b="rotor",
                   on_b=odyn.frame([0, 0, 0], Z))
    if kind == "rsda":
        m.add_rsda(name="spring", body_a="ground", on_a=odyn.frame([0, 0, 0], Z), body_b="rotor",
                   on_b=odyn.frame([0, 0, 0], Z), stiffness=k, damping=c, actuator=actuator)
    else:  # the damper as a Python torque
        m.add_point_torque(name="spring", body="rotor",
                           torque=lambda t, b: (0.0, 0.0, -c * b.angular_velocity[2]))
    return m


def test_rsda_twists_harmonically_and_counts_the_angle():
    covers("rsda")
    r = odyn.simulate(rotor("rsda"), t_end=2.0, step=1e-4, output_interval=0.01)
    np.testing.assert_allclose(r.state("spring")["angle"], 0.5 * np.sin(2 * r.t), atol=2e-5)
    r = odyn.simulate(rotor("rsda", actuator=lambda t, angle, rate: 2.0), t_end=2.0, step=1e-4,
                      output_interval=0.01)
    expected = 0.5 * (1 - np.cos(2 * r.t)) + 0.5 * np.sin(2 * r.t)
    np.testing.assert_allclose(r.state("spring")["angle"], expected, atol=2e-5)


def test_python_damping_torque_matches_the_cpp_rsda():
    ref = odyn.simulate(rotor("rsda", k=0.0, c=0.3), t_end=1.0, step=1e-4, output_interval=0.01)
    py = odyn.simulate(rotor("torque", c=0.3), t_end=1.0, step=1e-4, output_interval=0.01)
    np.testing.assert_allclose(py.v, ref.v, atol=1e-9)
    # omega = exp(-c t / J)
    np.testing.assert_allclose(py.body("rotor").angular_velocity[:, 2], np.exp(-0.3 * py.t),
                               atol=1e-6)


def test_primitives_compose_the_translational_joint():
    # in-line + orientation = translational: the same slide down the 45 degree guide.
    covers("inline", "orientation")
    axis = [1, 0, -1]
    m = odyn.Model()
    m.add_body(name="block", mass=2.0, inertia=[0.1, 0.1, 0.1])
    for kind in ("inline", "orientation"):
        m.add(kind, name=kind, body_a="ground", on_a=odyn.frame([0, 0, 0], axis),
              body_b="block", on_b=odyn.frame([0, 0, 0], axis))
    m.add_gravity(name="gravity", acceleration=[0, 0, -G])
    r = odyn.simulate(m, t_end=1.0, step=1e-3, output_interval=0.5)
    s = G * r.t**2 / (2 * math.sqrt(2))
    expected = np.column_stack([s / math.sqrt(2), 0 * s, -s / math.sqrt(2)])
    np.testing.assert_allclose(r.body("block").position, expected, atol=1e-9)
    # The line carries the normal force m g cos 45 along (1, 0, 1)/sqrt 2; the orientation
    # primitive carries no force, only a torque (here none).
    np.testing.assert_allclose(r.reaction("inline").force[-1], [G, 0, G], atol=1e-8)
    np.testing.assert_allclose(r.reaction("orientation").force[-1], [0, 0, 0], atol=1e-8)
    np.testing.assert_allclose(r.reaction("orientation").torque[-1], [0, 0, 0], atol=1e-8)


@pytest.mark.parametrize("composed", [False, True])
def test_planar_joint_and_its_primitives_slide_a_spinning_block_down_a_slope(composed):
    # planar = in-plane + parallel axes. On a plane tilted by alpha about x, the block slides
    # with g sin(alpha) down the slope and keeps its spin about the normal.
    covers("planar", "inplane", "parallel_axes")
    alpha, omega = 0.3, 2.0
    n = [0, math.sin(alpha), math.cos(alpha)]
    m = odyn.Model()
    tilt = [math.cos(-alpha / 2), math.sin(-alpha / 2), 0, 0]  # w, x, y, z: body z along n
    m.add_body(name="block", mass=2.0, inertia=[0.1, 0.2, 0.3], orientation=tilt,
               linear_velocity=[1.0, 0, 0], angular_velocity=[0, 0, omega])
    kinds = ("inplane", "parallel_axes") if composed else ("planar",)
    for kind in kinds:
        m.add(kind, name=kind, body_a="ground", on_a=odyn.frame([0, 0, 0], n), body_b="block")
    m.add_gravity(name="gravity", acceleration=[0, 0, -G])
    r = odyn.simulate(m, t_end=1.0, rtol=1e-10, atol=1e-10, output_interval=0.25)
    g_plane = np.array([0, 0, -G]) + G * math.cos(alpha) * np.array(n)
    expected = np.outer(r.t, [1.0, 0, 0]) + 0.5 * np.outer(r.t**2, g_plane)
    np.testing.assert_allclose(r.body("block").position, expected, atol=1e-8)
    np.testing.assert_allclose(r.body("block").angular_velocity[:, 2], omega, atol=1e-8)


def test_spherical_and_perpendicular_make_a_universal_joint():
    # A body hung from a Cardan joint swings the same way as from a ball joint plus the
    # perpendicular primitive on the cross's two axes.
    covers("perpendicular")

    def hung(composed):
        m = odyn.Model()
        m.add_body(name="arm", mass=1.0, inertia=[0.05, 0.02, 0.04], position=[0.3, 0, -0.4],
                   angular_velocity=[0.5, 1.0, -0.3])
        on_a, on_b = odyn.frame([0, 0, 0], X), odyn.frame([-0.3, 0, 0.4], Y)
        if composed:
            m.add_spherical(name="ball", body_a="ground", body_b="arm", point_b=[-0.3, 0, 0.4])
            m.add_perpendicular(name="cross", body_a="ground", on_a=on_a, body_b="arm",
                                on_b=on_b)
        else:
            m.add_universal(name="cross", body_a="ground", on_a=on_a, body_b="arm", on_b=on_b)
        m.add_gravity(name="gravity", acceleration=[0, 0, -G])
        return odyn.simulate(m, t_end=1.0, rtol=1e-10, atol=1e-10, output_interval=0.1)

    reference, composed = hung(False), hung(True)
    np.testing.assert_allclose(composed.q, reference.q, atol=1e-7)


def rotation_vectors(quaternions):
    """Rotation vectors (axis times angle) of unit quaternions w, x, y, z."""
    w = np.abs(quaternions[:, 0])
    v = quaternions[:, 1:] * np.sign(quaternions[:, :1])
    s = np.linalg.norm(v, axis=1)
    scale = np.where(s > 1e-12, 2 * np.arctan2(s, w) / np.maximum(s, 1e-300), 2.0)
    return v * scale[:, None]


def test_bushing_mount_vibrates_in_its_analytic_modes():
    # A block on a bushing at its centre of mass: the six components are uncoupled, each at
    # sqrt(k / m) or sqrt(k / J). Started displaced by 1e-5 in every one, each follows
    # x0 cos(w t) (the coupling through large angles is of order 1e-10 here).
    covers("bushing")
    k = [4e4, 2e4, 3e4, 300, 200, 100]
    inertia = [0.04, 0.07, 0.09]
    x0 = np.array([1, -2, 3, 2, -1, 1.5]) * 1e-5
    m = odyn.Model()
    m.add_body(name="block", mass=3.0, inertia=inertia, position=x0[:3],
               orientation=list(np.r_[np.cos(np.linalg.norm(x0[3:]) / 2),
                                      np.sin(np.linalg.norm(x0[3:]) / 2) * x0[3:]
                                      / np.linalg.norm(x0[3:])]))
    m.add_bushing("mount", "ground", body_b="block", stiffness=k)
    r = odyn.simulate(m, t_end=0.3, output_interval=0.005, integrator="dop853", rtol=1e-12,
                      atol=1e-13)
    omega = np.sqrt(np.array(k) / np.r_[[3.0] * 3, inertia])
    expected = x0 * np.cos(np.outer(r.t, omega))
    block = r.body("block")
    motion = np.c_[block.position, rotation_vectors(block.orientation)]
    np.testing.assert_allclose(motion, expected, atol=1e-4 * np.abs(x0).max())


def test_bushing_full_matrix_and_a_law_written_in_python():
    # The full 6 x 6 stiffness of a bushing offset from the centre of mass: its modes are those
    # of (A^T K A) phi = w^2 M phi, A the map from the block's small motion to the bushing's
    # displacement, with the bushing 0.2 m along x from the centre (frames coincide at rest).
    rng = np.random.default_rng(3)
    b = rng.uniform(-1, 1, (6, 6))
    root = np.sqrt([4e4, 2e4, 3e4, 400, 200, 300])
    stiffness = root[:, None] * (0.5 * np.eye(6) + b @ b.T / 6) * root[None, :]
    s = np.array([0.2, 0.0, 0.0])
    skew = np.array([[0, -s[2], s[1]], [s[2], 0, -s[0]], [-s[1], s[0], 0]])
    a = np.block([[np.eye(3), -skew], [np.zeros((3, 3)), np.eye(3)]])
    mass = np.diag([3.0, 3.0, 3.0, 0.04, 0.07, 0.09])
    root_m = np.diag(1 / np.sqrt(np.diag(mass)))
    w2, shapes = np.linalg.eigh(root_m @ a.T @ stiffness @ a @ root_m)
    mode = 2
    shape = root_m @ shapes[:, mode]
    shape *= 1e-6 / np.abs(shape).max()
    angle = np.linalg.norm(shape[3:])
    m = odyn.Model()
    m.add_body(name="block", mass=3.0, inertia=[0.04, 0.07, 0.09], position=shape[:3],
               orientation=[np.cos(angle / 2), *(np.sin(angle / 2) * shape[3:] / angle)])
    m.add_bushing("mount", "ground", on_a=odyn.frame(s, Z), body_b="block",
                  on_b=odyn.frame(s, Z), stiffness=stiffness)
    omega = np.sqrt(w2[mode])
    r = odyn.simulate(m, t_end=3 * np.pi / omega, output_interval=0.1 / omega,
                      integrator="dop853", rtol=1e-12, atol=1e-14)
    block = r.body("block")
    motion = np.c_[block.position, rotation_vectors(block.orientation)]
    np.testing.assert_allclose(motion, np.outer(np.cos(omega * r.t), shape), atol=1e-10)

    # A law written in Python: a spring and damper along z, k z + c z', under the default
    # (implicit) integrator, against the closed-form damped oscillator.
    k, c, mass_z, z0 = 5e3, 8.0, 2.0, 0.004
    seen = []

    def law(t, x, rate):
        seen.append((x.shape, rate.shape))
        return [0, 0, -k * x[2] - c * rate[2], 0, 0, 0]

    m = odyn.Model()
    m.add_body(name="block", mass=mass_z, inertia=[0.01] * 3, position=[0, 0, z0])
    m.add_bushing("mount", "ground", body_b="block", stiffness=[1e5, 1e5, 0, 1e3, 1e3, 1e3],
                  law=law)
    r = odyn.simulate(m, t_end=0.5, output_interval=0.01, rtol=1e-9, atol=1e-11)
    assert seen[0] == ((6,), (6,))
    omega, zeta = np.sqrt(k / mass_z), c / (2 * np.sqrt(k * mass_z))
    omega_d = omega * np.sqrt(1 - zeta**2)
    z = z0 * np.exp(-zeta * omega * r.t) * (np.cos(omega_d * r.t)
                                            + zeta / np.sqrt(1 - zeta**2) * np.sin(omega_d * r.t))
    np.testing.assert_allclose(r.body("block").position[:, 2], z, atol=2e-7)


def test_bushing_refuses_bad_matrices_by_name():
    m = odyn.Model()
    m.add_body(name="block", mass=1.0, inertia=[0.1] * 3)
    bad = np.diag([1.0] * 6)
    bad[0, 1] = 0.5
    with pytest.raises(odyn.ModelError, match="bushing 'mount'.*stiffness matrix is not "
                       "symmetric"):
        m.add_bushing("mount", "ground", body_b="block", stiffness=bad)
    with pytest.raises(odyn.ModelError, match="damping matrix is not positive semidefinite"):
        m.add_bushing("mount", "ground", body_b="block", damping=[1, 1, -1, 1, 1, 1])
    with pytest.raises(odyn.ModelError, match="expected 6 numbers .a diagonal. or a 6 x 6"):
        m.add_bushing("mount", "ground", body_b="block", stiffness=[1, 2, 3])
    with pytest.raises(odyn.ModelError, match="preload.*6 numbers"):
        m.add_bushing("mount", "ground", body_b="block", preload=[1, 2, 3])


def test_contacts_are_covered_by_their_own_tests():
    covers("sphere_plane", "sphere_sphere", "box_plane", "capsule_plane")  # test_contact.py


def test_stops_are_covered_by_their_own_tests():
    covers("revolute_limit", "translational_limit")  # tests/python/test_limits.py


def test_gears_are_covered_by_their_own_tests():
    covers("gear", "rack_pinion", "screw", "coupler")  # tests/python/test_gears.py


def test_joint_friction_is_covered_by_its_own_tests():
    covers("joint_friction")  # tests/python/test_joint_friction.py: closed forms


def test_user_constraint_is_covered_by_its_own_tests():
    covers("user_constraint")  # tests/python/test_user_constraint.py: closed forms, C++ distance


def test_every_element_type_is_tested():
    # Runs last in this file (pytest keeps file order).
    assert set(odyn.element_types) == TESTED


def test_python_callable_errors_reach_the_caller_with_partial_results():
    m = spring_on_rail("tsda")

    def bad(t, b):
        if t > 0.05:
            raise ZeroDivisionError("boom")
        return (0.0, 0.0, 0.0)
    m.add_point_force(name="bad", body="block", force=bad)
    with pytest.raises(ZeroDivisionError, match="boom") as info:
        odyn.simulate(m, t_end=1.0, step=1e-3, output_interval=0.01)
    # The exception stays the user's (its type and message), with a note saying where it rose.
    notes = getattr(info.value, "__notes__", [])
    assert len(notes) == 1 and "point_force 'bad'" in notes[0], notes
    time = float(notes[0].split("at t = ")[1].split(" s")[0])
    assert 0.05 < time <= 0.052  # generalized-alpha's steps of 1e-3
    partial = info.value.result  # the rows before it are kept, and say why they end there
    assert 5 <= len(partial) <= 7 and not partial.complete and not partial.interrupted
    assert partial.error == "ZeroDivisionError: boom"
    assert "stopped by ZeroDivisionError" in repr(partial)

    m = spring_on_rail("tsda")
    m.add_point_force(name="wrong", body="block", force=lambda t, b: (1.0, 2.0))
    with pytest.raises(TypeError, match="point_force 'wrong'.*3 numbers"):
        odyn.simulate(m, t_end=0.1)


def test_redundant_and_unassemblable_models_name_the_joints():
    # A hinge and a weld on the same body: consistent, but the weld repeats the hinge's five
    # equations. The analyses run with the minimum-norm multipliers and name the equations.
    m = odyn.Model()
    m.add_body(name="b", mass=1.0, inertia=[1, 1, 1], position=[0, 0, 1])
    m.add_revolute(name="hinge", body_a="ground", on_a=odyn.frame([0, 0, 1], Z), body_b="b",
                   on_b=odyn.frame())
    m.add_fixed(name="weld", body_a="ground", on_a=odyn.frame([0, 0, 1], Z), body_b="b",
                on_b=odyn.frame())
    m.add_gravity(name="gravity", acceleration=[0, 0, -G])
    with pytest.warns(odyn.RedundantConstraintsWarning,
                      match=r"\(equation \d\): constraint equations are redundant"):
        a = odyn.assemble(m)
    assert len(a.redundant_equations) == 5
    assert {e["joint"] for e in a.redundant_equations} <= {"hinge", "weld"}
    with pytest.warns(odyn.RedundantConstraintsWarning, match="minimum-norm"):
        r = odyn.simulate(m, t_end=0.1, step=1e-3, output_interval=0.05)
    assert r.redundant_equations == a.redundant_equations
    np.testing.assert_allclose(r.body("b").position[-1], [0, 0, 1], atol=1e-12)
    # Together the two joints carry the weight (how they share it is the minimum-norm choice).
    total = r.reaction("hinge").force + r.reaction("weld").force
    np.testing.assert_allclose(total[-1], [0, 0, G], atol=1e-8)
    m = odyn.Model()
    m.add_body(name="b", mass=1.0, inertia=[1, 1, 1], position=[0, 0, 1])
    m.add_distance(name="rod 1", body_a="ground", point_a=[0, 0, 0], body_b="b",
                   point_b=[0, 0, 0], length=1.0)
    m.add_distance(name="rod 2", body_a="ground", point_a=[0, 0, 3], body_b="b",
                   point_b=[0, 0, 0], length=1.0)  # the two spheres do not meet
    with pytest.raises(odyn.AssemblyError, match="largest residual .* at joint 'rod"):
        odyn.assemble(m)
