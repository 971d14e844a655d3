"""Point masses and slender rods, against closed forms: a point mass on a massless rod runs
round a cone at Omega^2 = g / (L cos alpha) and never turns; a slender rod hung from a
spherical joint runs round a cone at Omega^2 = 3 g / (2 L cos alpha) without spinning about its
axis; a point mass swinging in the plane from 2.5 rad returns after the elliptic-integral
period, also from a scene file; bodies that something turns where they have no inertia are
refused by name."""

import json
import math

import numpy as np
import pytest

import odyn

G = 9.81


def elliptic_k(m):
    """The complete elliptic integral of the first kind K(m), m = k^2, by the AGM."""
    a, b = 1.0, math.sqrt(1.0 - m)
    while abs(a - b) > 1e-16 * a:
        a, b = 0.5 * (a + b), math.sqrt(a * b)
    return math.pi / (2.0 * a)


@pytest.mark.parametrize("coordinates", ["absolute", "joint"])
def test_a_point_mass_on_a_massless_rod_runs_round_a_cone(coordinates):
    length, alpha = 0.8, 0.6
    rate = math.sqrt(G / (length * math.cos(alpha)))
    radius, depth = length * math.sin(alpha), -length * math.cos(alpha)
    m = odyn.Model()
    m.add_body("bob", 0.3, [0, 0, 0], position=[radius, 0, depth],
               linear_velocity=[0, rate * radius, 0])
    m.add_distance("rod", "ground", body_b="bob", length=length)
    m.add_gravity("gravity", [0, 0, -G])
    r = odyn.simulate(m, t_end=3 * 2 * math.pi / rate, output_interval=0.05,
                      integrator="dop853", coordinates=coordinates, rtol=1e-11, atol=1e-13)
    bob = r.body("bob")
    expected = np.column_stack([radius * np.cos(rate * r.t), radius * np.sin(rate * r.t),
                                np.full_like(r.t, depth)])
    np.testing.assert_allclose(bob.position, expected, atol=1e-8)
    assert np.all(bob.angular_velocity == 0.0)


def test_a_slender_rod_hung_from_a_spherical_joint_runs_round_a_cone():
    """The rod lies along its body z; its angular velocity is Omega about the vertical less the
    part along the rod, which a slender rod has no inertia for."""
    length, alpha, mass = 0.6, 0.5, 1.5
    rate = math.sqrt(3 * G / (2 * length * math.cos(alpha)))
    i = mass * length ** 2 / 12
    # Body z points up the rod: z turned about y by -alpha, the rod leaning out towards +x.
    up = np.array([-math.sin(alpha), 0.0, math.cos(alpha)])
    orientation = [math.cos(alpha / 2), 0.0, -math.sin(alpha / 2), 0.0]
    rotation = np.array([[math.cos(alpha), 0, -math.sin(alpha)], [0, 1, 0],
                         [math.sin(alpha), 0, math.cos(alpha)]])
    np.testing.assert_allclose(rotation @ [0, 0, 1], up, atol=1e-15)
    omega = rate * (np.array([0.0, 0.0, 1.0]) - math.cos(alpha) * up)
    centre = -0.5 * length * up
    m = odyn.Model()
    m.add_body("rod", mass, [i, i, 0.0], position=centre, orientation=orientation,
               linear_velocity=rate * np.cross([0, 0, 1], centre),
               angular_velocity=rotation.T @ omega)
    m.add_spherical("socket", "ground", body_b="rod", point_b=[0, 0, 0.5 * length])
    m.add_gravity("gravity", [0, 0, -G])
    r = odyn.simulate(m, t_end=2 * 2 * math.pi / rate, output_interval=0.05,
                      integrator="dop853", rtol=1e-11, atol=1e-13)
    rod = r.body("rod")
    sweep = rate * r.t
    expected = 0.5 * length * np.column_stack([math.sin(alpha) * np.cos(sweep),
                                               math.sin(alpha) * np.sin(sweep),
                                               np.full_like(r.t, -math.cos(alpha))])
    np.testing.assert_allclose(rod.position, expected, atol=1e-8)
    np.testing.assert_allclose(rod.angular_velocity[:, 2], 0.0, atol=1e-9)


