"""Static equilibrium and natural modes from Python (odyn.statics, odyn.modes) against closed
forms, in absolute and joint coordinates."""

import math

import numpy as np
import pytest

import odyn

G = 9.81


def spring_pendulum(stiffness, rest, start):
    """A 1 m, 1 kg bar hinged at one end, its angle from hanging down, held by a torsional
    spring whose rest is at `rest` (its angle is zero at the start pose)."""
    m = odyn.PlanarModel()
    m.add_body(name="bar", mass=1.0, inertia=1.0 / 12,
               position=[0.5 * math.sin(start), -0.5 * math.cos(start)], angle=start)
    m.add_revolute(name="pivot", body_a="ground", body_b="bar", on_b=odyn.frame([0, 0.5]))
    m.add_rsda(name="spring", body_a="ground", body_b="bar", stiffness=stiffness,
               free_angle=rest - start)
    m.add_gravity(name="gravity", acceleration=[0, -G])
    return m


def bisect(f, lo, hi):
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if f(mid) * f(lo) > 0 else (lo, mid)
    return 0.5 * (lo + hi)


@pytest.mark.parametrize("coordinates", ["absolute", "joint"])
def test_spring_pendulum_settles_where_the_moments_balance(coordinates):
    k, rest = 10.0, 1.2
    theta = bisect(lambda x: k * (x - rest) + G * 0.5 * math.sin(x), 0.0, rest)
    r = odyn.statics(spring_pendulum(k, rest, 0.3), coordinates=coordinates)
    assert len(r) == 1 and r.statics["method"] == "newton"
    assert r.body("bar").angle[0] == pytest.approx(theta, abs=1e-12)
    assert r.statics["constraint_residual"] <= 1e-12 and r.statics["force_residual"] <= 1e-12
    # The hinge carries the weight (the spring is a pure torque).
    np.testing.assert_allclose(r.reaction("pivot").force[0], [0, G], atol=1e-11)
    assert r.statics["stable"]
    omega2 = (k + G * 0.5 * math.cos(theta)) / (1.0 / 3)
    assert r.statics["squared_frequencies"] == pytest.approx([omega2], rel=1e-9)
    joint_name = "pivot.angle" if coordinates == "joint" else "bar.angle"
    assert joint_name in r.statics["least_stiff"]
    assert np.all(r.v == 0.0)


def test_inverted_pendulum_with_a_soft_spring_is_flagged_unstable():
    r = odyn.statics(spring_pendulum(3.0, math.pi, math.pi - 0.05))
    assert r.body("bar").angle[0] == pytest.approx(math.pi, abs=1e-12)
    assert not r.statics["stable"]
    assert r.statics["squared_frequencies"][0] == pytest.approx((3.0 - G * 0.5) * 3, rel=1e-9)


def test_a_free_motion_under_load_is_refused_by_name():
    m = odyn.PlanarModel()
    m.add_body(name="block", mass=2.0, inertia=0.1)
    m.add_translational(name="slide", body_a="ground", on_a=odyn.frame([0, 0], [0, 1]),
                        body_b="block")
    m.add_gravity(name="gravity", acceleration=[0, -G])
    with pytest.raises(odyn.SolverError, match="free motion along slide.travel"):
        odyn.statics(m, coordinates="joint")
    with pytest.raises(odyn.SceneError, match="coordinates: expected one of absolute, joint"):
        odyn.statics(m, coordinates="auto")
    with pytest.raises(odyn.SceneError, match="max_iterations"):
        odyn.statics(m, max_iterations=0)


M1, L1, M2, L2 = 1.0, 1.0, 0.6, 0.8  # the double pendulum's bars: masses, lengths


def double_pendulum():
    """Two uniform bars hanging straight down from a hinge at the origin."""
    d1, d2 = L1 / 2, L2 / 2
    m = odyn.PlanarModel()
    m.add_body(name="upper", mass=M1, inertia=M1 * L1 ** 2 / 12, position=[0, -d1])
    m.add_body(name="lower", mass=M2, inertia=M2 * L2 ** 2 / 12, position=[0, -L1 - d2])
    m.add_revolute(name="shoulder", body_a="ground", body_b="upper", on_b=odyn.frame([0, d1]))
    m.add_revolute(name="elbow", body_a="upper", on_a=odyn.frame([0, -d1]), body_b="lower",
                   on_b=odyn.frame([0, d2]))
    m.add_gravity(name="gravity", acceleration=[0, -G])
    return m


