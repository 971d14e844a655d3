"""Joint friction from Python and scene files, against closed forms: a block launched down a
slope flatter than the friction angle slows at g (mu_k cos - sin), sticks and creeps at
v_t atanh(tan / mu_s), in space and in the plane; a pendulum's energy falls by the integral of
its pin friction's power output; a block on a moving belt sticks and slips with the period of
Coulomb's law as the Stribeck velocity falls; scene round trips; bad input refused by name."""

import math

import numpy as np
import pytest

import odyn
from conftest import python_example

G = 9.81
MU, MU_S = 0.5, 0.6


def slope(space, angle, v0, **friction):
    """A 2 kg block on a rail along x, gravity tilted by `angle` so that down the slope is +x."""
    if space == "spatial":
        m = odyn.Model()
        m.add_body("block", 2.0, [0.1, 0.2, 0.3], linear_velocity=[v0, 0, 0])
        m.add_translational("rail", "ground", on_a={"axis": [1, 0, 0]}, body_b="block",
                            on_b={"axis": [1, 0, 0]})
        m.add_gravity("gravity", [G * math.sin(angle), 0, -G * math.cos(angle)])
    else:
        m = odyn.PlanarModel()
        m.add_body("block", 2.0, 0.1, linear_velocity=[v0, 0])
        m.add_translational("rail", "ground", on_a={"axis": [1, 0]}, body_b="block",
                            on_b={"axis": [1, 0]})
        m.add_gravity("gravity", [G * math.sin(angle), -G * math.cos(angle)])
    m.add_joint_friction("rubbing", joint="rail", coefficient=MU, static_coefficient=MU_S,
                         **friction)
    return m


def creep_speed(angle, v_t=1e-4, v_s=0.01):
    """Where mu(v) N tanh(v / v_t) = m g sin: v = v_t atanh(tan / mu(v)), by a fixed point from
    mu_s (mu(v) is within 1e-5 of it)."""
    v = 0.0
    for _ in range(20):
        mu = MU + (MU_S - MU) * math.exp(-(v / v_s) ** 2)
        v = v_t * math.atanh(math.tan(angle) / mu)
    return v


@pytest.mark.parametrize("space", ["spatial", "planar"])
@pytest.mark.parametrize("integrator", ["dop853", "auto"])
def test_a_block_slows_sticks_and_creeps(space, integrator):
    angle, v0 = math.radians(20.0), 1.0
    r = odyn.simulate(slope(space, angle, v0), t_end=1.2, output_interval=0.01,
                      integrator=integrator, rtol=1e-10, atol=1e-12)
    deceleration = G * (MU * math.cos(angle) - math.sin(angle))
    speed = r.body("block").linear_velocity[:, 0]
    slipping = r.t < 0.7  # well before the stop at v0 / deceleration = 0.80 s
    np.testing.assert_allclose(speed[slipping], v0 - deceleration * r.t[slipping], atol=1e-7)
    np.testing.assert_allclose(r.output("rubbing", "normal_load"),
                               2.0 * G * math.cos(angle), rtol=1e-9)
    np.testing.assert_allclose(r.output("rubbing", "slip_speed"), np.abs(speed), atol=1e-12)
    # Slipping, the friction is mu_k N; it sticks within the Stribeck range's shortcut of
    # v0 / deceleration, then creeps where mu_s N tanh(v / v_t) holds gravity's pull.
    np.testing.assert_allclose(r.output("rubbing", "friction")[slipping],
                               MU * 2.0 * G * math.cos(angle), rtol=1e-9)
    stuck = r.t[np.argmax(speed < 1e-3)]
    assert abs(stuck - v0 / deceleration) < 0.015
    assert speed[-1] == pytest.approx(creep_speed(angle), rel=1e-7)
    np.testing.assert_allclose(r.output("rubbing", "force")[-1], -2.0 * G * math.sin(angle),
                               rtol=1e-6)


