"""Andrews' squeezing mechanism (shared/specs/andrews.md), the Python twin of
examples/andrews.cpp (model: examples/andrews_model.hpp): seven planar bodies, ten pins, a
stiff spring and a motor torque, from rest. It writes the seven test-set angles and their
rates, and a summary.

    python examples/python/andrews.py [--t-end T] [--h STEP] [--dt-out DT] [--out FILE]
        [--integrator NAME] [--rho-inf R] [--newton-rtol R] [--rtol R] [--atol A]

The generalized-alpha family runs at a fixed step --h (default 1e-6 s: angles to about 2e-7
relative at t = 0.03); short steps tighten Newton's tolerance by themselves, and --newton-rtol
only changes it for long ones. --rtol/--atol turn on error control (--h is then the first
step); dopri5, dop853, adams and bdf always control their error.
"""

import argparse
import sys

import numpy as np

import odyn

# name, mass, moment of inertia, centre of mass x, y, angle at t = 0 (the spec's poses).
BODIES = (
    ("crank", 0.04325, 2.194e-6, 9.182485980307614359956e-4, -5.674074562905483222436e-5,
     -0.06171389001427644963589),
    ("rod FE", 0.00365, 4.410e-7, -4.491433359933072241283e-3, 2.775362557942899402279e-4,
     -0.06171389001427644963589),
    ("triangle", 0.02373, 5.255e-6, -1.874218667031545762186e-2, 2.048510678907393047663e-2,
     0.4552798191630703802559),
    ("rod GE", 0.00706, 5.667e-7, -3.022293983015888742160e-2, 1.207118235666393932334e-2,
     0.7100333697097284349001),
    ("link AG", 0.07050, 1.169e-5, -5.323682815570413865568e-2, 1.663184796661630721002e-2,
     0.4873649795438425502256),
    ("rod HE", 0.00706, 5.667e-7, -2.854326853678360407221e-2, -1.072225470725228785757e-2,
     1.007879054383935307823),
    ("link AH", 0.05498, 1.912e-5, -5.926240280179171659320e-2, -1.060069833271284384241e-2,
     1.230547444549821192497),
)
# Ground points.
O, A, B, C = [0.0, 0.0], [-0.06934, -0.00227], [-0.03635, 0.03273], [0.014, 0.072]
# The ten pins: name, body a and its point, body b and its point (from each centre of mass).
PINS = (
    ("J1", "crank", [-0.00092, 0.0], "ground", O),
    ("J2", "crank", [0.00608, 0.0], "rod FE", [0.0115, 0.0]),
    ("J3", "rod FE", [-0.0165, 0.0], "triangle", [-0.01043, -0.01626]),
    ("J4", "triangle", [-0.01043, 0.01874], "ground", B),
    ("J5", "rod FE", [-0.0165, 0.0], "rod GE", [0.0, -0.01421]),
    ("J6", "rod GE", [0.0, 0.00579], "link AG", [0.01692, -0.00916]),
    ("J7", "link AG", [-0.02308, -0.00916], "ground", A),
    ("J8", "rod FE", [-0.0165, 0.0], "rod HE", [0.01421, 0.0]),
    ("J9", "rod HE", [-0.00579, 0.0], "link AH", [0.00449, -0.02772]),
    ("J10", "link AH", [0.00449, 0.01228], "ground", A),
)
ANGLES = ("beta", "Theta", "gamma", "Phi", "delta", "Omega", "epsilon")
COLUMNS = ("t",) + ANGLES + tuple(f"{a}_d" for a in ANGLES)


def build():
    """The mechanism at the spec's consistent initial pose, at rest."""
    m = odyn.PlanarModel()
    for name, mass, inertia, x, y, phi in BODIES:
        m.add_body(name=name, mass=mass, inertia=inertia, position=[x, y], angle=phi)
    for name, body_a, point_a, body_b, point_b in PINS:
        m.add_revolute(name=name, body_a=body_a, on_a=odyn.frame(point_a), body_b=body_b,
                       on_b=odyn.frame(point_b))
    m.add_tsda(name="spring", body_a="triangle", point_a=[0.00957, 0.00074], body_b="ground",
               point_b=C, stiffness=4530.0, free_length=0.07785)
    m.add_point_torque(name="motor", body="crank", torque=0.033)
    return m


def test_set_angles(phi):
    """The seven test-set angles (or rates) from the body angles (or rates) phi1 .. phi7,
    each an array over the outputs."""
    return [phi[0], phi[1] - phi[0], phi[2], phi[3] - phi[4], phi[4], phi[5] - phi[6], phi[6]]


def table(res):
    names = [b[0] for b in BODIES]
    angles = test_set_angles([res.body(n).angle for n in names])
    rates = test_set_angles([res.body(n).angular_velocity for n in names])
    return dict(zip(COLUMNS, [res.t, *angles, *rates]))


def main(argv=None):
    p = argparse.ArgumentParser(prog="andrews", description=__doc__.splitlines()[0])
    p.add_argument("--t-end", type=float, default=0.03)
    p.add_argument("--h", type=float, default=1e-6)
    p.add_argument("--dt-out", type=float, default=1e-3)
    p.add_argument("--out", default="andrews.csv")
    p.add_argument("--integrator", default="generalized-alpha", choices=list(odyn.integrators()))
    p.add_argument("--rho-inf", type=float, default=0.9)
    p.add_argument("--newton-rtol", type=float, help="Newton tolerance for long steps")
    p.add_argument("--rtol", type=float, help="error control: relative tolerance")
    p.add_argument("--atol", type=float, help="error control: absolute tolerance")
    args = p.parse_args(argv)
    model = build()
    try:
        res = odyn.simulate(model, t_end=args.t_end, step=args.h, output_interval=args.dt_out,
                            integrator=args.integrator, rho_inf=args.rho_inf,
                            newton_rtol=args.newton_rtol, rtol=args.rtol, atol=args.atol)
    except odyn.Error as e:
        print(f"andrews: {e}", file=sys.stderr)
        return 1
    columns = table(res)
    with open(args.out, "w", encoding="utf-8") as f:  # 16 digits, as the C++ example
        f.write(",".join(COLUMNS) + "\n")
        for row in np.column_stack([columns[c] for c in COLUMNS]):
            f.write(",".join(f"{x:.16g}" for x in row) + "\n")
    s = res.statistics
    print(f"andrews: {args.integrator}, h = {args.h:g} s, t_end = {args.t_end:g} s -> "
          f"{args.out} ({len(res)} rows)")
    print(f"  {model.num_velocities} coordinates, {model.num_equations} constraint equations")
    print(f"  steps {s.steps}, Newton iterations {s.newton_iterations} "
          f"({s.newton_iterations / max(1, s.steps):.2f} per step), "
          f"factorizations {s.factorizations}")
    print(f"  wall time {s.wall_seconds:.3f} s "
          f"({1e6 * s.wall_seconds / max(1, s.steps):.2f} us per step)")
    print(f"  largest residuals: |Phi| {s.max_position_residual:.2e}, "
          f"|Phi_q v + Phi_t| {s.max_velocity_residual:.2e}")
    final = [columns[a][-1] for a in ANGLES]
    print("  final angles: " + ", ".join(f"{a} {v:.12f}" for a, v in zip(ANGLES, final)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
