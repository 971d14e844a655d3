"""Named points and element outputs (requests), against closed forms: a rotor turning at a
constant rate (a point's circle, its velocity and centripetal acceleration, and its motion
relative to the axis in the rotor's own axes), a mass on a spring (its length, rate and tension),
and their scene columns, files and errors."""

import json
import math

import numpy as np
import pytest

import odyn

OMEGA = 5.0  # rad/s


def rotor(space="spatial"):
    """A rotor on a revolute about z through the origin, turning at OMEGA with no load, with a
    point "rim" on it and a point "hub" on the ground at the axis."""
    if space == "planar":
        m = odyn.PlanarModel()
        m.add_body(name="rotor", mass=2.0, inertia=0.3, position=[0.2, 0.1],
                   angular_velocity=OMEGA)
        m.add_revolute(name="bearing", body_a="ground", body_b="rotor",
                       on_b=odyn.frame([-0.2, -0.1]))
        m.add_point("rim", "rotor", at=[0.3, -0.05])
        m.add_point("hub", "ground")
        return m
    m = odyn.Model()
    # The rotor's axes are turned about z; its centre sits off the axis and above the origin.
    half = 0.3
    m.add_body(name="rotor", mass=2.0, inertia=[0.2, 0.3, 0.4], position=[0.2, 0.1, 0.5],
               orientation=[math.cos(half), 0, 0, math.sin(half)],
               angular_velocity=[0, 0, OMEGA])
    m.add_revolute(name="bearing", body_a="ground", on_a=odyn.frame([0, 0, 0.5], [0, 0, 1]),
                   body_b="rotor", on_b=odyn.frame(
                       np.array([[math.cos(2 * half), math.sin(2 * half), 0],
                                 [-math.sin(2 * half), math.cos(2 * half), 0],
                                 [0, 0, 1]]) @ [-0.2, -0.1, 0], [0, 0, 1]))
    m.add_point("rim", "rotor", at=[0.3, -0.05, 0.1])
    m.add_point("hub", "ground", at=[0, 0, 0.5])
    return m


@pytest.mark.parametrize("space", ["spatial", "planar"])
def test_a_point_on_a_turning_rotor_follows_its_circle(space):
    m = rotor(space)
    r = odyn.simulate(m, t_end=1.0, output_interval=0.01, integrator="dop853", rtol=1e-11,
                      atol=1e-11)
    rim = r.point("rim")
    dim = 2 if space == "planar" else 3
    assert rim.position.shape == (len(r.t), dim)
    # The rim's offset from the axis turns at OMEGA: p(t) = hub + Rz(OMEGA t) (p(0) - hub).
    hub = np.array([0, 0, 0.5])[:dim]
    start = rim.position[0, :2] - hub[:2]
    angle = OMEGA * r.t
    expected = np.stack([np.cos(angle) * start[0] - np.sin(angle) * start[1],
                         np.sin(angle) * start[0] + np.cos(angle) * start[1]], -1)
    np.testing.assert_allclose(rim.position[:, :2] - hub[:2], expected, atol=1e-9)
    np.testing.assert_allclose(rim.velocity[:, :2],
                               OMEGA * np.stack([-expected[:, 1], expected[:, 0]], -1), atol=1e-8)
    np.testing.assert_allclose(rim.acceleration[:, :2], -OMEGA ** 2 * expected, atol=1e-7)
    if dim == 3:  # no motion along the axis
        np.testing.assert_allclose(rim.position[:, 2], rim.position[0, 2], atol=1e-10)
        np.testing.assert_allclose(rim.velocity[:, 2], 0, atol=1e-9)
        np.testing.assert_allclose(rim.acceleration[:, 2], 0, atol=1e-7)
    # Relative to the hub, in the rotor's axes, the rim stands still: its position is constant
    # and its velocity difference is omega x (its offset), both in body axes.
    relative = r.relative("rim", "hub", axes="rotor")
    np.testing.assert_allclose(relative.position, relative.position[:1].repeat(len(r.t), 0),
                               atol=1e-9)
    offset = relative.position[0]
    spin = OMEGA * np.array([-offset[1], offset[0]] + ([0.0] if dim == 3 else []))
    np.testing.assert_allclose(relative.velocity, np.tile(spin, (len(r.t), 1)), atol=1e-8)
    # Seen from the rotor itself, the rim neither moves nor accelerates.
    on_rotor = r.relative("rim", "hub", axes="rotor", seen_from="rotor")
    np.testing.assert_allclose(on_rotor.position, relative.position)
    np.testing.assert_allclose(on_rotor.velocity, 0, atol=1e-8)
    np.testing.assert_allclose(on_rotor.acceleration, 0, atol=1e-6)
    # The same axes named by a point on the rotor; the hub (on the ground) stands still.
    np.testing.assert_allclose(r.relative("rim", "hub", axes="rim").position, relative.position)
    np.testing.assert_allclose(r.point("hub").position, np.tile(hub, (len(r.t), 1)))
    assert not np.any(r.point("hub").velocity)
    # The rotor's centre of mass as a point at its origin is the body's own history.
    m.add_point("centre", "rotor")
    r = odyn.simulate(m, t_end=0.1, output_interval=0.01, integrator="dop853")
    body = r.body("rotor")
    np.testing.assert_allclose(r.point("centre").position, body.position)
    np.testing.assert_allclose(r.point("centre").velocity, body.linear_velocity)
    np.testing.assert_allclose(r.point("centre").acceleration, body.linear_acceleration)