def test_a_steep_slope_slides_off_at_the_kinetic_rate():
    angle = math.radians(35.0)
    r = odyn.simulate(slope("planar", angle, 0.0), t_end=1.0, output_interval=0.1,
                      integrator="dop853", rtol=1e-10, atol=1e-12)
    speed = r.body("block").linear_velocity[:, 0]
    accel = G * (math.sin(angle) - MU * math.cos(angle))
    np.testing.assert_allclose(np.diff(speed[3:]) / 0.1, accel, rtol=1e-8)


def test_a_pendulums_energy_falls_by_its_friction_work():
    """E(t) - E(0) = integral of the friction's power (gravity is in E): the power output
    reads the same friction and normal load that the motion felt."""
    length = 0.4
    m = odyn.Model()
    m.add_body("bob", 1.5, [0.03, 0.02, 0.01], position=[length, 0, 0])
    m.add_revolute("pin", "ground", on_a={"axis": [0, 1, 0]}, body_b="bob",
                   on_b={"point": [-length, 0, 0], "axis": [0, 1, 0]})
    m.add_joint_friction("pin_friction", joint="pin", coefficient=0.3, radius=0.05,
                         transition_velocity=1e-3, viscous=0.5)
    m.add_gravity("gravity", [0, 0, -G])
    r = odyn.simulate(m, t_end=1.5, output_interval=0.002, integrator="dop853", rtol=1e-11,
                      atol=1e-13)
    energy = r.kinetic_energy + r.potential_energy
    power = r.output("pin_friction", "power")
    work = np.concatenate([[0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(r.t))])
    assert energy[0] - energy[-1] > 0.2  # the friction takes a good part of the swing
    # The trapezoid rule's error on 2 ms outputs bounds the agreement.
    np.testing.assert_allclose(energy - energy[0], work, atol=2e-4 * (energy[0] - energy[-1]))
    # The normal load is the pin's reaction force (its axial part is zero here).
    force = r.reaction("pin", side="b").force
    np.testing.assert_allclose(r.output("pin_friction", "normal_load"),
                               np.linalg.norm(force, axis=1), rtol=1e-6)


def test_a_sleeve_slips_along_and_around_at_once():
    """A cylindrical joint's slip (s', r theta') slows along its own direction when the sleeve's
    mass equals its inertia over r^2: both rates fall by the factor 1 - mu g t / v0."""
    mu, radius, mass, s0, spin0 = 0.3, 0.02, 2.0, 0.3, 20.0
    m = odyn.Model()
    m.add_body("sleeve", mass, [mass * radius ** 2, 0.01, 0.01], linear_velocity=[s0, 0, 0],
               angular_velocity=[spin0, 0, 0])
    m.add_cylindrical("shaft", "ground", on_a={"axis": [1, 0, 0]}, body_b="sleeve",
                      on_b={"axis": [1, 0, 0]})
    m.add_joint_friction("rubbing", joint="shaft", coefficient=mu, radius=radius)
    m.add_gravity("gravity", [0, 0, -G])
    r = odyn.simulate(m, t_end=0.15, output_interval=0.01, integrator="dop853", rtol=1e-11,
                      atol=1e-13)
    v0 = math.hypot(s0, radius * spin0)
    factor = 1.0 - mu * G * r.t / v0  # it stops at v0 / (mu g) = 0.17 s
    np.testing.assert_allclose(r.body("sleeve").linear_velocity[:, 0], s0 * factor, rtol=1e-9)
    np.testing.assert_allclose(r.body("sleeve").angular_velocity[:, 0], spin0 * factor,
                               rtol=1e-9)
    np.testing.assert_allclose(r.output("rubbing", "slip_speed"), v0 * factor, rtol=1e-9)
    np.testing.assert_allclose(r.output("rubbing", "force"), -mu * mass * G * s0 / v0,
                               rtol=1e-9)
    np.testing.assert_allclose(r.output("rubbing", "torque"),
                               -mu * mass * G * radius * radius * spin0 / v0, rtol=1e-9)


