"""The bad-input catalogue: each kind of bad input gets a specific error naming the element,
setting or place, the bad value and what to do, through the Python API, scene files and the
command line alike, and keeps what was computed so far. Many of these once slipped through
(accepted silently, or answered with a traceback or a vague message; issue 28 lists them).
tests/python/test_fuzz.py fuzzes the scene loader beyond these kinds; an exception raised in a
user function is tested in test_elements.py."""

import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

import odyn
from conftest import ROOT
from test_kinematics import slider_crank

SCENE = ROOT / "examples" / "slider_crank_planar.json"


def falling_stone():
    m = odyn.Model()
    m.add_body(name="stone", mass=1.0, inertia=[0.1, 0.1, 0.1])
    m.add_gravity(name="gravity", acceleration=[0, 0, -9.81])
    return m


def scene_dict():
    with open(SCENE) as f:
        return json.load(f)


def pendulum():
    m = odyn.Model()
    m.add_body(name="bob", mass=1.0, inertia=[1e-3, 1e-3, 1e-3], position=[1, 0, 0])
    m.add_revolute(name="hinge", body_a="ground", on_a=odyn.frame([0, 0, 0], [0, 0, 1]),
                   body_b="bob", on_b=odyn.frame([-1, 0, 0], [0, 0, 1]))
    m.add_gravity(name="gravity", acceleration=[0, -9.81, 0])
    return m


def with_force(function):
    """A pendulum with a point force given by `function`, run for 0.01 s."""
    m = pendulum()
    m.add_point_force(name="push", body="bob", force=function)
    return odyn.simulate(m, t_end=0.01)


def contradicted():
    """The pendulum with a second hinge about x, 0.5 m along z: no pose meets both."""
    m = pendulum()
    m.add_revolute(name="second hinge", body_a="ground", on_a=odyn.frame([0, 0, 0.5], [1, 0, 0]),
                   body_b="bob", on_b=odyn.frame([-1, 0, 0.5], [0, 0, 1]))
    return m