def test_motion_seen_from_a_tumbling_body():
    """A free body tumbling under no force (angular velocity about a non-principal axis), a
    second body on a ground hinge turning at a constant rate; the second body's point as the
    first body sees it, against differences of its position in the first body's axes."""
    m = odyn.Model()
    m.add_body(name="tumbler", mass=1.0, inertia=[0.1, 0.2, 0.3], position=[0.3, -0.2, 0.1],
               linear_velocity=[0.2, 0.1, -0.3], angular_velocity=[3.0, 1.0, 4.0])
    m.add_body(name="arm", mass=1.0, inertia=[0.01, 0.01, 0.01], position=[0.5, 0, 0],
               angular_velocity=[0, 0, 2.0])
    m.add_revolute(name="hinge", body_a="ground", on_a=odyn.frame([0, 0, 0], [0, 0, 1]),
                   body_b="arm", on_b=odyn.frame([-0.5, 0, 0], [0, 0, 1]))
    m.add_point("tip", "arm", at=[0.5, 0.1, 0.05])
    m.add_point("mark", "tumbler", at=[0.05, 0.1, -0.1])
    dt = 1e-4
    r = odyn.simulate(m, t_end=0.2, output_interval=dt, integrator="dop853", rtol=1e-12,
                      atol=1e-12)
    seen = r.relative("tip", "mark", axes="tumbler", seen_from="tumbler")
    velocity = (seen.position[2:] - seen.position[:-2]) / (2 * dt)
    acceleration = (seen.velocity[2:] - seen.velocity[:-2]) / (2 * dt)
    assert np.max(np.abs(seen.acceleration)) > 5
    np.testing.assert_allclose(seen.velocity[1:-1], velocity, atol=1e-5)
    np.testing.assert_allclose(seen.acceleration[1:-1], acceleration, atol=1e-4)


def spring_mass():
    """A free mass on a spring from the origin, released stretched by A along -z."""
    m = odyn.Model()
    m.add_body(name="mass", mass=2.0, inertia=[0.1, 0.1, 0.1], position=[0, 0, -0.55])
    m.add_tsda(name="spring", body_a="ground", point_a=[0, 0, 0], body_b="mass",
               point_b=[0, 0, 0], stiffness=800.0, free_length=0.5)
    return m


