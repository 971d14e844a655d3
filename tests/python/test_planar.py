"""Planar models from Python: every planar element against an analytic value, Python forces
against the C++ elements, results (poses, reactions), and planar scene files."""

import json
import math

import numpy as np
import pytest

import odyn
from conftest import ROOT

G = 9.81
TESTED = set()
PLANAR_SCENE = ROOT / "examples" / "slider_crank_planar.json"


def covers(*types):
    TESTED.update(types)


def pendulum():
    """A 1 kg bob (inertia 1e-3) at (1, 0) pinned at the origin; gravity -y."""
    m = odyn.PlanarModel()
    m.add_body(name="bob", mass=1.0, inertia=1e-3, position=[1, 0])
    m.add_revolute(name="pin", body_a="ground", body_b="bob", on_b=odyn.frame([-1, 0]))
    m.add_gravity(name="gravity", acceleration=[0, -G])
    return m


def test_pendulum_released_horizontal():
    covers("revolute", "gravity")
    m = pendulum()
    assert m.space == "planar" and m.num_equations == 2 and m.num_velocities == 3
    a = odyn.assemble(m)
    alpha = -G / (1e-3 + 1.0)  # m g L / (J + m L^2)
    np.testing.assert_allclose(a.vdot[0], [0, alpha, alpha], atol=1e-12)
    # The pin's force on the bob: m a - m g; the opposite on the ground.
    np.testing.assert_allclose(a.reaction("pin").force[0], [0, alpha + G], atol=1e-12)
    np.testing.assert_allclose(a.reaction("pin", side="a").force[0], [0, -(alpha + G)],
                               atol=1e-12)
    assert a.reaction("pin").torque.shape == (1,)
    r = odyn.simulate(m, t_end=2.0, step=1e-3, output_interval=0.01)
    bob = r.body("bob")
    assert isinstance(bob, odyn.PlanarBodyHistory)
    assert bob.position.shape == (201, 2) and bob.angle.shape == (201,)
    # The bob's angle is its angle about the pin (the bar points at it).
    np.testing.assert_allclose(np.arctan2(bob.position[:, 1], bob.position[:, 0]), bob.angle,
                               atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(bob.position, axis=1), 1.0, atol=1e-10)
    assert r.energy_drift() < 2e-3 * G


def test_translational_slides_down_a_45_degree_guide():
    covers("translational")
    m = odyn.PlanarModel()
    m.add_body(name="block", mass=2.0, inertia=0.1)
    m.add_translational(name="guide", body_a="ground", on_a=odyn.frame([0, 0], [1, -1]),
                        body_b="block")
    m.add_gravity(name="gravity", acceleration=[0, -G])
    r = odyn.simulate(m, t_end=1.0, step=1e-3, output_interval=0.5)
    s = G * r.t**2 / (2 * math.sqrt(2))
    np.testing.assert_allclose(r.body("block").position,
                               np.column_stack([s, -s]) / math.sqrt(2), atol=1e-9)
    np.testing.assert_allclose(r.body("block").angle, 0.0, atol=1e-12)
    # The guide pushes perpendicular to itself: m g cos 45 along (1, 1)/sqrt 2.
    np.testing.assert_allclose(r.reaction("guide").force[-1], [G, G], atol=1e-8)


def test_fixed_holds_a_body_and_carries_its_weight_and_moment():
    covers("fixed")
    m = odyn.PlanarModel()
    m.add_body(name="beam", mass=3.0, inertia=0.2, position=[0.5, 0])
    m.add_fixed(name="weld", body_a="ground", body_b="beam", on_b=odyn.frame([-0.5, 0]))
    m.add_gravity(name="gravity", acceleration=[0, -G])
    r = odyn.simulate(m, t_end=0.5, step=1e-3, output_interval=0.25)
    np.testing.assert_allclose(r.body("beam").position[-1], [0.5, 0], atol=1e-10)
    np.testing.assert_allclose(r.reaction("weld").force, np.tile([0, 3 * G], (3, 1)), atol=1e-8)
    # About the weld point the wall holds the weight's moment: +m g 0.5.
    np.testing.assert_allclose(r.reaction("weld").torque, 1.5 * G, atol=1e-8)


