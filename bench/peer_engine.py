"""How two peer engines do on the flagship engine model: error against CPU time.

Runs the single-cylinder four-stroke engine of shared/specs/engine.md (crank, connecting rod and
piston; gravity; an Otto-cycle gas force on the piston that jumps at ignition, phi = 2 pi, and
when the exhaust valve opens, phi = 3 pi; a viscous load torque -0.1 omega_x on the crank; 1500
rpm at top dead centre; t = 0..1 s) in

  * MuJoCo  -- minimal coordinates: world -> crank (hinge about X); world -> piston (slide along
               Z) -> rod through the universal joint written as two hinges (piston y, then rod
               x); the crank pin - rod spherical joint closes the loop as an equality `connect`,
               made as stiff as MuJoCo lets it be (solref = (2 h, 1), the smallest time constant
               it accepts with its default safety check, solimp = (0.9999, 0.9999, 0.001)).
               The load torque is the crank hinge's own damping (0.1 N m s); the gas force is
               set in qfrc_applied by a Python control callback (mujoco.set_mjcb_control), so
               that RK4 re-evaluates it at every stage. Default solver options, contacts
               disabled. Integrators: Euler (MuJoCo's default, semi-implicit), RK4 and
               implicitfast, on fixed steps.
  * Exudyn  -- absolute coordinates: three ObjectRigidBody on Euler-parameter nodes; a revolute
               joint (ground - crank, X), a spherical joint (crank pin), the universal joint as an
               ObjectJointGeneric with one constrained rotation (piston y kept perpendicular to
               rod x) and a prismatic joint (ground - piston, Z, no rotation); the gas force is a
               LoadForceVector with a Python loadVectorUserFunction that reads the crank angle
               (unwrapped from the crank's rotation matrix) and the piston height; the load torque
               a TorsionalSpringDamper (damping 0.1). Solver: Exudyn's default implicit
               generalized-alpha (index 3, spectral radius 0.9, modified Newton), EigenSparse, on
               fixed steps. Its explicit solvers (RK44, DOPRI5) refuse joint constraints; that is
               recorded as a failed row.

Before timing, the physics of each model is checked at a coarse setting: theta(0.1) and theta(1)
next to the reference, and the piston height against z = r cos theta + sqrt(L^2 - r^2 sin^2
theta) at the engine's own crank angle (what is left is the constraint violation).

The error is |theta(1) - theta_ref(1)|, as on odyn's figure (bench/work_precision.cpp). The
reference is tests/reference/engine_reference.hpp ported to Python below: the one-coordinate
Lagrange equation, RK4 at h = 1e-5 with every stroke boundary theta = n pi hit exactly and
compensated summation; its theta(1) is checked against the C++ value. CPU time is
time.process_time() of the simulation alone (reset / solver initialization, the steps and the
storing of 1001 output samples, every 1e-3 s, as odyn's runs do); building the model is timed
separately and printed. Runs shorter than 1 s are repeated 3 times and the median is kept. Each
family goes from coarse to fine steps and stops after a run that took more than --budget-s.

Writes bench/results/peer_engine.csv with the columns of bench/results/work_precision.csv

    case,family,integrator,adaptive,value,error,error2,error3,cpu_seconds,steps,rejected,
    newton_iterations,jacobian_evaluations,factorizations,events,max_phi,status

(value = the step h, error2 = max |z_piston - z_ref| over the outputs [m], error3 = R_z is not
measured (nan), max_phi = the largest distance between the crank pin and the rod's end at the
outputs [m]; counters an engine does not report are left empty) and prints a table, then the cost
of the Python force callbacks (a run with a callback that returns zero against a run without one,
same dynamics, plus the gas-force function's own time per call).

The engines come from PyPI into the scratch virtual environment build/peer-venv, as in
bench/peer_scaling.py (created on first use); the script re-executes itself inside it. Run it
from anywhere, niced on a shared machine (about a minute):

    nice -n 10 python3 bench/peer_engine.py
    nice -n 10 python3 bench/peer_engine.py --quick        # two steps per family, no CSV
    nice -n 10 python3 bench/peer_engine.py --engines mujoco --out /tmp/mujoco_engine.csv
"""

import argparse
import csv
import math
import os
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from engine_equation import (C_LOAD, G, I_CRANK, I_PISTON, I_ROD, L, M_CRANK,  # noqa: E402
                             M_PISTON, M_ROD, OMEGA0, R, angular_acceleration, gas_force,
                             piston_height)
from peer_scaling import PACKAGES, ensure_venv_and_reexec, in_venv  # noqa: E402

REPO = Path(__file__).resolve().parent.parent
DEFAULT_CSV = REPO / "bench" / "results" / "peer_engine.csv"
NEEDED = ("numpy", "exudyn", "mujoco")  # distributions of PACKAGES this script imports