def test_a_spring_reports_its_length_rate_and_tension():
    r = odyn.simulate(spring_mass(), t_end=1.0, output_interval=0.01, integrator="dop853",
                      rtol=1e-11, atol=1e-11)
    w, a = math.sqrt(800.0 / 2.0), 0.05
    outputs = r.output("spring")
    assert list(outputs) == ["length", "rate", "tension"]
    assert r.output_names == {"spring": ["length", "rate", "tension"]}
    np.testing.assert_allclose(outputs["length"], 0.5 + a * np.cos(w * r.t), atol=1e-9)
    np.testing.assert_allclose(r.output("spring", "rate"), -a * w * np.sin(w * r.t), atol=1e-8)
    np.testing.assert_allclose(r.output("spring", "tension"), 800.0 * a * np.cos(w * r.t),
                               atol=1e-6)
    with pytest.raises(KeyError, match="length, rate, tension"):
        r.output("spring", "force")
    with pytest.raises(KeyError, match="spring"):
        r.output("mass")


def test_a_planar_bushing_reports_its_components():
    m = odyn.PlanarModel()
    m.add_body(name="block", mass=1.0, inertia=0.01, position=[0.01, -0.02], angle=0.03)
    m.add_bushing(name="mount", body_a="ground", body_b="block", stiffness=[1e4, 2e4, 50.0])
    r = odyn.assemble(m)
    out = r.output("mount")
    assert list(out) == ["x", "y", "rz", "vx", "vy", "wz", "fx", "fy", "tz"]
    np.testing.assert_allclose([out[k][0] for k in ("x", "y", "rz")], [0.01, -0.02, 0.03])
    np.testing.assert_allclose([out[k][0] for k in ("fx", "fy", "tz")], [-100.0, 400.0, -1.5])


def scene_dict():
    return {
        "bodies": [{"name": "mass", "mass": 2.0, "inertia": [0.1, 0.1, 0.1],
                    "position": [0, 0, -0.55]}],
        "forces": [{"type": "tsda", "name": "spring", "body_a": "ground", "point_a": [0, 0, 0],
                    "body_b": "mass", "point_b": [0, 0, 0], "stiffness": 800.0,
                    "free_length": 0.5}],
        "points": [{"name": "tip", "body": "mass", "at": [0, 0, -0.1]},
                   {"name": "origin", "body": "ground"}],
        "analysis": {"t_end": 0.2, "output_interval": 0.01, "integrator": "dop853",
                     "rtol": 1e-10, "atol": 1e-10},
        "outputs": [{"name": "tension", "element": "spring", "output": "tension"},
                    {"name": "tip_z", "point": "tip", "quantity": "position", "component": "z"},
                    {"name": "tip_vz", "point": "tip", "relative_to": "origin",
                     "axes": "mass", "seen_from": "mass", "quantity": "velocity",
                     "component": "z"}],
    }


def test_scene_points_and_output_columns(tmp_path):
    scene = odyn.loads(json.dumps(scene_dict()))
    assert scene.model.point_names == ["tip", "origin"]
    table = scene.columns(scene.simulate())
    w = math.sqrt(400.0)
    np.testing.assert_allclose(table["tension"], 40.0 * np.cos(w * table["t"]), atol=1e-6)
    np.testing.assert_allclose(table["tip_z"], -0.6 - 0.05 * np.cos(w * table["t"]), atol=1e-9)
    np.testing.assert_allclose(table["tip_vz"], 0.05 * w * np.sin(w * table["t"]), atol=1e-8)
    # Saved and loaded again, the scene keeps its points.
    path = tmp_path / "spring.json"
    odyn.save(scene, path)
    assert odyn.load(path).model.point("tip") == {"name": "tip", "body": "mass",
                                                  "at": [0.0, 0.0, -0.1]}
    # The CSV of `odyn run` has the columns.
    from odyn.cli import main
    out = tmp_path / "spring.csv"
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 0
    assert out.read_text().splitlines()[0] == "t,tension,tip_z,tip_vz"