def test_distance_lets_a_horizontal_bob_fall_freely_at_first():
    covers("distance")
    m = odyn.PlanarModel()
    m.add_body(name="bob", mass=1.0, inertia=1e-3, position=[1, 0])
    m.add_distance(name="rod", body_a="ground", body_b="bob")
    m.add_gravity(name="gravity", acceleration=[0, -G])
    a = odyn.assemble(m)
    np.testing.assert_allclose(a.vdot[0, :2], [0, -G], atol=1e-12)
    np.testing.assert_allclose(a.multipliers("rod"), [[0.0]], atol=1e-12)
    r = odyn.simulate(m, t_end=1.0, step=1e-3, output_interval=0.1)
    np.testing.assert_allclose(np.linalg.norm(r.body("bob").position, axis=1), 1.0, atol=1e-10)


def test_revolute_driver_turns_the_bob_and_counts_turns():
    covers("revolute_driver")
    m = pendulum()
    m.add_revolute_driver(name="motor", joint="pin", motion=odyn.constant_velocity(8.0))
    r = odyn.simulate(m, t_end=1.0, step=1e-3, output_interval=0.1)
    np.testing.assert_allclose(r.body("bob").angle, 8.0 * r.t, atol=1e-9)  # past a full turn
    # At constant rate the motor balances gravity's torque about the pin, m g L cos(angle)
    # (after the index-3 integrator's start-up transient in lambda, gone by the third output).
    torque = r.reaction("motor").torque
    np.testing.assert_allclose(torque, G * np.cos(8.0 * r.t), atol=5e-3)
    np.testing.assert_allclose(torque[2:], G * np.cos(8.0 * r.t[2:]), atol=1e-4)


def test_translational_driver_follows_a_harmonic_motion():
    covers("translational_driver")
    m = odyn.PlanarModel()
    m.add_body(name="slide", mass=1.0, inertia=0.1)
    m.add_translational(name="guide", body_a="ground", on_a=odyn.frame([0, 0], [1, 0]),
                        body_b="slide")
    m.add_translational_driver(name="drive", joint="guide", motion=odyn.harmonic(0.1, 3.0))
    r = odyn.simulate(m, t_end=1.0, step=1e-3, output_interval=0.05)
    np.testing.assert_allclose(r.body("slide").position[:, 0], 0.1 * np.sin(3 * r.t),
                               atol=1e-10)
    force = r.reaction("drive").force[:, 0]
    np.testing.assert_allclose(force[3:], -0.9 * np.sin(3 * r.t[3:]), atol=1e-5)


def test_point_force_and_torque_constant_and_from_python():
    covers("point_force", "point_torque")
    for force, torque in (([2, 0], 0.4), (lambda t, b: (2.0, 0.0), lambda t, b: 0.4)):
        m = odyn.PlanarModel()
        m.add_body(name="b", mass=0.5, inertia=0.2)
        m.add_point_force(name="push", body="b", force=force)
        m.add_point_torque(name="twist", body="b", torque=torque)
        r = odyn.simulate(m, t_end=1.0, step=1e-3, output_interval=0.5)
        np.testing.assert_allclose(r.body("b").position[:, 0], 2 * r.t**2, atol=1e-9)
        np.testing.assert_allclose(r.body("b").angular_velocity, 2 * r.t, atol=1e-9)
    # In body axes: a body turned by 90 degrees pushed along its x goes along global y.
    m = odyn.PlanarModel()
    m.add_body(name="b", mass=0.5, inertia=0.2, angle=math.pi / 2)
    m.add_point_force(name="push", body="b", force=[2, 0], axes="body")
    r = odyn.simulate(m, t_end=1.0, step=1e-3, output_interval=0.5)
    np.testing.assert_allclose(r.body("b").position, np.column_stack([0 * r.t, 2 * r.t**2]),
                               atol=1e-9)