COLUMNS = ["case", "family", "integrator", "adaptive", "value", "error", "error2", "error3",
           "cpu_seconds", "steps", "rejected", "newton_iterations", "jacobian_evaluations",
           "factorizations", "events", "max_phi", "status"]

# Step ladders, coarse to fine.
MUJOCO_STEPS = {
    "Euler": [2e-4, 1e-4, 5e-5, 2e-5, 1e-5, 5e-6, 2e-6, 1e-6],
    "RK4": [2e-4, 1e-4, 5e-5, 2e-5, 1e-5, 5e-6, 2e-6],
    "implicitfast": [1e-4, 2e-5, 5e-6],
}
EXUDYN_STEPS = [1e-3, 5e-4, 2e-4, 1e-4, 5e-5, 2e-5, 1e-5]
CHECK_STEP = {"mujoco": ("RK4", 1e-4), "exudyn": ("generalized-alpha", 1e-4)}

T_END = 1.0
DT_OUT = 1e-3
N_OUT = round(T_END / DT_OUT)

# =========================================================================================
# The model (shared/specs/engine.md) and its reference solution
# =========================================================================================

# theta(1) of tests/reference/engine_reference.hpp (RK4, h = 1e-5), as printed by the C++ code
# to 12 decimals (bench/minimal_ode_evaluations.py quotes it); the port must agree.
THETA1_CPP = 158.286033924795


def _rk4_increment(theta, omega, h, stroke):
    k1t, k1o = omega, angular_acceleration(stroke, theta, omega)
    k2t = omega + 0.5 * h * k1o
    k2o = angular_acceleration(stroke, theta + 0.5 * h * k1t, k2t)
    k3t = omega + 0.5 * h * k2o
    k3o = angular_acceleration(stroke, theta + 0.5 * h * k2t, k3t)
    k4t = omega + h * k3o
    k4o = angular_acceleration(stroke, theta + h * k3t, k4t)
    return h / 6 * (k1t + 2 * k2t + 2 * k3t + k4t), h / 6 * (k1o + 2 * k2o + 2 * k3o + k4o)


def reference_solution(t_end=T_END, dt_out=DT_OUT, h=1e-5):
    """[(t, theta, omega)] at t = k dt_out: engine_reference::solve of the C++ header, ported.

    Classical RK4 on equal steps of at most h between output times; a step that would cross
    the next stroke boundary theta = n pi is shortened (safeguarded Newton on its length) to end
    on it, so that no step straddles a jump of the gas force; Kahan-compensated sums."""
    pi = math.pi
    theta, omega, carry_theta, carry_omega = 0.0, OMEGA0, 0.0, 0.0
    n = 0  # theta in [n pi, (n + 1) pi)

    def add(total, carry, x):
        y = x - carry
        s = total + y
        return s, (s - total) - y

    out = [(0.0, theta, omega)]
    t = 0.0
    for i in range(1, round(t_end / dt_out) + 1):
        t_target = i * dt_out
        while t < t_target:
            t0 = t
            steps = int(max(1.0, math.ceil((t_target - t0) / h - 1e-9)))
            dt = (t_target - t0) / steps
            for j in range(1, steps + 1):
                if not omega > 0:
                    raise RuntimeError("reference: the crank stopped turning")
                boundary = (n + 1) * pi
                stroke = n % 4
                d_theta, d_omega = _rk4_increment(theta, omega, dt, stroke)
                overshoot = (theta - boundary) + (d_theta - carry_theta)
                if overshoot < 0:
                    theta, carry_theta = add(theta, carry_theta, d_theta)
                    omega, carry_omega = add(omega, carry_omega, d_omega)
                    t = t_target if j == steps else t0 + j * dt
                    continue
                lo, hi, tau = 0.0, dt, dt * (1 - overshoot / d_theta)
                for _ in range(100):
                    s_theta, s_omega = _rk4_increment(theta, omega, tau, stroke)
                    g = (theta - boundary) + (s_theta - carry_theta)
                    if g < 0:
                        lo = tau
                    else:
                        hi = tau
                    if abs(g) <= 1e-15 * (1 + abs(boundary)) or hi - lo <= 1e-18:
                        break
                    nxt = tau - g / (omega + s_omega)
                    tau = nxt if lo < nxt < hi else 0.5 * (lo + hi)
                d_theta, d_omega = _rk4_increment(theta, omega, tau, stroke)
                theta, carry_theta = add(theta, carry_theta, d_theta)
                omega, carry_omega = add(omega, carry_omega, d_omega)
                theta, carry_theta = boundary, 0.0
                n += 1
                t = t0 + (j - 1) * dt + tau
                break  # re-plan equal steps over the rest of the output interval
        out.append((t_target, theta, omega))
    return out


class Reference:
    def __init__(self):
        t0 = time.process_time()
        samples = reference_solution()
        self.cpu = time.process_time() - t0
        self.theta = [th for _, th, _ in samples]
        self.z = [piston_height(th) for th in self.theta]