def test_moments_over_the_bending_arm_add_to_the_normal_load():
    """A block whose centre sits a distance d along its rail from the joint point loads the rail
    with m g and the moment m g d: N = m g (1 + d / arm). Pulled by less than mu_s N it stays;
    by more, it slides at (F - mu_k N) / m."""
    mass, d, arm = 2.0, 0.1, 0.25
    normal = mass * G * (1 + d / arm)
    for pull, sticks in ((0.9 * MU_S * normal, True), (1.1 * MU_S * normal, False)):
        m = odyn.Model()
        m.add_body("block", mass, [0.1, 0.2, 0.3], position=[d, 0, 0])
        m.add_translational("rail", "ground", on_a={"axis": [1, 0, 0]}, body_b="block",
                            on_b={"point": [-d, 0, 0], "axis": [1, 0, 0]})
        m.add_joint_friction("rubbing", joint="rail", coefficient=MU, static_coefficient=MU_S,
                             bending_arm=arm)
        m.add_gravity("gravity", [0, 0, -G])
        m.add_point_force("pull", "block", [pull, 0, 0])
        r = odyn.simulate(m, t_end=1.0, output_interval=0.1, integrator="auto")
        np.testing.assert_allclose(r.output("rubbing", "normal_load"), normal, rtol=1e-6)
        speed = r.body("block").linear_velocity[:, 0]
        if sticks:
            assert abs(speed[-1]) < 1e-3  # the creep: v_t atanh(0.9), about 1.5e-4 m/s
        else:
            accel = (pull - MU * normal) / mass
            np.testing.assert_allclose(np.diff(speed[5:]) / 0.1, accel, rtol=1e-5)


def tall_slider(arm):
    """A block launched along a rail whose centre rides 0.4 m above its joint point: the
    friction's moment about the centre loads the rail, and the load feeds the friction."""
    m = odyn.Model()
    m.add_body("block", 2.0, [0.1, 0.2, 0.3], position=[0, 0, 0.4], linear_velocity=[1, 0, 0])
    m.add_translational("rail", "ground", on_a={"axis": [1, 0, 0]}, body_b="block",
                        on_b={"point": [0, 0, -0.4], "axis": [1, 0, 0]})
    m.add_joint_friction("rubbing", joint="rail", coefficient=0.5, bending_arm=arm)
    m.add_gravity("gravity", [0, 0, -G])
    return m


def test_a_load_that_feeds_the_friction_settles_where_the_closed_form_says():
    """Sliding, the rail carries m g and the moment mu N h of the friction at height h below
    the centre: N = m g + mu N h / arm, so N = m g / (1 - mu h / arm), and the block slows at
    mu N / m."""
    mu, h, arm = 0.5, 0.4, 1.0
    r = odyn.simulate(tall_slider(arm), t_end=0.15, output_interval=0.01, integrator="dop853",
                      rtol=1e-10, atol=1e-12)
    normal = 2.0 * G / (1 - mu * h / arm)
    sliding = r.t <= 0.1  # it stops at 1 / (mu N / m) = 0.163 s
    np.testing.assert_allclose(r.output("rubbing", "normal_load")[sliding], normal, rtol=1e-10)
    np.testing.assert_allclose(r.body("block").linear_velocity[sliding, 0],
                               1.0 - mu * normal / 2.0 * r.t[sliding], rtol=1e-9)


def test_a_friction_that_feeds_itself_without_bound_is_refused_by_name():
    """With mu h / arm = 2 the load has no solution (Painleve's paradox): the run stops with an
    error naming the friction instead of returning a load."""
    with pytest.raises(odyn.SolverError, match="rubbing.*did not settle"):
        odyn.simulate(tall_slider(0.1), t_end=0.2, output_interval=0.1, integrator="dop853")


