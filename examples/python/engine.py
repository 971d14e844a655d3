"""The O-DYN paper's engine (shared/specs/engine.md), the Python twin of examples/engine.cpp:
dynamic analysis from top dead centre, a CSV of the crank angle, piston height and bearing
reaction, and a summary. The engine is built call by call, as examples/engine_model.hpp does;
examples/engine.json is the same model as a scene file (odyn run examples/engine.json). The gas
force is the example's own element type, compiled with the engine's models in the module
odyn_engine (examples/python/odyn_engine/odyn_engine.cpp), which builds the model.

    python examples/python/engine.py [--h STEP] [--t-end T] [--dt-out DT] [--out FILE]
                                     [--integrator NAME] [--rho-inf R] [--rtol R] [--atol A]

--rtol/--atol turn on error control for generalized-alpha and hht (--h is then the first
step), as in the C++ example; dopri5, dop853 and bdf always control their error. The command
line is shared with slider_crank_planar.py (run_command_line).
"""

import argparse
import sys

import odyn
import odyn_engine

# Columns of the C++ examples' CSV (examples/engine_cli.hpp).
COLUMNS = ("t", "theta", "omega", "z_piston", "R_z", "phi_norm", "phid_norm")


def build(r=0.04, L=0.14, omega0=157.08, c_load=0.1):
    """The engine at top dead centre; only the crank's angular velocity is given."""
    x, y, z = [1, 0, 0], [0, 1, 0], [0, 0, 1]
    m = odyn.Model(module=odyn_engine)
    m.add_body(name="crank", mass=1.399, inertia=[1.524, 1.291, 0.836],
               angular_velocity=[omega0, 0, 0])
    m.add_body(name="rod", mass=0.253, inertia=[0.399, 0.372, 0.0349], position=[0, 0, r + L / 2])
    m.add_body(name="piston", mass=0.643, inertia=[0.457, 0.506, 0.653], position=[0, 0, r + L])
    m.add_revolute(name="bearing", body_a="ground", on_a=odyn.frame([0, 0, 0], x),
                   body_b="crank", on_b=odyn.frame([0, 0, 0], x))
    m.add_spherical(name="crank pin", body_a="crank", point_a=[0, 0, r], body_b="rod",
                    point_b=[0, 0, -L / 2])
    m.add_universal(name="piston pin", body_a="rod", on_a=odyn.frame([0, 0, L / 2], x),
                    body_b="piston", on_b=odyn.frame([0, 0, 0], y))
    m.add_translational(name="cylinder", body_a="ground", on_a=odyn.frame([0, 0, r + L], z),
                        body_b="piston", on_b=odyn.frame([0, 0, 0], z))
    m.add_gravity(name="gravity", acceleration=[0, 0, -9.81])
    m.add_rsda(name="load", body_a="ground", on_a=odyn.frame([0, 0, 0], x), body_b="crank",
               on_b=odyn.frame([0, 0, 0], x), damping=c_load)
    m.add("engine_gas_force", name="gas force", crank="crank", piston="piston", r=r, L=L)
    return m


def engine_table(res):
    """The CSV columns from a run of the spatial or the planar engine: theta is the gas
    force's cumulative crank angle, R_z the vertical force of the block on the crank."""
    crank, piston = res.body("crank"), res.body("piston")
    up = 1 if res.space == "planar" else 2  # the cylinder axis: planar y, spatial Z
    omega = crank.angular_velocity if res.space == "planar" else crank.angular_velocity[:, 0]
    return {"t": res.t, "theta": res.state("gas force")["theta"], "omega": omega,
            "z_piston": piston.position[:, up],
            "R_z": res.reaction("bearing", side="b").force[:, up],
            "phi_norm": res.phi_norm, "phid_norm": res.phid_norm}


def run_command_line(program, build_model, argv=None):
    """Parses the options of the C++ engine examples, runs the model `build_model()` returns,
    writes the CSV and prints the summary. Returns the exit status."""
    p = argparse.ArgumentParser(prog=program, description=__doc__.splitlines()[0])
    p.add_argument("--h", type=float, default=1e-4, help="step (first step with error control)")
    p.add_argument("--t-end", type=float, default=1.0)
    p.add_argument("--dt-out", type=float, default=1e-3)
    p.add_argument("--out", default=f"{program}.csv")
    p.add_argument("--integrator", default="generalized-alpha", choices=list(odyn.integrators()))
    p.add_argument("--rho-inf", type=float, default=0.9)
    p.add_argument("--rtol", type=float, help="error control: relative tolerance")
    p.add_argument("--atol", type=float, help="error control: absolute tolerance")
    args = p.parse_args(argv)
    try:
        model = build_model()
        res = odyn.simulate(model, step=args.h, t_end=args.t_end, output_interval=args.dt_out,
                            integrator=args.integrator, rho_inf=args.rho_inf, rtol=args.rtol,
                            atol=args.atol)
    except odyn.Error as e:
        print(f"{program}: {e}", file=sys.stderr)
        return 1
    table = engine_table(res)
    odyn.scene.write_table(table, args.out)
    s = res.statistics
    print(f"{program}: {args.integrator}, h = {args.h:g} s, t_end = {args.t_end:g} s -> "
          f"{args.out} ({len(res)} rows)")
    print(f"  {model.num_velocities} coordinates, {model.num_equations} constraint equations")
    print(f"  steps {s.steps}, Newton iterations {s.newton_iterations} "
          f"({s.newton_iterations / max(1, s.steps):.2f} per step), "
          f"factorizations {s.factorizations}")
    print(f"  wall time {s.wall_seconds:.3f} s "
          f"({1e6 * s.wall_seconds / max(1, s.steps):.2f} us per step)")
    print(f"  largest residuals: |Phi| {s.max_position_residual:.2e}, "
          f"|Phi_q v + Phi_t| {s.max_velocity_residual:.2e}")
    print(f"  final: theta {table['theta'][-1]:.9f} rad, omega {table['omega'][-1]:.6f} rad/s, "
          f"z_piston {table['z_piston'][-1]:.9f} m")
    return 0


if __name__ == "__main__":
    sys.exit(run_command_line("engine", build))