def unwrap(angles):
    """Cumulative angle from wrapped ones sampled densely (|jump| < pi between samples)."""
    out, total, last = [], 0.0, None
    for a in angles:
        if last is not None:
            total += (a - last + math.pi) % (2 * math.pi) - math.pi
        else:
            total = a
        last = a
        out.append(total)
    return out


def errors(ref, theta, z, violation):
    """The row's error columns and the physics checks from the output samples."""
    n = len(theta) - 1
    return {
        "theta_0.1": theta[100] if n >= 100 else float("nan"),
        "theta_end": theta[-1],
        "error": abs(theta[-1] - ref.theta[n]),
        "error2": max(abs(zi - zr) for zi, zr in zip(z, ref.z)),
        "kinematic": max(abs(zi - piston_height(th)) for zi, th in zip(z, theta)),
        "max_phi": max(violation) if violation else float("nan"),
    }


# =========================================================================================
# MuJoCo
# =========================================================================================

STIFF = "stiff"  # the connect's solref / solimp: STIFF, or None for MuJoCo's defaults


def mujoco_xml(h, integrator, softness=STIFF):
    ix = " ".join(repr(x) for x in I_CRANK)
    ir = " ".join(repr(x) for x in I_ROD)
    ip = " ".join(repr(x) for x in I_PISTON)
    # solref (2 h, 1): the smallest time constant MuJoCo accepts without disabling its
    # "refsafe" check; impedance 0.9999 (its upper limit) across the whole width
    solver = f'solref="{2 * h!r} 1" solimp="0.9999 0.9999 0.001 0.5 2"' if softness else ""
    return f"""<mujoco model="engine">
  <compiler angle="radian" inertiafromgeom="false"/>
  <option timestep="{h!r}" gravity="0 0 {-G!r}" integrator="{integrator}">
    <flag contact="disable"/>
  </option>
  <worldbody>
    <body name="crank" pos="0 0 0">
      <joint name="crank" type="hinge" axis="1 0 0" damping="{C_LOAD!r}"/>
      <inertial pos="0 0 0" mass="{M_CRANK!r}" diaginertia="{ix}"/>
    </body>
    <body name="piston" pos="0 0 {R + L!r}">
      <joint name="cylinder" type="slide" axis="0 0 1"/>
      <inertial pos="0 0 0" mass="{M_PISTON!r}" diaginertia="{ip}"/>
      <body name="rod" pos="0 0 0">
        <joint name="pin_y" type="hinge" axis="0 1 0"/>
        <joint name="pin_x" type="hinge" axis="1 0 0"/>
        <inertial pos="0 0 {-L / 2!r}" mass="{M_ROD!r}" diaginertia="{ir}"/>
      </body>
    </body>
  </worldbody>
  <equality>
    <connect name="crank_pin" body1="crank" body2="rod" anchor="0 0 {R!r}" {solver}/>
  </equality>
</mujoco>"""


