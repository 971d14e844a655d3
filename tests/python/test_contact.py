"""Compliant contact (sphere_plane, sphere_sphere and their planar twins circle_line and
circle_circle), against closed forms: the Hunt-Crossley law's restitution from its first
integral, a ball rolling down an incline (5/7 g sin(theta); a disc 2/3) and one sliding on it
(g (sin(theta) - mu cos(theta))), momentum in a collision of two free balls, and a bouncing ball
under the default integrator against a converged dop853 run; bad parameters refused by name.
Boxes and capsules (box_plane, capsule_plane, rectangle_line, capsule_line): a tall box on a
rough slope stands below its tipping angle atan(w / h) and tips over above it, a box settles at
its static sinking (m g / (4 k))^(1/n), and a planar capsule rolls down a slope like a disc
where its end circle touches."""

import json
import math

import numpy as np
import pytest

import odyn

G = 9.81


def exit_speed(d, v_in):
    """The speed at which a mass leaves a contact k delta^n (1 + d delta') entered at v_in with no
    other force: the root v in (0, 1/d) of d v_in - ln(1 + d v_in) = -d v - ln(1 - d v) (the
    law's first integral), by bisection."""
    if d == 0:
        return v_in
    target = d * v_in - math.log1p(d * v_in)
    lo, hi = 0.0, (1.0 - 1e-15) / d
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if -d * mid - math.log1p(-d * mid) < target:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def test_the_first_integral_gives_one_without_dissipation_and_less_with_it():
    assert exit_speed(0.0, 2.0) == 2.0
    assert exit_speed(1e-4, 2.0) == pytest.approx(2.0 * (1 - 2 * 2e-4 / 3), rel=1e-7)
    # Hunt and Crossley's small-dissipation estimate e = 1 - 2 d v_in / 3.
    assert exit_speed(0.01, 1.0) == pytest.approx(1.0 - 2 * 0.01 / 3, rel=1e-4)


@pytest.mark.parametrize("space", ["spatial", "planar"])
@pytest.mark.parametrize("exponent", [1.5, 1.0])
def test_an_impact_leaves_at_the_speed_of_the_laws_first_integral(space, exponent):
    """A ball thrown at a plane (tilted, and on a moving body held by nothing else: the plane's
    body is heavy, the relative motion uses the reduced mass) with no gravity."""
    v_in, d, radius = 1.5, 0.4, 0.05
    m_ball, m_wall = 0.3, 1e3
    if space == "spatial":
        m = odyn.Model()
        normal = np.array([0.0, 0.6, 0.8])
        m.add_body("wall", m_wall, [10.0, 10.0, 10.0])
        m.add_body("ball", m_ball, [0.4 * m_ball * radius ** 2] * 3,
                   position=(radius + 0.002) * normal, linear_velocity=-v_in * normal)
        m.add_sphere_plane("touch", "wall", "ball", radius, normal=normal, stiffness=1e6,
                           exponent=exponent, dissipation=d)
    else:
        m = odyn.PlanarModel()
        normal = np.array([0.6, 0.8])
        m.add_body("wall", m_wall, 10.0)
        m.add_body("ball", m_ball, 0.5 * m_ball * radius ** 2,
                   position=(radius + 0.002) * normal, linear_velocity=-v_in * normal)
        m.add_circle_line("touch", "wall", "ball", radius, normal=normal, stiffness=1e6,
                          exponent=exponent, dissipation=d)
    r = odyn.simulate(m, t_end=0.05, output_interval=0.001, integrator="dop853", rtol=1e-11,
                      atol=1e-13)
    ball, wall = r.body("ball"), r.body("wall")
    relative = (ball.linear_velocity[-1] - wall.linear_velocity[-1]) @ normal
    assert relative == pytest.approx(exit_speed(d, v_in), rel=1e-7)
    # Momentum is kept, and the ball is out of contact at the end.
    momentum = m_ball * ball.linear_velocity + m_wall * wall.linear_velocity
    np.testing.assert_allclose(momentum, np.tile(momentum[0], (len(r.t), 1)), atol=1e-9)
    gap = r.output("touch", "gap")
    assert gap[-1] > 0 and gap.min() < 0
    assert r.output("touch", "normal_force")[-1] == 0
    # No spin: the force passes through the ball's centre, without friction.
    np.testing.assert_allclose(ball.angular_velocity, 0, atol=1e-12)