@pytest.mark.parametrize("coordinates", ["absolute", "joint"])
def test_double_pendulum_frequencies(coordinates):
    """Two uniform bars hanging down: det(K - w^2 M) = 0 in the bars' angles."""
    m1, l1, m2, l2 = M1, L1, M2, L2
    d1, d2, i1, i2 = l1 / 2, l2 / 2, m1 * l1 ** 2 / 12, m2 * l2 ** 2 / 12
    mass = np.array([[i1 + m1 * d1 ** 2 + m2 * l1 ** 2, m2 * l1 * d2],
                     [m2 * l1 * d2, i2 + m2 * d2 ** 2]])
    stiffness = np.diag([(m1 * d1 + m2 * l1) * G, m2 * d2 * G])
    omega2 = np.sort(np.linalg.eigvals(np.linalg.solve(mass, stiffness)).real)
    expected = np.sqrt(omega2) / (2 * math.pi)

    modes = odyn.modes(double_pendulum(), coordinates=coordinates)
    assert len(modes) == 2
    np.testing.assert_allclose(modes.frequencies, expected, rtol=1e-10)
    np.testing.assert_allclose(modes.natural_frequencies, expected, rtol=1e-10)
    np.testing.assert_allclose(modes.damping_ratios, 0.0, atol=1e-10)
    assert modes.shapes.shape == (len(modes.coordinates), 2)
    assert modes.state_matrix.shape == (4, 4) and modes.mass.shape == (2, 2)
    # The lower mode swings both bars the same way.
    if coordinates == "joint":
        shoulder = modes.shape(0, "shoulder.angle")
        assert shoulder * (shoulder + modes.shape(0, "elbow.angle")) > 0
    else:
        assert modes.shape(0, "upper.angle") * modes.shape(0, "lower.angle") > 0
    with pytest.raises(odyn.SceneError, match="no coordinate 'wrist.angle'"):
        modes.shape(0, "wrist.angle")
    assert modes.equilibrium.body("lower").position[0] == pytest.approx([0, -l1 - d2], abs=1e-12)


def test_damped_oscillator():
    """A block on a slide between two spring-dampers: zeta = c_total / (2 sqrt(k_total m))."""
    mass, k, c = 2.0, 50.0, 1.5
    m = odyn.PlanarModel()
    m.add_body(name="block", mass=mass, inertia=0.01, position=[1, 0])
    m.add_translational(name="slide", body_a="ground", on_a=odyn.frame([1, 0], [1, 0]),
                        body_b="block")
    m.add_tsda(name="left", body_a="ground", point_a=[0, 0], body_b="block", point_b=[0, 0],
               stiffness=k, damping=c, free_length=1.0)
    m.add_tsda(name="right", body_a="block", point_a=[0, 0], body_b="ground", point_b=[2, 0],
               stiffness=k, damping=c, free_length=1.0)
    modes = odyn.modes(m, coordinates="joint", find_equilibrium=False)
    wn, zeta = math.sqrt(2 * k / mass), 2 * c / (2 * math.sqrt(2 * k * mass))
    assert modes.natural_frequencies[0] == pytest.approx(wn / (2 * math.pi), rel=1e-10)
    assert modes.damping_ratios[0] == pytest.approx(zeta, rel=1e-10)
    assert modes.eigenvalues[0].real == pytest.approx(-zeta * wn, rel=1e-10)
    assert modes.coordinates == ["slide.travel"]


