"""Scene files: save/load round trip, and a clear error (never a crash) for malformed scenes."""

import copy
import json
import subprocess
import sys

import numpy as np
import pytest

import odyn
from conftest import ENGINE_SCENE, ROOT


@pytest.fixture()
def engine_dict():
    with open(ENGINE_SCENE) as f:
        return json.load(f)


def test_round_trip_keeps_the_model_and_its_results(tmp_path):
    scene = odyn.load(ENGINE_SCENE)
    path = tmp_path / "again.json"
    odyn.save(scene, path)
    again = odyn.load(path)
    assert again.to_dict() == scene.to_dict()
    a = scene.simulate(t_end=0.05)
    b = again.simulate(t_end=0.05)
    np.testing.assert_array_equal(a.q, b.q)
    np.testing.assert_array_equal(a.reaction("bearing").force, b.reaction("bearing").force)


def test_a_model_built_in_python_saves_every_scene_element(tmp_path):
    m = odyn.Model()
    m.add_body(name="a", mass=1.0, inertia=[[0.1, 0, 0], [0, 0.2, 0], [0, 0, 0.25]],
               position=[0, 0, 1], orientation=[1, 0, 0, 0], velocity_given=[True] * 6)
    m.add_body(name="b", mass=2.0, inertia=[0.1, 0.1, 0.1], position=[1, 0, 1])
    m.add_revolute(name="r", body_a="ground", on_a=odyn.frame([0, 0, 1], [0, 0, 1], [1, 0, 0]),
                   body_b="a", on_b=odyn.frame())
    m.add_distance(name="d", body_a="a", point_a=[0, 0, 0], body_b="b", point_b=[0, 0, 0],
                   length=1.0)
    m.add_revolute_driver(name="motor", joint="r", motion=odyn.harmonic(0.1, 2.0))
    m.add_gravity(name="g", acceleration=[0, 0, -9.81])
    m.add_point_force(name="f", body="b", point=[0.1, 0, 0], force=[1, 2, 3], axes="body")
    m.add_point_torque(name="tq", body="b", torque=[0, 0, 1])
    m.add_tsda(name="s", body_a="ground", point_a=[2, 0, 1], body_b="b", point_b=[0, 0, 0],
               stiffness=10.0, damping=0.5, free_length=0.8)
    path = tmp_path / "m.json"
    odyn.save(m, path)
    again = odyn.load(path)
    assert again.model.element_names == m.element_names
    assert again.model.body("a") == m.body("a")
    assert again.model.element("motor") == m.element("motor")
    r1 = odyn.simulate(m, t_end=0.2, step=1e-3, output_interval=0.1)
    r2 = again.simulate(t_end=0.2, step=1e-3, output_interval=0.1)
    np.testing.assert_array_equal(r1.q, r2.q)


def test_python_functions_cannot_be_saved(tmp_path):
    m = odyn.Model()
    m.add_body(name="a", mass=1.0, inertia=[0.1] * 3)
    m.add_point_force(name="push", body="a", force=lambda t, b: (0, 0, 1))
    with pytest.raises(odyn.SceneError, match=r"push.*force: a Python function cannot be saved"):
        odyn.save(m, tmp_path / "x.json")


def broken(engine, path, value):
    """engine_dict with `value` put at `path` (a list of keys); None deletes."""
    d = copy.deepcopy(engine)
    target = d
    for key in path[:-1]:
        target = target[key]
    if value is None:
        del target[path[-1]]
    else:
        target[path[-1]] = value
    return d