def test_a_block_on_a_belt_sticks_and_slips_with_coulombs_period():
    """The friction between two moving bodies (a driven belt and a block held by a spring):
    the limit cycle's period and the block's farthest reach approach Coulomb's closed forms as
    the Stribeck velocity v_s falls (v_t = v_s / 100)."""
    example = python_example("stick_slip")
    k, mass, mu, mu_s, speed = 100.0, 1.0, 0.4, 0.6, 0.05
    omega, gap = math.sqrt(k / mass), (mu_s - mu) * mass * G / k
    reach = mu * mass * G / k + math.hypot(gap, speed / omega)  # the slip's swing
    errors = []
    for v_s in (1e-2, 1e-4):
        r = odyn.simulate(example.belt_and_block(stribeck_velocity=v_s,
                                                 transition_velocity=v_s / 100),
                          t_end=6.0, output_interval=1e-4, rtol=1e-9, atol=1e-11)
        period = np.diff(example.slip_onsets(r))[-1]
        errors.append(abs(period / example.coulomb_period() - 1))
        x = r.body("block").position[:, 0]
        if v_s == 1e-4:
            assert x.max() == pytest.approx(reach, rel=1e-3)
    assert errors[1] < 2e-3 and errors[0] > 10 * errors[1]


def test_friction_round_trips_through_a_scene_file(tmp_path):
    m = slope("planar", math.radians(20.0), 1.0, viscous=0.1, preload=2.0)
    settings = {"t_end": 0.5, "output_interval": 0.1, "integrator": "dop853", "rtol": 1e-10,
                "atol": 1e-12}
    path = tmp_path / "slope.json"
    odyn.save(odyn.Scene(m, settings), str(path))
    first, second = odyn.simulate(m, **settings), odyn.load(str(path)).simulate()
    np.testing.assert_allclose(second.output("rubbing", "friction"),
                               first.output("rubbing", "friction"), rtol=1e-12)
    np.testing.assert_allclose(first.output("rubbing", "normal_load"),
                               2.0 * G * math.cos(math.radians(20.0)) + 2.0, rtol=1e-9)


def test_auto_runs_friction_in_absolute_coordinates_and_joint_ones_refuse_it():
    m = slope("spatial", math.radians(20.0), 1.0)
    r = odyn.simulate(m, t_end=0.1, output_interval=0.1)
    assert "rubbing" in r.summary["coordinates_choice"]
    with pytest.raises(odyn.ModelError, match="rubbing.*absolute"):
        odyn.simulate(m, t_end=0.1, coordinates="joint")


@pytest.mark.parametrize("kwargs, error, words", [
    ({"joint": "ball", "coefficient": 0.2, "radius": 0.01}, odyn.SceneError,
     "no revolute or translational or cylindrical joint named 'ball'"),
    ({"joint": "nowhere", "coefficient": 0.2}, odyn.SceneError, "nowhere"),
    ({"joint": "hinge", "coefficient": 0.2}, odyn.ModelError, "pin radius"),
    ({"joint": "hinge", "coefficient": 0.2, "static_coefficient": 0.1, "radius": 0.01},
     odyn.ModelError, "static_coefficient is 0.1"),
    ({"joint": "hinge", "coefficient": -0.2, "radius": 0.01}, odyn.SceneError, "coefficient"),
    ({"joint": "hinge", "coefficient": 0.2, "radius": 0.01, "pitch": 1.0}, Exception, "pitch"),
])
def test_bad_friction_is_refused_by_name(kwargs, error, words):
    m = odyn.Model()
    m.add_body("b", 1.0, [0.1, 0.1, 0.1])
    m.add_spherical("ball", "ground", body_b="b")
    m.add_revolute("hinge", "ground", body_b="b")
    with pytest.raises(error) as raised:
        m.add_joint_friction("bad", **kwargs)
    assert words in str(raised.value)