@pytest.mark.parametrize("restitution", [0.9, 0.5])
def test_the_dissipation_for_a_restitution_gives_that_restitution_in_a_run(restitution):
    """odyn.hunt_crossley_dissipation inverts the first integral: a run with its d bounces back
    at that restitution (and Hunt and Crossley's 3 (1 - e) / (2 v) is its limit near e = 1)."""
    v_in = 2.0
    d = odyn.hunt_crossley_dissipation(restitution, v_in)
    assert exit_speed(d, v_in) == pytest.approx(restitution * v_in, rel=1e-12)
    m = odyn.Model()
    m.add_body("ball", 1.0, [1e-3] * 3, position=[0, 0, 0.101], linear_velocity=[0, 0, -v_in])
    m.add_sphere_plane("floor", "ground", "ball", 0.1, stiffness=1e5, exponent=1.0,
                       dissipation=d)
    r = odyn.simulate(m, t_end=0.05, output_interval=0.05, integrator="dop853", rtol=1e-11,
                      atol=1e-13)
    assert r.body("ball").linear_velocity[-1, 2] == pytest.approx(restitution * v_in, rel=1e-7)
    assert odyn.hunt_crossley_dissipation(0.999, v_in) == pytest.approx(
        3 * 0.001 / (2 * v_in), rel=2e-3)
    assert odyn.hunt_crossley_dissipation(1.0, v_in) == 0.0
    for bad in [(0.0, 1.0), (1.5, 1.0), (0.5, 0.0), (0.5, math.inf)]:
        with pytest.raises(ValueError):
            odyn.hunt_crossley_dissipation(*bad)


@pytest.mark.parametrize("space", ["spatial", "planar"])
def test_two_free_balls_collide_with_the_reduced_mass_restitution_and_keep_momentum(space):
    """Head-on: the relative speed after the contact follows the first integral (the relative
    motion obeys it with the reduced mass), and the momentum is kept."""
    v, d, r1, r2, m1, m2 = 2.0, 0.2, 0.1, 0.06, 1.0, 0.4
    if space == "spatial":
        m = odyn.Model()
        m.add_body("a", m1, [0.4 * m1 * r1 ** 2] * 3, linear_velocity=[v, 0, 0])
        m.add_body("b", m2, [0.4 * m2 * r2 ** 2] * 3, position=[r1 + r2 + 0.01, 0.0, 0.0])
        m.add_sphere_sphere("hit", "a", "b", r2, radius_a=r1, stiffness=5e6, dissipation=d)
    else:
        m = odyn.PlanarModel()
        m.add_body("a", m1, 0.5 * m1 * r1 ** 2, linear_velocity=[v, 0])
        m.add_body("b", m2, 0.5 * m2 * r2 ** 2, position=[r1 + r2 + 0.01, 0.0])
        m.add_circle_circle("hit", "a", "b", r2, radius_a=r1, stiffness=5e6, dissipation=d)
    r = odyn.simulate(m, t_end=0.03, output_interval=0.001, integrator="dop853", rtol=1e-11,
                      atol=1e-13)
    va, vb = r.body("a").linear_velocity[-1], r.body("b").linear_velocity[-1]
    assert vb[0] - va[0] == pytest.approx(exit_speed(d, v), rel=1e-7)
    np.testing.assert_allclose(m1 * va + m2 * vb, [m1 * v] + [0] * (len(va) - 1), atol=1e-10)
    assert r.output("hit", "gap")[-1] > 0


def static_depth(weight, k, n=1.5):
    """The penetration at which the contact law carries `weight` at rest."""
    return (weight / k) ** (1.0 / n)


