"""Constraints written in Python (user_constraint, as ADAMS's GCON): one equation phi = 0 on
one or two bodies, with the user's gradient and gamma or differences of phi. Checked against
closed forms (a conical pendulum, a slider driven along a sine), against the C++ distance
element between two turning bodies, and for the refusal of a gradient or gamma that
contradicts phi."""

import math

import numpy as np
import pytest

import odyn

G = 9.81


def conical_pendulum(given):
    """A bob on a massless rod of length L from the origin, at angle theta from the downward
    vertical, started on the circle at Omega = sqrt(g / (L cos theta)): it stays on the circle.
    The rod is phi = (|x|^2 - L^2) / 2 on the bob's centre x; given: with its gradient (x, then
    no turn, then no time) and gamma (-|x'|^2)."""
    length, theta = 1.5, 0.6
    radius, depth = length * math.sin(theta), length * math.cos(theta)
    omega = math.sqrt(G / depth)
    m = odyn.Model()
    m.add_body("bob", 2.0, [1e-3] * 3, position=[radius, 0, -depth],
               linear_velocity=[0, omega * radius, 0])
    extra = {}
    if given:
        extra = {"jacobian": lambda t, b: [*b.position, 0, 0, 0, 0],
                 "gamma": lambda t, b: -float(np.dot(b.linear_velocity, b.linear_velocity))}
    m.add_user_constraint("rod", ["bob"],
                          lambda t, b: 0.5 * (np.dot(b.position, b.position) - length**2),
                          **extra)
    m.add_gravity("gravity", [0, 0, -G])
    return m, radius, depth, omega


@pytest.mark.parametrize("given", [False, True], ids=["differences", "given"])
@pytest.mark.parametrize("coordinates", ["absolute", "joint"])
def test_conical_pendulum_stays_on_its_circle(given, coordinates):
    m, radius, depth, omega = conical_pendulum(given)
    r = odyn.simulate(m, t_end=2.0, rtol=1e-10, atol=1e-10, output_interval=0.1,
                      coordinates=coordinates)
    expected = np.column_stack([radius * np.cos(omega * r.t), radius * np.sin(omega * r.t),
                                np.full_like(r.t, -depth)])
    np.testing.assert_allclose(r.body("bob").position, expected, atol=1e-8)
    # The rod's tension m g / cos(theta) is the multiplier times |x| (phi's gradient is x):
    # -lambda x = the force on the bob, pointing to the origin.
    tension = 2.0 * G * math.hypot(radius, depth) / depth
    np.testing.assert_allclose(r.multipliers("rod")[:, 0] * math.hypot(radius, depth),
                               tension, rtol=1e-7)
    np.testing.assert_allclose(np.linalg.norm(r.reaction("rod").force, axis=1), tension,
                               rtol=1e-7)


@pytest.mark.parametrize("given", [False, True], ids=["differences", "given"])
def test_planar_slider_follows_a_time_dependent_constraint(given):
    # phi = x - A sin(w t) on a free planar body under gravity along -y: x follows the sine,
    # y falls freely, and the constraint's force along x is m x''.
    amplitude, w, mass = 0.2, 5.0, 3.0
    m = odyn.PlanarModel()
    m.add_body("slider", mass, 0.1, linear_velocity=[amplitude * w, 0])
    extra = {}
    if given:
        extra = {"jacobian": lambda t, b: [1.0, 0.0, 0.0, -amplitude * w * math.cos(w * t)],
                 "gamma": lambda t, b: -amplitude * w * w * math.sin(w * t)}
    m.add_user_constraint("drive", ["slider"],
                          lambda t, b: b.position[0] - amplitude * math.sin(w * t), **extra)
    m.add_gravity("gravity", [0, -G])
    r = odyn.simulate(m, t_end=1.0, rtol=1e-10, atol=1e-10, output_interval=0.05)
    position = r.body("slider").position
    np.testing.assert_allclose(position[:, 0], amplitude * np.sin(w * r.t), atol=1e-9)
    np.testing.assert_allclose(position[:, 1], -0.5 * G * r.t**2, atol=1e-8)
    force = r.reaction("drive").force[:, 0]
    np.testing.assert_allclose(force, -mass * amplitude * w * w * np.sin(w * r.t), atol=1e-6)