NAN = float("nan")
# (kind, an action on the Python API, the exception, the words its message must hold)
BAD_MODELS = [
    ("a mass of zero", lambda: odyn.Model().add_body(name="a", mass=0.0, inertia=[1, 1, 1]),
     odyn.SceneError, ["body 'a'.mass", "positive", "0"]),
    ("a mass of NaN", lambda: odyn.Model().add_body(name="a", mass=NAN, inertia=[1, 1, 1]),
     odyn.SceneError, ["body 'a'.mass", "finite", "nan"]),
    ("an inertia no body has", lambda: odyn.Model().add_body(name="a", mass=1, inertia=[1, 1, 5]),
     odyn.SceneError, ["triangle inequality", "(1 1 5)"]),
    ("an asymmetric inertia tensor", lambda: odyn.Model().add_body(
        name="a", mass=1, inertia=[[1, 0.5, 0], [0, 1, 0], [0, 0, 1]]),
     odyn.SceneError, ["body 'a'", "symmetric"]),
    ("an indefinite inertia tensor", lambda: odyn.Model().add_body(
        name="a", mass=1, inertia=[[1, 2, 0], [2, 1, 0], [0, 0, 1]]),
     odyn.SceneError, ["body 'a'", "positive definite"]),
    ("an empty name", lambda: odyn.Model().add_body(name="", mass=1, inertia=[1, 1, 1]),
     odyn.SceneError, ["name", "non-empty"]),
    ("a body named ground", lambda: odyn.Model().add_body(name="ground", mass=1,
                                                           inertia=[1, 1, 1]),
     odyn.SceneError, ["'ground' is already used"]),
    ("a name used twice", lambda: pendulum().add_body(name="bob", mass=1, inertia=[1, 1, 1]),
     odyn.SceneError, ["'bob' is already used"]),
    ("a joint on an unknown body", lambda: pendulum().add_revolute(
        name="h2", body_a="ground", body_b="bobb"),
     odyn.SceneError, ["revolute 'h2'.body_b", "no body named 'bobb'", "ground, bob"]),
    ("a misspelled keyword", lambda: pendulum().add_revolute(name="h2", body_a="ground",
                                                             body_bb="bob"),
     TypeError, ["body_bb"]),
    ("a zero axis", lambda: pendulum().add_revolute(
        name="h2", body_a="ground", on_a=odyn.frame([0, 0, 0], [0, 0, 0]), body_b="bob"),
     odyn.SceneError, ["revolute 'h2'.on_a.axis", "zero-length"]),
    ("a reference parallel to the axis", lambda: pendulum().add_revolute(
        name="h2", body_a="ground", on_a=odyn.frame([0, 0, 0], [0, 0, 1], [0, 0, 1]),
        body_b="bob"),
     odyn.SceneError, ["h2", "parallel to its axis"]),
    ("an axis with NaN", lambda: pendulum().add_revolute(
        name="h2", body_a="ground", on_a=odyn.frame([0, 0, 0], [0, NAN, 1]), body_b="bob"),
     odyn.SceneError, ["revolute 'h2'.on_a.axis[1]", "finite"]),
    ("a velocity_given of 5 flags", lambda: odyn.Model().add_body(
        name="a", mass=1, inertia=[1, 1, 1], velocity_given=[True] * 5),
     odyn.SceneError, ["velocity_given", "6 booleans"]),
    ("a driver of an unknown joint", lambda: pendulum().add_revolute_driver(
        name="motor", joint="hindge", motion=odyn.constant_velocity(1.0)),
     odyn.SceneError, ["revolute_driver 'motor'.joint", "'hindge'"]),
    ("a motion that is not one", lambda: pendulum().add_revolute_driver(
        name="motor", joint="hinge", motion=5),
     odyn.SceneError, ["'motor'.motion", "expected a motion"]),
    ("a motion with NaN", lambda: pendulum().add_revolute_driver(
        name="motor", joint="hinge", motion=odyn.constant_velocity(NAN)),
     odyn.SceneError, ["'motor'.motion.rate", "finite"]),
    ("an event on an unknown point", lambda: pendulum().add_event(
        "e", point=("rim", "position", "x")),
     odyn.SceneError, ["event 'e'.point", "no point named 'rim'"]),
    ("a force function returning NaN", lambda: with_force(lambda t, b: (NAN, 0.0, 0.0)),
     ValueError, ["point_force 'push'", "non-finite"]),
    ("a force function returning two numbers", lambda: with_force(lambda t, b: (1.0, 2.0)),
     TypeError, ["point_force 'push'", "3 numbers"]),
    ("a free mechanism in a kinematic analysis", lambda: odyn.kinematics(pendulum(), t_end=0.1),
     odyn.ModelError, ["fully driven", "1 degree of freedom", "its drivers: none"]),
    ("a static tolerance of zero", lambda: odyn.statics(pendulum(), tolerance=0.0),
     odyn.SceneError, ["tolerance", "positive"]),
    ("an unknown reaction", lambda: odyn.simulate(pendulum(), t_end=0.01).reaction("hindge"),
     KeyError, ["hindge", "constraints: hinge"]),
    ("contradictory joints", lambda: odyn.simulate(contradicted(), t_end=0.01),
     odyn.AssemblyError, ["could not be satisfied", "at joint 'second hinge'", "axes"]),
    ("a spring with a free length between coincident points",
     lambda: odyn.simulate(coincident_spring(), t_end=0.01),
     odyn.ModelError, ["spring", "points coincide", "-10 N", "no direction"]),
]


def coincident_spring():
    """The pendulum with a spring of free length 0.1 m from the hinge's point to the bob's
    point on it: once, it stored 1/2 k 0.1^2 while pushing with nothing."""
    m = pendulum()
    m.add_tsda(name="spring", body_a="ground", body_b="bob", point_b=[-1, 0, 0],
               stiffness=100.0, free_length=0.1)
    return m


@pytest.mark.parametrize("kind, action, exception, words", BAD_MODELS,
                         ids=[case[0] for case in BAD_MODELS])
def test_bad_models_are_refused_by_name(kind, action, exception, words):
    with pytest.raises(exception) as error:
        action()
    for word in words:
        assert word in str(error.value), (kind, str(error.value))


