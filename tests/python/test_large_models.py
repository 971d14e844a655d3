"""Large models from Python: every linear solver gives the dense solver's run, the sparse path
keeps a rope's far links in free fall at first, a bad solver name is refused by name, and the
assembly runs once per model (checked again when a Python force or motion changed)."""

import numpy as np
import pytest

import odyn

G = 9.81


def rope(links, springs=False):
    """A horizontal chain of 1 m, 1 kg links on ball joints from the origin along x; optionally
    a spring-damper between neighbouring centres."""
    m = odyn.Model()
    previous = "ground"
    for i in range(links):
        name = f"link{i}"
        m.add_body(name=name, mass=1.0, inertia=[5e-5, 1 / 12, 1 / 12],
                   position=[0.5 + i, 0, 0])
        m.add_spherical(name=f"ball{i}", body_a=previous,
                        point_a=[0, 0, 0] if previous == "ground" else [0.5, 0, 0],
                        body_b=name, point_b=[-0.5, 0, 0])
        if springs and previous != "ground":
            m.add_tsda(name=f"spring{i}", body_a=previous, point_a=[0, 0, 0], body_b=name,
                       point_b=[0, 0, 0], stiffness=50.0, damping=0.5, free_length=1.0)
        previous = name
    m.add_gravity(name="gravity", acceleration=[0, 0, -G])
    return m


@pytest.mark.parametrize("springs", [False, True])
def test_every_linear_solver_runs_like_the_dense_one(springs):
    model = rope(40, springs)
    runs = {}
    for solver in ["dense", "auto", "klu"] + ([] if springs else ["cholmod"]):
        runs[solver] = odyn.simulate(model, t_end=0.2, step=1e-3, output_interval=0.01,
                                     linear_solver=solver)
    reference = runs.pop("dense")
    for solver, run in runs.items():
        # Newton stops within its tolerance on each path: the runs agree to that level (the
        # index-3 multipliers less closely than the positions: 6e-5 of the largest, measured).
        np.testing.assert_allclose(run.q, reference.q, atol=1e-7, err_msg=solver)
        np.testing.assert_allclose(run.lambda_, reference.lambda_,
                                   atol=3e-4 * np.abs(reference.lambda_).max(), err_msg=solver)


def test_a_long_rope_starts_in_free_fall():
    # 300 links (the rope): setup and steps on the sparse path. The far links of a
    # horizontal chain released from rest fall freely at first: z = -g t^2 / 2.
    result = odyn.simulate(rope(300), t_end=0.05, step=1e-3, output_interval=0.05)
    tip_z = result.body("link299").position[:, 2]
    assert abs(tip_z[-1] - (-0.5 * G * 0.05 ** 2)) < 1e-6
    assert result.phi_norm.max() < 1e-9


def test_an_unknown_linear_solver_is_refused_by_name():
    with pytest.raises(Exception, match="linear_solver"):
        odyn.simulate(rope(2), t_end=0.01, linear_solver="umfpack")
    with pytest.raises(Exception, match="linear_solver"):
        odyn.assemble(rope(2), linear_solver="lu")


def test_runs_after_the_first_start_from_its_assembly():
    model = rope(150)
    assembled = odyn.assemble(model)
    settings = dict(t_end=0.02, step=1e-3, output_interval=0.01)
    first = odyn.simulate(model, **settings)
    again = odyn.simulate(model, **settings)
    assert first.summary["assembly"]["reused"] and again.summary["assembly"]["reused"]
    # The reference: the same model built anew, assembled by its run. Same start, same run.
    fresh = odyn.simulate(rope(150), **settings)
    assert not fresh.summary["assembly"]["reused"]
    np.testing.assert_array_equal(first.q, fresh.q)
    np.testing.assert_array_equal(again.q, fresh.q)
    np.testing.assert_array_equal(assembled.q[0], fresh.q[0])
    # The far links fall freely at first: z = -g t^2 / 2.
    assert abs(first.body("link149").position[-1, 2] + 0.5 * G * 0.02 ** 2) < 1e-8
    # Other assembly settings, or a change of the model, assemble again.
    assert not odyn.simulate(model, linear_solver="klu", **settings).summary["assembly"]["reused"]
    model.add_body(name="loose", mass=1.0, inertia=[0.1] * 3, position=[0, 5, 0])
    assert not odyn.simulate(model, **settings).summary["assembly"]["reused"]


def test_a_python_force_changed_after_assemble_gives_new_accelerations():
    push = [0.0]
    m = odyn.Model()
    m.add_body(name="block", mass=2.0, inertia=[0.1] * 3)
    m.add_user_force(name="push", bodies=["block"],
                     function=lambda t, body: [push[0], 0, 0, 0, 0, 0])
    assert odyn.assemble(m).vdot[0, 0] == 0.0
    push[0] = 3.0
    r = odyn.simulate(m, t_end=0.1, step=1e-3, output_interval=0.05)
    assert r.summary["assembly"]["reused"]  # the positions and velocities still hold
    # F / m, and x = a t^2 / 2 (generalized-alpha is exact for a constant acceleration).
    np.testing.assert_allclose(r.vdot[0, 0], 1.5, rtol=1e-12)
    np.testing.assert_allclose(r.body("block").position[-1, 0], 0.5 * 1.5 * 0.1 ** 2, rtol=1e-9)


def test_a_python_motion_changed_after_assemble_assembles_again():
    angle = [0.0]
    m = odyn.Model()
    m.add_body(name="bob", mass=1.0, inertia=[1e-3] * 3, position=[1, 0, 0])
    m.add_revolute(name="hinge", body_a="ground", on_a=odyn.frame([0, 0, 0], [0, 0, 1]),
                   body_b="bob", on_b=odyn.frame([-1, 0, 0], [0, 0, 1]))
    m.add_revolute_driver(name="motor", joint="hinge", motion=odyn.motion_function(
        lambda t: angle[0], lambda t: 0.0, lambda t: 0.0))
    odyn.assemble(m)
    angle[0] = 0.3
    r = odyn.simulate(m, t_end=0.01, step=1e-3, output_interval=0.01)
    assert not r.summary["assembly"]["reused"]
    np.testing.assert_allclose(r.body("bob").position[:, :2],
                               [[np.cos(0.3), np.sin(0.3)]] * 2, atol=1e-10)
