"""Gears, rack and pinion, and screw (spatial and planar), against closed forms: a torque-driven
gear pair turns as one inertia I_a + ratio^2 I_b for many turns (with the mesh torque on gear a
from the reactions and the outputs), a three-gear train's work-energy balance, a pushed rack
and its pinion, a nut sinking down a lead screw (with the torque and force the coupling passes
on), a planetary gear set of three-joint couplers against its Lagrangian and Willis's relation,
a coupler of a slide and an angle; scene files and bad input."""

import json
import math

import numpy as np
import pytest

import odyn

G = 9.81


def gear_pair(space, ratio, inertia_a=0.1, inertia_b=0.3, torque=2.0):
    """Two discs on hinges to the ground (z axes), meshing at `ratio`, gear a driven by a
    constant torque."""
    if space == "spatial":
        m = odyn.Model()
        m.add_body("a", 1.0, [inertia_a, inertia_a, inertia_a])
        m.add_body("b", 1.0, [inertia_b, inertia_b, inertia_b], position=[0.3, 0, 0])
        m.add_revolute("hinge_a", "ground", body_b="a")
        m.add_revolute("hinge_b", "ground", on_a={"point": [0.3, 0, 0]}, body_b="b")
        m.add_point_torque("motor", "a", [0, 0, torque])
    else:
        m = odyn.PlanarModel()
        m.add_body("a", 1.0, inertia_a)
        m.add_body("b", 1.0, inertia_b, position=[0.3, 0])
        m.add_revolute("hinge_a", "ground", body_b="a")
        m.add_revolute("hinge_b", "ground", on_a={"point": [0.3, 0]}, body_b="b")
        m.add_point_torque("motor", "a", torque)
    m.add_gear("mesh", joint_a="hinge_a", joint_b="hinge_b", ratio=ratio)
    return m


@pytest.mark.parametrize("space", ["spatial", "planar"])
@pytest.mark.parametrize("coordinates", ["absolute", "joint"])
@pytest.mark.parametrize("integrator", ["dop853", "auto"])
def test_a_gear_pair_turns_as_one_inertia(space, coordinates, integrator):
    """theta_a'' = T / (I_a + ratio^2 I_b): gear a turns 6.4 times in 2 s, gear b -4.4 times."""
    ratio, inertia_a, inertia_b, torque = -0.69, 0.1, 0.3, 2.0
    m = gear_pair(space, ratio, inertia_a, inertia_b, torque)
    r = odyn.simulate(m, t_end=2.0, output_interval=0.05, integrator=integrator,
                      coordinates=coordinates, rtol=1e-10, atol=1e-12, step=1e-3)
    accel = torque / (inertia_a + ratio ** 2 * inertia_b)
    tolerance = 1e-7 if integrator == "dop853" else 1e-4
    np.testing.assert_allclose(r.output("mesh", "angle_a"), 0.5 * accel * r.t ** 2,
                               rtol=tolerance, atol=1e-9)
    np.testing.assert_allclose(r.output("mesh", "angle_b"), ratio * 0.5 * accel * r.t ** 2,
                               rtol=tolerance, atol=1e-9)
    # The mesh holds gear a back by the torque that spins gear b, reflected: ratio^2 I_b accel.
    mesh_torque = r.reaction("mesh", side="b").torque
    mesh_torque = mesh_torque[:, 2] if space == "spatial" else mesh_torque
    np.testing.assert_allclose(mesh_torque[1:], -ratio ** 2 * inertia_b * accel,
                               rtol=10 * tolerance)
    # The outputs name the mesh's torque on each gear: I_a accel - T on a, I_b theta_b'' on b.
    np.testing.assert_allclose(r.output("mesh", "torque_a")[1:], -ratio ** 2 * inertia_b * accel,
                               rtol=10 * tolerance)
    np.testing.assert_allclose(r.output("mesh", "torque_b")[1:], ratio * inertia_b * accel,
                               rtol=10 * tolerance)


@pytest.mark.parametrize("coordinates", ["absolute", "joint"])
@pytest.mark.parametrize("settings", [{"integrator": "dop853", "rtol": 1e-9, "atol": 1e-9},
                                      {"integrator": "generalized-alpha", "step": 0.05}])