# (kind, the run's keyword arguments, the words its error must hold)
BAD_RUN_SETTINGS = [
    ("a relative tolerance of 1e300", {"rtol": 1e300}, ["rtol", "at most 1"]),
    ("a relative tolerance of 2", {"rtol": 2.0}, ["rtol", "at most 1"]),
    ("a negative Newton tolerance", {"integrator": "generalized-alpha", "newton_rtol": -1e-9},
     ["newton_rtol", "positive", "-1e-09"]),
    ("a Newton rtol of 2", {"integrator": "generalized-alpha", "newton_rtol": 2.0},
     ["newton_rtol", "at most 1"]),
    ("a zero constraint tolerance", {"integrator": "bdf", "constraint_tolerance": 0.0},
     ["constraint_tolerance", "positive"]),
    ("no Newton iterations", {"integrator": "generalized-alpha", "max_iterations": 0},
     ["max_iterations", "at least 1"]),
    ("a fractional iteration count", {"integrator": "generalized-alpha", "max_iterations": 2.5},
     ["max_iterations", "whole number"]),
    ("a negative projection tolerance", {"integrator": "dop853", "projection_tolerance": -1e-12},
     ["projection_tolerance", "positive"]),
    ("an output interval too short to count", {"output_interval": 1e-300},
     ["1e-300", "give a longer interval"]),
    ("a step too short to advance time", {"integrator": "generalized-alpha", "step": 1e-300},
     ["step", "1e-300", "time would not advance"]),
    ("a progress function that is not one", {"progress": 3}, ["progress", "callable"]),
]


@pytest.mark.parametrize("kind, settings, words", BAD_RUN_SETTINGS,
                         ids=[case[0] for case in BAD_RUN_SETTINGS])
def test_run_settings_are_refused_by_name(kind, settings, words):
    with pytest.raises(odyn.ModelError) as error:
        odyn.simulate(falling_stone(), t_end=0.01, **settings)
    for word in words:
        assert word in str(error.value), (kind, str(error.value))


@pytest.mark.parametrize("integrator", ["generalized-alpha", "dop853", "bdf", "auto"])
def test_a_run_ends_at_t_end_between_two_outputs(integrator):
    # Once the run stopped at the last whole output (0.01 for t_end 0.015), and an interval
    # longer than the run gave its first row alone. The stone falls z = -g t^2 / 2.
    for t_end, interval, times in ((0.015, 0.01, [0.0, 0.01, 0.015]), (0.015, 0.5, [0.0, 0.015])):
        r = odyn.simulate(falling_stone(), t_end=t_end, output_interval=interval,
                          integrator=integrator, step=1e-3, rtol=1e-10, atol=1e-10)
        np.testing.assert_allclose(r.t, times, rtol=1e-14, atol=0)
        np.testing.assert_allclose(r.q[:, 2], -0.5 * 9.81 * r.t ** 2, rtol=0, atol=1e-9)


class Broke(Exception):
    pass


def breaks_at(when):
    """A force that raises once past `when` seconds."""
    def force(t, bob):
        if t > when:
            raise Broke(f"broke at t = {t}")
        return (0.0, 0.0, 0.0)
    return force


@pytest.mark.parametrize("integrator", ["generalized-alpha", "dop853", "bdf", "auto"])
def test_a_failed_run_keeps_what_it_counted(integrator):
    """A run that stops on an error keeps its statistics (once None): as many outputs as rows,
    and about the steps of a whole run to the time it broke."""
    settings = {"integrator": integrator, "step": 1e-3, "output_interval": 0.01}
    if integrator != "generalized-alpha":
        settings.update(rtol=1e-8, atol=1e-8)
    m = pendulum()
    m.add_point_force(name="push", body="bob", force=breaks_at(0.3))
    with pytest.raises(Broke) as error:
        odyn.simulate(m, t_end=1.0, **settings)
    partial = error.value.result
    assert not partial.complete and partial.error.startswith("Broke")
    assert partial.statistics is not None
    assert partial.statistics.outputs == len(partial.t)
    whole = odyn.simulate(pendulum(), t_end=0.3, **settings)
    assert abs(partial.statistics.steps - whole.statistics.steps) <= 2, (
        partial.statistics.steps, whole.statistics.steps)


@pytest.mark.parametrize("analysis", [odyn.simulate, odyn.kinematics, odyn.statics,
                                      odyn.quasi_statics, odyn.modes, odyn.linearize,
                                      odyn.check, odyn.assemble])
def test_an_analysis_of_something_that_is_not_a_model_says_so(analysis):
    with pytest.raises(TypeError, match="model: expected an odyn.Model or odyn.PlanarModel"):
        analysis("engine.json")


