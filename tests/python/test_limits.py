"""Stops on joint coordinates (revolute_limit and translational_limit, spatial and planar),
against closed forms: the restitution that odyn.hunt_crossley_dissipation promises, the onset
of a free rotation at its exact time, a pendulum on a stop under gravity at its static
penetration (from the torque balance), a stop past half a turn; scene files and bad input."""

import json
import math

import numpy as np
import pytest

import odyn

G = 9.81


def rotor(space, rate=4.0):
    """A disc spinning freely at `rate` about a hinge to the ground (z), no gravity."""
    if space == "spatial":
        m = odyn.Model()
        m.add_body("disc", 1.0, [0.025, 0.025, 0.05], angular_velocity=[0, 0, rate])
    else:
        m = odyn.PlanarModel()
        m.add_body("disc", 1.0, 0.05, angular_velocity=rate)
    m.add_revolute("hinge", "ground", body_b="disc")
    return m


@pytest.mark.parametrize("space", ["spatial", "planar"])
@pytest.mark.parametrize("restitution", [0.8, 0.4])
def test_a_stop_returns_the_restitution_it_was_given(space, restitution):
    """The disc reaches the upper stop at 0.25 s and leaves it at e times its rate; the onset,
    an event on the clearance, at the free rotation's time (upper / rate)."""
    rate, upper = 4.0, 1.0
    m = rotor(space, rate)
    d = odyn.hunt_crossley_dissipation(restitution, rate)
    m.add_revolute_limit("stop", joint="hinge", lower=-2.0, upper=upper, stiffness=50.0,
                         exponent=1.5, dissipation=d)
    m.add_event("onset", output=("stop", "clearance"), direction="falling")
    r = odyn.simulate(m, t_end=0.6, output_interval=0.01, integrator="dop853", rtol=1e-11,
                      atol=1e-13)
    angle, torque = r.output("stop", "angle"), r.output("stop", "torque")
    assert r.output("stop", "rate")[-1] == pytest.approx(-restitution * rate, rel=1e-7)
    assert angle.max() > upper and torque.min() < 0 and torque[-1] == 0
    np.testing.assert_allclose(r.output("stop", "clearance"),
                               np.minimum(upper - angle, angle + 2.0), atol=1e-12)
    assert r.event_times("onset")[0] == pytest.approx(upper / rate, abs=1e-9)


@pytest.mark.parametrize("coordinates", ["absolute", "joint"])
@pytest.mark.parametrize("integrator", ["dop853", "generalized-alpha", "auto"])
def test_a_pendulum_rests_on_its_stop_at_the_static_penetration(coordinates, integrator):
    """A bar hinged at one end, held out horizontal by a stop at 0 that gravity presses on:
    m g l/2 = k delta (n = 1) at rest."""
    mass, length, k = 2.0, 0.8, 400.0
    m = odyn.PlanarModel()
    m.add_body("bar", mass, mass * length ** 2 / 12, position=[length / 2, 0])
    m.add_revolute("pivot", "ground", on_a={"point": [0, 0]}, body_b="bar",
                   on_b={"point": [-length / 2, 0]})
    m.add_gravity("gravity", [0, -G])
    m.add_revolute_limit("stop", joint="pivot", lower=0.0, stiffness=k, exponent=1.0,
                         dissipation=2.5)  # near critical damping
    r = odyn.simulate(m, t_end=4.0, output_interval=0.1, integrator=integrator,
                      coordinates=coordinates, step=1e-3)
    # At rest below the stop, where the stop's torque k delta cos-free balances the weight's.
    delta = mass * G * length / 2 * math.cos(-r.output("stop", "angle")[-1]) / k
    assert -r.output("stop", "angle")[-1] == pytest.approx(delta, rel=1e-6)
    assert r.output("stop", "torque")[-1] == pytest.approx(k * delta, rel=1e-6)