def test_a_fast_pinion_keeps_count_of_its_turns(coordinates, settings):
    """A light pinion spun up to 32 turns a second: in joint coordinates its angle is a
    polynomial in time, which dop853 would take in a few long steps, and the fixed step asked
    of generalized-alpha turns it by up to 10 rad. The gear's spatial angles count turns from
    the last step, so each step is kept to well under half a turn."""
    m = gear_pair("spatial", -0.25, inertia_a=1e-3, inertia_b=0.016, torque=0.2)
    r = odyn.simulate(m, t_end=2.0, output_interval=0.5, coordinates=coordinates, **settings)
    accel = 0.2 / (1e-3 + 0.25 ** 2 * 0.016)
    assert r.output("mesh", "angle_a")[-1] / (2 * math.pi) > 30
    tolerance = 1e-8 if settings["integrator"] == "dop853" else 1e-5
    np.testing.assert_allclose(r.output("mesh", "angle_a"), 0.5 * accel * r.t ** 2,
                               rtol=tolerance)
    np.testing.assert_allclose(r.output("mesh", "angle_b"), -0.25 * 0.5 * accel * r.t ** 2,
                               rtol=tolerance)


def test_a_gear_train_balances_work_and_energy():
    """Three gears in a row on a moving carrier that hangs from a hinge: the kinetic and
    potential energy grow by the motor's work T theta_a (the meshes do none)."""
    torque = 0.5
    m = odyn.Model()
    m.add_body("carrier", 2.0, [0.05, 0.3, 0.3], position=[0.4, 0, 0])
    for i, x in enumerate([0.2, 0.5, 0.7]):
        m.add_body(f"g{i}", 0.3 + 0.1 * i, [0.01 + 0.005 * i] * 2 + [0.02 + 0.01 * i],
                   position=[x, 0, 0])
        m.add_revolute(f"h{i}", "carrier", on_a={"point": [x - 0.4, 0, 0]}, body_b=f"g{i}")
    m.add_revolute("pivot", "ground", on_a={"axis": [0, 0, 1]}, body_b="carrier",
                   on_b={"point": [-0.4, 0, 0], "axis": [0, 0, 1]})
    m.add_gear("first", joint_a="h0", joint_b="h1", ratio=-0.6)
    m.add_gear("second", joint_a="h1", joint_b="h2", ratio=-1.5)
    m.add_point_torque("motor", "g0", [0, 0, torque], axes="body")
    m.add_gravity("gravity", [0, -G, 0])
    r = odyn.simulate(m, t_end=1.5, output_interval=0.01, integrator="dop853", rtol=1e-11,
                      atol=1e-13)
    # The motor's work is T times g0's turn about z (its axis stays along z): the hinge's
    # angle plus the carrier's, read here from g0's quaternion.
    q = r.body("g0").orientation
    turn = np.unwrap(2 * np.arctan2(q[:, 3], q[:, 0]))
    energy = r.kinetic_energy + r.potential_energy
    np.testing.assert_allclose(energy - energy[0], torque * (turn - turn[0]), atol=1e-8)
    np.testing.assert_allclose(np.diff(r.output("second", "angle_b")),
                               0.9 * np.diff(r.output("first", "angle_a")), atol=1e-9)
    assert abs(r.output("first", "angle_a")[-1]) > 2 * math.pi