@pytest.mark.parametrize("change, message", [
    (lambda d: d["points"].append({"name": "tip", "body": "mass"}), "already used"),
    (lambda d: d["points"].append({"name": "spring", "body": "mass"}), "already used"),
    (lambda d: d["points"].append({"name": "p", "body": "wheel"}), "no body named 'wheel'"),
    (lambda d: d["points"].append({"name": "p", "body": "mass", "at": [1, 2]}),
     "points\\[2\\].at: expected a list of 3 numbers"),
    (lambda d: d["points"].append({"name": "p", "body": "mass", "where": [0, 0, 0]}),
     "where"),
    (lambda d: d["outputs"].append({"name": "x", "point": "nose", "quantity": "position",
                                    "component": "x"}), "no point named 'nose'; points: tip"),
    (lambda d: d["outputs"].append({"name": "x", "element": "spring", "output": "force"}),
     "expected one of length, rate, tension"),
    (lambda d: d["outputs"].append({"name": "x", "point": "tip", "quantity": "jerk",
                                    "component": "x"}), "position, velocity, acceleration"),
])
def test_bad_points_and_columns_are_refused_by_place(change, message):
    d = scene_dict()
    change(d)
    with pytest.raises(odyn.SceneError, match=message):
        odyn.loads(json.dumps(d))


def test_points_and_outputs_in_npz(tmp_path):
    m = spring_mass()
    m.add_point("tip", "mass", at=[0, 0, -0.1])
    r = odyn.simulate(m, t_end=0.05, output_interval=0.01, integrator="dop853")
    r.save_npz(tmp_path / "run.npz")
    with np.load(tmp_path / "run.npz") as saved:
        np.testing.assert_array_equal(saved["output/spring/tension"], r.output("spring",
                                                                               "tension"))
        np.testing.assert_array_equal(saved["point/tip/velocity"], r.point("tip").velocity)
    with pytest.raises(odyn.SceneError, match="already used"):
        m.add_tsda(name="tip", body_a="ground", body_b="mass")
    with pytest.raises(KeyError, match="points: tip"):
        r.point("nose")


def test_joint_coordinates_report_the_same_points_and_outputs():
    """The engine in joint coordinates (recursive) against absolute coordinates, both tight: the
    crank pin's motion and the gas force's and the load's outputs agree."""
    from conftest import ENGINE_SCENE
    scene = odyn.load(ENGINE_SCENE)
    scene.model.add_point("pin", "crank", at=[0, 0, 0.04])
    runs = [scene.simulate(t_end=0.05, coordinates=c, integrator="dop853", rtol=1e-10,
                           atol=1e-10) for c in ("absolute", "joint")]
    absolute, joint = runs
    assert joint.summary["coordinates"] == "joint"
    for field in ("position", "velocity", "acceleration"):
        scale = np.max(np.abs(getattr(absolute.point("pin"), field)))
        np.testing.assert_allclose(getattr(joint.point("pin"), field),
                                   getattr(absolute.point("pin"), field), atol=1e-8 * scale)
    for element, name in (("gas force", "pressure"), ("gas force", "force"), ("load", "rate")):
        values = absolute.output(element, name)
        np.testing.assert_allclose(joint.output(element, name), values,
                                   atol=1e-8 * np.max(np.abs(values)))


G = 9.81


