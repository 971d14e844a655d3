"""Typed settings (odyn.settings): they mirror the C++ defaults, every field reaches the C++ run
and changes what it does, bad values are refused by name, and scenes and the command line take
them too."""

import dataclasses
import json
import math
import re
import subprocess
import sys
import warnings

import pytest

import odyn
from odyn import _core
from odyn.settings import INTEGRATOR_SETTINGS, integrator_settings


def pendulum(start=1.0):
    """A 1 m pendulum of a point-like bob, released at rest `start` rad from hanging."""
    m = odyn.PlanarModel()
    m.add_body(name="bob", mass=1.0, inertia=1e-6,
               position=[math.sin(start), -math.cos(start)], angle=start)
    m.add_revolute(name="pin", body_a="ground", body_b="bob", on_b=odyn.frame([0, 1]))
    m.add_gravity(name="gravity", acceleration=[0, -9.81])
    return m


@pytest.fixture(scope="module")
def reference():
    """The pendulum's angle at t = 1 s from dop853 at 1e-13 (a converged run of another
    method than the ones compared with it)."""
    r = odyn.simulate(pendulum(), t_end=1.0, output_interval=0.5,
                      integrator=odyn.Dop853(rtol=1e-13, atol=1e-13))
    return r.body("bob").angle[-1]


def angle_at_end(**keywords):
    r = odyn.simulate(pendulum(), t_end=1.0, output_interval=0.5, **keywords)
    return r.body("bob").angle[-1], r.statistics


def test_the_defaults_are_the_cpp_library_s():
    cpp = _core.default_settings()
    for cls in INTEGRATOR_SETTINGS.values():
        if cls.SECTION is None:
            continue
        defaults = {f.name: f.default for f in dataclasses.fields(cls) if f.name in
                    cls.own_fields()}
        for name, value in cpp[cls.SECTION].items():
            assert defaults[name] == value or (name == "adaptive" and defaults[name] is None), (
                cls.__name__, name)
        assert set(defaults) == set(cpp[cls.SECTION]), cls.__name__
    assembly = {f.name: f.default for f in dataclasses.fields(odyn.AssemblySettings)}
    assert assembly == cpp["assembly"]
    # simulate's defaults for what the objects leave at None
    assert cpp["run"]["step"] == 1e-4 and cpp["run"]["rtol"] == cpp["run"]["atol"] == 1e-6


def test_every_integrator_has_its_settings_class():
    assert set(INTEGRATOR_SETTINGS) == set(odyn.integrators())


def test_every_field_goes_to_the_run(monkeypatch):
    """What simulate hands the compiled core: each field given, in its integrator's section."""
    sent = {}

    def capture(core, settings, progress):
        sent.update(settings)
        raise RuntimeError("captured")

    monkeypatch.setattr(_core, "simulate", capture)
    for cls in INTEGRATOR_SETTINGS.values():
        values = {}
        for f in dataclasses.fields(cls):
            if f.name in cls.own_fields():
                default = f.default
                values[f.name] = (not default if isinstance(default, bool) or default is None
                                  else default - 1 if isinstance(default, int)
                                  else default * 0.5)
        if "adaptive" in values:
            values["adaptive"] = True
        if cls is odyn.Hht:
            values["rho_inf"] = 0.7
        settings = cls(**values)
        sent.clear()
        with pytest.raises(RuntimeError, match="captured"):
            odyn.simulate(pendulum(), t_end=0.1, integrator=settings)
        assert sent["integrator"] == cls.NAME
        if cls.SECTION is not None:
            assert sent[cls.SECTION] == values, cls.__name__
    sent.clear()
    with pytest.raises(RuntimeError, match="captured"):
        odyn.simulate(pendulum(), t_end=0.1, assembly={"tolerance": 1e-10})
    assert sent["assembly"] == {"tolerance": 1e-10, "max_iterations": 50,
                                "warn_translation": 1e-5, "warn_rotation": 1e-5}


