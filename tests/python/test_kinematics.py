"""Kinematic analysis (odyn.kinematics) against a slider-crank's closed form, with the motor's
torque from the power balance; its refusals; and the model report (odyn.check) against
Gruebler's count and the known mobility of over-constrained linkages."""

import math

import numpy as np
import pytest

import odyn
from conftest import python_example

R, L = 0.1, 0.35  # crank radius and rod length, m
MASS = {"crank": 2.0, "rod": 1.5, "piston": 0.8}
INERTIA = {"crank": 4e-3, "rod": 0.02, "piston": 1e-3}


def slider_crank(omega, rod=L, second_motor=False):
    """A planar slider-crank, crank along x at t = 0, its angle driven at omega rad/s (and,
    with second_motor, by a second motor on the same joint: one driver too many)."""
    m = odyn.PlanarModel()
    m.add_body(name="crank", mass=MASS["crank"], inertia=INERTIA["crank"], position=[R / 2, 0])
    m.add_body(name="rod", mass=MASS["rod"], inertia=INERTIA["rod"], position=[R + rod / 2, 0])
    m.add_body(name="piston", mass=MASS["piston"], inertia=INERTIA["piston"],
               position=[R + rod, 0])
    m.add_revolute(name="main", body_a="ground", body_b="crank", on_b=odyn.frame([-R / 2, 0]))
    m.add_revolute(name="crank_pin", body_a="crank", on_a=odyn.frame([R / 2, 0]), body_b="rod",
                   on_b=odyn.frame([-rod / 2, 0]))
    m.add_revolute(name="wrist_pin", body_a="rod", on_a=odyn.frame([rod / 2, 0]),
                   body_b="piston")
    m.add_translational(name="cylinder", body_a="ground", on_a=odyn.frame([0, 0], [1, 0]),
                        body_b="piston", on_b=odyn.frame([0, 0], [1, 0]))
    if omega is not None:
        m.add_revolute_driver(name="motor", joint="main", motion=odyn.constant_velocity(omega))
    if second_motor:
        m.add_revolute_driver(name="second", joint="main", motion=odyn.constant_velocity(omega))
    return m


def closed_form(theta, omega):
    """Piston travel x, rod angle phi and the rod's centre, with their first and second time
    derivatives, at crank angle theta turning at constant omega (derivatives in theta times
    omega and omega^2)."""
    s, c = math.sin(theta), math.cos(theta)
    d = math.sqrt(L * L - R * R * s * s)
    x = (R * c + d, -R * s - R * R * s * c / d,
         -R * c - R * R * (c * c - s * s) / d - R ** 4 * s * s * c * c / d ** 3)
    phi = (-math.asin(R * s / L), -R * c / d, R * s / d - R ** 3 * s * c * c / d ** 3)
    # The rod's centre: halfway between the crank pin (R c, R s) and the wrist pin (x, 0).
    centre_x = (0.5 * (R * c + x[0]), 0.5 * (-R * s + x[1]), 0.5 * (-R * c + x[2]))
    centre_y = (0.5 * R * s, 0.5 * R * c, -0.5 * R * s)
    scale = (1.0, omega, omega * omega)
    return [tuple(k * f for k, f in zip(scale, q)) for q in (x, phi, centre_x, centre_y)]


# The paths of a kinematic analysis: dense matrices, sparse rows, joint coordinates.
PATHS = {"dense": {"linear_solver": "dense"}, "klu": {"linear_solver": "klu"},
         "joint": {"coordinates": "joint"}}


