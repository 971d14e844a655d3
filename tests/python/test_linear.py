"""State-space models from Python (odyn.linearize) against closed forms and against odyn.modes,
whose stiffness and damping come another way."""

import math

import numpy as np
import pytest

import odyn

G = 9.81


def oscillator(mass, k, c):
    """A block on a slide between two spring-dampers: m x'' + 2 c x' + 2 k x = u."""
    m = odyn.PlanarModel()
    m.add_body(name="block", mass=mass, inertia=0.01, position=[1, 0])
    m.add_translational(name="slide", body_a="ground", on_a=odyn.frame([1, 0], [1, 0]),
                        body_b="block")
    m.add_tsda(name="left", body_a="ground", point_a=[0, 0], body_b="block", point_b=[0, 0],
               stiffness=k, damping=c, free_length=1.0)
    m.add_tsda(name="right", body_a="block", point_a=[0, 0], body_b="ground", point_b=[2, 0],
               stiffness=k, damping=c, free_length=1.0)
    m.add_point("centre", "block", [0, 0])
    return m


@pytest.mark.parametrize("coordinates", ["absolute", "joint"])
def test_an_oscillator_has_its_transfer_function(coordinates):
    mass, k, c = 2.0, 50.0, 1.5
    lin = odyn.linearize(oscillator(mass, k, c), coordinates=coordinates,
                         inputs={"push": {"body": "block", "force": [1.0, 0.0]}},
                         outputs=["centre.position.x", "left.length", ("centre", "velocity", "x")])
    assert lin.degrees_of_freedom == 1 and lin.states == ["z1", "z1'"]
    assert lin.inputs == ["push"]
    assert lin.outputs == ["centre.position.x", "left.length", "centre.velocity.x"]
    np.testing.assert_allclose(lin.drift, 0.0, atol=1e-12)
    np.testing.assert_allclose(lin.outputs_at_state, [1.0, 1.0, 0.0], atol=1e-12)
    # x(s) / u(s) = 1 / (m s^2 + 2 c s + 2 k), the spring's length is x, its rate s x.
    for f in (0.0, 0.7, 3.1):
        s = 2j * math.pi * f
        expected = 1.0 / (mass * s * s + 2 * c * s + 2 * k)
        h = lin.transfer(s)
        assert h.shape == (3, 1)
        assert h[0, 0] == pytest.approx(expected, rel=1e-9)
        assert h[1, 0] == pytest.approx(expected, rel=1e-9)
        assert h[2, 0] == pytest.approx(s * expected, rel=1e-9, abs=1e-15)
    response = lin.frequency_response([0.5, 1.0])
    assert response.shape == (2, 3, 1)
    wn, zeta = math.sqrt(2 * k / mass), c / math.sqrt(2 * k * mass)
    s = lin.eigenvalues
    assert s.real == pytest.approx([-zeta * wn] * 2, rel=1e-9)
    assert sorted(s.imag) == pytest.approx([-wn * math.sqrt(1 - zeta ** 2),
                                            wn * math.sqrt(1 - zeta ** 2)], rel=1e-9)