@pytest.mark.parametrize("orientation", [[2, 0, 0, 0], [0.5, 0.5, 0.5, 0.4]])
def test_an_orientation_that_is_not_a_unit_quaternion_is_refused(orientation):
    # It was scaled to one silently; a rounded unit quaternion still passes.
    m = odyn.Model()
    with pytest.raises(odyn.SceneError, match=r"body 'a'.orientation: expected a unit quaternion"):
        m.add_body(name="a", mass=1.0, inertia=[1, 1, 1], orientation=orientation)
    m.add_body(name="b", mass=1.0, inertia=[1, 1, 1], orientation=[0.7071, 0, 0, 0.7071])
    with pytest.raises(odyn.SceneError, match=r"point 'p'.orientation: expected a unit"):
        m.add_point("p", "b", orientation=orientation)


# (kind, how the scene dict is spoiled, the words the error must hold)
def _set(path, value):
    def spoil(d):
        target = d
        for key in path[:-1]:
            target = target[key]
        target[path[-1]] = value
    return spoil


BAD_SCENES = [
    ("analysis of 0", _set(["analysis"], 0), ["analysis", "expected an object", "leave it out"]),
    ("analysis of null", _set(["analysis"], None), ["analysis", "null", "leave it out"]),
    ("analysis of []", _set(["analysis"], []), ["analysis", "expected an object"]),
    ("analysis of an empty string", _set(["analysis"], ""), ["analysis", "expected an object"]),
    ("analysis of false", _set(["analysis"], False), ["analysis", "false"]),
    ("analysis of [1]", _set(["analysis"], [1]), ["analysis", "[1]"]),
    ("a huge integer for a mass", _set(["bodies", 0, "mass"], 10 ** 400),
     ["bodies[0].mass", "finite number", "401 digits"]),
    ("a lone surrogate in a name", _set(["bodies", 0, "name"], "crank\ud800"),
     ["bodies[0].name", "lone surrogate"]),
    ("a relative tolerance of 1e300", _set(["analysis", "rtol"], 1e300),
     ["analysis.rtol", "at most 1"]),
    ("a figure outside the figures' folder", _set(["figures", 0, "file"], "../../x.png"),
     ["figures[0].file", "not a file name"]),
    ("a figure in a format that cannot be drawn", _set(["figures", 0, "file"], "x.txt"),
     ["figures[0].file", ".png"]),
]


@pytest.mark.parametrize("kind, spoil, words", BAD_SCENES, ids=[case[0] for case in BAD_SCENES])
def test_scenes_are_refused_with_the_place(kind, spoil, words, tmp_path):
    d = scene_dict()
    spoil(d)
    with pytest.raises(odyn.SceneError) as error:
        odyn.loads(json.dumps(d))
    for word in words:
        assert word in str(error.value), (kind, str(error.value))
    # The command line says the same in one line, without a traceback.
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(d))  # a lone surrogate is written escaped, as a file would hold
    run = subprocess.run([sys.executable, "-m", "odyn", "run", str(path)], capture_output=True,
                         text=True)
    assert run.returncode == 1, run.stderr
    assert run.stderr.startswith("odyn: ") and run.stderr.count("\n") == 1, run.stderr
    assert words[0] in run.stderr