def rail(kind, k=100.0, c=0.0):
    """A 1 kg block on a rail along x, pulled towards x = 1 by a spring (k, c)."""
    m = odyn.PlanarModel()
    m.add_body(name="block", mass=1.0, inertia=0.1, position=[1.2, 0])
    m.add_translational(name="rail", body_a="ground", on_a=odyn.frame([0, 0], [1, 0]),
                        body_b="block")
    if kind == "tsda":
        m.add_tsda(name="spring", body_a="ground", body_b="block", stiffness=k, damping=c,
                   free_length=1.0)
    else:  # the same law as a Python user force on the block
        m.add_user_force(name="spring", bodies=["block"], function=lambda t, b: (
            -k * (b.position[0] - 1.0) - c * b.linear_velocity[0], 0.0, 0.0))
    return m


def test_tsda_oscillates_at_the_natural_frequency_and_python_matches_it():
    covers("tsda", "user_force")
    r = odyn.simulate(rail("tsda"), t_end=1.0, step=1e-4, output_interval=0.01)
    np.testing.assert_allclose(r.body("block").position[:, 0], 1 + 0.2 * np.cos(10 * r.t),
                               atol=1e-4)
    ref = odyn.simulate(rail("tsda", c=0.7), t_end=1.0, step=1e-4, output_interval=0.01)
    py = odyn.simulate(rail("user", c=0.7), t_end=1.0, step=1e-4, output_interval=0.01)
    np.testing.assert_allclose(py.q, ref.q, atol=1e-9)


def test_rsda_and_a_python_torque_on_two_bodies_agree():
    covers("rsda")

    def rotor(kind, actuator=None):
        m = odyn.PlanarModel()
        m.add_body(name="rotor", mass=1.0, inertia=0.25, angular_velocity=1.0)
        m.add_revolute(name="axle", body_a="ground", body_b="rotor")
        if kind == "rsda":
            m.add_rsda(name="spring", body_a="ground", body_b="rotor", stiffness=1.0,
                       actuator=actuator)
        else:  # torque -k angle on the rotor, +k angle on the ground
            m.add_user_force(name="spring", bodies=["ground", "rotor"], function=lambda t, g, b: (
                (0.0, 0.0, b.angle), (0.0, 0.0, -b.angle)))
        return m
    r = odyn.simulate(rotor("rsda"), t_end=2.0, step=1e-4, output_interval=0.01)
    # J theta'' = -k theta, theta'(0) = 1: theta = sin(2 t) / 2
    np.testing.assert_allclose(r.body("rotor").angle, 0.5 * np.sin(2 * r.t), atol=2e-5)
    py = odyn.simulate(rotor("python"), t_end=2.0, step=1e-4, output_interval=0.01)
    np.testing.assert_allclose(py.q, r.q, atol=1e-10)
    r = odyn.simulate(rotor("rsda", actuator=lambda t, angle, rate: 0.5), t_end=2.0, step=1e-4,
                      output_interval=0.01)
    expected = 0.5 * (1 - np.cos(2 * r.t)) + 0.5 * np.sin(2 * r.t)
    np.testing.assert_allclose(r.body("rotor").angle, expected, atol=2e-5)


def test_pin_in_an_inclined_slot_slides_and_spins():
    # in-line (a pin in a slot): the block's centre on a slot inclined by alpha slides with
    # g sin(alpha) along it and keeps its spin; the slot pushes with m g cos(alpha) across it.
    covers("inline")
    alpha, omega, mass = 0.4, 3.0, 2.0
    m = odyn.PlanarModel()
    m.add_body("block", mass=mass, inertia=0.1, angular_velocity=omega)
    m.add_inline("slot", "ground", on_a=odyn.frame([0, 0], [math.cos(alpha), -math.sin(alpha)]),
                 body_b="block")
    m.add_gravity("gravity", (0, -G))
    r = odyn.simulate(m, t_end=1.0, rtol=1e-10, atol=1e-10, output_interval=0.25)
    s = 0.5 * G * math.sin(alpha) * r.t**2
    expected = np.column_stack([s * math.cos(alpha), -s * math.sin(alpha)])
    np.testing.assert_allclose(r.body("block").position, expected, atol=1e-9)
    np.testing.assert_allclose(r.body("block").angle, omega * r.t, atol=1e-9)
    normal = mass * G * math.cos(alpha) * np.array([math.sin(alpha), math.cos(alpha)])
    np.testing.assert_allclose(r.reaction("slot").force[-1], normal, atol=1e-8)