@pytest.mark.parametrize("space", ["spatial", "planar"])
def test_a_ball_rolls_down_an_incline_at_its_analytic_acceleration(space):
    """Rolling without slip (mu above (2/7) tan(theta)), once the regularized friction has
    reached its steady creep, the centre accelerates at g sin(theta) / (1 + I / (m r_c^2)):
    5/7 g sin(theta) for a ball and 2/3 for a disc, r_c = r - delta / 2 being the distance from
    the centre to the contact point (the midpoint of the overlap delta, which carries
    m g cos(theta)). The ball starts at that overlap, at rest."""
    theta, radius, mass, k = 0.3, 0.1, 2.0, 1e7
    s, c = math.sin(theta), math.cos(theta)
    depth = static_depth(mass * G * c, k)
    if space == "spatial":
        m = odyn.Model()
        normal = np.array([-s, 0.0, c])
        inertia_ratio = 0.4
        m.add_body("ball", mass, [inertia_ratio * mass * radius ** 2] * 3,
                   position=(radius - depth) * normal)
        m.add_gravity("g", [0, 0, -G])
        m.add_sphere_plane("floor", "ground", "ball", radius, normal=normal, stiffness=k,
                           dissipation=2.0, friction=0.6, slip_speed=1e-4)
        downhill = np.array([c, 0.0, s])
    else:
        m = odyn.PlanarModel()
        normal = np.array([-s, c])
        inertia_ratio = 0.5
        m.add_body("ball", mass, inertia_ratio * mass * radius ** 2,
                   position=(radius - depth) * normal)
        m.add_gravity("g", [0, -G])
        m.add_circle_line("floor", "ground", "ball", radius, normal=normal, stiffness=k,
                          dissipation=2.0, friction=0.6, slip_speed=1e-4)
        downhill = np.array([c, s])
    r = odyn.simulate(m, t_end=1.0, output_interval=0.01, integrator="dop853", rtol=1e-10,
                      atol=1e-12)
    velocity = r.body("ball").linear_velocity @ -downhill
    late = r.t >= 0.5
    slope = np.polyfit(r.t[late], velocity[late], 1)[0]
    lever = radius - 0.5 * depth
    assert slope == pytest.approx(G * s / (1 + inertia_ratio * (radius / lever) ** 2), rel=1e-6)
    # The normal force carries the weight across the slope; the contact point barely slips.
    np.testing.assert_allclose(r.output("floor", "normal_force")[late], mass * G * c, rtol=1e-6)
    assert np.all(r.output("floor", "slip")[late] < 1e-4)


def test_a_ball_slides_down_a_steep_incline_against_coulomb_friction():
    """mu below (2/7) tan(theta): the ball slips all the way, its centre at
    g (sin(theta) - mu cos(theta)) and its spin at mu m g cos(theta) r_c / I."""
    theta, radius, mass, mu, k = 0.6, 0.1, 1.0, 0.1, 1e7
    s, c = math.sin(theta), math.cos(theta)
    depth = static_depth(mass * G * c, k)
    m = odyn.Model()
    normal = np.array([0.0, -s, c])
    inertia = 0.4 * mass * radius ** 2
    m.add_body("ball", mass, [inertia] * 3, position=(radius - depth) * normal)
    m.add_gravity("g", [0, 0, -G])
    m.add_sphere_plane("floor", "ground", "ball", radius, normal=normal, stiffness=k,
                       dissipation=2.0, friction=mu, slip_speed=1e-4)
    r = odyn.simulate(m, t_end=0.5, output_interval=0.01, integrator="dop853", rtol=1e-10,
                      atol=1e-12)
    ball = r.body("ball")
    late = r.t >= 0.2
    speed = -ball.linear_velocity @ np.array([0.0, c, s])  # down the slope
    spin = ball.angular_velocity[:, 0]  # about x (body axes: the ball turns about x only)
    assert np.polyfit(r.t[late], speed[late], 1)[0] == pytest.approx(G * (s - mu * c), rel=1e-6)
    lever = radius - 0.5 * depth
    assert np.polyfit(r.t[late], spin[late], 1)[0] == pytest.approx(
        mu * mass * G * c * lever / inertia, rel=1e-6)
    np.testing.assert_allclose(r.output("floor", "friction_force")[late], mu * mass * G * c,
                               rtol=1e-6)


def bouncing_ball():
    m = odyn.Model()
    m.add_body("ball", 0.5, [0.4 * 0.5 * 0.05 ** 2] * 3, position=[0, 0, 0.3],
               linear_velocity=[0.5, 0, 0])
    m.add_gravity("g", [0, 0, -G])
    m.add_sphere_plane("floor", "ground", "ball", 0.05, stiffness=1e6, dissipation=0.5,
                       friction=0.3)
    return m


def test_a_bouncing_ball_runs_with_the_default_integrator_as_dop853_does():
    """With the defaults (auto: dop853, then bdf where the friction's stick region makes the
    run stiff, then dop853 again, in joint coordinates) and with generalized-alpha, the ball's
    path agrees with a converged dop853 run; the energy only falls. (Auto once handed over at
    the last output's state instead of the last step's: 1e-3 m off at outputs every 1 ms.)"""
    reference = odyn.simulate(bouncing_ball(), t_end=1.0, output_interval=0.001,
                              integrator="dop853", rtol=1e-11, atol=1e-12)
    auto = odyn.simulate(bouncing_ball(), t_end=1.0, output_interval=0.001)
    assert auto.summary["coordinates"] == "joint"
    assert "then bdf" in auto.summary["integrator"]
    # Where the sliding contact comes to stick, Newton converges only linearly (docs/contact.md):
    # at h = 1e-4 s it needs 12 iterations, beyond the default 8.
    alpha = odyn.simulate(bouncing_ball(), t_end=1.0, output_interval=0.001,
                          integrator="generalized-alpha", step=1e-4, max_iterations=20)
    for r, tolerance in [(auto, 1e-5), (alpha, 2e-4)]:
        np.testing.assert_allclose(r.body("ball").position, reference.body("ball").position,
                                   atol=tolerance)
    # The ball bounced (several contacts) and lost energy in each.
    touching = reference.output("floor", "gap") < 0
    assert np.count_nonzero(np.diff(touching.astype(int)) == 1) >= 2
    assert np.all(np.diff(reference.total_energy) < 1e-8)
    assert reference.total_energy[-1] < 0.9 * reference.total_energy[0]