def test_a_mode_moves_the_bodies_as_its_joint_coordinates_say(tmp_path):
    """The double pendulum's modes in joint coordinates, mapped to the bars' motions, are those
    of absolute coordinates (up to sign); the upper bar's centre travels d1 per unit of its
    angle; and the lowest mode animates."""
    absolute = odyn.modes(double_pendulum(), coordinates="absolute")
    joint = odyn.modes(double_pendulum(), coordinates="joint")
    for k in range(2):
        a, b = absolute.body_shapes[:, k], joint.body_shapes[:, k]
        assert min(np.linalg.norm(a - b), np.linalg.norm(a + b)) < 1e-8 * np.linalg.norm(a)
        travel, turn = joint.body_motion(k, "upper")
        assert turn == pytest.approx(joint.shape(k, "shoulder.angle"), abs=1e-12)
        np.testing.assert_allclose(travel, [0.5 * turn, 0.0], atol=1e-12)  # hanging: along x
    np.testing.assert_array_equal(absolute.body_shapes, absolute.shapes)
    path = tmp_path / "mode.gif"
    joint.animate(0, str(path), frames=6)
    assert path.stat().st_size > 0
    with pytest.raises(odyn.SceneError, match="no moving body 'elbow'"):
        joint.body_motion(0, "elbow")


def hanging_chain(links):
    """`links` hinged bars of 1 m and 1 kg hanging straight down from the origin."""
    m = odyn.PlanarModel()
    for i in range(links):
        m.add_body(name=f"link{i}", mass=1.0, inertia=1.0 / 12, position=[0, -0.5 - i])
        m.add_revolute(name=f"hinge{i}", body_a="ground" if i == 0 else f"link{i - 1}",
                       on_a=odyn.frame([0, 0 if i == 0 else -0.5]), body_b=f"link{i}",
                       on_b=odyn.frame([0, 0.5]))
    m.add_gravity(name="gravity", acceleration=[0, -G])
    return m


def test_the_sparse_method_finds_the_dense_lowest_modes():
    """Shift-invert Lanczos on sparse matrices (absolute coordinates) against the dense
    eigenproblem in joint coordinates: the lowest four of a 12-link chain's twelve modes."""
    chain = hanging_chain(12)
    sparse = odyn.modes(chain, method="sparse", count=4)
    dense = odyn.modes(chain, coordinates="joint", method="dense")
    assert len(sparse) == 4 and len(dense) == 12
    np.testing.assert_allclose(sparse.frequencies, dense.frequencies[:4], rtol=1e-9)
    # Nothing damps: the damped modes are the undamped ones; no reduced matrices.
    np.testing.assert_allclose(sparse.natural_frequencies, dense.frequencies[:4], rtol=1e-9)
    assert sparse.mass.size == 0
    for k in range(4):
        a, b = sparse.body_shapes[:, k], dense.body_shapes[:, k]
        assert min(np.linalg.norm(a - b), np.linalg.norm(a + b)) < 1e-7 * np.linalg.norm(a)
    at_rest = odyn.statics(chain, method="sparse")
    assert at_rest.statics["stable"]
    assert at_rest.statics["squared_frequencies"][0] == pytest.approx(
        (2 * math.pi * dense.frequencies[0]) ** 2, rel=1e-9)
    with pytest.raises(odyn.SceneError, match="method"):
        odyn.modes(chain, method="fast")
    with pytest.raises(odyn.SceneError, match="count"):
        odyn.modes(chain, count=-1)
    with pytest.raises(odyn.ModelError, match="absolute coordinates"):
        odyn.modes(chain, coordinates="joint", method="sparse")


CRANK, ROD, SPRING, WALL, FREE = 0.2, 0.5, 200.0, 1.0, 0.4
MASSES = {"crank": 1.0, "rod": 0.5, "piston": 2.0}


def turned_slider_crank():
    """A slider-crank turned by its motor at 1 rad/s against a spring on the piston and the
    bars' weight."""
    r, rod = CRANK, ROD
    m = odyn.PlanarModel()
    m.add_body(name="crank", mass=MASSES["crank"], inertia=0.01, position=[r / 2, 0])
    m.add_body(name="rod", mass=MASSES["rod"], inertia=0.02, position=[r + rod / 2, 0])
    m.add_body(name="piston", mass=MASSES["piston"], inertia=0.01, position=[r + rod, 0])
    m.add_revolute(name="main", body_a="ground", body_b="crank", on_b=odyn.frame([-r / 2, 0]))
    m.add_revolute(name="pin", body_a="crank", on_a=odyn.frame([r / 2, 0]), body_b="rod",
                   on_b=odyn.frame([-rod / 2, 0]))
    m.add_revolute(name="wrist", body_a="rod", on_a=odyn.frame([rod / 2, 0]), body_b="piston")
    m.add_translational(name="cylinder", body_a="ground", on_a=odyn.frame([0, 0], [1, 0]),
                        body_b="piston", on_b=odyn.frame([0, 0], [1, 0]))
    m.add_tsda(name="spring", body_a="piston", point_a=[0, 0], body_b="ground",
               point_b=[WALL, 0], stiffness=SPRING, damping=0.0, free_length=FREE)
    m.add_gravity(name="gravity", acceleration=[0, -G])
    m.add_revolute_driver(name="motor", joint="main", motion=odyn.constant_velocity(1.0))
    return m