@pytest.mark.parametrize("path", list(PATHS))
def test_a_driven_slider_crank_follows_its_closed_form_and_power_balance(path):
    omega = 20.0
    r = odyn.kinematics(slider_crank(omega), t_end=0.5, output_interval=0.01, **PATHS[path])
    assert len(r) == 51 and r.kinematics["outputs"] == 51
    piston, rod = r.body("piston"), r.body("rod")
    torque = r.reaction("motor").torque
    largest_torque = 0.0
    for k, t in enumerate(r.t):
        x, phi, cx, cy = closed_form(omega * t, omega)
        assert piston.position[k, 0] == pytest.approx(x[0], abs=1e-12)
        assert piston.linear_velocity[k, 0] == pytest.approx(x[1], abs=1e-11)
        assert piston.linear_acceleration[k, 0] == pytest.approx(x[2], abs=1e-9)
        assert math.remainder(rod.angle[k] - phi[0], 2 * math.pi) == pytest.approx(0, abs=1e-12)
        assert rod.angular_velocity[k] == pytest.approx(phi[1], abs=1e-11)
        assert rod.angular_acceleration[k] == pytest.approx(phi[2], abs=1e-9)
        # The motor's power is the rate of the kinetic energy (no other force works): the
        # crank turns steadily, so only the rod and the piston take it.
        power = (MASS["piston"] * x[1] * x[2] + MASS["rod"] * (cx[1] * cx[2] + cy[1] * cy[2])
                 + INERTIA["rod"] * phi[1] * phi[2])
        assert torque[k] == pytest.approx(power / omega, abs=1e-9)
        largest_torque = max(largest_torque, abs(power / omega))
    assert largest_torque > 1.0  # the check above is not vacuous
    np.testing.assert_array_less(r.phi_norm, 1e-12)


def test_the_joints_carry_what_the_equations_of_motion_ask():
    """At every time the forces on the piston balance its inertia: the wrist pin's and the
    cylinder's reactions sum to m a (gravity off)."""
    r = odyn.kinematics(slider_crank(30.0), t_end=0.2, output_interval=0.02)
    on_piston = (r.reaction("wrist_pin", side="b").force + r.reaction("cylinder", side="b").force)
    np.testing.assert_allclose(on_piston, MASS["piston"] * r.body("piston").linear_acceleration,
                               atol=1e-9)


def test_a_mechanism_with_freedom_left_is_refused_by_name():
    with pytest.raises(odyn.ModelError, match="1 degree of freedom remain.*drivers: none"):
        odyn.kinematics(slider_crank(None), t_end=0.1)


def test_an_over_driven_mechanism_names_the_driver():
    with pytest.raises(odyn.ModelError, match="over-driven: driver 'second'"):
        odyn.kinematics(slider_crank(10.0, second_motor=True), t_end=0.1)


@pytest.mark.parametrize("path", list(PATHS))
def test_a_lock_up_is_named_with_its_time_and_keeps_the_rows_before_it(path):
    """With the rod shorter than the crank, the crank cannot pass R sin(theta) = rod."""
    omega, rod = 10.0, 0.06
    lock = math.asin(rod / R) / omega
    with pytest.raises(odyn.AssemblyError, match="locks up") as error:
        odyn.kinematics(slider_crank(omega, rod=rod), t_end=0.5, output_interval=0.005,
                        **PATHS[path])
    rows = error.value.result
    assert 0 < len(rows) and rows.t[-1] <= lock < rows.t[-1] + 0.005 + 1e-12


def test_bad_settings_are_refused_by_name():
    with pytest.raises(odyn.SceneError, match="output_interval"):
        odyn.kinematics(slider_crank(1.0), output_interval=0.0)
    with pytest.raises(odyn.SceneError, match="max_halvings"):
        odyn.kinematics(slider_crank(1.0), max_halvings=-1)
    with pytest.raises(odyn.SceneError, match="linear_solver"):
        odyn.kinematics(slider_crank(1.0), linear_solver="umfpack")
    with pytest.raises(odyn.SceneError, match="coordinates"):
        odyn.kinematics(slider_crank(1.0), coordinates="auto")
    with pytest.raises(odyn.ModelError, match="asks for 1e\\+300 outputs"):
        odyn.kinematics(slider_crank(1.0), output_interval=1e-300)