def test_contact_parameters_are_checked_by_name():
    def model():
        m = odyn.Model()
        m.add_body("ball", 1.0, [1e-3] * 3, position=[0, 0, 1])
        return m

    cases = [
        (dict(radius_b=0.0, stiffness=1e6), "radius_b"),
        (dict(radius_b=0.1, stiffness=-1.0), "stiffness"),
        (dict(radius_b=0.1, stiffness=1e6, exponent=0.5), "exponent"),
        (dict(radius_b=0.1, stiffness=1e6, normal=[0, 0, 0]), "normal"),
        (dict(radius_b=0.1, stiffness=1e6, friction=-0.1), "friction"),
        (dict(radius_b=0.1, stiffness=1e6, slip_speed=0), "slip_speed"),
        (dict(radius_b=0.1, stiffness=1e6, radius=0.1), "radius"),
    ]
    for kwargs, word in cases:
        with pytest.raises((odyn.ModelError, TypeError, ValueError)) as error:
            model().add_sphere_plane("c", "ground", "ball", **kwargs)
        assert word in str(error.value)
    with pytest.raises(odyn.ModelError, match="different bodies"):
        model().add_sphere_sphere("c", "ball", "ball", 0.1, radius_a=0.1, stiffness=1e6)


def test_a_contact_in_a_scene_file_with_its_touchdown_as_an_event(tmp_path):
    """The ball's first touchdown, an event on the contact's gap, at the free fall's time."""
    m = bouncing_ball()
    m.add_event("touch", output=("floor", "gap"), direction="falling")
    path = tmp_path / "ball.json"
    odyn.save(odyn.Scene(m, {"t_end": 0.5, "output_interval": 0.01, "integrator": "dop853",
                             "rtol": 1e-10, "atol": 1e-12}), str(path))
    saved = json.loads(path.read_text())
    (floor,) = [f for f in saved["forces"] if f["name"] == "floor"]
    assert floor["type"] == "sphere_plane" and floor["radius_b"] == 0.05
    r = odyn.load(str(path)).simulate()
    touches = r.event_times("touch")
    assert touches[0] == pytest.approx(math.sqrt(2 * 0.25 / G), abs=1e-9)
    assert len(touches) >= 2
    floor["radius"] = 0.05
    path.write_text(json.dumps(saved))
    with pytest.raises(odyn.SceneError, match="radius"):
        odyn.load(str(path))


@pytest.mark.parametrize("beyond", [-0.04, 0.04])
def test_a_tall_box_on_a_rough_slope_tips_over_beyond_atan_of_its_width_over_its_height(beyond):
    """Statics: a box of half width w and half height h held from sliding (mu > tan(theta))
    tips about its lower edge once its weight's line passes that edge, at tan(theta) = w / h.
    The slope is the plane z = 0 under a gravity tilted by theta along x."""
    w, depth, h, mass, k = 0.1, 0.2, 0.3, 2.0, 1e6
    theta = math.atan(w / h) + beyond
    inertia = mass / 3 * np.array([depth ** 2 + h ** 2, w ** 2 + h ** 2, w ** 2 + depth ** 2])
    m = odyn.Model()
    sinking = mass * G * math.cos(theta) / (4 * k)
    m.add_body("box", mass, inertia, position=[0.0, 0.0, h - sinking])
    m.add_gravity("gravity", [G * math.sin(theta), 0.0, -G * math.cos(theta)])
    m.add_box_plane("slope", "ground", "box", [w, depth, h], stiffness=k, exponent=1.0,
                    dissipation=50.0, friction=0.8)
    r = odyn.simulate(m, t_end=1.0, output_interval=0.01)
    q = r.body("box").orientation
    pitch = 2 * np.arctan2(q[:, 2], q[:, 0])  # about y: the box turns about its edge along y
    points = r.output("slope", "points")
    if beyond < 0:
        assert np.abs(pitch).max() < 1e-3 and points[-1] == 4
        assert r.output("slope", "normal_force")[-1] == pytest.approx(
            mass * G * math.cos(theta), rel=1e-4)
    else:
        assert pitch[-1] > 0.5 and points.min() <= 2