def test_bdf_s_highest_order_reaches_the_run(reference):
    """BDF held to order 1 needs many more steps for the same tolerance than up to order 5;
    both meet it against the reference."""
    high, high_stats = angle_at_end(integrator=odyn.Bdf(rtol=1e-6, atol=1e-6))
    low, low_stats = angle_at_end(integrator=odyn.Bdf(rtol=1e-6, atol=1e-6, max_order=1))
    assert abs(high - reference) < 1e-3 and abs(low - reference) < 1e-3
    assert low_stats.steps > 5 * high_stats.steps


def test_adams_order_reaches_the_run(reference):
    """At the same fixed step, Adams of order 1 is far less accurate than of order 5."""
    first, _ = angle_at_end(integrator=odyn.Adams(step=1e-3, order=1))
    fifth, _ = angle_at_end(integrator=odyn.Adams(step=1e-3, order=5))
    assert abs(fifth - reference) < 1e-7
    assert abs(first - reference) > 100 * abs(fifth - reference)


def test_generalized_alpha_s_factorization_reuse_reaches_the_run(reference):
    reused, reused_stats = angle_at_end(integrator=odyn.GeneralizedAlpha(step=1e-3))
    fresh, fresh_stats = angle_at_end(integrator=odyn.GeneralizedAlpha(step=1e-3,
                                                                       reuse_iterations=0))
    assert abs(reused - reference) < 1e-3 and abs(fresh - reference) < 1e-3
    assert fresh_stats.factorizations > reused_stats.factorizations


def test_the_assembly_s_warning_threshold_reaches_the_run():
    m = pendulum()
    m.add_body(name="loose", mass=1.0, inertia=0.1, position=[0.3, 0.0])
    m.add_revolute(name="stud", body_a="ground", body_b="loose")  # assembly moves it 0.3 m
    with pytest.warns(odyn.AssemblyWarning, match="'loose' by 0.3 m"):
        odyn.simulate(m, t_end=0.01)
    m = pendulum()
    m.add_body(name="loose", mass=1.0, inertia=0.1, position=[0.3, 0.0])
    m.add_revolute(name="stud", body_a="ground", body_b="loose")
    with warnings.catch_warnings():
        warnings.simplefilter("error", odyn.AssemblyWarning)
        odyn.simulate(m, t_end=0.01, assembly=odyn.AssemblySettings(warn_translation=1.0))


def test_a_keyword_beside_an_object_overrides_its_field():
    loose, loose_stats = angle_at_end(integrator=odyn.Dop853(rtol=1e-3, atol=1e-3))
    tight, tight_stats = angle_at_end(integrator=odyn.Dop853(rtol=1e-3, atol=1e-3), rtol=1e-11,
                                      atol=1e-11)
    assert tight_stats.steps > 3 * loose_stats.steps
    with pytest.raises(odyn.SceneError, match="order: dop853 has no setting 'order'"):
        odyn.simulate(pendulum(), t_end=0.1, integrator=odyn.Dop853(), order=3)


def test_a_dict_is_a_settings_object():
    a, _ = angle_at_end(integrator={"name": "bdf", "rtol": 1e-6, "atol": 1e-6, "max_order": 2})
    b, _ = angle_at_end(integrator=odyn.Bdf(rtol=1e-6, atol=1e-6, max_order=2))
    assert a == b