def test_a_point_mass_in_the_plane_swings_with_the_elliptic_period(tmp_path):
    """From 2.5 rad at rest, a pendulum of length L returns after 4 sqrt(L / g) K(sin^2(1.25));
    the scene file keeps the zero moment of inertia."""
    length, theta0 = 1.2, 2.5
    period = 4 * math.sqrt(length / G) * elliptic_k(math.sin(theta0 / 2) ** 2)
    m = odyn.PlanarModel()
    start = [length * math.sin(theta0), -length * math.cos(theta0)]
    m.add_body("bob", 0.2, 0.0, position=start)
    m.add_distance("rod", "ground", body_b="bob", length=length)
    m.add_gravity("gravity", [0, -G])
    path = tmp_path / "pendulum.json"
    settings = {"t_end": period, "output_interval": period / 4, "integrator": "dop853",
                "rtol": 1e-11, "atol": 1e-13}
    odyn.save(odyn.Scene(m, settings), str(path))
    for r in (odyn.simulate(m, **settings), odyn.load(str(path)).simulate()):
        bob = r.body("bob")
        np.testing.assert_allclose(bob.position[-1], start, atol=1e-8)
        np.testing.assert_allclose(bob.position[2], [-start[0], start[1]], atol=1e-8)
        assert np.all(bob.angle == 0.0)


def test_bodies_that_something_turns_where_they_have_no_inertia_are_refused():
    m = odyn.Model()
    m.add_body("arm", 1.0, [0.1, 0.1, 0.01], position=[0.5, 0, 0])
    m.add_body("bob", 0.5, [0, 0, 0], position=[1, 0, 0])
    m.add_revolute("hinge", "ground", on_a={"axis": [0, 1, 0]}, body_b="arm",
                   on_b={"point": [-0.5, 0, 0], "axis": [0, 1, 0]})
    m.add_fixed("weld", "arm", on_a={"point": [0.5, 0, 0]}, body_b="bob")
    m.add_gravity("gravity", [0, 0, -G])
    with pytest.raises(odyn.ModelError, match="bob: a point mass has no inertia to turn with.*"
                       "point joints"):
        odyn.simulate(m, t_end=0.5, output_interval=0.01, integrator="dop853")
    with pytest.raises(odyn.ModelError, match="rod: a slender rod has no inertia to spin about "
                       "its axis"):
        m.add_body("rod", 1.0, [0.1, 0.1, 0.0], angular_velocity=[0, 0.3, 2.0])
    with pytest.raises(odyn.ModelError, match="dot: a point mass has no inertia"):
        odyn.PlanarModel().add_body("dot", 1.0, 0.0, angular_velocity=1.0)
    with pytest.raises(odyn.ModelError, match="plate: principal moments .* violate the "
                       "triangle inequality"):
        m.add_body("plate", 1.0, [1.0, 2.0, 0.0])


# --- composite bodies ---------------------------------------------------------------------------
# A pendulum of a slender rod (1.2 kg, 0.8 m) with a ball (2 kg, radius 0.1 m) at its end, the
# parts frame's origin at the rod's top. By hand: mass 3.2 kg, centre 0.65 m down, inertia
# about the centre 0.139 (rod) + 0.053 (ball) = 0.192 kg m^2 across, the ball's 0.008 along.
ROD, BALL, LENGTH, RADIUS = 1.2, 2.0, 0.8, 0.1


def pendulum_parts(space):
    if space == "planar":
        return [{"name": "rod", "mass": ROD, "inertia": ROD * LENGTH ** 2 / 12,
                 "at": [0, -LENGTH / 2]},
                {"name": "ball", "mass": BALL, "inertia": 0.4 * BALL * RADIUS ** 2,
                 "at": [0, -LENGTH]}]
    i_rod, i_ball = ROD * LENGTH ** 2 / 12, 0.4 * BALL * RADIUS ** 2
    return [{"name": "rod", "mass": ROD, "inertia": [i_rod, i_rod, 0.0],
             "at": [0, 0, -LENGTH / 2]},
            {"name": "ball", "mass": BALL, "inertia": [i_ball] * 3, "at": [0, 0, -LENGTH]}]


