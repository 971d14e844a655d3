"""Integrators by name (the C++ library's list), their options and their statistics, from the
API, scene files and the command line."""

import json
import math
import subprocess
import sys
import warnings

import numpy as np
import pytest

import odyn
from conftest import ENGINE_SCENE

G = 9.81
J = 1e-3 + 1.0  # the pendulum's inertia about its pin


def pendulum():
    """A planar 1 kg bob (inertia 1e-3) at (1, 0) pinned at the origin; gravity -y."""
    m = odyn.PlanarModel()
    m.add_body(name="bob", mass=1.0, inertia=1e-3, position=[1, 0])
    m.add_revolute(name="pin", body_a="ground", body_b="bob", on_b=odyn.frame([-1, 0]))
    m.add_gravity(name="gravity", acceleration=[0, -G])
    return m


@pytest.fixture(scope="module")
def exact_angle():
    """The pendulum's angle theta(t), theta'' = -g cos(theta) / J from rest, by RK4 at 1e-4 s
    (error ~1e-13), at t = 0, 0.1, ..., 1."""
    def f(y):
        return np.array([y[1], -G * math.cos(y[0]) / J])
    y, h, out = np.array([0.0, 0.0]), 1e-4, [0.0]
    for step in range(1, 10001):
        k1 = f(y)
        k2 = f(y + h / 2 * k1)
        k3 = f(y + h / 2 * k2)
        k4 = f(y + h * k3)
        y = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        if step % 1000 == 0:
            out.append(y[0])
    return np.array(out)


def test_the_names_come_from_the_cpp_library():
    names = odyn.integrators()
    assert list(names) == [n for n, _ in odyn._core.integrators()]
    assert {"generalized-alpha", "hht", "dopri5", "dop853"} <= set(names)
    assert all(isinstance(what, str) and what for what in names.values())


@pytest.mark.parametrize("name", list(odyn.integrators()))
def test_every_integrator_solves_the_pendulum_with_error_control(name, exact_angle):
    r = odyn.simulate(pendulum(), t_end=1.0, step=1e-3, output_interval=0.1, integrator=name,
                      rtol=1e-7, atol=1e-7)
    np.testing.assert_allclose(r.body("bob").angle, exact_angle, atol=2e-4)
    assert r.phi_norm.max() < 1e-9
    s = r.statistics
    assert s.steps > 0 and s.outputs == 11 and s.rejected_steps >= 0
    assert s.residual_evaluations >= s.steps
    # Accepted steps of an error-controlled run meet the tolerance.
    assert 0 < s.max_error_estimate <= 1.0
    assert s == odyn.Statistics(**{k: r.summary[k] for k in odyn.Statistics._fields})


@pytest.mark.parametrize("name", list(odyn.integrators()))
def test_outputs_land_on_the_output_times(name):
    r = odyn.simulate(pendulum(), t_end=0.1, output_interval=0.01, integrator=name,
                      rtol=1e-8, atol=1e-8)
    np.testing.assert_allclose(r.t, np.linspace(0.0, 0.1, 11), rtol=0, atol=1e-14)


def test_generalized_alpha_fixed_and_adaptive(exact_angle):
    fixed = odyn.simulate(pendulum(), t_end=1.0, step=1e-3, output_interval=0.1)
    assert fixed.statistics.steps == 1000 and fixed.statistics.rejected_steps == 0
    assert fixed.statistics.jacobian_evaluations > 0
    np.testing.assert_allclose(fixed.body("bob").angle, exact_angle, atol=1e-4)
    # rtol/atol turn on error control (as the C++ examples' --rtol) ...
    adaptive = odyn.simulate(pendulum(), t_end=1.0, step=1e-3, output_interval=0.1,
                             rtol=1e-5, atol=1e-5, integrator="generalized-alpha")
    assert adaptive.statistics.steps != 1000
    # ... unless adaptive=False: fixed steps, the tolerances only scale the error estimate.
    off = odyn.simulate(pendulum(), t_end=1.0, step=1e-3, output_interval=0.1, rtol=1e-5,
                        atol=1e-5, adaptive=False)
    np.testing.assert_array_equal(off.q, fixed.q)
    hht = odyn.simulate(pendulum(), t_end=1.0, step=1e-3, output_interval=0.1, integrator="hht")
    assert hht.statistics.steps == 1000
    np.testing.assert_allclose(hht.body("bob").angle, exact_angle, atol=1e-4)


@pytest.mark.parametrize("name", ["dopri5", "dop853"])
def test_max_step_bounds_an_adaptive_step(name):
    free = odyn.simulate(pendulum(), t_end=1.0, output_interval=0.5, integrator=name)
    bounded = odyn.simulate(pendulum(), t_end=1.0, output_interval=0.5, integrator=name,
                            max_step=1e-3)
    assert free.statistics.steps < 1000 <= bounded.statistics.steps