def test_bushing_mount_modes_and_a_scene():
    # A block on a planar bushing 0.2 m from its centre, with a coupled 3 x 3 stiffness: small
    # vibrations follow the modes of (A^T K A) phi = w^2 M phi, A the map from the block's
    # motion (x, y, phi) to the bushing's displacement (here A = [[1, 0, -0.2 sin 0], [0, 1,
    # 0.2], [0, 0, 1]] with the bushing on the block's x axis).
    covers("bushing")
    rng = np.random.default_rng(4)
    b = rng.uniform(-1, 1, (3, 3))
    root = np.sqrt([2e4, 1e4, 200.0])
    stiffness = root[:, None] * (0.5 * np.eye(3) + b @ b.T / 3) * root[None, :]
    a = np.array([[1.0, 0, 0], [0, 1, 0.2], [0, 0, 1]])
    mass = np.array([1.5, 1.5, 0.02])
    w2, shapes = np.linalg.eigh(a.T @ stiffness @ a / np.sqrt(np.outer(mass, mass)))
    for mode in range(3):
        shape = shapes[:, mode] / np.sqrt(mass)
        shape *= 1e-6 / np.abs(shape).max()
        m = odyn.PlanarModel()
        m.add_body(name="block", mass=1.5, inertia=0.02, position=shape[:2], angle=shape[2])
        m.add_bushing("mount", "ground", on_a=odyn.frame([0.2, 0]), body_b="block",
                      on_b=odyn.frame([0.2, 0]), stiffness=stiffness)
        omega = np.sqrt(w2[mode])
        r = odyn.simulate(m, t_end=3 * np.pi / omega, output_interval=0.1 / omega,
                          integrator="dop853", rtol=1e-12, atol=1e-14)
        block = r.body("block")
        motion = np.c_[block.position, block.angle]
        np.testing.assert_allclose(motion, np.outer(np.cos(omega * r.t), shape), atol=1e-10)

    # From a scene file: a preloaded, damped vertical mount under gravity settles where the
    # spring, the preload and the weight balance: y = (preload - m g) / k.
    scene = odyn.loads("""{
        "space": "planar",
        "bodies": [{"name": "block", "mass": 2, "inertia": 0.1}],
        "forces": [{"type": "bushing", "name": "mount", "body_a": "ground", "body_b": "block",
                    "stiffness": [1e4, 1e4, 100], "damping": [50, 50, 1],
                    "preload": [0, 5, 0]},
                   {"type": "gravity", "name": "g", "acceleration": [0, -9.81]}],
        "analysis": {"t_end": 3, "output_interval": 0.5}
    }""")
    result = scene.simulate()
    assert result.body("block").position[-1] == pytest.approx([0, (5 - 2 * G) / 1e4], abs=1e-9)


def test_contacts_are_covered_by_their_own_tests():
    covers("circle_line", "circle_circle", "rectangle_line", "capsule_line")  # test_contact.py


def test_stops_are_covered_by_their_own_tests():
    covers("revolute_limit", "translational_limit")  # tests/python/test_limits.py


def test_gears_are_covered_by_their_own_tests():
    covers("gear", "rack_pinion", "coupler")  # tests/python/test_gears.py


def test_joint_friction_is_covered_by_its_own_tests():
    covers("joint_friction")  # tests/python/test_joint_friction.py: closed forms


def test_user_constraint_is_covered_by_its_own_tests():
    covers("user_constraint")  # tests/python/test_user_constraint.py: a slider on a sine


def test_every_planar_element_type_is_tested():
    assert set(odyn.planar_element_types) == TESTED
    assert set(odyn.PlanarModel().element_types) == TESTED


