"""Events (Model.add_event): crossings located within steps, against closed forms: a compound
pendulum's turning points at its exact half periods (elliptic integral), a mass on a spring
passing its free length at a quarter period, a ball stopped by a terminal event on the floor;
the engine's top dead centres and gas pressure in joint coordinates, with generalized-alpha and
with auto as with dop853 in absolute ones; scene files, the CLI and bad input."""

import json
import math
import subprocess
import sys

import numpy as np
import pytest

import odyn
from test_points_and_outputs import spring_mass  # 2 kg on 800 N/m, free length 0.5, L(0) 0.55

G = 9.81


def elliptic_k(k):
    """The complete elliptic integral of the first kind, by the arithmetic-geometric mean."""
    a, b = 1.0, math.sqrt(1.0 - k * k)
    for _ in range(30):
        a, b = 0.5 * (a + b), math.sqrt(a * b)
    return math.pi / (2.0 * a)


# Released below the horizontal, so that the tip's horizontal velocity vanishes only where
# the bar turns.
MASS, INERTIA, ARM, ANGLE0 = 1.2, 0.03, 0.4, 1.4
PERIOD = 4.0 * math.sqrt((INERTIA + MASS * ARM ** 2) / (MASS * G * ARM)) * elliptic_k(
    math.sin(0.5 * ANGLE0))


def pendulum():
    """A bar pivoted ARM above its centre, released at rest ANGLE0 from hanging down."""
    m = odyn.PlanarModel()
    m.add_body(name="bar", mass=MASS, inertia=INERTIA, angle=ANGLE0,
               position=[ARM * math.sin(ANGLE0), -ARM * math.cos(ANGLE0)])
    m.add_revolute(name="pivot", body_a="ground", body_b="bar", on_b=odyn.frame([0, ARM]))
    m.add_gravity(name="gravity", acceleration=[0, -G])
    m.add_point("tip", "bar", at=[0, -ARM])
    return m


@pytest.mark.parametrize("integrator", ["dop853", "bdf", "generalized-alpha"])
def test_a_pendulums_turning_points_are_its_half_periods(integrator):
    m = pendulum()
    # The tip's horizontal velocity vanishes where the bar turns; so does a function of the bar.
    m.add_event("turn", point=("tip", "velocity", "x"))
    m.add_event("back", function=lambda t, bar: bar.angular_velocity, bodies=["bar"],
                direction="rising")
    r = odyn.simulate(m, t_end=2.2 * PERIOD, output_interval=0.01, integrator=integrator,
                      step=1e-4, rtol=1e-10, atol=1e-10, adaptive=False if
                      integrator == "generalized-alpha" else None)
    turns = r.event_times("turn")
    # About 10 times the errors measured: 3.6e-15 s, 1.3e-11 s, 1.5e-7 s (its phase error).
    tolerance = {"dop853": 1e-10, "bdf": 1e-9, "generalized-alpha": 1e-6}[integrator]
    np.testing.assert_allclose(turns, PERIOD / 2 * np.arange(1, 5), atol=tolerance)
    assert [e.direction for e in r.events if e.name == "turn"] == [
        "rising", "falling", "rising", "falling"]  # the tip swings back to -x first
    np.testing.assert_allclose(r.event_times("back"), PERIOD * np.array([0.5, 1.5]),
                               atol=tolerance)
    assert r.ended_by is None and len(r.events) == 6
    assert [e.time for e in r.events] == sorted(e.time for e in r.events)


def test_an_output_event_ends_the_run_where_the_spring_passes_its_free_length():
    # L = 0.5 + 0.05 cos(w t): the free length at a quarter period, falling.
    m = spring_mass()
    m.add_event("free", output=("spring", "length"), value=0.5, direction="falling",
                terminal=True)
    r = odyn.simulate(m, t_end=1.0, output_interval=0.01, integrator="dop853", rtol=1e-11,
                      atol=1e-11)
    w = math.sqrt(800.0 / 2.0)
    assert r.ended_by == "free"
    assert r.events == [odyn.Event("free", r.t[-1], "falling", True)]
    assert r.t[-1] == pytest.approx(math.pi / (2 * w), abs=1e-10)
    assert r.output("spring", "tension")[-1] == pytest.approx(0.0, abs=1e-7)
    assert r.output("spring", "rate")[-1] == pytest.approx(-0.05 * w, rel=1e-9)
    assert r.t[-2] < r.t[-1] and np.all(np.diff(r.t) > 0)


def test_a_terminal_event_stops_a_falling_ball_on_the_floor():
    m = odyn.PlanarModel()
    m.add_body(name="ball", mass=0.5, inertia=1e-3, position=[0, 1.1])
    m.add_gravity(name="gravity", acceleration=[0, -G])
    m.add_point("bottom", "ball", at=[0, -0.1])
    m.add_event("floor", point=("bottom", "position", "y"), direction="falling",
                terminal=True)
    for integrator in ("dop853", "generalized-alpha"):
        r = odyn.simulate(m, t_end=2.0, step=1e-3, output_interval=0.01,
                          integrator=integrator)
        landing = math.sqrt(2 * 1.0 / G)
        assert r.ended_by == "floor" and r.t[-1] == pytest.approx(landing, abs=1e-9)
        assert r.point("bottom").position[-1, 1] == pytest.approx(0.0, abs=1e-9)
        assert r.body("ball").linear_velocity[-1, 1] == pytest.approx(-G * landing, rel=1e-9)