def test_a_composite_body_combines_its_parts():
    m = odyn.Model()
    m.add_body("pendulum", parts=pendulum_parts("spatial"))
    body = m.body("pendulum")
    assert body["mass"] == pytest.approx(3.2)
    np.testing.assert_allclose(body["center_of_mass"], [0, 0, -0.65], atol=1e-15)
    np.testing.assert_allclose(body["inertia"], np.diag([0.192, 0.192, 0.008]), atol=1e-15)
    # Points in the parts frame and in a part's own frame, in body coordinates.
    np.testing.assert_allclose(m.at("pendulum", [0, 0, 0]), [0, 0, 0.65], atol=1e-15)
    np.testing.assert_allclose(m.at("pendulum", [0, 0, -0.1], part="ball"), [0, 0, -0.25],
                               atol=1e-15)
    # A part turned a quarter turn about z: its x axis is the frame's y.
    q = [math.cos(math.pi / 4), 0, 0, math.sin(math.pi / 4)]
    m.add_body("bracket", parts=[{"name": "arm", "mass": 1.0, "inertia": [0.1, 0.2, 0.25],
                                  "at": [1, 0, 0], "orientation": q},
                                 {"name": "nut", "mass": 1.0, "inertia": [0, 0, 0]}])
    np.testing.assert_allclose(m.at("bracket", [0.3, 0, 0], part="arm"), [0.5, 0.3, 0],
                               atol=1e-15)
    # The arm's moments 0.1 about y and 0.2 about -x, and the two masses 0.5 m either side.
    np.testing.assert_allclose(m.body("bracket")["inertia"],
                               np.diag([0.2, 0.1 + 0.5, 0.25 + 0.5]), atol=1e-15)
    # Two point masses make a slender rod: no inertia about the line through them.
    m.add_body("dumbbell", parts=[{"name": "left", "mass": 1.0, "inertia": [0, 0, 0],
                                   "at": [-0.5, 0, 0]},
                                  {"name": "right", "mass": 1.0, "inertia": [0, 0, 0],
                                   "at": [0.5, 0, 0]}])
    np.testing.assert_allclose(m.body("dumbbell")["inertia"], np.diag([0, 0.5, 0.5]), atol=0)


@pytest.mark.parametrize("space", ["spatial", "planar"])
def test_a_composite_pendulum_swings_with_the_elliptic_period(space, tmp_path):
    """Hinged at the parts frame's origin and released from 2 rad, it returns after
    4 sqrt(I_p / (M g d)) K(sin^2(1)), I_p = 1.544 kg m^2 about the hinge, d = 0.65 m (also
    from a scene file)."""
    theta0, mass, depth = 2.0, 3.2, 0.65
    pivot_inertia = ROD * LENGTH ** 2 / 3 + 0.4 * BALL * RADIUS ** 2 + BALL * LENGTH ** 2
    period = 4 * math.sqrt(pivot_inertia / (mass * G * depth)) * elliptic_k(
        math.sin(theta0 / 2) ** 2)
    if space == "planar":
        m = odyn.PlanarModel()
        m.add_body("pendulum", parts=pendulum_parts(space), angle=theta0)
        m.add_revolute("hinge", "ground", body_b="pendulum",
                       on_b={"point": m.at("pendulum", [0, 0])})
        m.add_gravity("gravity", [0, -G])
    else:
        m = odyn.Model()
        m.add_body("pendulum", parts=pendulum_parts(space),
                   orientation=[math.cos(theta0 / 2), 0, math.sin(theta0 / 2), 0])
        m.add_revolute("hinge", "ground", on_a={"axis": [0, 1, 0]}, body_b="pendulum",
                       on_b={"point": m.at("pendulum", [0, 0, 0]), "axis": [0, 1, 0]})
        m.add_gravity("gravity", [0, 0, -G])
    path = tmp_path / "pendulum.json"
    settings = {"t_end": period, "output_interval": period / 2, "integrator": "dop853",
                "rtol": 1e-11, "atol": 1e-13}
    odyn.save(odyn.Scene(m, settings), str(path))
    for r in (odyn.simulate(m, **settings), odyn.load(str(path)).simulate()):
        assert not r.assembly["moved_bodies"]  # the centre of mass is where the parts put it
        position = r.body("pendulum").position
        # Half a period on, the centre of mass is at the mirror point; after one, back.
        np.testing.assert_allclose(position[-1], position[0], atol=1e-8)
        mirror = position[0] * ([-1, 1] if space == "planar" else [-1, 1, 1])
        np.testing.assert_allclose(position[1], mirror, atol=1e-8)
        np.testing.assert_allclose(np.linalg.norm(position[0]), depth, rtol=1e-14)