def test_python_frame_view_of_a_planar_body():
    seen = []

    def look(t, b):
        if not seen:
            seen.append((b.position.copy(), b.angle, b.rotation.copy(), b.linear_velocity.copy(),
                         b.angular_velocity))
        return (0.0, 0.0, 0.0)
    m = odyn.PlanarModel()
    m.add_body(name="b", mass=1.0, inertia=1.0, position=[1, 2], angle=0.3,
               linear_velocity=[3, 4], angular_velocity=5.0)
    m.add_user_force(name="look", bodies=["b"], function=look)
    odyn.simulate(m, t_end=1e-3, step=1e-3, output_interval=1e-3)
    position, angle, rotation, velocity, rate = seen[0]
    np.testing.assert_allclose(position, [1, 2])
    assert angle == pytest.approx(0.3) and rate == pytest.approx(5.0)
    c, s = math.cos(0.3), math.sin(0.3)
    np.testing.assert_allclose(rotation, [[c, -s], [s, c]])
    np.testing.assert_allclose(velocity, [3, 4])


def test_spatial_and_planar_elements_do_not_mix():
    with pytest.raises(odyn.SceneError, match=r"'spherical' is a spatial element; this is a "
                       "planar model"):
        odyn.PlanarModel().add("spherical", name="s", body_a="ground", body_b="ground")
    m = odyn.PlanarModel()
    with pytest.raises(odyn.SceneError, match=r"body 'b'\.inertia: expected a number"):
        m.add_body(name="b", mass=1.0, inertia=[1, 1, 1])
    m.add_body(name="b", mass=1.0, inertia=1.0)
    with pytest.raises(odyn.SceneError, match=r"gravity 'g'\.acceleration: expected a list of 2"):
        m.add_gravity(name="g", acceleration=[0, 0, -9.81])
    with pytest.raises(odyn.SceneError, match=r"on_a\.axis: zero-length vector.*leave 'axis' out"):
        m.add_revolute(name="p", body_a="ground", on_a=odyn.frame([0, 0], [0, 0]), body_b="b")
    with pytest.raises(odyn.SceneError, match=r"body 'c'\.inertia: expected a number >= 0"):
        odyn.PlanarModel().add_body(name="c", mass=1.0, inertia=-1.0)


# --- scenes -------------------------------------------------------------------------------------

@pytest.fixture()
def planar_dict():
    with open(PLANAR_SCENE) as f:
        return json.load(f)


def test_planar_scene_round_trip(tmp_path):
    scene = odyn.load(PLANAR_SCENE)
    assert scene.model.space == "planar" and scene.model.num_equations == 8
    path = tmp_path / "again.json"
    odyn.save(scene, path)
    again = odyn.load(path)
    assert again.to_dict() == scene.to_dict() and again.to_dict()["space"] == "planar"
    a, b = scene.simulate(t_end=0.02), again.simulate(t_end=0.02)
    np.testing.assert_array_equal(a.q, b.q)
    table = scene.columns(a)
    assert list(table) == ["t", "theta", "omega", "z_piston", "R_z", "phi_norm", "phid_norm"]


def test_a_planar_model_built_in_python_saves_every_scene_element(tmp_path):
    m = odyn.PlanarModel()
    m.add_body(name="a", mass=1.0, inertia=0.1, position=[0, 1], angle=0.2,
               velocity_given=[True, True, True])
    m.add_body(name="b", mass=2.0, inertia=0.2, position=[1, 1])
    m.add_revolute(name="r", body_a="ground", on_a=odyn.frame([0, 1], [1, 0]), body_b="a")
    m.add_distance(name="d", body_a="a", body_b="b", length=1.0)
    m.add_revolute_driver(name="motor", joint="r", motion=odyn.harmonic(0.1, 2.0))
    m.add_gravity(name="g", acceleration=[0, -9.81])
    m.add_point_force(name="f", body="b", point=[0.1, 0], force=[1, 2], axes="body")
    m.add_point_torque(name="tq", body="b", torque=0.5)
    m.add_tsda(name="s", body_a="ground", point_a=[2, 1], body_b="b", stiffness=10.0,
               damping=0.5, free_length=0.8)
    m.add_rsda(name="rs", body_a="a", body_b="b", stiffness=1.0)
    path = tmp_path / "m.json"
    odyn.save(m, path)
    again = odyn.load(path)
    assert again.model.space == "planar"
    assert again.model.element_names == m.element_names
    assert again.model.body("a") == m.body("a") and again.model.element("r") == m.element("r")
    r1 = odyn.simulate(m, t_end=0.2, step=1e-3, output_interval=0.1)
    r2 = again.simulate(t_end=0.2, step=1e-3, output_interval=0.1)
    np.testing.assert_array_equal(r1.q, r2.q)


