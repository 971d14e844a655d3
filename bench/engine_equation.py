"""The engine of shared/specs/engine.md reduced to its one minimal coordinate theta (the crank
angle): its constants, the gas force, the piston's height and Lagrange's equation
J(theta) theta'' + J'(theta) theta'^2 / 2 = Q, the same equation as
tests/reference/engine_reference.hpp. Standard library only: bench/peer_engine.py (the peers'
reference) and bench/minimal_ode_evaluations.py (SciPy's evaluation counts) both use it.
"""

import math

R, L, D, C = 0.04, 0.14, 0.08, 9.0
P_ATM, KAPPA, P_COMB = 101325.0, 1.4, 3.0e6
C_LOAD, G = 0.1, 9.81
M_CRANK, M_ROD, M_PISTON = 1.399, 0.253, 0.643
I_CRANK, I_ROD, I_PISTON = (1.524, 1.291, 0.836), (0.399, 0.372, 0.0349), (0.457, 0.506, 0.653)
OMEGA0 = 157.08
AREA = math.pi * D * D / 4
V_C = AREA * 2 * R / (C - 1)
V_1 = V_C + 2 * R * AREA
P_POWER = P_ATM * C**KAPPA + P_COMB


def gas_force(stroke, z_piston):
    """Gas force on the piston along +Z in the given stroke (engine.md, Forces 2)."""
    if stroke == 1:
        volume = V_C + AREA * ((R + L) - z_piston)
        return -(P_ATM * (V_1 / volume) ** KAPPA - P_ATM) * AREA
    if stroke == 2:
        volume = V_C + AREA * ((R + L) - z_piston)
        return -(P_POWER * (V_C / volume) ** KAPPA - P_ATM) * AREA
    return 0.0


def piston_height(theta):
    """z of the piston for crank angle theta, from the loop's kinematics."""
    s = math.sin(theta)
    return R * math.cos(theta) + math.sqrt(L * L - R * R * s * s)


def angular_acceleration(stroke, theta, omega):
    """Lagrange's equation in theta: J alpha + J' omega^2 / 2 = Q (engine_reference.hpp)."""
    s, c = math.sin(theta), math.cos(theta)
    w = math.sqrt(L * L - R * R * s * s)
    dw = -R * R * s * c / w
    ddw = -(R * R * (c * c - s * s) + dw * dw) / w
    z_piston, dz_piston, ddz_piston = R * c + w, -R * s + dw, -R * c + ddw
    dz_rod, ddz_rod = -R * s + 0.5 * dw, -R * c + 0.5 * ddw
    dy_rod, ddy_rod = -0.5 * R * c, 0.5 * R * s
    dphi_rod = -R * c / w
    ddphi_rod = R * s / w + R * c * dw / (w * w)
    inertia = (I_CRANK[0] + M_ROD * (dy_rod * dy_rod + dz_rod * dz_rod)
               + I_ROD[0] * dphi_rod * dphi_rod + M_PISTON * dz_piston * dz_piston)
    inertia_rate = 2 * (M_ROD * (dy_rod * ddy_rod + dz_rod * ddz_rod)
                        + I_ROD[0] * dphi_rod * ddphi_rod + M_PISTON * dz_piston * ddz_piston)
    force = (gas_force(stroke, z_piston) * dz_piston - C_LOAD * omega
             - G * (M_ROD * dz_rod + M_PISTON * dz_piston))
    return (force - 0.5 * inertia_rate * omega * omega) / inertia
