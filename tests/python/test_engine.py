"""The engine from Python (scene file, CLI, model API) equals the C++ example's output."""

import subprocess
import sys

import numpy as np
import pytest

import odyn
import odyn_engine
from conftest import ENGINE_SCENE, read_csv

COLUMNS = ["t", "theta", "omega", "z_piston", "R_z", "phi_norm", "phid_norm"]


def assert_engine_equal(header, data, cpp):
    cpp_header, cpp_data = cpp
    assert header == cpp_header == COLUMNS
    assert data.shape == cpp_data.shape == (1001, 7)
    t, theta, omega, z, r_z = (data[:, i] for i in range(5))
    ct, ctheta, comega, cz, cr_z = (cpp_data[:, i] for i in range(5))
    np.testing.assert_allclose(t, ct, atol=1e-12)
    # Same model, same integrator: only the order of the element types and constraint rows
    # differs, so the Schur complement is summed in another order (rounding). Newton's decisions
    # amplify rounding (a 1e-15 change of the initial speed moves z by up to 5e-8 m); the model
    # API's build measured 3.9e-8 rad, 3.6e-7 rad/s and 1.6e-9 m from the C++ one, while both
    # are 5e-4 rad and 2e-5 m off the exact motion.
    np.testing.assert_allclose(theta, ctheta, rtol=0, atol=1e-7)
    np.testing.assert_allclose(omega, comega, rtol=0, atol=1e-6)
    np.testing.assert_allclose(z, cz, rtol=0, atol=5e-9)
    np.testing.assert_allclose(r_z, cr_z, rtol=0, atol=1e-5 * np.max(np.abs(cr_z)))
    # Residuals are rounding-level numbers: same magnitude, not the same digits.
    assert np.max(data[:, 5]) < 1e-10 and np.max(cpp_data[:, 5]) < 1e-10
    np.testing.assert_allclose(np.max(data[:, 6]), np.max(cpp_data[:, 6]), rtol=1e-3)