def broken(d, path, value):
    target = d
    for key in path[:-1]:
        target = target[key]
    if value is None:
        del target[path[-1]]
    else:
        target[path[-1]] = value
    return d


CASES = [
    ("unknown space", ["space"], "curved", r"^space: expected one of spatial, planar"),
    ("spatial inertia", ["bodies", 0, "inertia"], [1.5, 1.3, 0.8],
     r"bodies\[0\]\.inertia: expected a number"),
    ("3-vector position", ["bodies", 1, "position"], [0, 0, 0.11],
     r"bodies\[1\]\.position: expected a list of 2 numbers"),
    ("orientation in the plane", ["bodies", 2, "orientation"], [1, 0, 0, 0],
     r"bodies\[2\]\.orientation: unknown key; expected one of name, mass, inertia, position, "
     "angle"),
    ("zero axis", ["joints", 3, "on_a", "axis"], [0, 0],
     r"joints\[3\]\.on_a\.axis: zero-length vector"),
    ("3-vector point", ["joints", 1, "on_a", "point"], [0, 0, 0.04],
     r"joints\[1\]\.on_a\.point: expected a list of 2 numbers"),
    ("reference in the plane", ["joints", 0, "on_a"], {"reference": [1, 0]},
     r"joints\[0\]\.on_a\.reference: unknown key; expected one of point, axis"),
    ("spatial joint", ["joints", 1, "type"], "spherical",
     r"joints\[1\]\.type: unknown joint type 'spherical' \('spherical' is a spatial joint; "
     "this scene's space is planar\\)"),
    ("component of a number", ["outputs", 1, "component"], "x",
     r"outputs\[1\]\.component: a planar angular_velocity is a number; leave 'component' out"),
    ("z in the plane", ["outputs", 2, "component"], "z",
     r"outputs\[2\]\.component: expected one of x, y"),
    ("planar rsda has no state", ["outputs", 0, "state"], "load",
     r"outputs\[0\]\.state: no stateful force \(engine_gas_force\) named 'load'"),
]


@pytest.mark.parametrize("what, path, value, message", CASES, ids=[c[0] for c in CASES])
def test_malformed_planar_scene_names_the_place(planar_dict, what, path, value, message):
    with pytest.raises(odyn.SceneError, match=message):
        odyn.loads(json.dumps(broken(planar_dict, path, value)))


def test_gif_of_a_planar_mechanism(tmp_path):
    pytest.importorskip("matplotlib")
    from PIL import Image
    import odyn.plot
    scene = odyn.load(PLANAR_SCENE)
    result = scene.simulate(t_end=0.02)
    odyn.plot.animate(result, scene.model, str(tmp_path / "a.gif"), frames=4)
    with Image.open(tmp_path / "a.gif") as gif:
        assert gif.n_frames == 4


def test_planar_engine_in_joint_coordinates():
    """coordinates="joint" on a planar model: the crank, rod and piston angles carry the
    bodies and the cylinder closes the loop. The same poses and reactions as absolute
    coordinates (both converged), with dop853 and with generalized-alpha at second order."""
    scene = odyn.load(PLANAR_SCENE)
    settings = dict(t_end=0.1, integrator="dop853", rtol=1e-11, atol=1e-11)
    joint = scene.simulate(coordinates="joint", **settings)
    absolute = scene.simulate(**settings)
    for name in ("crank", "rod", "piston"):
        np.testing.assert_allclose(joint.body(name).position, absolute.body(name).position,
                                   atol=1e-10)
        np.testing.assert_allclose(joint.body(name).angle, absolute.body(name).angle, atol=1e-9)
    for name in ("bearing", "crank pin", "piston pin", "cylinder"):
        reference = absolute.reaction(name).force
        np.testing.assert_allclose(joint.reaction(name).force, reference,
                                   atol=1e-7 * np.max(np.abs(reference)))
    assert np.max(joint.phi_norm) < 1e-11
    crank = absolute.body("crank").angle
    errors = [np.max(np.abs(scene.simulate(t_end=0.1, step=step, coordinates="joint")
                            .body("crank").angle - crank)) for step in (2e-4, 1e-4)]
    assert 3.5 < errors[0] / errors[1] < 4.5, errors