def driven_chain(links, driven=True):
    """A planar chain of 0.5 m links hinged end to end from the ground, straight along x, each
    hinge's angle driven at 1 rad/s (or left free)."""
    m = odyn.PlanarModel()
    for i in range(links):
        m.add_body(name=f"link{i}", mass=1.0, inertia=0.02, position=[0.25 + 0.5 * i, 0])
        m.add_revolute(name=f"hinge{i}", body_a="ground" if i == 0 else f"link{i - 1}",
                       on_a=odyn.frame([0 if i == 0 else 0.25, 0]), body_b=f"link{i}",
                       on_b=odyn.frame([-0.25, 0]))
        if driven:
            m.add_revolute_driver(name=f"motor{i}", joint=f"hinge{i}",
                                  motion=odyn.constant_velocity(1.0))
    return m


def test_a_large_driven_chain_curls_as_its_motors_say():
    """400 links (2400 velocities and equations: the sparse path). Each hinge turns at 1 rad/s,
    so link i turns at (i + 1) rad/s and the chain curls into arcs of a circle."""
    links = 400
    r = odyn.kinematics(driven_chain(links), t_end=0.02, output_interval=0.01)
    assert len(r) == 3
    for i in (0, 1, links // 2, links - 1):
        link = r.body(f"link{i}")
        np.testing.assert_allclose(link.angle, (i + 1) * r.t, atol=1e-12)
        np.testing.assert_allclose(link.angular_velocity, i + 1, rtol=1e-12)
        np.testing.assert_allclose(link.angular_acceleration, 0, atol=1e-9)
    # The tip's hinge point: the sum of the links' half-length steps along their angles.
    t = r.t[-1]
    angles = (np.arange(links) + 1) * t
    tip = 0.5 * np.array([np.cos(angles).sum(), np.sin(angles).sum()])
    last = r.body(f"link{links - 1}")
    end = last.position[-1] + 0.25 * np.array([math.cos(last.angle[-1]), math.sin(last.angle[-1])])
    np.testing.assert_allclose(end, tip, atol=1e-10)


def test_check_counts_the_freedom_of_a_large_chain():
    """600 undriven hinges: 600 degrees of freedom, from the sparse rank pass."""
    report = odyn.check(driven_chain(600, driven=False))
    assert (report.velocities, report.equations, report.rank) == (1800, 1200, 1200)
    assert report.degrees_of_freedom == 600 and report.redundant_equations == []


def test_check_counts_a_slider_crank():
    report = odyn.check(slider_crank(None))
    assert (report.velocities, report.equations, report.rank) == (9, 8, 8)
    assert report.gruebler == 1 and report.degrees_of_freedom == 1
    assert report.redundant_equations == [] and report.drivers == []
    driven = odyn.check(slider_crank(5.0))
    assert driven.fully_driven and driven.drivers == ["motor"]
    assert "fully driven" in str(driven)


def spatial_four_bar():
    """A planar four-bar built of spatial bodies and revolute joints: Gruebler's count says -2,
    the linkage moves with 1 degree of freedom, so 3 of its equations are redundant."""
    crank, coupler, rocker, base = 0.4, 1.0, 0.8, 1.0
    a = np.array([0.0, crank])  # the crank stands up
    # The coupler-rocker pin: on both circles, above the base.
    d = np.array([base, 0.0]) - a
    dist = np.linalg.norm(d)
    along = (coupler ** 2 - rocker ** 2 + dist ** 2) / (2 * dist)
    normal = np.array([-d[1], d[0]]) / dist
    b = a + along * d / dist + math.sqrt(coupler ** 2 - along ** 2) * normal
    m = odyn.Model()

    def link(name, p, q):
        angle = math.atan2(q[1] - p[1], q[0] - p[0])
        centre = 0.5 * (p + q)
        m.add_body(name=name, mass=1.0, inertia=[0.01, 0.1, 0.1],
                   position=[centre[0], centre[1], 0.0],
                   orientation=[math.cos(angle / 2), 0, 0, math.sin(angle / 2)])
        return 0.5 * np.linalg.norm(q - p)

    h1 = link("crank", np.zeros(2), a)
    h2 = link("coupler", a, b)
    h3 = link("rocker", np.array([base, 0.0]), b)
    z = [0, 0, 1]
    m.add_revolute(name="o2", body_a="ground", on_a=odyn.frame([0, 0, 0], z), body_b="crank",
                   on_b=odyn.frame([-h1, 0, 0], z))
    m.add_revolute(name="a", body_a="crank", on_a=odyn.frame([h1, 0, 0], z), body_b="coupler",
                   on_b=odyn.frame([-h2, 0, 0], z))
    m.add_revolute(name="b", body_a="coupler", on_a=odyn.frame([h2, 0, 0], z), body_b="rocker",
                   on_b=odyn.frame([h3, 0, 0], z))
    m.add_revolute(name="o4", body_a="ground", on_a=odyn.frame([base, 0, 0], z), body_b="rocker",
                   on_b=odyn.frame([-h3, 0, 0], z))
    return m


def test_check_finds_the_redundant_equations_of_a_spatial_four_bar():
    with pytest.warns(odyn.RedundantConstraintsWarning):
        odyn.assemble(spatial_four_bar())  # a run warns of them too
    report = odyn.check(spatial_four_bar())
    assert (report.velocities, report.equations) == (18, 20)
    assert report.gruebler == -2 and report.degrees_of_freedom == 1 and report.rank == 17
    assert len(report.redundant_equations) == 3
    assert set(report.overconstraining) <= {"o2", "a", "b", "o4"}
    assert "redundant equations (3)" in str(report)
    assert report.assembly["position_residual"] < 1e-12


def test_check_names_the_velocities_assembly_kept_and_changed():
    """A pendulum bob below its hinge: of a velocity along x and the matching spin, which the
    one degree of freedom ties together, the first is held and the second follows unchanged; a
    radial velocity is changed."""
    def pendulum(velocity, spin):
        m = odyn.PlanarModel()
        m.add_body(name="bob", mass=1.0, inertia=0.01, position=[0, -1],
                   linear_velocity=velocity, angular_velocity=spin)
        m.add_revolute(name="hinge", body_a="ground", body_b="bob", on_b=odyn.frame([0, 1]))
        return m

    kept = odyn.check(pendulum([2.0, 0.0], 2.0))
    assert kept.kept_velocities == ["bob.x"] and kept.adjusted_velocities == []
    assert kept.state.body("bob").angular_velocity[0] == pytest.approx(2.0, abs=1e-12)
    spun = odyn.check(pendulum([2.0, 0.0], 3.0))  # the spin disagrees: it is changed to 2
    assert spun.kept_velocities == ["bob.x"] and spun.adjusted_velocities == ["bob.angle"]
    assert "given velocities changed to meet the constraints: bob.angle" in str(spun)
    changed = odyn.check(pendulum([0.0, 1.0], 0.0))
    assert "bob.y" in changed.adjusted_velocities
    assert changed.state.body("bob").linear_velocity[0] == pytest.approx([0, 0], abs=1e-12)


def test_scenes_name_the_analysis_and_the_command_line_runs_it(tmp_path, capsys):
    from odyn import cli
    omega = 20.0
    scene = odyn.Scene(slider_crank(omega),
                       analysis={"type": "kinematic", "t_end": 0.3, "output_interval": 0.05},
                       outputs=[{"name": "x", "body": "piston", "quantity": "position",
                                 "component": "x"},
                                {"name": "torque", "reaction": "motor", "quantity": "torque"}])
    path = tmp_path / "slider_crank.json"
    odyn.save(scene, path)
    assert odyn.load(path).analysis_type == "kinematic"
    out = tmp_path / "out.csv"
    assert cli.main(["run", str(path), "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "kinematic analysis, t_end = 0.3 s: 7 outputs" in printed
    assert "driver motor: largest effort" in printed
    table = np.genfromtxt(out, delimiter=",", names=True)
    for t, x in zip(table["t"], table["x"]):
        assert x == pytest.approx(closed_form(omega * t, omega)[0][0], abs=1e-11)
    # On sparse rows, as a large model's analysis runs, and in joint coordinates.
    for option in (["--linear-solver", "klu"], ["--coordinates", "joint"]):
        assert cli.main(["run", str(path), *option, "--quiet", "--out", str(out)]) == 0
        other = np.genfromtxt(out, delimiter=",", names=True)
        for t, x in zip(other["t"], other["x"]):
            assert x == pytest.approx(closed_form(omega * t, omega)[0][0], abs=1e-11)
        np.testing.assert_allclose(other["torque"], table["torque"],
                                   atol=1e-10 * np.abs(table["torque"]).max())
    # Asked for by name instead, the dynamic analysis runs the same scene (the driver moves
    # the crank as before).
    assert cli.main(["run", str(path), "--analysis", "dynamic", "--quiet", "--rtol", "1e-10",
                     "--atol", "1e-10", "--out", str(out)]) == 0
    table = np.genfromtxt(out, delimiter=",", names=True)
    assert table["x"][-1] == pytest.approx(closed_form(omega * 0.3, omega)[0][0], abs=1e-8)
    # A setting of another analysis is refused by name.
    assert cli.main(["run", str(path), "--integrator", "dop853"]) == 1
    assert "--integrator: not a setting of a kinematic analysis" in capsys.readouterr().err
    assert cli.main(["check", str(path)]) == 0
    printed = capsys.readouterr().out
    assert "degrees of freedom: 0 (Gruebler's count 0" in printed and "fully driven" in printed


def test_the_command_line_finds_an_equilibrium_and_its_modes(tmp_path, capsys):
    """A bar hinged at one end under gravity, held by a torsional spring: its equilibrium angle
    from the moment balance and its frequency from the stiffness there."""
    from odyn import cli
    k, rest = 10.0, 1.2
    m = odyn.PlanarModel()
    m.add_body(name="bar", mass=1.0, inertia=1.0 / 12, position=[0, -0.5])
    m.add_revolute(name="pivot", body_a="ground", body_b="bar", on_b=odyn.frame([0, 0.5]))
    m.add_rsda(name="spring", body_a="ground", body_b="bar", stiffness=k, free_angle=rest)
    m.add_gravity(name="gravity", acceleration=[0, -9.81])
    path = tmp_path / "bar.json"
    odyn.save(odyn.Scene(m, analysis={"type": "static"},
                         outputs=[{"name": "angle", "body": "bar", "quantity": "angle"}]), path)
    lo, hi = 0.0, rest  # bisection on k (theta - rest) + m g d sin(theta) = 0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if k * (mid - rest) + 9.81 * 0.5 * math.sin(mid) < 0 else (lo, mid)
    theta = 0.5 * (lo + hi)
    out = tmp_path / "rest.csv"
    assert cli.main(["run", str(path), "--out", str(out)]) == 0
    assert "static equilibrium by newton" in capsys.readouterr().out
    table = np.genfromtxt(out, delimiter=",", names=True)
    assert float(table["angle"]) == pytest.approx(theta, abs=1e-12)
    gif = tmp_path / "mode.gif"
    assert cli.main(["run", str(path), "--analysis", "modes", "--out", str(out),
                     "--gif", str(gif)]) == 0
    assert gif.stat().st_size > 0
    assert "1 mode; the lowest" in capsys.readouterr().out
    table = np.genfromtxt(out, delimiter=",", names=True)
    omega2 = (k + 9.81 * 0.5 * math.cos(theta)) / (1.0 / 3)
    assert float(table["frequency"]) == pytest.approx(math.sqrt(omega2) / (2 * math.pi),
                                                      rel=1e-9)
    assert cli.main(["run", str(path), "--plot", str(tmp_path / "p.png")]) == 1
    assert "a static analysis gives one configuration" in capsys.readouterr().err


def test_a_scene_refuses_settings_its_analysis_does_not_take():
    with pytest.raises(odyn.SceneError, match=r"analysis\.integrator: does not apply to a "
                       "kinematic analysis, which takes t_end, output_interval, max_iterations"):
        odyn.Scene(slider_crank(1.0), analysis={"type": "kinematic", "integrator": "dop853"})
    with pytest.raises(odyn.SceneError, match=r"analysis\.type: expected one of dynamic, "):
        odyn.Scene(slider_crank(1.0), analysis={"type": "transient"})
    with pytest.raises(odyn.SceneError, match=r"analysis\.coordinates: expected one of "
                       "absolute, joint, got 'auto'"):
        odyn.Scene(slider_crank(1.0), analysis={"type": "static", "coordinates": "auto"})


def recorded_motion(t, theta, omega, alpha):
    """g, g' and g'' of a motion recorded at the times t (angle, rate and acceleration), by
    quintic Hermite interpolation on each interval: exact at the samples."""
    def piece(x):
        k = int(np.clip(np.searchsorted(t, x) - 1, 0, len(t) - 2))
        h = t[k + 1] - t[k]
        s = (x - t[k]) / h
        # Coefficients of the quintic in s matching value, slope and curvature at both ends.
        y0, y1 = theta[k], theta[k + 1]
        d0, d1 = omega[k] * h, omega[k + 1] * h
        c0, c1 = alpha[k] * h * h, alpha[k + 1] * h * h
        a3 = 10 * (y1 - y0) - 6 * d0 - 4 * d1 - 1.5 * c0 + 0.5 * c1
        a4 = -15 * (y1 - y0) + 8 * d0 + 7 * d1 + 1.5 * c0 - c1
        a5 = 6 * (y1 - y0) - 3 * d0 - 3 * d1 - 0.5 * c0 + 0.5 * c1
        coefficients = [y0, d0, 0.5 * c0, a3, a4, a5]
        value = sum(a * s ** i for i, a in enumerate(coefficients))
        slope = sum(i * a * s ** (i - 1) for i, a in enumerate(coefficients) if i)
        curve = sum(i * (i - 1) * a * s ** (i - 2) for i, a in enumerate(coefficients) if i > 1)
        return value, slope / h, curve / (h * h)
    return odyn.motion_function(lambda x: piece(x)[0], lambda x: piece(x)[1],
                                lambda x: piece(x)[2])


def test_the_engine_driven_at_its_simulated_crank_angle_gives_back_gas_and_load_torques():
    """Inverse dynamics of a recorded motion: the engine's dynamic run (gas force, load, gravity)
    gives the crank angle theta(t); the engine without gas force and load, its crank driven along
    theta(t), needs a motor torque whose power is the gas force's and the load's:
    tau omega = F_z v_piston - c omega^2 (gravity does the same work in both)."""
    import odyn_engine
    build = python_example("engine").build

    dynamic = odyn.simulate(build(), t_end=0.1, output_interval=5e-4, integrator="dop853",
                            rtol=1e-11, atol=1e-11)
    crank = dynamic.body("crank")
    theta = dynamic.state("gas force")["theta"]
    omega, alpha = crank.angular_velocity[:, 0], crank.angular_acceleration[:, 0]
    gas = dynamic.output("gas force", "force")
    v_piston = dynamic.body("piston").linear_velocity[:, 2]
    c_load = 0.1
    expected = (gas * v_piston - c_load * omega ** 2) / omega

    driven = build()
    assert driven.module is odyn_engine
    m = odyn.Model()  # the same engine from the core catalogue, without gas force and load
    for name in driven.body_names[1:]:
        m.add_body(**{k: v for k, v in driven.body(name).items() if k != "angular_velocity"})
    for name in ("bearing", "crank pin", "piston pin", "cylinder", "gravity"):
        m.add(driven.element_type(name), **driven.element(name))
    m.add_revolute_driver(name="motor", joint="bearing",
                          motion=recorded_motion(dynamic.t, theta, omega, alpha))
    r = odyn.kinematics(m, t_end=0.1, output_interval=5e-3)
    torque = r.reaction("motor").torque[:, 0]
    samples = np.searchsorted(dynamic.t, r.t - 1e-12)
    np.testing.assert_allclose(r.t, dynamic.t[samples], atol=1e-12)
    error = np.max(np.abs(torque - expected[samples]))
    largest = np.max(np.abs(expected[samples]))
    assert largest > 100.0  # a combustion lies within the run
    assert error < 1e-8 * largest, f"torque error {error:.3g} of {largest:.3g} N m"
    # The piston follows too: the kinematic run's motion is the dynamic one's.
    np.testing.assert_allclose(r.body("piston").position[:, 2],
                               dynamic.body("piston").position[samples, 2], atol=1e-10)