def test_a_swinging_pendulum_linearizes_to_its_equation_about_the_moving_state():
    """J_O theta'' = -m g d sin(theta) + u: about (theta0, theta0') the joint angle's state
    matrix is [0 1; -kappa cos(theta0) 0], kappa = m g d / J_O, and B = (0, 1 / J_O)."""
    mass, length, theta0, rate0 = 1.5, 0.8, 2.0, 3.0
    d, inertia = length / 2, mass * length ** 2 / 12
    j_o = inertia + mass * d * d
    kappa = mass * G * d / j_o
    m = odyn.PlanarModel()
    m.add_body(name="bar", mass=mass, inertia=inertia,
               position=[d * math.sin(theta0), -d * math.cos(theta0)], angle=theta0,
               linear_velocity=[d * math.cos(theta0) * rate0, d * math.sin(theta0) * rate0],
               angular_velocity=rate0)
    m.add_revolute(name="pin", body_a="ground", body_b="bar", on_b=odyn.frame([0, d]))
    m.add_gravity(name="gravity", acceleration=[0, -G])
    lin = odyn.linearize(m, coordinates="joint", inputs={"motor": {"body": "bar", "torque": 1.0}})
    assert lin.coordinates == ["pin.angle"]
    np.testing.assert_allclose(lin.a, [[0, 1], [-kappa * math.cos(theta0), 0]], atol=1e-9 * kappa)
    np.testing.assert_allclose(lin.b, [[0], [1 / j_o]], rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(lin.drift, [rate0, -kappa * math.sin(theta0)], rtol=1e-9)
    assert lin.state.body("bar").angular_velocity[0] == pytest.approx(rate0, rel=1e-12)


def spring_plate(damping):
    """A plate hung from a ball joint and held by three spring-dampers, under gravity."""
    m = odyn.Model()
    m.add_body(name="plate", mass=2.0, inertia=[0.05, 0.08, 0.12], position=[0, 0, -0.3])
    m.add_spherical(name="ball", body_a="ground", point_a=[0, 0, 0], body_b="plate",
                    point_b=[0, 0, 0.3])
    on_plate = ([0.4, 0.0, -0.1], [-0.2, 0.35, -0.1], [-0.2, -0.35, 0.1])
    anchors = ([1.0, 0.2, -0.5], [-0.6, 1.0, 0.2], [-0.5, -0.9, -0.8])
    for i, (k, rest) in enumerate(((40.0, 0.5), (60.0, 0.6), (50.0, 0.4))):
        m.add_tsda(name=f"spring{i}", body_a="plate", point_a=on_plate[i], body_b="ground",
                   point_b=anchors[i], stiffness=k, damping=damping, free_length=rest)
    m.add_gravity(name="gravity", acceleration=[0, 0, -G])
    return m


@pytest.mark.parametrize("coordinates", ["absolute", "joint"])
def test_a_spatial_mechanisms_state_matrix_has_the_modes_eigenvalues(coordinates):
    """The modes come from the tangent's M, C and K on the constraint manifold, the state
    matrix from differences of the accelerations the dynamics give: at the equilibrium both
    have the same eigenvalues, damped ones included."""
    for damping in (0.0, 2.0):
        model = spring_plate(damping)
        modes = odyn.modes(model, coordinates=coordinates)
        lin = odyn.linearize(model, coordinates=coordinates, find_equilibrium=True)
        assert lin.degrees_of_freedom == 3
        np.testing.assert_allclose(lin.drift, 0.0, atol=1e-9)
        upper = lin.eigenvalues[lin.eigenvalues.imag >= 0]
        expected = modes.eigenvalues
        assert len(upper) == len(expected) == 3
        assert abs(expected.real).max() > (0.02 if damping else -1.0) * abs(expected).max()
        np.testing.assert_allclose(upper[np.argsort(abs(upper))],
                                   expected[np.argsort(abs(expected))],
                                   rtol=1e-8, atol=1e-8 * abs(expected).max())


def test_inputs_and_outputs_that_do_not_apply_are_refused_by_name():
    m = oscillator(2.0, 50.0, 0.0)
    with pytest.raises(odyn.SceneError, match=r"inputs\['push'\].body"):
        odyn.linearize(m, inputs={"push": {"body": "crate", "force": [1, 0]}})
    with pytest.raises(odyn.SceneError, match="ground"):
        odyn.linearize(m, inputs={"push": {"body": "ground", "force": [1, 0]}})
    with pytest.raises(odyn.SceneError, match="both zero"):
        odyn.linearize(m, inputs={"push": {"body": "block", "force": [0, 0]}})
    with pytest.raises(odyn.SceneError, match="give a force, a torque"):
        odyn.linearize(m, inputs={"push": {"body": "block"}})
    with pytest.raises(odyn.SceneError, match=r"outputs\[0\]"):
        odyn.linearize(m, outputs=["left.stretch"])
    with pytest.raises(odyn.SceneError, match="no point named 'tip'"):
        odyn.linearize(m, outputs=["tip.position.x"])
    with pytest.raises(odyn.SceneError, match="more than once"):
        odyn.linearize(m, outputs=["left.length", ("left", "length")])
    with pytest.raises(odyn.SceneError, match="coordinates"):
        odyn.linearize(m, coordinates="minimal")


def test_a_scene_names_a_linear_analysis_and_the_command_line_writes_its_matrices(tmp_path,
                                                                                  capsys):
    from odyn import cli
    mass, k, c = 2.0, 50.0, 1.5
    scene = odyn.Scene(oscillator(mass, k, c),
                       analysis={"type": "linear", "find_equilibrium": True,
                                 "inputs": {"push": {"body": "block", "force": [1.0, 0.0]}},
                                 "outputs": ["centre.position.x", "left.length"]})
    path = tmp_path / "oscillator.json"
    odyn.save(scene, path)
    assert odyn.load(path).analysis == scene.analysis
    matrices = tmp_path / "linear.npz"
    assert cli.main(["run", str(path), "--out", str(matrices)]) == 0
    printed = capsys.readouterr().out
    assert "linear analysis about the equilibrium" in printed
    assert "2 states (1 degree of freedom), 1 inputs (push), 2 outputs" in printed
    found = np.load(matrices)
    assert list(found["inputs"]) == ["push"] and list(found["states"]) == ["z1", "z1'"]
    assert list(found["outputs"]) == ["centre.position.x", "left.length"]
    s = 2j * math.pi * 1.3
    transfer = found["c"] @ np.linalg.solve(s * np.eye(2) - found["a"], found["b"])
    expected = 1.0 / (mass * s * s + 2 * c * s + 2 * k)
    np.testing.assert_allclose(transfer[:, 0], [expected, expected], rtol=1e-9)
    # The eigenvalues as a table: the natural frequency and damping ratio of m x'' + 2 c x' +
    # 2 k x = 0, in absolute coordinates as in joint ones.
    table_file = tmp_path / "eigenvalues.csv"
    for coordinates in ("absolute", "joint"):
        assert cli.main(["run", str(path), "--quiet", "--coordinates", coordinates,
                         "--out", str(table_file)]) == 0
        table = np.genfromtxt(table_file, delimiter=",", names=True)
        wn, zeta = math.sqrt(2 * k / mass), c / math.sqrt(2 * k * mass)
        np.testing.assert_allclose(table["natural_frequency"], [wn / (2 * math.pi)] * 2,
                                   rtol=1e-9)
        np.testing.assert_allclose(table["damping_ratio"], [zeta] * 2, rtol=1e-9)
    assert cli.main(["check", str(path)]) == 0
    assert ("analysis: linear about the equilibrium, in absolute coordinates; inputs: push; "
            "outputs: centre.position.x, left.length") in capsys.readouterr().out
    assert cli.main(["run", str(path), "--gif", str(tmp_path / "x.gif")]) == 1
    assert "a linear analysis gives one configuration" in capsys.readouterr().err
    # The inputs and outputs are checked against the model when the scene is made.
    with pytest.raises(odyn.SceneError, match=r"analysis\.inputs\['push'\]\.body: "):
        odyn.Scene(oscillator(mass, k, c),
                   analysis={"type": "linear", "inputs": {"push": {"body": "crate",
                                                                    "force": [1, 0]}}})
    with pytest.raises(odyn.SceneError, match=r"analysis\.outputs\[1\]"):
        odyn.Scene(oscillator(mass, k, c),
                   analysis={"type": "linear", "outputs": ["left.length", "left.stretch"]})
    with pytest.raises(odyn.SceneError, match=r"analysis\.inputs: does not apply to a dynamic"):
        odyn.Scene(oscillator(mass, k, c), analysis={"inputs": {}})