def virtual_work_torque(theta):
    """The piston's position and the motor's torque dV/dtheta at crank angles theta, V the
    spring's and the bars' potential energy."""
    r, rod = CRANK, ROD
    root = np.sqrt(rod ** 2 - (r * np.sin(theta)) ** 2)
    x = r * np.cos(theta) + root
    slope = -r * np.sin(theta) - r ** 2 * np.sin(theta) * np.cos(theta) / root
    torque = (-SPRING * (WALL - x - FREE) * slope
              + G * (MASSES["crank"] + MASSES["rod"]) * (r / 2) * np.cos(theta))
    return x, torque


def test_a_slowly_turned_crank_needs_the_virtual_work_torque():
    """Turned quasi-statically, the motor's torque is dV/dtheta at every angle."""
    m = turned_slider_crank()
    result = odyn.quasi_statics(m, t_end=3.0, output_interval=0.1, coordinates="joint")
    theta = result.t
    assert len(theta) == 31 and len(result.statics) == 31
    x, expected = virtual_work_torque(theta)
    torque = result.reaction("motor").torque
    np.testing.assert_allclose(torque, expected, atol=1e-9 * np.abs(expected).max())
    np.testing.assert_allclose(result.body("piston").position[:, 0], x, atol=1e-12)
    assert all(row["force_residual"] < 1e-12 for row in result.statics)
    with pytest.raises(odyn.SceneError, match="max_halvings"):
        odyn.quasi_statics(m, max_halvings=-1)
    with pytest.raises(odyn.ModelError, match="quasi-static.*asks for 1e\\+300 outputs"):
        odyn.quasi_statics(m, output_interval=1e-300)


def test_a_scene_names_a_quasi_static_analysis_and_the_command_line_runs_it(tmp_path, capsys):
    from odyn import cli
    scene = odyn.Scene(turned_slider_crank(),
                       analysis={"type": "quasi_static", "t_end": 3.0, "output_interval": 0.5,
                                 "coordinates": "joint", "max_halvings": 4},
                       outputs=[{"name": "torque", "reaction": "motor", "quantity": "torque"}])
    path = tmp_path / "crank.json"
    odyn.save(scene, path)
    assert odyn.load(path).analysis == scene.analysis
    out = tmp_path / "torque.csv"
    assert cli.main(["run", str(path), "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "quasi-static analysis, t_end = 3 s: 7 outputs" in printed
    assert "force imbalance" in printed and "driver motor: largest effort" in printed
    table = np.genfromtxt(out, delimiter=",", names=True)
    expected = virtual_work_torque(table["t"])[1]
    np.testing.assert_allclose(table["torque"], expected, atol=1e-9 * np.abs(expected).max())
    assert cli.main(["run", str(path), "--integrator", "dop853"]) == 1
    assert "--integrator: not a setting of a quasi_static analysis" in capsys.readouterr().err
    assert cli.main(["check", str(path)]) == 0
    assert "analysis: quasi-static, t_end 3 s, output every 0.5 s, in joint coordinates" in \
        capsys.readouterr().out
    with pytest.raises(odyn.SceneError, match=r"analysis\.max_halvings: expected a whole "
                       "number of at least 0"):
        odyn.Scene(turned_slider_crank(), analysis={"type": "quasi_static", "max_halvings": -1})
    with pytest.raises(odyn.SceneError, match=r"analysis\.max_halvings: does not apply to a "
                       "static analysis"):
        odyn.Scene(turned_slider_crank(), analysis={"type": "static", "max_halvings": 2})