CASES = [
    # (what is broken, where, new value, expected message)
    ("missing mass", ["bodies", 0, "mass"], None, r"bodies\[0\]: missing 'mass'"),
    ("wrong type", ["bodies", 1, "mass"], "heavy", r"bodies\[1\]\.mass: expected a number"),
    ("NaN", ["bodies", 2, "position"], [0, float("nan"), 0.18],
     r"bodies\[2\]\.position\[1\]: expected a finite number, got nan"),
    ("negative mass", ["bodies", 0, "mass"], -1.0, r"bodies\[0\]\.mass: expected a positive"),
    ("unknown element type", ["joints", 1, "type"], "hinge",
     r"joints\[1\]\.type: unknown joint type 'hinge'; expected one of revolute"),
    ("force type among joints", ["joints", 1, "type"], "gravity",
     r"joints\[1\]\.type: .*'gravity' belongs in 'forces'"),
    ("zero axis", ["joints", 2, "on_a", "axis"], [0, 0, 0],
     r"joints\[2\]\.on_a\.axis: zero-length vector"),
    ("duplicate names", ["joints", 1, "name"], "bearing",
     r"joints\[1\]\.name: the name 'bearing' is already used"),
    ("body and joint share a name", ["joints", 0, "name"], "crank",
     r"joints\[0\]\.name: the name 'crank' is already used"),
    ("missing body", ["joints", 3, "body_b"], "pistn",
     r"joints\[3\]\.body_b: no body named 'pistn'"),
    ("unknown key", ["joints", 0, "stiffness"], 3.0,
     r"joints\[0\]\.stiffness: unknown key; expected one of name, body_a"),
    ("unknown top-level key", ["solver"], {}, r"^solver: unknown key"),
    ("vector of the wrong size", ["forces", 0, "acceleration"], [0, -9.81],
     r"forces\[0\]\.acceleration: expected a list of 3 numbers"),
    ("bad integrator", ["analysis", "integrator"], "euler",  # the names of the C++ library
     r"analysis\.integrator: expected one of " + ", ".join(odyn.integrators()) + ", got 'euler'"),
    ("negative step", ["analysis", "step"], -1e-4, r"analysis\.step: expected a positive"),
    ("output naming a missing joint", ["outputs", 3, "reaction"], "crank bearing",
     r"outputs\[3\]\.reaction: no joint or driver named 'crank bearing'"),
    ("figure of a missing column", ["figures", 0, "y"], "z", r"figures\[0\]\.y: no output column"),
    ("same body twice", ["joints", 1, "body_b"], "crank",
     r"joints\[1\]\.body_b: body_a and body_b are both 'crank'"),
    ("bodies not a list", ["bodies"], {"crank": {}}, r"bodies: expected a list"),
    ("no bodies", ["bodies"], [], r"bodies: the list is empty: a model needs at least one"),
    ("element not an object", ["forces", 0], 3, r"forces\[0\]: expected an object, got 3"),
    ("physics the library rejects", ["bodies", 0, "inertia"], [1.0, 1.0, 5.0],
     r"bodies\[0\]: crank: principal moments .* violate the triangle inequality"),
]


@pytest.mark.parametrize("what, path, value, message", CASES, ids=[c[0] for c in CASES])
def test_malformed_scene_names_the_place(engine_dict, tmp_path, what, path, value, message):
    d = broken(engine_dict, path, value)
    file = tmp_path / "bad.json"
    file.write_text(json.dumps(d))  # NaN is written as the non-JSON token NaN
    with pytest.raises(odyn.SceneError, match=message):
        odyn.loads(json.dumps(d))
    with pytest.raises(odyn.SceneError, match=str(file)):
        odyn.load(file)


def test_result_saves_every_array(tmp_path):
    scene = odyn.load(ENGINE_SCENE)
    r = scene.simulate(t_end=0.01)
    r.save_npz(tmp_path / "all.npz")
    data = np.load(tmp_path / "all.npz")
    np.testing.assert_array_equal(data["lambda"], r.lambda_)
    np.testing.assert_array_equal(data["reaction/bearing"][:, 1, 0, :3], r.reaction("bearing").force)
    np.testing.assert_array_equal(data["state/gas force/theta"], r.state("gas force")["theta"])
    assert list(data["bodies"]) == ["crank", "rod", "piston"]


def test_not_json_at_all():
    with pytest.raises(odyn.SceneError, match=r"not valid JSON: .*line 1"):
        odyn.loads("{bodies: []}")


