"""How many evaluations the engine's own equation of motion needs for a given theta(1) error.

The engine of shared/specs/engine.md reduced to its one minimal coordinate theta (the same
equation as tests/reference/engine_reference.hpp), integrated by SciPy's LSODA (variable-order
Adams while not stiff) and DOP853 with every stroke boundary theta = n pi located as an event and
the integration restarted there. The counts are a floor for any integrator of these families:
odyn's integrators solve the 18-coordinate system at each evaluation, so CPU time is about
these counts times the cost of one evaluation of the full system (see the README's
work-precision section).

    python bench/minimal_ode_evaluations.py     # needs numpy and scipy (pip install scipy)
"""

import numpy as np
from scipy.integrate import solve_ivp

# shared/specs/engine.md
R, L, D, C = 0.04, 0.14, 0.08, 9.0
P_ATM, KAPPA, P_COMB = 101325.0, 1.4, 3.0e6
C_LOAD, G = 0.1, 9.81
M_ROD, M_PISTON, I_CRANK, I_ROD = 0.253, 0.643, 1.524, 0.399
OMEGA0 = 157.08
AREA = np.pi * D * D / 4
V_C = AREA * 2 * R / (C - 1)
V_1 = V_C + 2 * R * AREA


def angular_acceleration(stroke, theta, omega):
    """Lagrange's equation in theta, as in the C++ reference."""
    s, c = np.sin(theta), np.cos(theta)
    w = np.sqrt(L * L - R * R * s * s)
    dw = -R * R * s * c / w
    ddw = -(R * R * (c * c - s * s) + dw * dw) / w
    z_piston, dz_piston, ddz_piston = R * c + w, -R * s + dw, -R * c + ddw
    dz_rod, ddz_rod = -R * s + 0.5 * dw, -R * c + 0.5 * ddw
    dy_rod, ddy_rod = -0.5 * R * c, 0.5 * R * s
    dphi_rod = -R * c / w
    ddphi_rod = R * s / w + R * c * dw / (w * w)
    inertia = (I_CRANK + M_ROD * (dy_rod**2 + dz_rod**2) + I_ROD * dphi_rod**2
               + M_PISTON * dz_piston**2)
    inertia_rate = 2 * (M_ROD * (dy_rod * ddy_rod + dz_rod * ddz_rod) + I_ROD * dphi_rod * ddphi_rod
                        + M_PISTON * dz_piston * ddz_piston)
    volume = V_C + AREA * ((R + L) - z_piston)
    pressure = P_ATM
    if stroke == 1:
        pressure = P_ATM * (V_1 / volume) ** KAPPA
    elif stroke == 2:
        pressure = (P_ATM * C**KAPPA + P_COMB) * (V_C / volume) ** KAPPA
    gas = -(pressure - P_ATM) * AREA
    force = gas * dz_piston - C_LOAD * omega - G * (M_ROD * dz_rod + M_PISTON * dz_piston)
    return (force - 0.5 * inertia_rate * omega * omega) / inertia


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