@pytest.mark.parametrize("build, words", [
    (lambda: odyn.Bdf(max_order=6), ["Bdf.max_order", "from 1 to 5", "6"]),
    (lambda: odyn.Dop853(rtol=2.0), ["Dop853.rtol", "at most 1"]),
    (lambda: odyn.Dopri5(atol=-1e-9), ["Dopri5.atol", "positive"]),
    (lambda: odyn.GeneralizedAlpha(rho_inf=1.5), ["GeneralizedAlpha.rho_inf", "[0, 1]"]),
    (lambda: odyn.Hht(rho_inf=0.3), ["Hht.rho_inf", "[0.5, 1]"]),
    (lambda: odyn.GeneralizedAlpha(max_iterations=0), ["max_iterations", "at least 1"]),
    (lambda: odyn.GeneralizedAlpha(adaptive="yes"), ["GeneralizedAlpha.adaptive", "yes"]),
    (lambda: odyn.Adams(rtol=1e-6), ["Adams.rtol", "fixed step"]),
    (lambda: odyn.Adams(order=7), ["Adams.order", "from 1 to 6"]),
    (lambda: odyn.AssemblySettings(tolerance=0.0), ["AssemblySettings.tolerance", "positive"]),
    (lambda: integrator_settings({"name": "dop853", "rtoll": 1e-8}),
     ["integrator.rtoll", "dop853 has no setting", "rtol"]),
    (lambda: integrator_settings({"rtol": 1e-8}), ["integrator", "missing 'name'"]),
    (lambda: integrator_settings({"name": "rk4"}), ["integrator.name", "'rk4'", "dop853"]),
    (lambda: integrator_settings({"name": "bdf", "max_order": 0}),
     ["integrator.max_order", "from 1 to 5"]),
    (lambda: integrator_settings(3), ["integrator", "settings object"]),
])
def test_bad_settings_are_refused_by_name(build, words):
    with pytest.raises(odyn.SceneError) as error:
        build()
    for word in words:
        assert word in str(error.value), str(error.value)


def scene(tmp_path, integrator, **beside):
    """The pendulum as a scene file whose analysis names `integrator`."""
    start = 1.0
    data = {
        "space": "planar",
        "bodies": [{"name": "bob", "mass": 1.0, "inertia": 1e-6, "angle": start,
                    "position": [math.sin(start), -math.cos(start)]}],
        "joints": [{"type": "revolute", "name": "pin", "body_a": "ground", "body_b": "bob",
                    "on_b": {"point": [0, 1]}}],
        "forces": [{"type": "gravity", "name": "gravity", "acceleration": [0, -9.81]}],
        "analysis": {"t_end": 1.0, "output_interval": 0.5, "integrator": integrator, **beside},
        "outputs": [{"name": "angle", "body": "bob", "quantity": "angle"}],
    }
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(data))
    return path


def test_a_scene_takes_a_settings_object_and_saves_it_back(tmp_path, reference):
    path = scene(tmp_path, {"name": "bdf", "rtol": 1e-7, "atol": 1e-7, "max_order": 3})
    loaded = odyn.load(path)
    assert loaded.analysis["integrator"] == odyn.Bdf(rtol=1e-7, atol=1e-7, max_order=3)
    r = loaded.run()
    assert abs(r.body("bob").angle[-1] - reference) < 1e-4
    odyn.save(loaded, tmp_path / "again.json")
    again = json.loads((tmp_path / "again.json").read_text())
    assert again["analysis"]["integrator"] == odyn.Bdf(rtol=1e-7, atol=1e-7,
                                                       max_order=3).to_dict()
    assert odyn.load(tmp_path / "again.json").analysis == loaded.analysis


def test_a_scene_refuses_settings_beside_its_object_and_names_a_bad_field(tmp_path):
    with pytest.raises(odyn.SceneError, match=r"analysis.rtol: give the integrator's settings"):
        odyn.load(scene(tmp_path, {"name": "bdf"}, rtol=1e-6))
    with pytest.raises(odyn.SceneError, match=r"analysis.integrator.max_order: expected a whole"):
        odyn.load(scene(tmp_path, {"name": "bdf", "max_order": 9}))


def test_the_command_line_s_tolerance_goes_into_the_scene_s_object(tmp_path):
    path = scene(tmp_path, {"name": "dop853", "rtol": 1e-3, "atol": 1e-3})
    runs = [subprocess.run([sys.executable, "-m", "odyn", "run", str(path), *extra,
                            "--out", str(tmp_path / f"{i}.csv")], capture_output=True, text=True)
            for i, extra in enumerate([[], ["--rtol", "1e-11", "--atol", "1e-11"]])]
    for run in runs:
        assert run.returncode == 0, run.stderr
    steps = [int(re.search(r"steps (\d+)", run.stdout).group(1)) for run in runs]
    assert steps[1] > 3 * steps[0], [run.stdout for run in runs]