def test_cli_writes_the_cpp_examples_csv(cpp_engine, tmp_path):
    out = tmp_path / "engine.csv"
    run = subprocess.run([sys.executable, "-m", "odyn", "run", str(ENGINE_SCENE), "--out",
                          str(out), "--figures", str(tmp_path)], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert "steps 10050" in run.stdout and "largest residuals" in run.stdout
    header, data = read_csv(out)
    assert_engine_equal(header, data, cpp_engine)
    assert (tmp_path / "engine_piston.png").stat().st_size > 10_000
    assert (tmp_path / "engine_bearing.png").stat().st_size > 10_000


def test_model_api_engine_equals_cpp(cpp_engine):
    """The engine built call by call (the Python twin of examples/engine_model.hpp), with the
    gas force of the module odyn_engine (examples/python/odyn_engine/odyn_engine.cpp)."""
    r, L = 0.04, 0.14
    x, y, z = [1, 0, 0], [0, 1, 0], [0, 0, 1]
    m = odyn.Model(module=odyn_engine)
    m.add_body(name="crank", mass=1.399, inertia=[1.524, 1.291, 0.836],
               angular_velocity=[157.08, 0, 0])
    m.add_body(name="rod", mass=0.253, inertia=[0.399, 0.372, 0.0349], position=[0, 0, r + L / 2])
    m.add_body(name="piston", mass=0.643, inertia=[0.457, 0.506, 0.653], position=[0, 0, r + L])
    m.add_revolute(name="bearing", body_a="ground", on_a=odyn.frame([0, 0, 0], x),
                   body_b="crank", on_b=odyn.frame([0, 0, 0], x))
    m.add_spherical(name="crank pin", body_a="crank", point_a=[0, 0, r], body_b="rod",
                    point_b=[0, 0, -L / 2])
    m.add_universal(name="piston pin", body_a="rod", on_a=odyn.frame([0, 0, L / 2], x),
                    body_b="piston", on_b=odyn.frame([0, 0, 0], y))
    m.add_translational(name="cylinder", body_a="ground", on_a=odyn.frame([0, 0, r + L], z),
                        body_b="piston", on_b=odyn.frame([0, 0, 0], z))
    m.add_gravity(name="gravity", acceleration=[0, 0, -9.81])
    m.add_rsda(name="load", body_a="ground", on_a=odyn.frame([0, 0, 0], x), body_b="crank",
               on_b=odyn.frame([0, 0, 0], x), damping=0.1)
    m.add("engine_gas_force", name="gas force", crank="crank", piston="piston")
    res = odyn.simulate(m, t_end=1.0, step=1e-4, output_interval=1e-3)
    data = np.column_stack([
        res.t, res.state("gas force")["theta"], res.body("crank").angular_velocity[:, 0],
        res.body("piston").position[:, 2], res.reaction("bearing", side="b").force[:, 2],
        res.phi_norm, res.phid_norm])
    assert_engine_equal(COLUMNS, data, cpp_engine)
    assert res.summary["steps"] == 10050 and res.summary["events"] == 50
    # The load's unwrapped angle is the same crank angle.
    np.testing.assert_allclose(res.state("load")["angle"], data[:, 1], atol=1e-12)


def test_engine_kinematics_hold():
    """Independent of the C++ run: the slider-crank relation between theta and z_piston,
    z = r cos(theta) + sqrt(L^2 - r^2 sin^2(theta)), and the bearing reaction's balance."""
    scene = odyn.load(ENGINE_SCENE)
    res = scene.simulate(t_end=0.1)
    theta = res.state("gas force")["theta"]
    z = res.body("piston").position[:, 2]
    r, L = 0.04, 0.14
    np.testing.assert_allclose(z, r * np.cos(theta) + np.sqrt(L**2 - (r * np.sin(theta))**2),
                               atol=1e-10)
    # Reaction on the crank (side b) and on the block (side a) are opposite.
    on_crank = res.reaction("bearing", "b").force
    on_block = res.reaction("bearing", "a").force
    np.testing.assert_allclose(on_crank, -on_block, atol=1e-8 * np.max(np.abs(on_crank)))


def test_gas_force_outputs_follow_the_spec():
    """The gas force's outputs (crank angle, stroke, pressure, force) against the spec's
    Otto-cycle law written out here from the piston's height (shared/specs/engine.md)."""
    scene = odyn.load(ENGINE_SCENE)
    res = scene.simulate(t_end=0.1)
    out = res.output("gas force")
    state = res.state("gas force")
    np.testing.assert_array_equal(out["crank_angle"], state["theta"])
    np.testing.assert_array_equal(out["stroke"], np.mod(state["half_turn"], 4))
    assert set(out["stroke"]) == {0, 1, 2, 3}
    r, L, D, C, p_atm, kappa, p_comb = 0.04, 0.14, 0.08, 9.0, 101325.0, 1.4, 3.0e6
    area = np.pi * D**2 / 4
    v_c = area * 2 * r / (C - 1)
    volume = v_c + area * ((r + L) - res.body("piston").position[:, 2])
    pressure = np.select([out["stroke"] == 1, out["stroke"] == 2],
                         [p_atm * ((v_c + 2 * r * area) / volume)**kappa,
                          (p_atm * C**kappa + p_comb) * (v_c / volume)**kappa], p_atm)
    np.testing.assert_allclose(out["pressure"], pressure, rtol=1e-12)
    np.testing.assert_allclose(out["force"], -(pressure - p_atm) * area, rtol=1e-12, atol=1e-9)
    assert np.max(out["pressure"]) > 5e6  # the power stroke's peak


def test_engine_in_joint_coordinates():
    """coordinates="joint": the same motion and reactions as absolute coordinates (both at a
    tight tolerance: a converged run of a different formulation), the slider-crank relation
    exactly, and the choice refused by name where it does not apply."""
    scene = odyn.load(ENGINE_SCENE)
    joint = scene.simulate(t_end=0.1, integrator="dop853", rtol=1e-10, atol=1e-10,
                           coordinates="joint")
    absolute = scene.simulate(t_end=0.1, integrator="dop853", rtol=1e-10, atol=1e-10,
                              coordinates="absolute")
    assert absolute.summary["coordinates"] == "absolute"
    assert joint.summary["coordinates"] == "joint"
    theta = joint.state("gas force")["theta"]
    np.testing.assert_allclose(theta, absolute.state("gas force")["theta"], atol=1e-9)
    z = joint.body("piston").position[:, 2]
    r, L = 0.04, 0.14
    np.testing.assert_allclose(z, r * np.cos(theta) + np.sqrt(L**2 - (r * np.sin(theta))**2),
                               atol=1e-12)
    force = joint.reaction("bearing", side="b").force
    reference = absolute.reaction("bearing", side="b").force
    np.testing.assert_allclose(force, reference, atol=1e-7 * np.max(np.abs(reference)))
    assert np.max(joint.phi_norm) < 1e-11
    # Adams (order 6, h = 1e-5) steps the same coordinates: measured 1.7e-12 rad from dop853.
    adams = scene.simulate(t_end=0.1, integrator="adams", order=6, step=1e-5,
                           coordinates="joint")
    np.testing.assert_allclose(adams.state("gas force")["theta"], theta, atol=1e-10)
    # Generalized-alpha (the default integrator) at second order: its error at h = 1e-4 and at
    # 5e-5 against dop853, in a ratio of about 4, and about as large as in absolute coordinates.
    errors = []
    for step in (1e-4, 5e-5):
        alpha = scene.simulate(t_end=0.1, step=step, coordinates="joint")
        errors.append(np.max(np.abs(alpha.state("gas force")["theta"] - theta)))
        z = alpha.body("piston").position[:, 2]
        assert np.max(np.abs(z - (r * np.cos(alpha.state("gas force")["theta"]) + np.sqrt(
            L**2 - (r * np.sin(alpha.state("gas force")["theta"]))**2)))) < 1e-10
    absolute_error = np.max(np.abs(scene.simulate(t_end=0.1, coordinates="absolute")
                                   .state("gas force")["theta"] - theta))
    assert 3.5 < errors[0] / errors[1] < 4.5, errors
    assert 0.5 < errors[0] / absolute_error < 2.0, (errors, absolute_error)
    # BDF steps them too: within its tolerance's reach of dop853.
    bdf = scene.simulate(t_end=0.1, integrator="bdf", rtol=1e-10, atol=1e-10, coordinates="joint")
    np.testing.assert_allclose(bdf.state("gas force")["theta"], theta, atol=1e-7)
    with pytest.raises(odyn.SceneError, match="coordinates"):
        scene.simulate(t_end=0.01, integrator="dop853", coordinates="relative")