def test_cli_bad_input_is_one_line_and_status_1(engine_dict, tmp_path):
    d = broken(engine_dict, ["joints", 2, "on_a", "axis"], [0, 0, 0])
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(d))
    for args in (["run", str(bad)], ["run", str(tmp_path / "missing.json")],
                 ["run", str(ENGINE_SCENE), "--h", "fast"],
                 ["run", str(ENGINE_SCENE), "--h", "-1"],
                 ["run", str(ENGINE_SCENE), "--out", "x.txt"], ["fly"]):
        run = subprocess.run([sys.executable, "-m", "odyn", *args], capture_output=True,
                             text=True, cwd=tmp_path)
        assert run.returncode == 1, (args, run.stderr)
        assert run.stderr.count("\n") == 1 and run.stderr.startswith("odyn: "), run.stderr
        assert "Traceback" not in run.stderr
    run = subprocess.run([sys.executable, "-m", "odyn", "run", str(bad)], capture_output=True,
                         text=True)
    assert "joints[2].on_a.axis: zero-length vector" in run.stderr


def test_cli_npz_and_overrides(tmp_path):
    out = tmp_path / "r.npz"
    run = subprocess.run([sys.executable, "-m", "odyn", "run", str(ENGINE_SCENE), "--t-end",
                          "0.02", "--h", "2e-4", "--integrator", "hht", "--out", str(out),
                          "--plot", str(tmp_path / "all.png")], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    data = np.load(out)
    assert list(data.keys()) == ["t", "theta", "omega", "z_piston", "R_z", "phi_norm",
                                 "phid_norm"]
    assert len(data["t"]) == 21 and data["t"][-1] == pytest.approx(0.02)
    assert "hht" in run.stdout and (tmp_path / "all.png").stat().st_size > 10_000


def test_a_scene_without_an_integrator_takes_simulates_default(engine_dict, tmp_path):
    # Left out, the integrator is simulate()'s choice: auto, or generalized-alpha for a step
    # given without tolerances; the CLI says which, and both meet the crank angle of the
    # scene's own generalized-alpha run (h = 1e-4, good to about 1e-5 rad at 0.05 s).
    given = odyn.loads(json.dumps(engine_dict)).simulate(t_end=0.05)
    for removed, expected in (("step", "dop853"), (None, "generalized-alpha")):
        d = copy.deepcopy(engine_dict)
        del d["analysis"]["integrator"], d["analysis"]["rho_inf"]
        if removed:
            del d["analysis"][removed]
        scene = odyn.loads(json.dumps(d))
        assert "integrator" not in scene.analysis
        assert "integrator" not in scene.to_dict()["analysis"]
        result = scene.simulate(t_end=0.05)
        assert result.summary["integrator"] == expected
        np.testing.assert_allclose(result.q[-1], given.q[-1], atol=1e-5)
        file = tmp_path / "scene.json"
        file.write_text(json.dumps(d))
        run = subprocess.run([sys.executable, "-m", "odyn", "run", str(file), "--t-end", "0.02"],
                             capture_output=True, text=True)
        assert run.returncode == 0, run.stderr
        assert run.stdout.splitlines()[1].startswith("auto" if removed else "generalized-alpha")


def test_the_energy_line_tells_work_from_drift(tmp_path, capsys):
    """The summary's energy line names the elements whose work changes kinetic + potential
    energy (a driven, damped run is not drifting), and calls the change a drift only where
    every force has a potential."""
    from odyn import cli
    assert cli.main(["run", str(ROOT / "examples" / "slider_crank_planar.json"), "--t-end",
                     "0.02"]) == 0
    assert "through the work of load, gas force (not an error)" in capsys.readouterr().out
    m = odyn.PlanarModel()
    m.add_body(name="bar", mass=1.0, inertia=1 / 12, position=[0.5, 0])
    m.add_revolute(name="pivot", body_a="ground", body_b="bar", on_b=odyn.frame([-0.5, 0]))
    m.add_gravity(name="gravity", acceleration=[0, -9.81])
    m.add_rsda(name="spring", body_a="ground", body_b="bar", stiffness=5.0)
    path = tmp_path / "pendulum.json"
    odyn.save(m, path)
    assert cli.main(["run", str(path), "--t-end", "0.1"]) == 0
    printed = capsys.readouterr().out
    assert "largest drift" in printed and "this is the integration's error" in printed
    m.add_tsda(name="damper", body_a="ground", point_a=[1, 1], body_b="bar", damping=0.5)
    odyn.save(m, path)
    assert cli.main(["run", str(path), "--t-end", "0.1"]) == 0
    assert "through the work of damper (not an error)" in capsys.readouterr().out