def two_links(user, given=True):
    """Two bodies hung from the ground by ball joints, their off-centre points held at a
    distance: by the C++ distance element, or by a Python phi = (|d|^2 - L^2) / 2 with
    d = p_b - p_a, p = x + R s, whose gradient over a turn of body k about its axes is
    +-(s x R^T d)."""
    s_a, s_b = np.array([0.3, 0.1, 0.0]), np.array([-0.2, 0.0, 0.1])
    m = odyn.Model()
    m.add_body("a", 1.0, [0.02, 0.03, 0.04], position=[0, 0, -1],
               angular_velocity=[0.5, -1.0, 2.0])
    m.add_body("b", 1.5, [0.05, 0.02, 0.03], position=[1.0, 0, -1],
               angular_velocity=[-1.0, 0.3, 0.7])
    m.add_spherical("pin a", "ground", point_a=[0, 0, 0], body_b="a", point_b=[0, 0, 1])
    m.add_spherical("pin b", "ground", point_a=[1.0, 0, 0], body_b="b", point_b=[0, 0, 1])
    m.add_gravity("gravity", [0, 0, -G])
    start = (np.array([1.0, 0, -1]) + s_b) - (np.array([0, 0, -1]) + s_a)
    length = float(np.linalg.norm(start))
    if not user:
        m.add_distance("link", "a", point_a=s_a, body_b="b", point_b=s_b, length=length)
        return m

    def gap(a, b):
        return (b.position + b.rotation @ s_b) - (a.position + a.rotation @ s_a)

    def phi(t, a, b):
        d = gap(a, b)
        return 0.5 * (d @ d - length**2)

    def jacobian(t, a, b):
        d = gap(a, b)
        return [*-d, *-np.cross(s_a, a.rotation.T @ d), *d, *np.cross(s_b, b.rotation.T @ d), 0.0]

    extra = {"jacobian": jacobian} if given else {}
    m.add_user_constraint("link", ["a", "b"], phi, **extra)
    return m


@pytest.mark.parametrize("given", [False, True], ids=["differences", "given gradient"])
def test_two_body_user_constraint_matches_the_cpp_distance(given):
    settings = dict(t_end=1.0, rtol=1e-10, atol=1e-10, output_interval=0.1)
    reference = odyn.simulate(two_links(user=False), **settings)
    r = odyn.simulate(two_links(user=True, given=given), **settings)
    np.testing.assert_allclose(r.q, reference.q, atol=1e-7)
    # The same force on body b (at its centre, where a user constraint reports it; the C++
    # distance reports it at its point, which moves the torque only).
    np.testing.assert_allclose(r.reaction("link").force, reference.reaction("link").force,
                               atol=1e-6)


def test_user_constraint_with_generalized_alpha():
    m, radius, depth, omega = conical_pendulum(given=True)
    r = odyn.simulate(m, t_end=1.0, step=1e-3, integrator="generalized-alpha",
                      output_interval=0.5)
    expected = [radius * math.cos(omega), radius * math.sin(omega), -depth]
    np.testing.assert_allclose(r.body("bob").position[-1], expected, atol=1e-4)


def test_a_wrong_gradient_or_gamma_is_refused_by_name():
    m = odyn.Model()
    m.add_body("bob", 1.0, [1e-3] * 3, position=[1.0, 0, 0], linear_velocity=[0, 1.0, 0])
    m.add_user_constraint("rod", ["bob"], lambda t, b: 0.5 * (b.position @ b.position - 1.0),
                          jacobian=lambda t, b: [*(2.0 * b.position), 0, 0, 0, 0])
    with pytest.raises(odyn.ModelError, match=r"rod: the jacobian\(\) value \[0\] is 2 but "
                                              r"differences of phi give 1"):
        odyn.assemble(m)
    m = odyn.Model()
    m.add_body("bob", 1.0, [1e-3] * 3, position=[1.0, 0, 0], linear_velocity=[0, 1.0, 0])
    m.add_user_constraint("rod", ["bob"], lambda t, b: 0.5 * (b.position @ b.position - 1.0),
                          gamma=lambda t, b: 0.0)
    with pytest.raises(odyn.ModelError, match=r"rod: the gamma\(\) value is 0 but differences "
                                              r"of phi give -1"):
        odyn.simulate(m, t_end=0.01)


def test_bad_user_constraints_get_clear_errors(tmp_path):
    m = odyn.Model()
    m.add_body("bob", 1.0, [1e-3] * 3, position=[1.0, 0, 0])
    with pytest.raises(odyn.ModelError, match="one or two body names"):
        m.add_user_constraint("rod", [], lambda t: 0.0)
    m.add_user_constraint("rod", ["bob"], lambda t, b: [1.0, 2.0])
    with pytest.raises((TypeError, ValueError, odyn.ModelError), match="rod"):
        odyn.assemble(m)
    with pytest.raises(odyn.ModelError, match="Python function and cannot be saved"):
        odyn.save(odyn.Scene(m), tmp_path / "scene.json")