def parallelogram_chain(n, angle=0.5, r=0.15, d=0.4, crank_mass=0.5, coupler_mass=1.2):
    """n parallelogram four-bars in a row (examples/parallelogram_chain_model.hpp): n + 1
    cranks hinged to the ground at (i d, 0), n couplers joining their tips, at rest."""
    m = odyn.PlanarModel()
    c, s = math.cos(angle), math.sin(angle)
    for i in range(n + 1):
        m.add_body(f"crank {i}", crank_mass, crank_mass * r * r / 12,
                   position=(i * d + r * c / 2, r * s / 2), angle=angle)
        m.add_revolute(f"O{i}", body_a="ground", body_b=f"crank {i}",
                       on_a=odyn.frame([i * d, 0]), on_b=odyn.frame([-r / 2, 0]))
    for j in range(n):
        m.add_body(f"coupler {j}", coupler_mass, coupler_mass * d * d / 12,
                   position=((j + 0.5) * d + r * c, r * s))
        m.add_revolute(f"A{j}", body_a=f"crank {j}", body_b=f"coupler {j}",
                       on_a=odyn.frame([r / 2, 0]), on_b=odyn.frame([-d / 2, 0]))
        m.add_revolute(f"B{j}", body_a=f"coupler {j}", body_b=f"crank {j + 1}",
                       on_a=odyn.frame([d / 2, 0]), on_b=odyn.frame([r / 2, 0]))
    m.add_gravity("gravity", (0, -G))
    return m


def test_a_chain_of_parallelograms_passes_its_singular_configurations_with_the_defaults():
    # Every link on the ground line twice a half period: Phi_q loses n ranks for an instant.
    # The defaults (auto, rtol = atol = 1e-6) and a step alone (generalized-alpha, h = 1e-4)
    # must pass the crossings on the parallelogram branch, the crank following the
    # minimal-coordinate pendulum J theta'' = -G cos theta.
    n, r, d, mc, mp = 6, 0.15, 0.4, 0.5, 1.2
    inertia = (n + 1) * mc * r * r / 3 + n * mp * r * r
    moment = G * ((n + 1) * mc * r / 2 + n * mp * r)
    theta, omega, h, reference = 0.5, 0.0, 1e-4, [0.5]
    for _ in range(100):  # RK4 at 1e-4 s between outputs (error ~1e-10 rad)
        for _ in range(100):
            k1 = (omega, -moment / inertia * math.cos(theta))
            k2 = (omega + h / 2 * k1[1], -moment / inertia * math.cos(theta + h / 2 * k1[0]))
            k3 = (omega + h / 2 * k2[1], -moment / inertia * math.cos(theta + h / 2 * k2[0]))
            k4 = (omega + h * k3[1], -moment / inertia * math.cos(theta + h * k3[0]))
            theta += h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
            omega += h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
        reference.append(theta)
    reference = np.array(reference)
    assert np.sum(np.diff(np.floor(reference / math.pi)) != 0) == 4  # four crossings
    for given in ({}, {"step": 1e-4}):
        result = odyn.simulate(parallelogram_chain(n), t_end=1.0, output_interval=0.01, **given)
        np.testing.assert_allclose(result.body("crank 0").angle, reference, atol=3e-5)
        for i in range(1, n + 1):  # every crank at crank 0's angle: the branch kept
            np.testing.assert_allclose(result.body(f"crank {i}").angle,
                                       result.body("crank 0").angle, atol=1e-8)
        if given:  # generalized-alpha: some steps ended at a crossing's rounding floor
            assert result.summary["integrator"] == "generalized-alpha"
            assert result.statistics.singular_steps > 0 and result.statistics.rejected_steps == 0
        else:
            assert result.summary["integrator"].startswith("dop853")