def test_integrator_options_are_checked():
    names = ", ".join(odyn.integrators())
    with pytest.raises(odyn.SceneError, match=f"integrator: expected one of {names}, got 'euler'"):
        odyn.simulate(pendulum(), integrator="euler")
    with pytest.raises(odyn.SceneError, match=r"adaptive: applies to generalized-alpha and hht; "
                       "dopri5 chooses its steps itself"):
        odyn.simulate(pendulum(), integrator="dopri5", adaptive=True)
    with pytest.raises(odyn.SceneError, match=r"rtol: expected a positive number, got -1"):
        odyn.simulate(pendulum(), rtol=-1.0)


@pytest.mark.parametrize("name", odyn.integrators())
def test_a_model_without_bodies_is_refused_by_every_integrator(name):
    # Used to end the process with a segmentation fault (generalized-alpha, hht).
    planar_gravity_only = odyn.PlanarModel()
    planar_gravity_only.add_gravity(name="g", acceleration=[0.0, -9.81])
    for empty in (odyn.Model(), planar_gravity_only):
        with pytest.raises(odyn.ModelError, match="the model has no moving bodies"):
            odyn.simulate(empty, t_end=0.01, integrator=name)


def engine_with(analysis):
    with open(ENGINE_SCENE) as f:
        d = json.load(f)
    d["analysis"].update(analysis)
    return d


def test_scene_analysis_with_an_integrator_by_name_and_its_options():
    scene = odyn.loads(json.dumps(engine_with(
        {"integrator": "dopri5", "rtol": 1e-7, "atol": 1e-7, "max_step": 1e-3, "t_end": 0.05})))
    r = scene.simulate()
    ref = odyn.load(ENGINE_SCENE).simulate(t_end=0.05)
    theta, theta_ref = r.state("gas force")["theta"], ref.state("gas force")["theta"]
    np.testing.assert_allclose(theta, theta_ref, atol=5e-4)  # generalized-alpha's own error
    assert r.statistics.events == ref.statistics.events == 2  # ignition at 2 half turns
    for bad, message in (
            ({"integrator": "rk4"}, r"analysis\.integrator: expected one of " +
             ", ".join(odyn.integrators())),
            ({"integrator": "dopri5", "adaptive": True}, r"analysis\.adaptive: applies to"),
            ({"adaptive": "yes"}, r"analysis\.adaptive: expected true or false"),
            ({"rtol": 0}, r"analysis\.rtol: expected a positive number"),
            ({"max_step": "big"}, r"analysis\.max_step: expected a number")):
        with pytest.raises(odyn.SceneError, match=message):
            odyn.loads(json.dumps(engine_with(bad)))


def test_cli_integrators_and_error_control(tmp_path):
    run = subprocess.run([sys.executable, "-m", "odyn", "integrators"], capture_output=True,
                         text=True, check=True)
    for name, what in odyn.integrators().items():
        assert name in run.stdout and what in run.stdout
    out = tmp_path / "r.csv"
    run = subprocess.run([sys.executable, "-m", "odyn", "run", str(ENGINE_SCENE), "--t-end",
                          "0.02", "--integrator", "generalized-alpha", "--rtol", "1e-6",
                          "--atol", "1e-6", "--max-step", "2e-4", "--out", str(out)],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert "error control rtol 1e-06, atol 1e-06" in run.stdout
    assert "max step 0.0002 s" in run.stdout and "Jacobians" in run.stdout
    assert "largest local error estimate" in run.stdout
    run = subprocess.run([sys.executable, "-m", "odyn", "run", str(ENGINE_SCENE), "--integrator",
                          "leapfrog"], capture_output=True, text=True)
    assert run.returncode == 1 and "invalid choice: 'leapfrog'" in run.stderr


def test_adams_fixed_steps_and_its_order(exact_angle):
    """Explicit Adams-Bashforth on fixed steps: the error falls with the order, and the order
    is checked (API and scene files)."""
    errors = {}
    for order in (2, 5):
        r = odyn.simulate(pendulum(), t_end=1.0, step=1e-2, output_interval=0.1,
                          integrator="adams", order=order)
        assert r.statistics.steps == 100 and r.statistics.rejected_steps == 0
        assert r.phi_norm.max() < 1e-10
        errors[order] = np.abs(r.body("bob").angle - exact_angle).max()
    # 1.9e-6 and 4.1e-3 rad: the error of order k falls as h^k (h = 1e-2 against 0.1 s swings)
    assert errors[5] < 5e-6 and 1e3 * errors[5] < errors[2] < 1e-2
    with pytest.raises(odyn.SceneError, match=r"order: expected an integer from 1 to 6, got 7"):
        odyn.simulate(pendulum(), integrator="adams", order=7)
    with pytest.raises(odyn.SceneError, match=r"analysis\.order: expected an integer from 1 to 6"):
        odyn.loads(json.dumps(engine_with({"integrator": "adams", "order": 0})))


def test_a_tolerance_below_what_doubles_deliver_is_raised_with_a_warning(exact_angle):
    with pytest.warns(odyn.ToleranceWarning, match=r"rtol 1e-16 .* 2\.2\d*e-14"):
        raised = odyn.simulate(pendulum(), t_end=0.1, output_interval=0.1, integrator="dop853",
                               rtol=1e-16, atol=1e-16)
    assert len(raised.warnings) == 1 and "100 machine epsilons" in raised.warnings[0]
    assert abs(raised.body("bob").angle[-1] - exact_angle[1]) < 1e-12
    # The run is the one at the floor, step for step; that one says nothing.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        floor = odyn.simulate(pendulum(), t_end=0.1, output_interval=0.1, integrator="dop853",
                              rtol=100 * np.finfo(float).eps, atol=1e-16)
    assert floor.warnings == []
    assert raised.statistics.steps == floor.statistics.steps
    np.testing.assert_array_equal(raised.q, floor.q)


