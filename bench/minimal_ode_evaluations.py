"""How many evaluations the engine's own equation of motion needs for a given theta(1) error.

The engine of shared/specs/engine.md reduced to its one minimal coordinate theta (the same
equation as tests/reference/engine_reference.hpp), integrated by SciPy's LSODA (variable-order
Adams while not stiff) and DOP853 with every stroke boundary theta = n pi located as an event and
the integration restarted there. The counts are a floor for any integrator of these families:
odyn's integrators solve the 18-coordinate system at each evaluation, so CPU time is about
these counts times the cost of one evaluation of the full system (see docs/benchmarks.md's
work-precision section).

    python bench/minimal_ode_evaluations.py     # needs numpy and scipy (pip install scipy)
"""

import sys
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

sys.path.insert(0, str(Path(__file__).resolve().parent))
from engine_equation import OMEGA0, angular_acceleration  # noqa: E402


def theta_at_one_second(method, tol):
    """theta(1) and the number of evaluations, restarting at every stroke boundary."""
    t, y, half_turn, evaluations = 0.0, np.array([0.0, OMEGA0]), 0, 0
    while t < 1.0:
        boundary = (half_turn + 1) * np.pi
        stroke = half_turn % 4

        def rate(_, state, stroke=stroke):
            return [state[1], angular_acceleration(stroke, state[0], state[1])]

        def crossing(_, state, boundary=boundary):
            return state[0] - boundary

        crossing.terminal, crossing.direction = True, 1
        solution = solve_ivp(rate, (t, 1.0), y, method=method, rtol=tol, atol=tol,
                             events=crossing)
        evaluations += solution.nfev
        t, y = solution.t[-1], solution.y[:, -1].copy()
        if solution.status != 1:
            break
        half_turn += 1
        y[0] = boundary
    return y[0], evaluations


def main():
    # The C++ reference (RK4 at h = 1e-5 with exact stroke boundaries) gives 158.286033924795;
    # DOP853 at 3e-14 lands within about 1e-10 of it, below every error in the table.
    reference, _ = theta_at_one_second("DOP853", 3e-14)
    print(f"theta(1) = {reference:.12f} rad (DOP853 at tol 3e-14)")
    print(f"{'method':8} {'tol':>7} {'theta(1) error':>15} {'evaluations':>12}")
    for method in ("LSODA", "DOP853"):
        for tol in (1e-8, 1e-9, 1e-10, 1e-11):
            theta, evaluations = theta_at_one_second(method, tol)
            print(f"{method:8} {tol:7.0e} {abs(theta - reference):15.2e} {evaluations:12d}")


if __name__ == "__main__":
    main()