class MujocoEngine:
    """qpos = (theta, piston slide, universal y, universal x); nv = 4, one connect (3 rows)."""

    def __init__(self, h, integrator, softness=STIFF):
        import mujoco
        self.mj = mujoco
        self.h = h
        t0 = time.process_time()
        self.model = mujoco.MjModel.from_xml_string(mujoco_xml(h, integrator, softness))
        self.data = mujoco.MjData(self.model)
        self.setup_s = time.process_time() - t0
        m = self.model
        self.q_crank, self.q_slide, self.q_uy, self.q_ux = (
            int(m.jnt_qposadr[m.joint(name).id])
            for name in ("crank", "cylinder", "pin_y", "pin_x"))
        self.v_crank, self.v_slide, self.v_ux = (
            int(m.jnt_dofadr[m.joint(name).id]) for name in ("crank", "cylinder", "pin_x"))

    def callback(self, mode):
        """The control callback: "gas" (the real force), "zero" (writes 0), or None."""
        q_crank, q_slide, v_slide, z0 = self.q_crank, self.q_slide, self.v_slide, R + L
        if mode == "gas":
            def control(m, d):
                q = d.qpos
                d.qfrc_applied[v_slide] = gas_force(int(q[q_crank] // math.pi) % 4,
                                                    z0 + q[q_slide])
            return control
        if mode == "zero":
            def control(m, d):
                d.qfrc_applied[v_slide] = 0.0
            return control
        return None

    def run(self, mode="gas"):
        """Simulate 0..1 s; return (cpu seconds, output samples of qpos, warnings)."""
        import numpy as np
        mj, m, d = self.mj, self.model, self.data
        mj.set_mjcb_control(self.callback(mode))
        per_output = round(DT_OUT / self.h)
        samples = np.empty((N_OUT + 1, m.nq))
        try:
            t0 = time.process_time()
            mj.mj_resetData(m, d)
            d.qvel[self.v_crank] = OMEGA0
            d.qvel[self.v_ux] = -R / L * OMEGA0  # rod angle: sin(phi) = -r sin(theta) / L
            samples[0] = d.qpos
            for i in range(1, N_OUT + 1):
                mj.mj_step(m, d, nstep=per_output)
                samples[i] = d.qpos
            cpu = time.process_time() - t0
        finally:
            mj.set_mjcb_control(None)
        bad = int(d.warning[mj.mjtWarning.mjWARN_BADQACC].number)
        return cpu, samples, bad

    def outputs(self, samples):
        theta = [float(x) for x in samples[:, self.q_crank]]
        z = [R + L + float(x) for x in samples[:, self.q_slide]]
        violation = []
        for th, zp, a, b in zip(theta, z, samples[:, self.q_uy], samples[:, self.q_ux]):
            # crank pin (0, -r sin th, r cos th); rod end = pin + Ry(a) Rx(b) (0, 0, -L)
            ca, sa, cb, sb = math.cos(a), math.sin(a), math.cos(b), math.sin(b)
            dx = L * sa * cb
            dy = -R * math.sin(th) - L * sb
            dz = R * math.cos(th) - (zp - L * ca * cb)
            violation.append(math.sqrt(dx * dx + dy * dy + dz * dz))
        return theta, z, violation


# =========================================================================================
# Exudyn
# =========================================================================================

class ExudynEngine:
    def __init__(self, gas="gas", counter=None):
        """gas: "gas" (the real user function), "zero" (a user function returning zeros) or None
        (no gas-force load at all); counter: a one-element list counting the calls."""
        import numpy as np
        import exudyn as exu
        from exudyn.itemInterface import SensorBody
        from exudyn.utilities import RigidBodyInertia, RotationMatrixY
        self.exu = exu
        t0 = time.process_time()
        self.SC = exu.SystemContainer()
        self.mbs = mbs = self.SC.AddSystem()
        ground = mbs.CreateGround()
        gravity = [0.0, 0.0, -G]

        def body(mass, inertia, position, velocity=(0, 0, 0), angular_velocity=(0, 0, 0)):
            return mbs.CreateRigidBody(
                inertia=RigidBodyInertia(mass=mass, inertiaTensor=np.diag(inertia)),
                referencePosition=list(position), initialVelocity=list(velocity),
                initialAngularVelocity=list(angular_velocity), gravity=gravity,
                nodeType=exu.NodeType.RotationEulerParameters, show=False)

        # consistent initial velocities at top dead centre: the pin moves with -omega r along Y,
        # the piston is at rest, so the rod turns at -omega r / L about X
        self.crank = crank = body(M_CRANK, I_CRANK, (0, 0, 0), angular_velocity=(OMEGA0, 0, 0))
        self.rod = rod = body(M_ROD, I_ROD, (0, 0, R + L / 2), velocity=(0, -OMEGA0 * R / 2, 0),
                              angular_velocity=(-OMEGA0 * R / L, 0, 0))
        self.piston = piston = body(M_PISTON, I_PISTON, (0, 0, R + L))
        mbs.CreateRevoluteJoint(itemNumbers=[ground, crank], position=[0, 0, 0], axis=[1, 0, 0],
                                useGlobalFrame=True, show=False)
        mbs.CreateSphericalJoint(itemNumbers=[crank, rod], position=[0, 0, R],
                                 useGlobalFrame=True, show=False)
        # universal joint: constrainedAxes (1,1,1, 1,0,0) keeps joint axis y of body 0 (piston)
        # perpendicular to joint axis z of body 1 (rod); the joint axes RotY(pi/2) make those
        # global Y (the piston's y) and global X (the rod's x)
        mbs.CreateGenericJoint(itemNumbers=[piston, rod], position=[0, 0, R + L],
                               rotationMatrixAxes=RotationMatrixY(math.pi / 2),
                               constrainedAxes=[1, 1, 1, 1, 0, 0], useGlobalFrame=True,
                               show=False)
        mbs.CreatePrismaticJoint(itemNumbers=[ground, piston], position=[0, 0, R + L],
                                 axis=[0, 0, 1], useGlobalFrame=True, show=False)
        mbs.CreateTorsionalSpringDamper(itemNumbers=[ground, crank], position=[0, 0, 0],
                                        axis=[1, 0, 0], stiffness=0.0, damping=C_LOAD,
                                        useGlobalFrame=True, show=False)
        self.last_theta = 0.0
        if gas == "gas":
            rotation = exu.OutputVariableType.RotationMatrix
            position = exu.OutputVariableType.Position
            two_pi, pi, z_index = 2 * math.pi, math.pi, 2

            def load(mbs_, t, static_load):
                a = mbs_.GetObjectOutputBody(crank, rotation)  # row-major 3 x 3
                wrapped = math.atan2(a[7], a[4])               # rotation about X
                last = self.last_theta
                theta = last + (wrapped - last + pi) % two_pi - pi
                self.last_theta = theta
                z_piston = mbs_.GetObjectOutputBody(piston, position)[z_index]
                return [0.0, 0.0, gas_force(int(theta // pi) % 4, z_piston)]
            self.load = load
        elif gas == "zero":
            zero = [0.0, 0.0, 0.0]

            def load(mbs_, t, static_load):
                return zero
        if gas and counter is not None:
            inner = load

            def load(mbs_, t, static_load):
                counter[0] += 1
                return inner(mbs_, t, static_load)
        if gas:
            mbs.CreateForce(itemNumber=piston, loadVector=[0, 0, 0], loadVectorUserFunction=load,
                            show=False)
        # output samples: crank rotation, piston position, both ends of the crank pin joint
        out = exu.OutputVariableType

        def sensor(item, variable, local=(0, 0, 0)):
            return mbs.AddSensor(SensorBody(bodyNumber=item, localPosition=list(local),
                                            outputVariableType=variable, storeInternal=True,
                                            writeToFile=False))
        self.s_rotation = sensor(crank, out.RotationMatrix)
        self.s_piston = sensor(piston, out.Position)
        self.s_pin = sensor(crank, out.Position, (0, 0, R))
        self.s_rod_end = sensor(rod, out.Position, (0, 0, -L / 2))
        mbs.Assemble()
        self.setup_s = time.process_time() - t0

    def settings(self, h):
        exu = self.exu
        ss = exu.SimulationSettings()
        ti = ss.timeIntegration
        ti.numberOfSteps = round(T_END / h)
        ti.endTime = T_END
        ti.adaptiveStep = False  # fixed h, as the ladder asks
        ti.verboseMode = 0
        ss.solution.file.write = False
        ss.solution.sensors.active = True
        ss.solution.sensors.writePeriod = DT_OUT
        ss.linearSolver.solverType = exu.LinearSolverType.EigenSparse
        return ss

    def run(self, h):
        """Generalized-alpha from the initial state; return (cpu, ok, counters)."""
        exu, mbs = self.exu, self.mbs
        ss = self.settings(h)
        solver = exu.MainSolverImplicitSecondOrder()
        t0 = time.process_time()
        self.last_theta = 0.0
        solver.InitializeSolver(mbs, ss)  # resets to the initial state, initial accelerations
        ok = solver.SolveSteps(mbs, ss)
        solver.FinalizeSolver(mbs, ss)
        cpu = time.process_time() - t0
        done = solver.it.currentTime
        counters = {"steps": round(done / h), "newton": solver.it.newtonStepsCount,
                    "jacobians": solver.it.newtonJacobiCount,
                    "message": "" if ok else " ".join(solver.GetErrorString().split())[:120]}
        return cpu, bool(ok) and abs(done - T_END) < 1e-9, counters

    def run_explicit(self, h, solver_type):
        """One of Exudyn's explicit solvers (they raise on this model: see the rows)."""
        ss = self.settings(h)
        ss.timeIntegration.solverType = solver_type
        self.last_theta = 0.0
        return self.mbs.SolveDynamic(ss, solverType=solver_type)

    def outputs(self):
        import numpy as np
        mbs = self.mbs
        rot = mbs.GetSensorStoredData(self.s_rotation)
        times = rot[:, 0]
        if len(times) != N_OUT + 1 or np.max(np.abs(times - DT_OUT * np.arange(N_OUT + 1))) > 1e-9:
            raise RuntimeError(f"unexpected sensor times ({len(times)} samples)")
        theta = unwrap([math.atan2(r[8], r[5]) for r in rot])  # column 0 is time
        z = [float(x) for x in mbs.GetSensorStoredData(self.s_piston)[:, 3]]
        pin = mbs.GetSensorStoredData(self.s_pin)[:, 1:]
        end = mbs.GetSensorStoredData(self.s_rod_end)[:, 1:]
        violation = [float(x) for x in np.linalg.norm(pin - end, axis=1)]
        return theta, z, violation


# =========================================================================================
# Driver
# =========================================================================================

def timed(run_once, first_cpu):
    """Median CPU of 3 runs when the first took under a second."""
    if first_cpu >= 1.0:
        return first_cpu
    return statistics.median([first_cpu] + [run_once() for _ in range(2)])


def row(family, integrator, h, status, res=None, cpu=None, steps=None, newton="", jac=""):
    res = res or {}
    return {"case": "engine", "family": family, "integrator": integrator, "adaptive": 0,
            "value": h, "error": res.get("error", float("nan")),
            "error2": res.get("error2", float("nan")), "error3": float("nan"),
            "cpu_seconds": cpu if cpu is not None else float("nan"), "steps": steps or "",
            "rejected": 0 if status == "ok" else "", "newton_iterations": newton,
            "jacobian_evaluations": jac, "factorizations": "", "events": "",
            "max_phi": res.get("max_phi", float("nan")), "status": status,
            # printed only
            "kinematic": res.get("kinematic", float("nan")),
            "theta_0.1": res.get("theta_0.1", float("nan")),
            "theta_end": res.get("theta_end", float("nan"))}


def mujoco_run(ref, integrator, h, repeat=True, softness=STIFF):
    family = f"MuJoCo {integrator}"
    try:
        engine = MujocoEngine(h, integrator, softness)
        cpu, samples, bad = engine.run()
        if bad:
            return row(family, integrator, h, f"failed: diverged (mjWARN_BADQACC x{bad})",
                       cpu=cpu), engine.setup_s
        res = errors(ref, *engine.outputs(samples))
        if not math.isfinite(res["error"]):
            return row(family, integrator, h, "failed: non-finite state", cpu=cpu), engine.setup_s
        if repeat:
            cpu = timed(lambda: engine.run()[0], cpu)
        return row(family, integrator, h, "ok", res, cpu, round(T_END / h)), engine.setup_s
    except Exception as err:  # recorded, not fatal
        return row(family, integrator, h, f"failed: {type(err).__name__}: {str(err)[:100]}"), None


def exudyn_run(ref, h, engine, repeat=True):
    family = "Exudyn generalized-alpha"
    try:
        cpu, ok, c = engine.run(h)
        if not ok:
            return row(family, "generalized-alpha", h,
                       f"failed: solver stopped at step {c['steps']}: {c['message']}", cpu=cpu)
        res = errors(ref, *engine.outputs())
        if repeat:
            cpu = timed(lambda: engine.run(h)[0], cpu)
        return row(family, "generalized-alpha", h, "ok", res, cpu, c["steps"], c["newton"],
                   c["jacobians"])
    except Exception as err:
        return row(family, "generalized-alpha", h,
                   f"failed: {type(err).__name__}: {' '.join(str(err).split())[:100]}")


def exudyn_explicit_rows(h=1e-4):
    import exudyn as exu
    rows = []
    for name, solver_type in (("RK44", exu.DynamicSolverType.RK44),
                              ("DOPRI5", exu.DynamicSolverType.DOPRI5)):
        try:
            engine = ExudynEngine()
            exu.SetWriteToConsole(False)  # its failure banner; the row records the failure
            try:
                engine.run_explicit(h, solver_type)
            finally:
                exu.SetWriteToConsole(True)
            status = "failed: ran, but this script does not evaluate explicit runs"
        except Exception as err:
            text = " ".join(str(err).split())
            if "algebraic" in text or "constraints" in text:
                status = "failed: explicit solvers refuse the joint constraints (ModelError)"
            else:
                status = f"failed: {type(err).__name__}: {text[:100]}"
        rows.append(row(f"Exudyn {name}", name, h, status))
    return rows


def check_physics(ref, engines):
    """Coarse runs: theta(0.1), theta(1) next to the reference, piston height vs the crank's."""
    print("## Physics check (before timing)")
    print(f"reference (RK4 on theta, h = 1e-5, {ref.cpu:.2f} s CPU): theta(0.1) = "
          f"{ref.theta[100]:.9f}, theta(1) = {ref.theta[-1]:.12f} rad; C++ engine_reference: "
          f"{THETA1_CPP:.12f} (difference {ref.theta[-1] - THETA1_CPP:+.1e})")
    print(f"{'model / integrator, h':36s} {'theta(0.1)':>13s} {'theta(1)':>13s} "
          f"{'|dtheta(1)|':>11s} {'max|z-z(theta)|':>15s} {'max|z-z_ref|':>12s} "
          f"{'max pin gap':>11s}  verdict")
    passed = {}
    for engine in engines:
        integrator, h = CHECK_STEP[engine]
        if engine == "mujoco":
            r, _ = mujoco_run(ref, integrator, h, repeat=False)
        else:
            r = exudyn_run(ref, h, ExudynEngine(), repeat=False)
        # a real model error (a wrong sign, axis or mass) is off by far more than this at h=1e-4
        ok = r["status"] == "ok" and r["error"] < 1e-2 and r["kinematic"] < 1e-5
        passed[engine] = ok
        print(f"{r['family'] + f', h = {h:g}':36s} {r['theta_0.1']:13.9f} {r['theta_end']:13.9f} "
              f"{r['error']:11.2e} {r['kinematic']:15.2e} {r['error2']:12.2e} "
              f"{r['max_phi']:11.2e}  {'OK' if ok else 'FAILED: ' + r['status']}", flush=True)
        if engine == "mujoco":  # for comparison: the connect with MuJoCo's default softness
            r, _ = mujoco_run(ref, integrator, h, repeat=False, softness=None)
            print(f"{'  same, default solref/solimp':36s} {r['theta_0.1']:13.9f} "
                  f"{r['theta_end']:13.9f} {r['error']:11.2e} {r['kinematic']:15.2e} "
                  f"{r['error2']:12.2e} {r['max_phi']:11.2e}  (not used)", flush=True)
    return passed


def callback_cost(engines, h=1e-4):
    """What the Python gas-force callback costs. The same dynamics (no gas force) run with and
    without a callback that writes / returns zero gives the cost of the C++ -> Python bridge per
    call; the gas function's own time comes from calling it in a loop; both times the number of
    calls in the real run (counted in an untimed run) estimate the callback's share."""
    lines = [f"## Cost of the Python gas-force callback (h = {h:g}, 1 s, median of 3)"]

    def per_call(function, args, n=20000):
        t0 = time.process_time()
        for _ in range(n):
            function(*args)
        return (time.process_time() - t0) / n

    if "mujoco" in engines:
        import mujoco
        for integrator, stages in (("Euler", 1), ("RK4", 4)):
            engine = MujocoEngine(h, integrator)
            calls = stages * round(T_END / h)  # mj_forward at each stage calls it once
            base, zero, real = (statistics.median(engine.run(mode)[0] for _ in range(3))
                                for mode in (None, "zero", "gas"))
            m, d = engine.model, engine.data
            mujoco.mj_resetData(m, d)
            d.qpos[engine.q_crank] = 1.5 * math.pi  # compression stroke: a costly branch
            d.qpos[engine.q_slide] = -0.05
            body = per_call(engine.callback("gas"), (m, d))
            bridge = max(zero - base, 0.0) / calls
            share = calls * (bridge + body) / real
            lines.append(
                f"MuJoCo {integrator}: without gas force {1e3 * base:.1f} ms, with a callback "
                f"writing zero {1e3 * zero:.1f} ms -> bridge {1e6 * bridge:.2f} us/call; the gas "
                f"callback's own time {1e6 * body:.2f} us/call; {calls} calls; real run "
                f"{1e3 * real:.1f} ms, ~{100 * share:.0f} % of it in the callback")
    if "exudyn" in engines:
        cpu, calls, newton = {}, {}, {}
        for mode in (None, "zero", "gas"):
            engine = ExudynEngine(mode)
            cpu[mode] = statistics.median(engine.run(h)[0] for _ in range(3))
            counter = [0]
            counted = ExudynEngine(mode, counter)
            newton[mode] = counted.run(h)[2]["newton"]
            calls[mode] = counter[0]
        engine = ExudynEngine("gas")
        engine.run(h)
        body = per_call(engine.load, (engine.mbs, 0.5, [0.0, 0.0, 0.0]))
        bridge = max(cpu["zero"] - cpu[None], 0.0) / max(calls["zero"], 1)
        share = calls["gas"] * (bridge + body) / cpu["gas"]
        lines.append(
            f"Exudyn generalized-alpha: without gas force {1e3 * cpu[None]:.1f} ms "
            f"({newton[None]} Newton iterations), with a user function returning zero "
            f"{1e3 * cpu['zero']:.1f} ms ({calls['zero']} calls) -> bridge {1e6 * bridge:.2f} "
            f"us/call; the gas function's own time (two GetObjectOutputBody + the formula) "
            f"{1e6 * body:.2f} us/call; real run {1e3 * cpu['gas']:.1f} ms with {calls['gas']} "
            f"calls ({newton['gas']} Newton iterations), ~{100 * share:.0f} % of it in the "
            f"callback")
    for line in lines:
        print(line, flush=True)
    return lines


def fmt(x, spec=".3e"):
    if x == "" or x is None:
        return ""
    if isinstance(x, float) and not math.isfinite(x):
        return "nan"
    return format(x, spec) if isinstance(x, float) else str(x)


def ladder(family, steps, run_one, budget_s):
    """Coarse to fine; after a run over budget_s of CPU the finer steps are skipped."""
    rows, stop = [], None
    for h in steps:
        if stop:
            r = row(family, family.split(" ", 1)[1], h, f"skipped ({stop})")
        else:
            r = run_one(h)
            if r["status"] == "ok" and r["cpu_seconds"] > budget_s:
                stop = f"h = {h:g} took {r['cpu_seconds']:.1f} s"
        rows.append(r)
        print(f"  {family:26s} h = {h:7.1e}  error {fmt(r['error']):>10s}  CPU "
              f"{fmt(1e3 * r['cpu_seconds'], '.1f'):>8s} ms  {r['status']}", flush=True)
    return rows


def write_csv(rows, path):
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(COLUMNS)
        for r in rows:
            w.writerow([fmt(r[c], ".6g") if isinstance(r[c], float) else r[c] for c in COLUMNS])


def print_table(rows):
    print("| family | h [s] | theta(1) error [rad] | CPU [ms] | max z_piston error [m] | "
          "max pin gap [m] | Newton it. | status |")
    print("|---|---:|---:|---:|---:|---:|---:|---|")
    for r in rows:
        print(f"| {r['family']} | {r['value']:g} | {fmt(r['error'], '.2e')} | "
              f"{fmt(1e3 * r['cpu_seconds'], '.1f')} | {fmt(r['error2'], '.1e')} | "
              f"{fmt(r['max_phi'], '.1e')} | {r['newton_iterations']} | {r['status']} |")


def reexec_in_venv(argv):
    """bench/peer_scaling.py's scratch environment with the packages this script imports, one
    thread per numerical library."""
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1")
    ensure_venv_and_reexec(argv, script=__file__,
                           packages={dist: PACKAGES[dist] for dist in NEEDED}, env=env)


def parse_args(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--engines", default="mujoco,exudyn",
                    help="comma-separated subset of mujoco,exudyn (default: both)")
    ap.add_argument("--out", help=f"CSV to write (default {DEFAULT_CSV.relative_to(REPO)}; "
                                  "--quick writes none unless given)")
    ap.add_argument("--quick", action="store_true", help="two steps per family, a smoke test")
    ap.add_argument("--budget-s", type=float, default=6.0,
                    help="a family stops refining after a run of more CPU seconds (default 6)")
    ap.add_argument("--no-callback-cost", action="store_true",
                    help="skip the measurement of the Python callbacks' cost")
    return ap.parse_args(argv)


def main(argv):
    args = parse_args(argv)
    engines = [e.strip() for e in args.engines.split(",") if e.strip()]
    for e in engines:
        if e not in ("mujoco", "exudyn"):
            sys.exit(f"unknown engine {e!r}; choose from mujoco, exudyn")
    if not in_venv():
        reexec_in_venv(argv)
    import warnings
    warnings.simplefilter("ignore", DeprecationWarning)
    import exudyn
    import mujoco
    import numpy
    wall0 = time.perf_counter()
    print(f"# peer engine: mujoco {mujoco.__version__}, exudyn {exudyn.__version__}, numpy "
          f"{numpy.__version__}, python {sys.version.split()[0]}; load average "
          f"{os.getloadavg()[0]:.2f} on {os.cpu_count()} cores", flush=True)
    if "mujoco" in engines:  # MuJoCo's warnings (divergence) are recorded in the rows instead
        mujoco.set_mju_user_warning(lambda message: None)

    ref = Reference()
    if abs(ref.theta[-1] - THETA1_CPP) > 1e-9:
        sys.exit(f"the ported reference gives theta(1) = {ref.theta[-1]!r}, the C++ one "
                 f"{THETA1_CPP!r}: the port is wrong")
    passed = check_physics(ref, engines)

    mujoco_steps = {k: (v[:3:2] if args.quick else v) for k, v in MUJOCO_STEPS.items()}
    exudyn_steps = EXUDYN_STEPS[:3:2] if args.quick else EXUDYN_STEPS
    rows, setup = [], {}
    print("\n## Runs")
    if "mujoco" in engines:
        for integrator, steps in mujoco_steps.items():
            family = f"MuJoCo {integrator}"
            if not passed["mujoco"]:
                rows += [row(family, integrator, h, "skipped (physics check failed)")
                         for h in steps]
                continue

            def run_one(h, integrator=integrator):
                r, setup_s = mujoco_run(ref, integrator, h)
                if setup_s is not None:
                    setup.setdefault("MuJoCo (MjModel.from_xml_string + MjData)", setup_s)
                return r
            rows += ladder(family, steps, run_one, args.budget_s)
    if "exudyn" in engines:
        family = "Exudyn generalized-alpha"
        if not passed["exudyn"]:
            rows += [row(family, "generalized-alpha", h, "skipped (physics check failed)")
                     for h in exudyn_steps]
        else:
            engine = ExudynEngine()
            setup["Exudyn (items + mbs.Assemble())"] = engine.setup_s
            rows += ladder(family, exudyn_steps, lambda h: exudyn_run(ref, h, engine),
                           args.budget_s)
        rows += exudyn_explicit_rows()

    out = Path(args.out) if args.out else (None if args.quick else DEFAULT_CSV)
    print()
    print_table(rows)
    print("\nmodel building (not in the CPU times above): " + ", ".join(
        f"{name} {1e3 * s:.1f} ms" for name, s in setup.items()))
    if not args.no_callback_cost:
        print()
        callback_cost(engines)
    if out:
        write_csv(rows, out)
        print(f"\nwrote {out.relative_to(REPO) if out.is_relative_to(REPO) else out}")
    print(f"load average at the end {os.getloadavg()[0]:.2f}; wall time "
          f"{time.perf_counter() - wall0:.0f} s")


if __name__ == "__main__":
    main(sys.argv[1:])
