"""The Python twins of the C++ examples run as scripts and print or write what the C++ does."""

import importlib.util
import math
import subprocess
import sys

import numpy as np
import pytest

import odyn
from conftest import ROOT, read_csv
from test_engine import assert_engine_equal

TWINS = ROOT / "examples" / "python"


def twin(name):
    """A twin imported as a module (its build() and helpers)."""
    sys.path.insert(0, str(TWINS))
    spec = importlib.util.spec_from_file_location(f"twin_{name}", TWINS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


engine_twin, four_bar, andrews = twin("engine"), twin("four_bar"), twin("andrews")


def test_engine_twin_writes_the_cpp_examples_csv(cpp_engine, tmp_path):
    out = tmp_path / "engine.csv"
    run = subprocess.run([sys.executable, str(TWINS / "engine.py"), "--out", str(out)],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert "steps 10050" in run.stdout
    header, data = read_csv(out)
    assert_engine_equal(header, data, cpp_engine)


def test_pendulum_twin_prints_what_the_cpp_program_prints():
    """README's first program (tests/downstream/main.cpp, with its drag written in C++)."""
    binary = ROOT / "build" / "downstream" / "odyn_downstream"
    if not binary.is_file():
        pytest.skip("tests/downstream is not built (bash scripts/test.sh builds it)")
    cpp = subprocess.run([str(binary)], capture_output=True, text=True, check=True).stdout
    py = subprocess.run([sys.executable, str(TWINS / "pendulum.py")], capture_output=True,
                        text=True, check=True).stdout
    assert py == cpp and py.count("\n") == 5


def run_twin(script, tmp_path, *args):
    out = tmp_path / f"{script}.csv"
    run = subprocess.run([sys.executable, str(TWINS / f"{script}.py"), "--out", str(out), *args],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    return run.stdout, *read_csv(out)


def cpp_example(name, tmp_path, *args):
    """The C++ example's CSV (header, data), or None if it is not built."""
    binary = ROOT / "build" / "examples" / name
    if not binary.is_file():
        return None
    out = tmp_path / f"{name}_cpp.csv"
    subprocess.run([str(binary), "--out", str(out), *args], check=True, capture_output=True)
    return read_csv(out)


ENGINE_COLUMNS = ["t", "theta", "omega", "z_piston", "R_z", "phi_norm", "phid_norm"]


@pytest.fixture(scope="module")
def planar_twin(tmp_path_factory):
    return run_twin("slider_crank_planar", tmp_path_factory.mktemp("planar"))


def test_slider_crank_planar_twin_equals_the_spatial_engine(planar_twin):
    """The planar slider-crank discretizes the engine's motion as the spatial model does:
    docs/writing-elements.md, "Model only what a scene needs" (measured 2.2e-7 m apart; both
    are 2e-5 m off the exact motion)."""
    stdout, header, data = planar_twin
    assert header == ENGINE_COLUMNS and data.shape == (1001, 7)
    assert "9 coordinates, 8 constraint equations" in stdout and "steps 10050" in stdout
    spatial = odyn.simulate(engine_twin.build(), t_end=1.0, step=1e-4, output_interval=1e-3)
    reference = engine_twin.engine_table(spatial)
    np.testing.assert_allclose(data[:, 0], reference["t"], atol=1e-12)
    np.testing.assert_allclose(data[:, 1], reference["theta"], atol=2e-6)
    np.testing.assert_allclose(data[:, 2], reference["omega"], atol=2e-3)
    np.testing.assert_allclose(data[:, 3], reference["z_piston"], atol=5e-7)
    np.testing.assert_allclose(data[:, 4], reference["R_z"], atol=5.0)
    assert np.max(data[:, 5]) < 1e-10


def test_slider_crank_planar_twin_equals_the_cpp_example_and_its_scene(planar_twin, tmp_path):
    _, header, data = planar_twin
    cpp = cpp_example("slider_crank_planar", tmp_path)
    if cpp is not None:  # same model, same integrator: equal to rounding
        assert cpp[0] == header
        np.testing.assert_allclose(data[:, :4], cpp[1][:, :4], rtol=0, atol=1e-8)
        np.testing.assert_allclose(data[:, 4], cpp[1][:, 4], rtol=0, atol=1e-5 * 3e4)
    out = tmp_path / "scene.csv"
    run = subprocess.run([sys.executable, "-m", "odyn", "run",
                          str(ROOT / "examples" / "slider_crank_planar.json"), "--out", str(out)],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert "planar model: 9 coordinates, 8 constraint equations" in run.stdout
    scene_header, scene_data = read_csv(out)
    assert scene_header == header
    # The scene writes 0.11 and 0.18 where the script computes r + L/2 and r + L: equal to
    # rounding, which the reaction's step-to-step ripple amplifies a little. z_piston moves by
    # at most r = 0.04 m times the crank angle's difference.
    for column, atol in ((0, 1e-12), (1, 2e-7), (2, 2e-6), (3, 0.04 * 2e-7)):
        np.testing.assert_allclose(scene_data[:, column], data[:, column], rtol=0, atol=atol)
    np.testing.assert_allclose(scene_data[:, 4], data[:, 4], rtol=0,
                               atol=1e-5 * np.max(np.abs(data[:, 4])))


def test_four_bar_twin_drives_the_crank_and_closes_the_loop(tmp_path):
    stdout, header, data = run_twin("four_bar", tmp_path)
    assert header == ["t", "crank_angle", "rocker_angle", "rocker_rate", "motor_torque", "F_O2",
                      "F_A", "F_B", "F_O4"]
    assert data.shape == (201, 9) and "peak motor torque" in stdout
    t, crank, rocker = data[:, 0], data[:, 1], data[:, 2]
    np.testing.assert_allclose(crank, 2 * math.pi * t, atol=1e-9)  # the motor's constant speed
    # Loop closure: B reached along crank + coupler equals B along the rocker from O4. The
    # coupler's angle is not written, so it comes from the circle about A; B must then lie on
    # the rocker's circle about O4 at the rocker's angle (Freudenstein's condition).
    for theta, phi in zip(crank, rocker):
        b = four_bar.point_b(theta)
        np.testing.assert_allclose(b, [0.40 + 0.30 * math.cos(phi), 0.30 * math.sin(phi)],
                                   atol=1e-8)
    # The rate is the derivative of the angle (central differences, 10 ms apart).
    rate = np.gradient(rocker, t)
    np.testing.assert_allclose(data[1:-1, 3], rate[1:-1], atol=0.02 * np.max(np.abs(rate)))
    cpp = cpp_example("four_bar", tmp_path)
    if cpp is not None:
        np.testing.assert_allclose(data, cpp[1], rtol=0, atol=1e-7)


def test_andrews_twin_against_the_spec_and_the_test_set_reference(tmp_path):
    # t = 0: the spec's accelerations and pin forces (tests/test_andrews.cpp).
    a = odyn.assemble(andrews.build())
    assert a.q.shape == (1, 21) and a.lambda_.shape == (1, 20)
    np.testing.assert_allclose(a.body("crank").angular_acceleration[0], 14222.44391995411387,
                               rtol=1e-11)
    np.testing.assert_allclose(a.body("rod FE").angular_acceleration[0], 3555.610979988528468,
                               rtol=1e-11)
    np.testing.assert_allclose(a.body("crank").position[0], andrews.BODIES[0][3:5], atol=1e-15)
    # Pin forces on body b: J3 the rod's on the triangle, J1 the crank's on the ground.
    np.testing.assert_allclose(a.reaction("J3").force[0], [98.56687039624108961,
                                                           -6.122688344255662655], rtol=1e-11)
    np.testing.assert_allclose(a.reaction("J1").force[0],
                               [-98.61497962337862585, 5.344125604523791506], rtol=1e-11)
    np.testing.assert_allclose(a.reaction("J1", side="a").force[0],
                               [98.61497962337862585, -5.344125604523791506], rtol=1e-11)
    # t = 0.03: the Test Set for IVP Solvers' reference solution (Mazzia and Magherini).
    reference = [15.81077119629904, -15.75637105984298, 0.04082224013073101,
                 -0.5347301163226948, 0.5244099658805304, 0.5347301163226948,
                 1.048080741042263]
    stdout, header, data = run_twin("andrews", tmp_path)
    assert header == list(andrews.COLUMNS) and data.shape == (31, 15)
    assert "21 coordinates, 20 constraint equations" in stdout
    np.testing.assert_allclose(data[-1, 1:8], reference, rtol=3e-7)
    cpp = cpp_example("andrews", tmp_path)
    if cpp is not None:  # same model, same integrator
        np.testing.assert_allclose(data[:, 1:8], cpp[1][:, 1:8], rtol=1e-10)


def test_driveline_example_prints_its_output_speeds():
    # The test of the model itself is in test_elements.py; here the script runs as a user would.
    run = subprocess.run([sys.executable, str(TWINS / "driveline.py"), "--bend", "30"],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    lines = run.stdout.splitlines()
    assert lines[0].startswith("cv_joint : output speed 3.0000 to 3.0000 rad/s"), run.stdout
    # cos(30 deg) and 1 / cos(30 deg) times the input speed 3.
    assert lines[1].startswith("universal: output speed 2.5981 to 3.4641 rad/s"), run.stdout


def test_planetary_example_meets_willis_and_the_torque_split():
    """A 30-15-60 set with the ring braked: the carrier at omega Z_s / (Z_s + Z_r) = 10 / 3
    rad/s, the planet on it at -(Z_s / Z_p)(omega - omega_c) = -40 / 3, the motor taking
    T Z_s / (Z_s + Z_r) = 5 / 3 N m of the 5 N m load and the brake the other 10 / 3."""
    run = subprocess.run([sys.executable, str(TWINS / "planetary.py"), "--teeth", "30", "15",
                          "60", "--load", "5"], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    speeds, torques = run.stdout.splitlines()
    assert speeds.startswith("carrier speed 3.333333 rad/s (Willis: 3.333333), planet on the "
                             "carrier -13.333333 rad/s (-13.333333)"), run.stdout
    assert torques.startswith("motor torque 1.666667 N m (T Z_s / (Z_s + Z_r): 1.666667), "
                              "brake torque 3.333333 N m"), run.stdout
    # Every output, not just the means: the speeds and torques are constant to 1e-9.
    r = odyn.simulate(twin("planetary").planetary_reduction((30, 15, 60), 10.0, 5.0), t_end=1.0,
                      output_interval=0.05, rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(r.body("carrier").angular_velocity[:, 2], 10 / 3, rtol=1e-9)
    np.testing.assert_allclose(r.reaction("motor").torque[:, 2], 5 / 3, rtol=1e-9)
    np.testing.assert_allclose(r.reaction("brake").torque[:, 2], 10 / 3, rtol=1e-9)