@pytest.mark.parametrize("space", ["spatial", "planar"])
def test_a_box_settles_at_its_static_sinking_on_its_corners(space):
    """Dropped flat from 1 cm with dissipation, it comes to rest on all its corners, sunk by
    (m g / (c k))^(1/n) with c corners; the gap output is minus that."""
    mass, k, n = 3.0, 2e6, 1.5
    if space == "spatial":
        m = odyn.Model()
        m.add_body("box", mass, [0.05, 0.06, 0.07], position=[0.0, 0.0, 0.11])
        m.add_gravity("gravity", [0.0, 0.0, -G])
        m.add_box_plane("floor", "ground", "box", [0.2, 0.15, 0.1], stiffness=k, exponent=n,
                        dissipation=20.0, friction=0.5)
        corners = 4
    else:
        m = odyn.PlanarModel()
        m.add_body("box", mass, 0.05, position=[0.0, 0.11])
        m.add_gravity("gravity", [0.0, -G])
        m.add_rectangle_line("floor", "ground", "box", [0.2, 0.1], stiffness=k, exponent=n,
                             dissipation=20.0, friction=0.5)
        corners = 2
    r = odyn.simulate(m, t_end=1.5, output_interval=0.5)
    sinking = (mass * G / (corners * k)) ** (1 / n)
    assert r.output("floor", "points")[-1] == corners
    assert r.output("floor", "gap")[-1] == pytest.approx(-sinking, rel=1e-4)
    assert r.output("floor", "normal_force")[-1] == pytest.approx(mass * G, rel=1e-5)


def test_a_capsule_in_a_scene_file_lands_at_the_free_falls_time(tmp_path):
    """A capsule lying level 0.25 m above the floor touches down at sqrt(2 h / g) (an event on
    the element's gap), from a saved scene; a key the capsule does not have is refused."""
    m = odyn.Model()
    m.add_body("rod", 1.0, [0.01, 0.01, 0.002], position=[0.0, 0.0, 0.3])
    m.add_gravity("g", [0, 0, -G])
    m.add_capsule_plane("floor", "ground", "rod", 0.05, half_length=0.2, axis_b=[1, 0, 0],
                        stiffness=1e6, dissipation=0.5)
    m.add_event("touch", output=("floor", "gap"), direction="falling")
    path = tmp_path / "rod.json"
    odyn.save(odyn.Scene(m, {"t_end": 0.4, "output_interval": 0.01, "integrator": "dop853",
                             "rtol": 1e-10, "atol": 1e-12}), str(path))
    saved = json.loads(path.read_text())
    (floor,) = [f for f in saved["forces"] if f["name"] == "floor"]
    assert floor["type"] == "capsule_plane" and floor["half_length"] == 0.2
    r = odyn.load(str(path)).simulate()
    assert r.event_times("touch")[0] == pytest.approx(math.sqrt(2 * 0.25 / G), abs=1e-9)
    assert r.output("floor", "points").max() == 2
    floor["half_extents"] = [0.1, 0.1, 0.1]
    path.write_text(json.dumps(saved))
    with pytest.raises(odyn.SceneError, match="half_extents"):
        odyn.load(str(path))


def test_bad_box_and_capsule_parameters_are_refused_by_name():
    m = odyn.Model()
    m.add_body("box", 1.0, [0.1, 0.1, 0.1])
    with pytest.raises(odyn.ModelError, match="lid: half_extents"):
        m.add_box_plane("lid", "ground", "box", [0.1, -0.1, 0.1], stiffness=1e6)
    with pytest.raises(odyn.ModelError, match="'rod'.half_length: expected a positive number"):
        m.add_capsule_plane("rod", "ground", "box", 0.05, half_length=0.0, stiffness=1e6)
    with pytest.raises(odyn.ModelError, match="rod: axis_b"):
        m.add_capsule_plane("rod", "ground", "box", 0.05, half_length=0.2, axis_b=[0, 0, 0],
                            stiffness=1e6)
    with pytest.raises(TypeError):
        m.add_box_plane("lid", "ground", "box", [0.1, 0.1, 0.1], stiffness=1e6, radius_b=0.1)