@pytest.mark.parametrize("space", ["spatial", "planar"])
def test_a_pushed_rack_drives_its_pinion(space, tmp_path):
    """(m + I / r^2) s'' = F and theta = s / r, also after a round trip through a scene file."""
    mass, inertia, radius, force = 2.0, 0.01, 0.05, 3.0
    if space == "spatial":
        m = odyn.Model()
        m.add_body("pinion", 0.5, [0.2, 0.2, inertia])
        m.add_body("rack", mass, [1, 1, 1], position=[0, -radius, 0])
        m.add_translational("guide", "ground", on_a={"point": [0, -radius, 0], "axis": [1, 0, 0]},
                            body_b="rack", on_b={"axis": [1, 0, 0]})
        m.add_point_force("push", "rack", [force, 0, 0])
    else:
        m = odyn.PlanarModel()
        m.add_body("pinion", 0.5, inertia)
        m.add_body("rack", mass, 1.0, position=[0, -radius])
        m.add_translational("guide", "ground", on_a={"point": [0, -radius], "axis": [1, 0]},
                            body_b="rack", on_b={"axis": [1, 0]})
        m.add_point_force("push", "rack", [force, 0])
    m.add_revolute("hinge", "ground", body_b="pinion")
    m.add_rack_pinion("drive", pinion="hinge", rack="guide", radius=-radius)
    settings = {"t_end": 1.0, "output_interval": 0.1, "integrator": "dop853", "rtol": 1e-11,
                "atol": 1e-13}
    accel = force / (mass + inertia / radius ** 2)
    path = tmp_path / "rack.json"
    odyn.save(odyn.Scene(m, settings), str(path))
    for r in (odyn.simulate(m, **settings), odyn.load(str(path)).simulate()):
        np.testing.assert_allclose(r.output("drive", "slide"), 0.5 * accel * r.t ** 2,
                                   rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(r.output("drive", "angle"),
                                   -0.5 * accel * r.t ** 2 / radius, rtol=1e-9, atol=1e-12)
        # The mesh turns the pinion with I theta'' and holds the rack back by (I / r^2) s''.
        np.testing.assert_allclose(r.output("drive", "torque")[1:], -inertia * accel / radius,
                                   rtol=1e-8)
        np.testing.assert_allclose(r.output("drive", "force")[1:],
                                   -inertia / radius ** 2 * accel, rtol=1e-8)
    saved = json.loads(path.read_text())
    (drive,) = [j for j in saved["joints"] if j["name"] == "drive"]
    assert drive["pinion"]["body_b"] == "pinion" and drive["rack"]["body_b"] == "rack"


@pytest.mark.parametrize("coordinates", ["absolute", "joint"])
def test_a_nut_sinks_down_a_lead_screw(coordinates):
    """s'' = -g m / (m + I (2 pi / p)^2), theta = 2 pi s / p."""
    mass, inertia, pitch = 0.4, 2e-5, 0.01
    m = odyn.Model()
    m.add_body("nut", mass, [1e-5, 1e-5, inertia])
    m.add_cylindrical("shaft", "ground", body_b="nut")
    m.add_screw("thread", joint="shaft", pitch=pitch)
    m.add_gravity("gravity", [0, 0, -G])
    r = odyn.simulate(m, t_end=0.5, output_interval=0.05, integrator="dop853",
                      coordinates=coordinates, rtol=1e-11, atol=1e-13)
    lead = 2 * math.pi / pitch
    accel = -G * mass / (mass + inertia * lead ** 2)
    np.testing.assert_allclose(r.output("thread", "slide"), 0.5 * accel * r.t ** 2, rtol=1e-9,
                               atol=1e-13)
    np.testing.assert_allclose(r.output("thread", "angle"), lead * 0.5 * accel * r.t ** 2,
                               rtol=1e-9, atol=1e-10)
    # The thread spins the nut with J theta'' and holds it up by m (s'' + g).
    np.testing.assert_allclose(r.output("thread", "torque")[1:], inertia * lead * accel,
                               rtol=1e-8)
    np.testing.assert_allclose(r.output("thread", "force")[1:], mass * (accel + G), rtol=1e-8)


@pytest.mark.parametrize("kwargs, words", [
    ({"joint_a": "hinge_a", "joint_b": "hinge_b", "ratio": 0.0}, "ratio is 0"),
    ({"joint_a": "hinge_a", "joint_b": "hinge_b", "ratio": float("inf")}, "ratio"),
    ({"joint_a": "slide", "joint_b": "hinge_b", "ratio": 2.0},
     "no revolute or cylindrical joint named 'slide'"),
    ({"joint_a": "hinge_a", "joint_b": "nowhere", "ratio": 2.0}, "nowhere"),
    ({"joint_a": "hinge_a", "ratio": 2.0}, "joint_b"),
    ({"joint_a": "hinge_a", "joint_b": "hinge_b", "ratio": 2.0, "radius": 1.0}, "radius"),
])
def test_bad_gears_are_refused_by_name(kwargs, words):
    m = gear_pair("spatial", 2.0)
    m.add_body("block", 1.0, [0.1, 0.1, 0.1])
    m.add_translational("slide", "ground", body_b="block")
    with pytest.raises((odyn.ModelError, ValueError, TypeError)) as error:
        m.add_gear("bad", **kwargs)
    assert words in str(error.value)


def test_bad_racks_and_screws_are_refused_by_name():
    m = gear_pair("planar", 2.0)
    with pytest.raises(odyn.SceneError, match="no translational joint named 'hinge_b'"):
        m.add_rack_pinion("drive", pinion="hinge_a", rack="hinge_b", radius=0.1)
    s = odyn.Model()
    s.add_body("nut", 1.0, [0.1, 0.1, 0.1])
    s.add_revolute("hinge", "ground", body_b="nut")
    with pytest.raises(odyn.SceneError, match="no cylindrical joint named 'hinge'"):
        s.add_screw("thread", joint="hinge", pitch=0.01)
    s.add_cylindrical("shaft", "ground", body_b="nut")
    with pytest.raises(odyn.ModelError, match="thread.*pitch is 0"):
        s.add_screw("thread", joint="shaft", pitch=0.0)


# A planetary set: sun, ring and carrier on coaxial hinges, one planet on the carrier. Teeth, the
# planet's pitch radius, inertias and the torques on the sun and the carrier.
TEETH_SUN, TEETH_PLANET, TEETH_RING = 24, 18, 60
PLANET_RADIUS = 0.002 * (TEETH_SUN + TEETH_PLANET) / 2
INERTIA = {"sun": 0.002, "ring": 0.03, "carrier": 0.01, "planet": 8e-4}
PLANET_MASS, TORQUE_SUN, TORQUE_CARRIER = 0.4, 0.05, -0.03


def planetary(space):
    """The set, its meshes as couplers of three joint angles (phi the planet's on the carrier):
    Z_p phi + Z_s (theta_s - theta_c) = 0 and Z_p phi - Z_r (theta_r - theta_c) = 0."""
    planar = space == "planar"
    m = odyn.PlanarModel() if planar else odyn.Model()
    at = [0.0, PLANET_RADIUS] if planar else [0.0, PLANET_RADIUS, 0.0]
    for name in ("sun", "ring", "carrier", "planet"):
        i = INERTIA[name]
        mass = PLANET_MASS if name == "planet" else 0.5
        m.add_body(name, mass, i if planar else [i, i, i],
                   position=at if name == "planet" else [0.0] * len(at))
        if name != "planet":
            m.add_revolute(f"{name} hinge", "ground", body_b=name)
    m.add_revolute("planet pin", "carrier", on_a={"point": at}, body_b="planet")
    m.add_coupler("sun mesh", joint_1="planet pin", scale_1=TEETH_PLANET,
                  joint_2="sun hinge", scale_2=TEETH_SUN,
                  joint_3="carrier hinge", scale_3=-TEETH_SUN)
    m.add_coupler("ring mesh", joint_1="planet pin", scale_1=TEETH_PLANET,
                  joint_2="ring hinge", scale_2=-TEETH_RING,
                  joint_3="carrier hinge", scale_3=TEETH_RING)
    m.add_point_torque("motor", "sun", TORQUE_SUN if planar else [0, 0, TORQUE_SUN])
    m.add_point_torque("load", "carrier", TORQUE_CARRIER if planar else [0, 0, TORQUE_CARRIER])
    return m


def planetary_reference():
    """The velocities (sun, ring, carrier, planet in the ground, planet on the carrier) as a
    5 x 2 matrix times (theta_s', theta_r'), and (theta_s'', theta_r'') from Lagrange's
    equations in those two coordinates."""
    c_sun = TEETH_SUN / (TEETH_SUN + TEETH_RING)
    a = np.zeros((5, 2))
    a[0], a[1], a[2] = [1, 0], [0, 1], [c_sun, 1 - c_sun]
    a[4] = -TEETH_SUN / TEETH_PLANET * (a[0] - a[2])
    a[3] = a[2] + a[4]
    inertia = np.diag([INERTIA["sun"], INERTIA["ring"],
                       INERTIA["carrier"] + PLANET_MASS * PLANET_RADIUS ** 2, INERTIA["planet"],
                       0.0])
    torque = np.array([TORQUE_SUN, 0.0, TORQUE_CARRIER, 0.0, 0.0])
    return a, np.linalg.solve(a.T @ inertia @ a, a.T @ torque)


@pytest.mark.parametrize("space", ["spatial", "planar"])
@pytest.mark.parametrize("coordinates", ["absolute", "joint"])
def test_a_planetary_set_of_couplers_keeps_willis_relation(space, coordinates, tmp_path):
    """The sun turns 2.4 times in 1.5 s; every joint angle follows the Lagrangian's, Willis's
    (theta_s - theta_c) / (theta_r - theta_c) = -Z_r / Z_s holds throughout, and what each
    mesh passes on to the sun and the ring is their inertia times their acceleration, less the
    torque on them. A scene file's round trip keeps the couplers."""
    m = planetary(space)
    a, accel = planetary_reference()
    settings = {"t_end": 1.5, "output_interval": 0.1, "integrator": "dop853", "rtol": 1e-11,
                "atol": 1e-13, "coordinates": coordinates}
    path = tmp_path / "planetary.json"
    odyn.save(odyn.Scene(m, settings), str(path))
    for r in (odyn.simulate(m, **settings), odyn.load(str(path)).simulate()):
        angles = np.outer(0.5 * r.t ** 2, a @ accel)
        sun, ring = r.output("sun mesh", "coordinate_2"), r.output("ring mesh", "coordinate_2")
        carrier = r.output("sun mesh", "coordinate_3")
        np.testing.assert_allclose(sun, angles[:, 0], rtol=1e-8, atol=1e-10)
        np.testing.assert_allclose(ring, angles[:, 1], rtol=1e-8, atol=1e-10)
        np.testing.assert_allclose(carrier, angles[:, 2], rtol=1e-8, atol=1e-10)
        np.testing.assert_allclose(r.output("ring mesh", "coordinate_1"), angles[:, 4],
                                   rtol=1e-8, atol=1e-10)
        np.testing.assert_allclose((sun - carrier)[1:] / (ring - carrier)[1:],
                                   -TEETH_RING / TEETH_SUN, rtol=1e-8)
        assert sun[-1] / (2 * math.pi) > 2.3
        np.testing.assert_allclose(r.output("sun mesh", "effort_2")[1:],
                                   INERTIA["sun"] * accel[0] - TORQUE_SUN, rtol=1e-7)
        np.testing.assert_allclose(r.output("ring mesh", "effort_2")[1:],
                                   INERTIA["ring"] * accel[1], rtol=1e-7)


@pytest.mark.parametrize("space", ["spatial", "planar"])
def test_a_coupler_of_a_slide_and_an_angle_is_a_rack(space):
    """A coupler of two joints, a slider's slide and a hinge's angle: s = r theta, and
    (m + I / r^2) s'' = F under a push on the slider."""
    mass, inertia, radius, force = 2.0, 0.01, 0.05, 3.0
    planar = space == "planar"
    m = odyn.PlanarModel() if planar else odyn.Model()
    m.add_body("pinion", 0.5, inertia if planar else [0.2, 0.2, inertia])
    m.add_body("slider", mass, 1.0 if planar else [1, 1, 1])
    x = [1.0, 0.0] if planar else [1.0, 0.0, 0.0]
    m.add_revolute("hinge", "ground", body_b="pinion")
    m.add_translational("guide", "ground", on_a={"axis": x}, body_b="slider", on_b={"axis": x})
    m.add_coupler("drive", joint_1="guide", scale_1=1.0, joint_2="hinge", scale_2=-radius)
    assert m.element("drive")["coordinate_1"] == "slide"
    assert m.element("drive")["coordinate_2"] == "angle"
    m.add_point_force("push", "slider", [force * c for c in x])
    r = odyn.simulate(m, t_end=1.0, output_interval=0.1, integrator="dop853", rtol=1e-11,
                      atol=1e-13)
    accel = force / (mass + inertia / radius ** 2)
    np.testing.assert_allclose(r.output("drive", "coordinate_1"), 0.5 * accel * r.t ** 2,
                               rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(r.output("drive", "coordinate_2"),
                               0.5 * accel * r.t ** 2 / radius, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(r.output("drive", "effort_2")[1:], inertia * accel / radius,
                               rtol=1e-8)
    np.testing.assert_allclose(r.output("drive", "coordinate_3"), 0.0)


@pytest.mark.parametrize("kwargs, words", [
    ({"scale_1": 0.0}, "scale_1 is 0"),
    ({"coordinate_1": "slide"}, "'planet pin' is a revolute joint, which has no slide"),
    ({"coordinate_1": "twist"}, "twist"),
    ({"joint_2": "shaft"}, "'shaft' is a cylindrical joint, which both turns and slides"),
    ({"joint_3": None}, "scale_3 is given without joint_3"),
    ({"scale_3": None}, "joint_3 is given without scale_3"),
    ({"scale_3": float("nan")}, "scale_3: expected a finite number"),
    ({"joint_3": "motor"}, "no revolute, translational or cylindrical joint named 'motor'"),
    ({"ratio": 2.0}, "unknown"),
])
def test_bad_couplers_are_refused_by_name(kwargs, words):
    m = planetary("spatial")
    m.add_body("nut", 1.0, [0.1, 0.1, 0.1])
    m.add_cylindrical("shaft", "ground", body_b="nut")
    given = {"joint_1": "planet pin", "scale_1": 18.0, "joint_2": "sun hinge", "scale_2": 24.0,
             "joint_3": "carrier hinge", "scale_3": -24.0, **kwargs}
    given = {k: v for k, v in given.items() if v is not None}
    with pytest.raises((odyn.ModelError, odyn.SceneError)) as error:
        m.add("coupler", name="bad", **given)
    assert "bad" in str(error.value) and words in str(error.value)