def test_a_composite_body_takes_the_parts_frames_velocity():
    """Given the parts frame's angular velocity about the hinge at its origin, the centre of
    mass moves at omega x c, and the run conserves I_p omega^2 / 2 - M g d cos theta."""
    m = odyn.Model()
    m.add_body("pendulum", parts=pendulum_parts("spatial"), angular_velocity=[0, 2.0, 0])
    # The hinge's point on the pendulum by name: a marker at the parts frame's origin.
    m.add_point("pivot", "pendulum", m.at("pendulum", [0, 0, 0]))
    m.add_revolute("hinge", "ground", on_a={"axis": [0, 1, 0]}, body_b="pendulum",
                   on_b={"point": "pivot", "axis": [0, 1, 0]})
    assert m.element("hinge")["on_b"]["point"] == pytest.approx([0, 0, 0.65])
    m.add_gravity("gravity", [0, 0, -G])
    r = odyn.simulate(m, t_end=1.0, output_interval=0.1, integrator="dop853", rtol=1e-11,
                      atol=1e-13)
    np.testing.assert_allclose(r.body("pendulum").linear_velocity[0], [-2.0 * 0.65, 0, 0],
                               atol=1e-12)
    energy = r.kinetic_energy + r.potential_energy
    np.testing.assert_allclose(energy, 0.5 * 1.544 * 4.0 - 3.2 * G * 0.65, atol=1e-9)


@pytest.mark.parametrize("body, words", [
    ({"mass": 1.0, "parts": [{"name": "a", "mass": 1.0, "inertia": [1, 1, 1]}]},
     "give either mass and inertia or parts"),
    ({"parts": []}, "expected a non-empty list of parts"),
    ({"parts": [{"name": "a", "mass": 1.0, "inertia": [1, 1, 1]},
                {"name": "a", "mass": 1.0, "inertia": [1, 1, 1]}]}, "another part has that name"),
    ({"parts": [{"name": "a", "mass": 1.0, "inertia": [1, -1, 1]}]}, "positive semidefinite"),
    ({"parts": [{"name": "a", "mass": 1.0, "inertia": [1, 1, 3]}]}, "triangle inequality"),
    ({"parts": [{"name": "a", "inertia": [1, 1, 1]}]}, "missing 'mass'"),
    ({"parts": [{"name": "a", "mass": 1.0, "inertia": [1, 1, 1], "offset": [1, 0, 0]}]},
     "unknown key"),
])
def test_bad_parts_are_refused_by_name(body, words):
    with pytest.raises(odyn.SceneError) as error:
        odyn.Model().add_body("wheel", **body)
    assert "wheel" in str(error.value) and words in str(error.value)
    m = odyn.Model()
    m.add_body("wheel", parts=[{"name": "hub", "mass": 1.0, "inertia": [1, 1, 1]}])
    with pytest.raises(odyn.SceneError, match="'wheel' has no part named 'rim'; its parts: hub"):
        m.at("wheel", [0, 0, 0], part="rim")


def test_point_parameters_may_name_a_point_on_their_body(tmp_path):
    """A joint frame's point, a point of a pair and a load's point given by a point's name
    take its coordinates; a point on another body, or no such point, is refused by name. A
    scene file may name points too (they are read before the elements)."""
    m = odyn.Model()
    m.add_body("arm", 1.0, [0.1, 0.1, 0.02], position=[0.5, 0, 0])
    m.add_point("elbow", "arm", [0.5, 0, 0])
    m.add_point("shoulder", "arm", [-0.5, 0, 0])
    m.add_revolute("hinge", "ground", on_a=([0, 0, 0], [0, 1, 0]), body_b="arm",
                   on_b=("shoulder", [0, 1, 0]))
    m.add_point_force("push", "arm", [0, 0, 1.0], point="elbow")
    assert m.element("hinge")["on_b"]["point"] == [-0.5, 0, 0]
    assert m.element("push")["point"] == [0.5, 0, 0]
    with pytest.raises(odyn.SceneError, match=r"tsda 'spring'\.point_a: the point 'elbow' is "
                       "on 'arm', but point_a is a point on body_a, 'ground'"):
        m.add_tsda("spring", "ground", point_a="elbow", body_b="arm", point_b="elbow")
    with pytest.raises(odyn.SceneError, match=r"ball'\.point_b: no point named 'wrist'; points: "
                       "elbow, shoulder"):
        m.add_spherical("ball", "ground", body_b="arm", point_b="wrist")
    scene = {"odyn": 1, "bodies": [{"name": "arm", "mass": 1.0, "inertia": [0.1, 0.1, 0.02],
                                    "position": [0.5, 0, 0]}],
             "points": [{"name": "shoulder", "body": "arm", "at": [-0.5, 0, 0]}],
             "joints": [{"type": "spherical", "name": "ball", "body_a": "ground",
                         "body_b": "arm", "point_b": "shoulder"}]}
    path = tmp_path / "arm.json"
    path.write_text(json.dumps(scene))
    assert odyn.load(str(path)).model.element("ball")["point_b"] == [-0.5, 0, 0]