def test_a_hinge_on_markers_takes_their_axes():
    """A bar hinged about global y through markers whose z axes are turned onto y (a quarter
    turn about x): it swings in the x-z plane with omega^2 = 2 m g L (cos theta - cos theta0)
    / I_O, and its centre, seen from the ground marker in the marker's axes, is at
    (L sin theta, L cos theta, 0)."""
    mass, inertia, length, theta0 = 1.0, 0.01, 0.8, 1.0
    onto_y = [math.cos(-math.pi / 4), math.sin(-math.pi / 4), 0.0, 0.0]  # -90 deg about x
    m = odyn.Model()
    m.add_body(name="bar", mass=mass, inertia=[inertia] * 3,
               position=[length * math.sin(theta0), 0.0, -length * math.cos(theta0)])
    m.add_point("pivot", "ground", orientation=onto_y)
    m.add_point("end", "bar", at=[-length * math.sin(theta0), 0.0, length * math.cos(theta0)],
                orientation=onto_y)
    m.add_point("centre", "bar")
    m.add_revolute(name="hinge", body_a="ground", on_a="pivot", body_b="bar", on_b="end")
    m.add_gravity(name="gravity", acceleration=[0.0, 0.0, -G])
    assert m.point("end")["orientation"] == onto_y
    r = odyn.simulate(m, t_end=1.5, output_interval=0.01, integrator="dop853", rtol=1e-10,
                      atol=1e-12)
    centre = r.body("bar").position
    theta = np.arctan2(centre[:, 0], -centre[:, 2])
    np.testing.assert_allclose(centre[:, 1], 0.0, atol=1e-9)
    assert theta.min() < -0.9 * theta0  # it swung through
    omega = r.body("bar").angular_velocity  # body axes: the bar turns about its y
    np.testing.assert_allclose(omega[:, [0, 2]], 0.0, atol=1e-9)
    i_o = inertia + mass * length ** 2
    expected = 2 * mass * G * length * (np.cos(theta) - math.cos(theta0)) / i_o
    np.testing.assert_allclose(omega[:, 1] ** 2, expected, atol=1e-7)
    seen = r.relative("centre", to="pivot", axes="pivot").position
    np.testing.assert_allclose(seen, np.column_stack(
        [length * np.sin(theta), length * np.cos(theta), np.zeros_like(theta)]), atol=1e-9)
    np.testing.assert_allclose(seen[0], [length * math.sin(theta0), length * math.cos(theta0),
                                         0.0], atol=1e-12)


def test_a_planar_slot_on_markers_takes_their_axis(tmp_path):
    """A block in a slot along markers turned 30 degrees down from x slides down it at
    g sin 30 without turning; in the marker's axes it moves along x only."""
    slope = math.radians(30.0)
    m = odyn.PlanarModel()
    m.add_body(name="block", mass=2.0, inertia=0.1)
    m.add_point("slot", "ground", orientation=-slope)
    m.add_point("runner", "block", orientation=-slope)
    m.add_translational(name="guide", body_a="ground", on_a="slot", body_b="block",
                        on_b="runner")
    m.add_gravity(name="gravity", acceleration=[0.0, -G])
    path = tmp_path / "slot.json"
    odyn.save(m, path)
    assert json.loads(path.read_text())["points"][0]["orientation"] == -slope
    for model in (m, odyn.load(path).model):
        r = odyn.simulate(model, t_end=1.0, output_interval=0.1, integrator="dop853",
                          rtol=1e-10, atol=1e-12)
        s = 0.5 * G * math.sin(slope) * r.t ** 2
        np.testing.assert_allclose(r.body("block").position, np.column_stack(
            [s * math.cos(slope), -s * math.sin(slope)]), atol=1e-9)
        np.testing.assert_allclose(r.body("block").angle, 0.0, atol=1e-12)
        along = r.relative("runner", to="slot", axes="slot").position
        np.testing.assert_allclose(along, np.column_stack([s, np.zeros_like(s)]), atol=1e-9)


def test_bad_marker_axes_are_refused():
    m = odyn.Model()
    m.add_body(name="bar", mass=1.0, inertia=[0.01] * 3)
    with pytest.raises(odyn.SceneError, match=r"point 'p'\.orientation: zero-length vector"):
        m.add_point("p", "bar", orientation=[0, 0, 0, 0])
    with pytest.raises(odyn.SceneError, match=r"point 'p'\.orientation: expected a list of 4"):
        m.add_point("p", "bar", orientation=0.5)
    m.add_point("p", "bar", orientation=[1, 0, 0, 0])
    with pytest.raises(odyn.SceneError, match=r"revolute 'hinge'\.on_a: the point 'p' is on "
                       r"'bar', but on_a is a point on body_a, 'ground'"):
        m.add_revolute(name="hinge", body_a="ground", on_a="p", body_b="bar")
    p = odyn.PlanarModel()
    p.add_body(name="block", mass=1.0, inertia=0.1)
    with pytest.raises(odyn.SceneError, match=r"point 'q'\.orientation: expected a number"):
        p.add_point("q", "block", orientation=[1, 0])