def test_a_slider_on_an_incline_rests_on_its_stop():
    """A slider on a guide rising at 30 degrees, on a lower stop with n = 1.5: k delta^1.5 =
    m g sin(30 deg)."""
    mass, k, n = 3.0, 2e4, 1.5
    axis = [math.cos(math.pi / 6), 0.0, math.sin(math.pi / 6)]
    m = odyn.Model()
    m.add_body("slider", mass, [0.1, 0.1, 0.1])
    m.add_translational("guide", "ground", on_a={"axis": axis}, body_b="slider",
                        on_b={"axis": axis})
    m.add_translational_limit("stop", joint="guide", lower=-0.01, upper=0.5, stiffness=k,
                              exponent=n, dissipation=10.0)
    m.add_gravity("gravity", [0, 0, -G])
    r = odyn.simulate(m, t_end=3.0, output_interval=0.1, integrator="generalized-alpha",
                      step=1e-3)
    depth = (mass * G * 0.5 / k) ** (1 / n)
    assert r.output("stop", "position")[-1] == pytest.approx(-0.01 - depth, rel=1e-8)
    assert r.output("stop", "force")[-1] == pytest.approx(mass * G * 0.5, rel=1e-6)
    assert r.output("stop", "clearance")[-1] == pytest.approx(-depth, rel=1e-6)


def test_a_stop_past_half_a_turn_counts_turns():
    """A one-sided stop at 4 rad (past pi) on a spatial hinge: reached at 4 / rate, not at the
    angle's wrap; with no dissipation the rotor comes back at its full rate."""
    rate = 5.0
    m = rotor("spatial", rate)
    m.add_revolute_limit("stop", joint="hinge", upper=4.0, stiffness=20.0)
    m.add_event("onset", output=("stop", "clearance"), direction="falling")
    r = odyn.simulate(m, t_end=1.2, output_interval=0.01, integrator="dop853", rtol=1e-11,
                      atol=1e-13)
    assert r.event_times("onset")[0] == pytest.approx(4.0 / rate, abs=1e-9)
    assert r.output("stop", "rate")[-1] == pytest.approx(-rate, rel=1e-8)
    assert r.output("stop", "angle").max() > 4.0


def test_stops_in_a_scene_file(tmp_path):
    m = rotor("planar")
    m.add_revolute_limit("stop", joint="hinge", lower=-1.0, upper=1.0, stiffness=50.0)
    path = tmp_path / "stop.json"
    odyn.save(odyn.Scene(m, {"t_end": 0.6, "output_interval": 0.01, "integrator": "dop853"}),
              str(path))
    saved = json.loads(path.read_text())
    (stop,) = [f for f in saved["forces"] if f["name"] == "stop"]
    assert stop["type"] == "revolute_limit" and stop["body_b"] == "disc"
    r = odyn.load(str(path)).simulate()
    assert r.output("stop", "angle").max() > 1.0
    stop.pop("body_a"), stop.pop("body_b"), stop.pop("on_a"), stop.pop("on_b")
    stop["joint"] = "hinge"
    path.write_text(json.dumps(saved))
    assert odyn.load(str(path)).simulate().output("stop", "angle").max() > 1.0
    stop["joint"] = "nowhere"
    path.write_text(json.dumps(saved))
    with pytest.raises(odyn.SceneError, match="nowhere"):
        odyn.load(str(path))


@pytest.mark.parametrize("kwargs, words", [
    ({"joint": "hinge", "stiffness": 10.0}, "neither lower nor upper"),
    ({"joint": "hinge", "lower": 1.0, "upper": 0.5, "stiffness": 10.0}, "below upper"),
    ({"joint": "hinge", "upper": 1.0, "stiffness": 0.0}, "stiffness"),
    ({"joint": "hinge", "upper": 1.0, "stiffness": 1.0, "exponent": 0.5}, "exponent"),
    ({"joint": "hinge", "upper": 1.0, "stiffness": 1.0, "dissipation": -1.0}, "dissipation"),
    ({"joint": "slide", "upper": 1.0, "stiffness": 1.0}, "no revolute or cylindrical joint"),
    ({"joint": "hinge", "body_a": "ground", "upper": 1.0, "stiffness": 1.0}, "either 'joint'"),
    ({"upper": 1.0, "stiffness": 1.0}, "body_a"),
    ({"joint": "hinge", "upper": 1.0, "stiffness": 1.0, "limit": 2.0}, "limit"),
    ({"joint": "hinge", "upper": float("nan"), "stiffness": 1.0}, "upper"),
])
def test_bad_stops_are_refused_by_name(kwargs, words):
    m = rotor("spatial")
    m.add_body("block", 1.0, [0.1, 0.1, 0.1])
    m.add_translational("slide", "ground", body_b="block")
    with pytest.raises((odyn.ModelError, ValueError, TypeError)) as error:
        m.add_revolute_limit("stop", **kwargs)
    assert words in str(error.value)