def engine_events(**settings):
    """The engine's top dead centres (its crank pin's vertical velocity falling through zero;
    it starts on one, which does not count) and the gas pressure rising through 1 MPa."""
    from conftest import ENGINE_SCENE
    scene = odyn.load(ENGINE_SCENE)
    scene.model.add_point("pin", "crank", at=[0, 0, 0.04])
    scene.model.add_event("top", point=("pin", "velocity", "z"), direction="falling")
    scene.model.add_event("pressure", output=("gas force", "pressure"), value=1e6,
                          direction="rising")
    r = scene.simulate(t_end=0.2, **settings)
    return r, {name: r.event_times(name) for name in ("top", "pressure")}


def test_the_engines_events_agree_across_coordinates_and_integrators():
    """Absolute against joint coordinates (recursive), and generalized-alpha (shorter attempts,
    the gas force's law switches inside its steps) and auto against dop853: the same events,
    each within the other method's accuracy (measured: 2.3e-9 s for generalized-alpha at
    h = 1e-5 s, 3.6e-8 s for auto at 1e-9)."""
    reference, expected = engine_events(coordinates="absolute", integrator="dop853",
                                        rtol=1e-10, atol=1e-10)
    assert reference.summary["coordinates"] == "absolute"
    assert len(expected["top"]) == 5 and len(expected["pressure"]) == 3
    for settings, tolerance in (
            ({"coordinates": "joint", "integrator": "dop853", "rtol": 1e-10, "atol": 1e-10},
             1e-8),
            ({"coordinates": "absolute", "integrator": "generalized-alpha", "step": 1e-5}, 1e-8),
            ({"rtol": 1e-9, "atol": 1e-9}, 3e-7)):
        r, times = engine_events(**settings)
        if "coordinates" in settings:
            assert r.summary["coordinates"] == settings["coordinates"]
        for name in expected:
            np.testing.assert_allclose(times[name], expected[name], atol=tolerance,
                                       err_msg=f"{name} with {settings}")


def test_events_in_scene_files_and_the_cli(tmp_path):
    m = spring_mass()
    m.add_point("centre", "mass")
    m.add_event("low", point=("centre", "position", "z"), value=-0.5, direction="rising")
    m.add_event("free", output=("spring", "length"), value=0.5, terminal=False)
    scene = odyn.Scene(m, {"t_end": 0.3, "output_interval": 0.01, "integrator": "dop853",
                           "rtol": 1e-10, "atol": 1e-10})
    path = tmp_path / "spring.json"
    odyn.save(scene, str(path))
    saved = json.loads(path.read_text())
    assert [e["name"] for e in saved["events"]] == ["low", "free"]
    loaded = odyn.load(str(path))
    assert loaded.model.event("free") == m.event("free")
    r = loaded.simulate()
    w = math.sqrt(800.0 / 2.0)
    # Both watch L = 0.5 + 0.05 cos(w t) pass 0.5: at (2k + 1) pi / (2 w).
    expected = (2 * np.arange(3) + 1) * math.pi / (2 * w)
    np.testing.assert_allclose(r.event_times("free"), expected[expected < 0.3], atol=1e-9)
    np.testing.assert_allclose(r.event_times("low"), expected[expected < 0.3][::2], atol=1e-9)
    out = subprocess.run([sys.executable, "-m", "odyn", "run", str(path), "--out",
                          str(tmp_path / "spring.csv")], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert "events (3): " in out.stdout and "low rising at 0.0785398" in out.stdout
    # A function event cannot be saved.
    m.add_event("f", function=lambda t: t - 0.1)
    with pytest.raises(odyn.SceneError, match="events: 'f'.*cannot be saved"):
        odyn.save(odyn.Scene(m, {}), str(tmp_path / "no.json"))


@pytest.mark.parametrize("given, message", [
    ({}, "give one quantity to watch"),
    ({"output": ("spring", "length"), "point": ("centre", "position", "z")},
     "got output, point"),
    ({"output": ("spring", "force")}, "expected one of length, rate, tension"),
    ({"output": ("mass", "length")}, "no element named 'mass'"),
    ({"point": ("centre", "acceleration", "z")}, "position or velocity"),
    ({"point": ("rim", "position", "z")}, "no point named 'rim'"),
    ({"point": ("centre", "position", "w")}, "expected one of x, y, z"),
    ({"output": ("spring", "length"), "direction": "up"}, "expected one of rising"),
    ({"output": ("spring", "length"), "bodies": ["mass"]}, "only a function event"),
    ({"function": lambda t: t, "bodies": ["wheel"]}, "no body named 'wheel'"),
    ({"function": 3.0}, "expected a Python callable"),
    ({"output": ("spring", "length"), "value": "high"}, "value"),
])
def test_bad_events_are_refused_by_name(given, message):
    m = spring_mass()
    m.add_point("centre", "mass")
    with pytest.raises(odyn.SceneError, match=message):
        m.add_event("e", **given)


def test_an_exception_in_an_event_function_stops_the_run():
    m = spring_mass()

    def broken(t):
        if t > 0.01:
            raise ZeroDivisionError("no")
        return 1.0
    m.add_event("broken", function=broken)
    with pytest.raises(ZeroDivisionError) as raised:
        odyn.simulate(m, t_end=0.1, integrator="dop853")
    assert 1 <= len(raised.value.result) and raised.value.result.t[-1] < 0.1