def test_assembly_says_how_far_it_moved_a_body_given_off_its_joint(tmp_path):
    # The engine's rod given 2 mm off along the crank axis (x): its joints put it back, alone.
    scene = json.loads(ENGINE_SCENE.read_text())
    rod = next(b for b in scene["bodies"] if b["name"] == "rod")
    rod["position"] = [0.002, rod["position"][1], rod["position"][2]]
    path = tmp_path / "moved.json"
    path.write_text(json.dumps(scene))
    with pytest.warns(odyn.AssemblyWarning, match=r"'rod' by 0\.002 m"):
        r = odyn.load(path).simulate(t_end=0.002)
    moved = {b["body"]: b for b in r.assembly["moved_bodies"]}
    assert moved["rod"]["translation"] == pytest.approx(0.002, rel=1e-9)
    assert moved["rod"]["rotation"] < 1e-12 and "crank" not in moved
    # odyn.assemble says the same; the CLI prints it as one line.
    with pytest.warns(odyn.AssemblyWarning, match="'rod'"):
        odyn.assemble(odyn.load(path).model)
    run = subprocess.run([sys.executable, "-m", "odyn", "run", str(path), "--t-end", "0.002",
                          "--quiet"], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert run.stderr.startswith("odyn: warning: assembly moved 1 body") and "'rod'" in run.stderr
    # The unchanged scene assembles without a warning.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        odyn.assemble(odyn.load(ENGINE_SCENE).model)


def test_the_default_is_auto_and_a_step_alone_means_generalized_alpha(exact_angle):
    chosen = odyn.simulate(pendulum(), t_end=1.0, output_interval=0.1)
    assert chosen.summary["integrator"] == "dop853"
    assert "not stiff" in chosen.summary["integrator_choice"]
    assert chosen.summary["coordinates"] == "absolute"  # a planar model
    assert "planar" in chosen.summary["coordinates_choice"]
    # rtol = atol = 1e-6 by default; the pendulum's angle to about that.
    np.testing.assert_allclose(chosen.body("bob").angle, exact_angle, atol=1e-5)
    fixed = odyn.simulate(pendulum(), t_end=1.0, step=1e-3, output_interval=0.1)
    assert fixed.summary["integrator"] == "generalized-alpha"
    assert fixed.summary["integrator_choice"] == ""
    assert fixed.statistics.steps == 1000


def test_auto_coordinates_are_joint_ones_for_the_engine_with_the_same_answer():
    """The engine (spatial, 3 closure equations) runs in joint coordinates by default with an
    explicit method, and ends where a run in absolute coordinates does."""
    scene = odyn.load(ENGINE_SCENE)
    chosen = scene.simulate(t_end=0.1, integrator="auto", rtol=1e-9, atol=1e-9)
    assert chosen.summary["coordinates"] == "joint"
    assert "3 closure equations" in chosen.summary["coordinates_choice"]
    absolute = scene.simulate(t_end=0.1, integrator="auto", rtol=1e-9, atol=1e-9,
                              coordinates="absolute")
    assert absolute.summary["coordinates"] == "absolute"
    assert absolute.summary["coordinates_choice"] == ""
    np.testing.assert_allclose(chosen.state("gas force")["theta"],
                               absolute.state("gas force")["theta"], atol=1e-7)
    # The scene's own integrator, generalized-alpha, is implicit: absolute coordinates.
    named = scene.simulate(t_end=0.01)
    assert named.summary["coordinates"] == "absolute"
    assert "implicit" in named.summary["coordinates_choice"]