SCENE_TEXTS = [
    ("a list at the top", lambda text: "[" + text + "]", ["scene: expected a JSON object"]),
    ("a file cut in half", lambda text: text[:len(text) // 2], ["not valid JSON", "line"]),
    ("a key given twice", lambda text: text.replace('"mass": 1.399', '"mass": 1.399, "mass": 2'),
     ["'mass' appears twice", "remove one"]),
    ("nesting thousands deep", lambda text: text[:-2] + ', "x": ' + "[" * 100000
     + "]" * 100000 + "}", ["nested too deeply"]),
]


@pytest.mark.parametrize("kind, spoil, words", SCENE_TEXTS, ids=[case[0] for case in SCENE_TEXTS])
def test_scene_texts_are_refused(kind, spoil, words, tmp_path):
    text = spoil(SCENE.read_text().rstrip() + "\n")
    with pytest.raises(odyn.SceneError) as error:
        odyn.loads(text, "bad.json")
    for word in words:
        assert word in str(error.value), (kind, str(error.value))
    path = tmp_path / "bad.json"
    path.write_text(text)
    run = subprocess.run([sys.executable, "-m", "odyn", "check", str(path)],
                         capture_output=True, text=True)
    assert run.returncode == 1 and "Traceback" not in run.stderr, run.stderr
    assert words[0] in run.stderr


def test_a_scene_file_that_is_not_utf8(tmp_path):
    path = tmp_path / "latin1.json"
    path.write_bytes(SCENE.read_bytes().replace(b'"crank"', b'"crank\xe9"', 1))
    with pytest.raises(odyn.SceneError, match=r"latin1.json: not UTF-8 text \(byte 0xe9 at "
                                              r"offset \d+\); save the scene as UTF-8"):
        odyn.load(path)


@pytest.mark.parametrize("option, words", [
    (["--out", "missing/r.csv"], ["--out missing/r.csv: the folder", "does not exist"]),
    (["--out", "folder.csv"], ["is a directory"]),
    (["--out", "r.txt"], ["expected a .csv or .npz"]),
    (["--out", "/proc/r.csv"], ["--out /proc/r.csv: cannot be written here"]),
    (["--gif", "r.txt"], ["--gif r.txt: expected a .gif file name"]),
    (["--gif", "missing/r.gif"], ["--gif missing/r.gif: the folder", "does not exist"]),
    (["--plot", "r.txt"], ["--plot r.txt: expected a file name ending in one of", ".png"]),
    (["--figures", "/proc/figures"], ["--figures /proc/figures: cannot create the folder"]),
])
def test_an_output_the_cli_could_not_write_is_refused_before_the_run(option, words, tmp_path):
    (tmp_path / "folder.csv").mkdir()
    # t_end 1e4 s: a run that started would take minutes, and the test's timeout stops it.
    run = subprocess.run([sys.executable, "-m", "odyn", "run", str(SCENE), "--t-end", "1e4",
                          *option], capture_output=True, text=True, cwd=tmp_path, timeout=120)
    assert run.returncode == 1, run.stderr
    for word in words:
        assert word in run.stderr, run.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["folder.csv"]  # nothing left behind


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes anywhere")
def test_an_unwritable_output_folder_is_refused_before_the_run(tmp_path):
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o500)
    try:
        run = subprocess.run([sys.executable, "-m", "odyn", "run", str(SCENE), "--t-end", "1e4",
                              "--out", str(locked / "r.csv")], capture_output=True, text=True,
                             timeout=120)
    finally:
        locked.chmod(0o700)
    assert run.returncode == 1 and "not writable" in run.stderr, run.stderr


def test_a_failed_run_says_where_its_partial_table_went(tmp_path):
    path = tmp_path / "locking.json"
    # A slider-crank whose rod (0.06 m) is shorter than its crank (0.1 m), turned at 10 rad/s:
    # it locks up where 0.1 sin(theta) = 0.06, at t = asin(0.6) / 10 = 0.0644 s.
    odyn.save(odyn.Scene(slider_crank(10.0, rod=0.06), {"type": "kinematic", "t_end": 0.5,
                                                       "output_interval": 0.005}), path)
    run = subprocess.run([sys.executable, "-m", "odyn", "run", str(path), "--out", "r.csv"],
                         capture_output=True, text=True, cwd=tmp_path)
    assert run.returncode == 1, run.stderr
    assert "locks up" in run.stderr
    rows = (tmp_path / "r.csv").read_text().splitlines()[1:]
    last = float(rows[-1].split(",")[0])
    lock = math.asin(0.6) / 10.0
    assert last <= lock < last + 0.005 + 1e-12
    assert f"the {len(rows)} rows before the error, to t = {last:g} s, were written to r.csv" \
        in run.stderr, run.stderr
    assert not (tmp_path / "r.csv.part").exists()


def test_a_table_is_written_whole_or_not_at_all(tmp_path, monkeypatch):
    # An interruption while writing (a second Ctrl-C) leaves the earlier file as it was.
    path = tmp_path / "r.csv"
    path.write_text("t\n0\n")
    table = {"t": np.arange(1000.0), "x": np.arange(1000.0)}
    calls = {"n": 0}
    real_writerow = odyn.scene.csv.writer

    class Interrupting:
        def __init__(self, f, **kwargs):
            self.writer = real_writerow(f, **kwargs)

        def writerow(self, row):
            calls["n"] += 1
            if calls["n"] == 500:
                raise KeyboardInterrupt
            self.writer.writerow(row)

    monkeypatch.setattr(odyn.scene.csv, "writer", Interrupting)
    with pytest.raises(KeyboardInterrupt):
        odyn.scene.write_table(table, path)
    assert path.read_text() == "t\n0\n"
    assert not (tmp_path / "r.csv.part").exists()
    monkeypatch.undo()
    odyn.scene.write_table(table, path)
    assert path.read_text().count("\n") == 1001
