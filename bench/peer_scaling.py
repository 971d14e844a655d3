"""How three peer engines scale on an N-link spherical pendulum chain.

Measures, for N = 1, 2, 4, ..., 4096 links, the setup time and the time per step of

  * Exudyn    -- redundant (absolute) coordinates: ObjectRigidBody on Euler-parameter nodes,
                 SphericalJoint constraints, the default implicit generalized-alpha solver
                 (index 3, spectral radius 0.9, modified Newton) with the EigenSparse linear
                 solver, fixed step h;
  * MuJoCo    -- minimal coordinates: nested bodies with ball joints, mj_step with the
                 default (semi-implicit) Euler integrator, contacts disabled;
  * Pinocchio -- minimal coordinates: one forward-dynamics evaluation pin.aba(model, data, q,
                 v, tau) (it has no time stepper here, so the "step" is one ABA call),

and writes bench/results/peer_scaling.csv with the columns

    engine,method,N,setup_s,step_s,steps,status

where step_s is the median over >= 3 repetitions of the wall time of a block of `steps` steps
(or ABA calls) divided by `steps`, each repetition starting from rest, and setup_s is the time
to build the model (Exudyn: items + mbs.Assemble(); MuJoCo: MjModel.from_xml_string + MjData;
Pinocchio: pin.Model + createData). A short markdown table and the growth exponents of step_s
over N (least squares of log step_s on log N for N >= 64) are printed to stdout.

The model (the same for all engines): N rigid links in a chain, each 1 m long along x, mass
1 kg, principal inertia about the centre of mass (5e-5, 1/12, 1/12) kg m^2; link i has its
centre at (0.5 + i, 0, 0), identity orientation, at rest; ball joints connect link 0's end
(-0.5, 0, 0) to the ground at the origin and link i's end (-0.5, 0, 0) to link i-1's end
(+0.5, 0, 0); gravity (0, 0, -9.81); h = 1e-3 s.

Before the scaling runs, a physics sanity check is printed: after 0.05 s from rest the far
links of the horizontal chain are in free fall, z = -g t^2 / 2 = -0.0122625 m; every engine
(and MuJoCo / Pinocchio integrated with RK4) is compared with that and with each other.

Each engine and N runs in its own subprocess (timeout 120 s, address space capped at
--mem-limit-gb so that an engine that allocates too much fails with MemoryError instead of
taking the shared machine down); an engine stops growing N after a failure or after one
measurement took more than --budget-s (20 s) of wall time, and the larger N are recorded as
skipped.

The engines come from PyPI into a scratch virtual environment, build/peer-venv, created with
Debian's /usr/bin/python3 -m venv on first use (packages already importable are not
reinstalled); the script re-executes itself inside it. Run it from anywhere, niced on a
shared machine:

    nice -n 10 python3 bench/peer_scaling.py                # full range, all three engines
    nice -n 10 python3 bench/peer_scaling.py --quick        # N <= 64, to build/peer_scaling_quick.csv
    nice -n 10 python3 bench/peer_scaling.py --engines mujoco,pinocchio --max-n 256
"""

import argparse
import csv
import json
import math
import os
import re
import statistics
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
VENV = REPO / "build" / "peer-venv"
VENV_PYTHON = VENV / "bin" / "python"
DEFAULT_CSV = REPO / "bench" / "results" / "peer_scaling.csv"
QUICK_CSV = REPO / "build" / "peer_scaling_quick.csv"

# PyPI distribution -> (import name, version this script was written and run against).
# The Exudyn settings used below (simulationSettings.solution / .linearSolver) are those of
# this version; older names are used as a fallback.
PACKAGES = {
    "numpy": ("numpy", "2.4.6"),
    "exudyn": ("exudyn", "1.13.6"),
    "mujoco": ("mujoco", "4.0.0"),
    "pin": ("pinocchio", "4.1.0"),
}

ENGINES = ("exudyn", "mujoco", "pinocchio")

# ---- the model -------------------------------------------------------------------------
LINK_LENGTH = 1.0
LINK_MASS = 1.0
LINK_INERTIA = (5e-5, 1.0 / 12.0, 1.0 / 12.0)  # principal, about the COM, x along the link
GRAVITY = (0.0, 0.0, -9.81)
H = 1e-3

# ---- measurement budgets ---------------------------------------------------------------
MAX_STEPS = 200          # steps per timed block for the steppers (fewer for large N)
MAX_ABA_CALLS = 20000    # ABA calls per timed block for Pinocchio
MIN_REPS = 3             # repetitions of a block; step_s is their median
MAX_REPS = 25            # cheap blocks are repeated until MIN_TIMED_S of timed work or this
MIN_TIMED_S = 1.0


# =========================================================================================
# Bootstrap: the scratch virtual environment
# =========================================================================================

def in_venv():
    return Path(sys.prefix).resolve() == VENV.resolve()


def ensure_venv_and_reexec(argv, script=None, packages=None, env=None):
    """Create build/peer-venv if missing, pip-install what is not importable (of `packages`,
    a subset of PACKAGES; all by default), re-exec `script` (this file by default) in it, with
    the environment `env` (this process's by default)."""
    packages = PACKAGES if packages is None else packages
    if not VENV_PYTHON.exists():
        base = "/usr/bin/python3" if Path("/usr/bin/python3").exists() else sys.executable
        print(f"creating {VENV} with {base} -m venv", flush=True)
        subprocess.run([base, "-m", "venv", str(VENV)], check=True)
    probe = ("import importlib.util, sys\n"
             "print(' '.join(m for m in sys.argv[1:] if importlib.util.find_spec(m) is None))")
    modules = [mod for mod, _ in packages.values()]
    out = subprocess.run([str(VENV_PYTHON), "-c", probe, *modules],
                         check=True, capture_output=True, text=True).stdout.split()
    missing = [f"{dist}=={ver}" for dist, (mod, ver) in packages.items() if mod in out]
    if missing:
        print("pip install " + " ".join(missing), flush=True)
        subprocess.run([str(VENV_PYTHON), "-m", "pip", "install", "--quiet", *missing],
                       check=True)
    sys.stdout.flush()
    script = Path(script or __file__).resolve()
    os.execve(str(VENV_PYTHON), [str(VENV_PYTHON), str(script), *argv],
              os.environ if env is None else env)


# =========================================================================================
# Engines. Each one builds the chain, advances it K steps from rest, and reports the link
# centres; they only run inside worker subprocesses.
# =========================================================================================

class ExudynChain:
    """Redundant coordinates: 7 ODE2 coordinates (position + Euler parameters) per link,
    3 joint constraints + 1 Euler-parameter constraint per link; generalized-alpha."""

    def __init__(self, n):
        import numpy as np
        import exudyn as exu
        from exudyn.utilities import RigidBodyInertia
        self.exu = exu
        self.n = n
        self.SC = exu.SystemContainer()
        self.mbs = mbs = self.SC.AddSystem()
        ground = mbs.CreateGround()
        inertia = RigidBodyInertia(mass=LINK_MASS, inertiaTensor=np.diag(LINK_INERTIA),
                                   com=[0.0, 0.0, 0.0])
        self.bodies = []
        previous = ground
        for i in range(n):
            body = mbs.CreateRigidBody(inertia=inertia, referencePosition=[0.5 + i, 0.0, 0.0],
                                       gravity=list(GRAVITY), show=False)
            # the joint at the global point (i, 0, 0) of the reference configuration
            mbs.CreateSphericalJoint(itemNumbers=[previous, body], position=[float(i), 0.0, 0.0],
                                     show=False)
            self.bodies.append(body)
            previous = body
        mbs.Assemble()
        self.method = "GeneralizedAlpha/EigenSparse"
        self.newton_per_step = self.jacobians_per_step = float("nan")

    def _settings(self, k):
        exu = self.exu
        ss = exu.SimulationSettings()
        ti = ss.timeIntegration
        ti.numberOfSteps = k
        ti.endTime = k * H
        ti.adaptiveStep = False      # fixed h: a Newton failure fails instead of halving h
        ti.verboseMode = 0
        ss.displayStatistics = False
        ss.displayComputationTime = False
        if hasattr(ss, "solution"):  # names of Exudyn 1.13
            ss.solution.file.write = False
            ss.solution.sensors.active = False
            ss.linearSolver.solverType = exu.LinearSolverType.EigenSparse
        else:                        # older names
            ss.solutionSettings.writeSolutionToFile = False
            ss.linearSolverType = exu.LinearSolverType.EigenSparse
        return ss

    def run(self, k):
        """Advance k steps from the initial state (rest); return the wall time of the steps
        alone (solver initialization, i.e. initial accelerations, is not timed)."""
        exu = self.exu
        ss = self._settings(k)
        solver = exu.MainSolverImplicitSecondOrder()
        solver.InitializeSolver(self.mbs, ss)     # resets the state to the initial values
        n0, j0 = solver.it.newtonStepsCount, solver.it.newtonJacobiCount
        t0 = time.perf_counter()
        ok = solver.SolveSteps(self.mbs, ss)
        elapsed = time.perf_counter() - t0
        steps_done = round(solver.it.currentTime / H)
        self.newton_per_step = (solver.it.newtonStepsCount - n0) / k
        self.jacobians_per_step = (solver.it.newtonJacobiCount - j0) / k
        solver.FinalizeSolver(self.mbs, ss)
        if not ok or steps_done != k:
            raise RuntimeError(f"Exudyn solver failed after {steps_done} of {k} steps: "
                               f"{solver.GetErrorString()}")
        return elapsed

    def centres_z(self):
        pos = self.exu.OutputVariableType.Position
        return [self.mbs.GetObjectOutputBody(b, pos, localPosition=[0.0, 0.0, 0.0])[2]
                for b in self.bodies]

    def notes(self):
        return (f"Newton it/step {self.newton_per_step:.2f}, "
                f"Jacobians/step {self.jacobians_per_step:.3f}")


def mujoco_xml(n, integrator):
    """MJCF of the chain: nested bodies whose frame sits at the joint (parent-side end)."""
    inertia = " ".join(repr(x) for x in LINK_INERTIA)
    opening = []
    for i in range(n):
        pos = "0 0 0" if i == 0 else f"{LINK_LENGTH!r} 0 0"
        opening.append(
            f'<body name="link{i}" pos="{pos}">'
            f'<joint name="ball{i}" type="ball" pos="0 0 0"/>'
            f'<inertial pos="{LINK_LENGTH / 2!r} 0 0" mass="{LINK_MASS!r}" diaginertia="{inertia}"/>'
            f'<geom type="capsule" fromto="0 0 0 {LINK_LENGTH!r} 0 0" size="0.01"'
            f' contype="0" conaffinity="0"/>')
    gravity = " ".join(repr(g) for g in GRAVITY)
    return (f'<mujoco model="chain{n}">'
            f'<compiler inertiafromgeom="false"/>'
            f'<option timestep="{H!r}" gravity="{gravity}" integrator="{integrator}">'
            f'<flag contact="disable"/></option>'
            f'<worldbody>{"".join(opening)}{"</body>" * n}</worldbody></mujoco>')


def mujoco_spec(n, integrator):
    """The same model through mujoco.MjSpec, for chains deeper than the XML parser allows."""
    import mujoco
    spec = mujoco.MjSpec()
    spec.compiler.inertiafromgeom = mujoco.mjtInertiaFromGeom.mjINERTIAFROMGEOM_FALSE
    spec.option.timestep = H
    spec.option.gravity = list(GRAVITY)
    spec.option.integrator = {"Euler": mujoco.mjtIntegrator.mjINT_EULER,
                              "implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
                              "implicit": mujoco.mjtIntegrator.mjINT_IMPLICIT,
                              "RK4": mujoco.mjtIntegrator.mjINT_RK4}[integrator]
    spec.option.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
    parent = spec.worldbody
    for i in range(n):
        body = parent.add_body(name=f"link{i}", pos=[0.0 if i == 0 else LINK_LENGTH, 0, 0],
                               mass=LINK_MASS, ipos=[LINK_LENGTH / 2, 0, 0],
                               inertia=list(LINK_INERTIA), explicitinertial=True)
        body.add_joint(name=f"ball{i}", type=mujoco.mjtJoint.mjJNT_BALL)
        body.add_geom(type=mujoco.mjtGeom.mjGEOM_CAPSULE, fromto=[0, 0, 0, LINK_LENGTH, 0, 0],
                      size=[0.01, 0, 0], contype=0, conaffinity=0)
        parent = body
    return spec


class MujocoChain:
    """Minimal coordinates: one quaternion (nq = 4, nv = 3) per ball joint; mj_step."""

    def __init__(self, n, integrator="Euler", force_spec=False):
        import mujoco
        self.mj = mujoco
        self.xml_error = None
        if not force_spec:
            xml = mujoco_xml(n, integrator)
            try:
                t0 = time.perf_counter()
                self.model = mujoco.MjModel.from_xml_string(xml)
                self.data = mujoco.MjData(self.model)
                self.setup_s = time.perf_counter() - t0
                self.method = f"mj_step/{integrator}/xml"
                return
            except ValueError as err:   # tinyxml2: XML_ELEMENT_DEPTH_EXCEEDED for deep chains
                if "XML" not in str(err):
                    raise
                code = re.search(r"Error=(\w+)", str(err))
                self.xml_error = code.group(1) if code else " ".join(str(err).split())[:80]
        t0 = time.perf_counter()
        self.model = mujoco_spec(n, integrator).compile()
        self.data = mujoco.MjData(self.model)
        self.setup_s = time.perf_counter() - t0
        self.method = f"mj_step/{integrator}/MjSpec"

    def run(self, k):
        self.mj.mj_resetData(self.model, self.data)
        t0 = time.perf_counter()
        self.mj.mj_step(self.model, self.data, nstep=k)
        return time.perf_counter() - t0

    def centres_z(self):
        # xipos is computed at the start of mj_step, i.e. for the previous qpos: refresh it
        self.mj.mj_kinematics(self.model, self.data)
        return [float(z) for z in self.data.xipos[1:, 2]]

    def notes(self):
        return f"nq={self.model.nq} nv={self.model.nv} nM={self.model.nM}"


class PinocchioChain:
    """Minimal coordinates: JointModelSpherical (nq = 4, nv = 3) per link; pin.aba."""

    def __init__(self, n):
        import numpy as np
        import pinocchio as pin
        self.np, self.pin = np, pin
        self.model = model = pin.Model()
        model.gravity = pin.Motion(np.array(GRAVITY), np.zeros(3))
        inertia = pin.Inertia(LINK_MASS, np.array([LINK_LENGTH / 2, 0.0, 0.0]),
                              np.diag(LINK_INERTIA))
        parent = 0
        for i in range(n):
            placement = pin.SE3(np.eye(3), np.array([0.0 if i == 0 else LINK_LENGTH, 0.0, 0.0]))
            joint = model.addJoint(parent, pin.JointModelSpherical(), placement, f"ball{i}")
            model.appendBodyToJoint(joint, inertia, pin.SE3.Identity())
            parent = joint
        try:
            self.data = model.createData()
        except MemoryError:
            # Data preallocates third-order (nv x nv x nv) derivative buffers: the resident
            # size measured here is ~8 nv^3 doubles (3.7 GB at nv = 384)
            raise MemoryError(f"model.createData() for nv={model.nv}: Data holds ~8 nv^3 "
                              f"doubles = {64 * model.nv**3 / 2**30:.0f} GiB") from None
        self.method = "aba"
        self.q = pin.neutral(model)
        self.v = np.zeros(model.nv)
        self.tau = np.zeros(model.nv)

    def run(self, k):
        """k ABA evaluations at the initial state (the cost of ABA does not depend on it)."""
        aba, model, data, q, v, tau = self.pin.aba, self.model, self.data, self.q, self.v, self.tau
        t0 = time.perf_counter()
        for _ in range(k):
            aba(model, data, q, v, tau)
        return time.perf_counter() - t0

    def simulate(self, t_end, scheme):
        """Sanity check only: integrate from rest with semi-implicit Euler or RK4 on pin.aba."""
        pin, np = self.pin, self.np
        model, data, tau = self.model, self.data, self.tau
        q, v = pin.neutral(model), np.zeros(model.nv)

        def acc(q_, v_):
            return pin.aba(model, data, q_, v_, tau).copy()

        for _ in range(round(t_end / H)):
            if scheme == "Euler":  # same scheme as MuJoCo's Euler: v first, then q with new v
                v = v + H * acc(q, v)
                q = pin.integrate(model, q, H * v)
            else:                  # RK4 with the configuration update through pin.integrate
                k1v, k1q = acc(q, v), v
                v2 = v + 0.5 * H * k1v
                k2v, k2q = acc(pin.integrate(model, q, 0.5 * H * k1q), v2), v2
                v3 = v + 0.5 * H * k2v
                k3v, k3q = acc(pin.integrate(model, q, 0.5 * H * k2q), v3), v3
                v4 = v + H * k3v
                k4v, k4q = acc(pin.integrate(model, q, H * k3q), v4), v4
                q = pin.integrate(model, q, H / 6 * (k1q + 2 * k2q + 2 * k3q + k4q))
                v = v + H / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
        pin.forwardKinematics(model, data, q)
        centre = np.array([LINK_LENGTH / 2, 0.0, 0.0])
        return [float(data.oMi[j].act(centre)[2]) for j in range(1, model.njoints)]

    def notes(self):
        return f"nq={self.model.nq} nv={self.model.nv}"


# =========================================================================================
# Worker side: one engine, one N, in its own process
# =========================================================================================

def limit_memory(gib):
    import resource
    cap = int(gib * 2**30)
    resource.setrlimit(resource.RLIMIT_AS, (cap, cap))


def build(engine, n, args):
    """Return (chain, setup seconds). A one-link model is built first, untimed, so that the
    setup time does not include the engines' lazy imports and first-call costs."""
    def make(links, **kw):
        if engine == "mujoco":
            return MujocoChain(links, args.mujoco_integrator, **kw)
        return ExudynChain(links) if engine == "exudyn" else PinocchioChain(links)

    make(1)
    if engine == "mujoco":
        make(1, force_spec=True)
    t0 = time.perf_counter()
    chain = make(n)
    setup_s = time.perf_counter() - t0
    if engine == "mujoco":
        setup_s = chain.setup_s  # MjModel (from XML, or MjSpec) + MjData, not the XML text
    return chain, setup_s


def worker_bench(engine, n, args):
    chain, setup_s = build(engine, n, args)
    # probe: a short block, also a warm-up, to size the timed blocks
    k_probe = 200 if engine == "pinocchio" else 3
    per_step = chain.run(k_probe) / k_probe
    k_max = MAX_ABA_CALLS if engine == "pinocchio" else MAX_STEPS
    k = max(1, min(k_max, int(args.target_block_s / max(per_step, 1e-9))))
    times = []
    while len(times) < MIN_REPS or (len(times) < MAX_REPS and sum(times) * k < MIN_TIMED_S):
        times.append(chain.run(k) / k)
    status = "ok"
    if getattr(chain, "xml_error", None):
        status = f"ok; MJCF XML refused ({chain.xml_error}), same model built with MjSpec"
    return {"method": chain.method, "setup_s": setup_s, "step_s": statistics.median(times),
            "steps": k, "reps": len(times), "status": status, "notes": chain.notes()}


def worker_sanity(engine, n, args):
    """z of every link centre after t from rest, for each checkpoint t and integrator."""
    out = {}
    for t_end in args.sanity_times:
        k = round(t_end / H)
        if engine == "exudyn":
            chain = ExudynChain(n)
            chain.run(k)
            out[f"GA(rho=0.9)@{t_end}"] = chain.centres_z()
        elif engine == "mujoco":
            for integ in dict.fromkeys([args.mujoco_integrator, "RK4"]):
                for force_spec in (False, True):
                    chain = MujocoChain(n, integ, force_spec=force_spec)
                    chain.run(k)
                    tag = "MjSpec" if force_spec else "xml"
                    out[f"{integ}/{tag}@{t_end}"] = chain.centres_z()
        else:
            chain = PinocchioChain(n)
            for scheme in ("Euler", "RK4"):
                out[f"aba+{scheme}@{t_end}"] = chain.simulate(t_end, scheme)
    return out


def worker_main(args):
    limit_memory(args.mem_limit_gb)
    try:
        if args.mode == "sanity":
            result = worker_sanity(args.worker, args.n, args)
        else:
            result = worker_bench(args.worker, args.n, args)
    except BaseException as err:  # MemoryError, solver failures, ...
        message = " ".join(str(err).split())[:200]  # one line, for the CSV and the table
        result = {"status": f"failed: {type(err).__name__}: {message}"}
    print("RESULT " + json.dumps(result), flush=True)


# =========================================================================================
# Driver side
# =========================================================================================

def run_worker(engine, n, mode, args):
    """Run one worker; return (result dict, wall seconds)."""
    cmd = [sys.executable, str(Path(__file__).resolve()), "--worker", engine, "--n", str(n),
           "--mode", mode, "--mujoco-integrator", args.mujoco_integrator,
           "--target-block-s", str(args.target_block_s), "--mem-limit-gb", str(args.mem_limit_gb)]
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1",
               PYTHONWARNINGS="ignore")
    t0 = time.perf_counter()
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=args.timeout_s,
                              env=env)
    except subprocess.TimeoutExpired:
        return {"status": f"timeout (> {args.timeout_s:g} s)"}, time.perf_counter() - t0
    wall = time.perf_counter() - t0
    for line in reversed(proc.stdout.splitlines()):
        if line.startswith("RESULT "):
            return json.loads(line[len("RESULT "):]), wall
    tail = (proc.stderr.strip().splitlines() or ["no output"])[-1][:200]
    how = f"signal {-proc.returncode}" if proc.returncode < 0 else f"exit {proc.returncode}"
    return {"status": f"failed: {how}: {tail}"}, wall


def free_fall_z(t):
    return 0.5 * GRAVITY[2] * t * t


def sanity_check(engines, args, n=8):
    """Print the free-fall check and the cross-engine agreement; return the printed lines."""
    lines = [f"## Sanity check: N={n}, from rest; far links in free fall, "
             f"z(0.05 s) = -g t^2/2 = {free_fall_z(0.05):.7f} m"]
    runs = {}
    for engine in engines:
        res, _ = run_worker(engine, n, "sanity", args)
        if "status" in res:
            lines.append(f"  {engine}: {res['status']}")
            continue
        for key, zs in res.items():
            label, t_end = key.rsplit("@", 1)
            runs[(engine, label, float(t_end))] = zs
    t0 = args.sanity_times[0]
    steps = round(t0 / H)
    # semi-implicit Euler in free fall: z_n = g h^2 n (n + 1) / 2, first order in h
    euler_ff = 0.5 * GRAVITY[2] * H * H * steps * (steps + 1)
    ref_key = next((k for k in runs if k[0] == "mujoco" and k[1].startswith("RK4/xml")), None)
    lines.append(f"  {'engine / integrator':30s} {'z_last(0.05)':>13s} {'- free fall':>11s}"
                 f"  verdict; max|dz| over links vs MuJoCo RK4 at t = "
                 + ", ".join(f"{t:g}" for t in args.sanity_times) + " s")
    for (engine, label, t_end), zs in sorted(runs.items()):
        if t_end != t0:
            continue
        dev = zs[-1] - free_fall_z(t0)
        # MuJoCo's Euler, implicitfast and implicit are first order, like semi-implicit Euler
        first_order = label.split("/")[0] in ("Euler", "implicitfast", "implicit") or "Euler" in label
        if first_order:  # compare with the discrete free fall of the scheme instead
            ok = abs(zs[-1] - euler_ff) < 1e-4
            verdict = (f"{'OK' if ok else 'DISAGREES'} (first-order scheme: discrete free fall "
                       f"{euler_ff:.7f}, dev {zs[-1] - euler_ff:+.1e})")
        else:
            verdict = "OK" if abs(dev) < 1e-4 else "DISAGREES (> 1e-4 m)"
        cross = []
        for t in args.sanity_times:
            a, b = runs.get((engine, label, t)), runs.get((ref_key[0], ref_key[1], t)) if ref_key else None
            cross.append(f"{max(abs(x - y) for x, y in zip(a, b)):.1e}" if a and b else "-")
        lines.append(f"  {engine + ' ' + label:30s} {zs[-1]:13.7f} {dev:+11.1e}  {verdict}; "
                     + ", ".join(cross))
    for line in lines:
        print(line, flush=True)
    return lines


def fit_exponent(rows, n_min=64):
    pts = [(math.log(r["N"]), math.log(r["step_s"])) for r in rows
           if r["status"].startswith("ok") and r["N"] >= n_min and r["step_s"]]
    if len(pts) < 2:
        return None, 0
    mx = sum(x for x, _ in pts) / len(pts)
    my = sum(y for _, y in pts) / len(pts)
    slope = (sum((x - mx) * (y - my) for x, y in pts) / sum((x - mx) ** 2 for x, _ in pts))
    return slope, len(pts)


def fmt(x):
    return "" if x is None or x == "" else f"{x:.3e}"


def driver_main(args):
    engines = [e.strip() for e in args.engines.split(",") if e.strip()]
    for e in engines:
        if e not in ENGINES:
            sys.exit(f"unknown engine {e!r}; choose from {', '.join(ENGINES)}")
    max_n = min(args.max_n, 64) if args.quick else args.max_n
    ns = [2**k for k in range(0, 13) if 2**k <= max_n]
    out_csv = Path(args.out) if args.out else (QUICK_CSV if args.quick else DEFAULT_CSV)

    import exudyn, mujoco, numpy, pinocchio  # noqa: E401 -- versions for the report
    print(f"# peer scaling: exudyn {exudyn.__version__}, mujoco {mujoco.__version__}, "
          f"pinocchio {pinocchio.__version__}, numpy {numpy.__version__}, "
          f"python {sys.version.split()[0]}; load average {os.getloadavg()[0]:.2f}", flush=True)

    if not args.no_sanity:
        sanity_check(engines, args)

    rows = []
    for engine in engines:
        stopped = None
        for n in ns:
            if stopped:
                rows.append({"engine": engine, "method": "", "N": n, "setup_s": "", "step_s": "",
                             "steps": "", "status": f"skipped ({stopped})", "notes": ""})
                continue
            res, wall = run_worker(engine, n, "bench", args)
            row = {"engine": engine, "method": res.get("method", ""), "N": n,
                   "setup_s": res.get("setup_s", ""), "step_s": res.get("step_s", ""),
                   "steps": res.get("steps", ""), "status": res["status"],
                   "notes": (res.get("notes", "") + f"; wall {wall:.1f} s").lstrip("; ")}
            rows.append(row)
            print(f"{engine:9s} N={n:5d} {row['status'][:60]:14s} setup {fmt(row['setup_s']):>10s} s"
                  f"  step {fmt(row['step_s']):>10s} s  x{row['steps']}  [{row['notes']}]",
                  flush=True)
            if not row["status"].startswith("ok"):
                stopped = f"N={n} failed"
            elif wall > args.budget_s:
                stopped = f"N={n} took {wall:.0f} s > {args.budget_s:g} s"

    out_csv.parent.mkdir(parents=True, exist_ok=True)
    with open(out_csv, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["engine", "method", "N", "setup_s", "step_s", "steps", "status"])
        for r in rows:
            w.writerow([r["engine"], r["method"], r["N"],
                        f"{r['setup_s']:.6g}" if r["setup_s"] != "" else "",
                        f"{r['step_s']:.6g}" if r["step_s"] != "" else "",
                        r["steps"], r["status"]])
    print(f"\nwrote {out_csv}\n")

    print("| engine | method | N | setup [s] | per step [s] | steps | status | notes |")
    print("|---|---|---:|---:|---:|---:|---|---|")
    for r in rows:
        print(f"| {r['engine']} | {r['method']} | {r['N']} | {fmt(r['setup_s'])} | "
              f"{fmt(r['step_s'])} | {r['steps']} | {r['status']} | {r['notes']} |")
    print(f"\nload average at the end: {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    print("\nGrowth exponent p of per-step time ~ N^p (least squares, N >= 64, ok rows):")
    for engine in engines:
        p, npts = fit_exponent([r for r in rows if r["engine"] == engine])
        ok_ns = [r["N"] for r in rows if r["engine"] == engine and r["status"].startswith("ok")]
        span = f"N = 64..{max(ok_ns)}" if ok_ns and max(ok_ns) >= 64 else "-"
        print(f"  {engine:9s} " + (f"p = {p:.2f} over {span} ({npts} points)" if p is not None
                                   else "not enough points"))


def parse_args(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--engines", default=",".join(ENGINES),
                    help="comma-separated subset of exudyn,mujoco,pinocchio (default: all)")
    ap.add_argument("--max-n", type=int, default=4096, help="largest N (default 4096)")
    ap.add_argument("--quick", action="store_true",
                    help=f"N up to 64 only; writes {QUICK_CSV.relative_to(REPO)} unless --out")
    ap.add_argument("--out", help=f"CSV path (default {DEFAULT_CSV.relative_to(REPO)})")
    ap.add_argument("--no-sanity", action="store_true", help="skip the physics sanity check")
    ap.add_argument("--budget-s", type=float, default=20.0,
                    help="stop growing N for an engine after a measurement took longer (20)")
    ap.add_argument("--timeout-s", type=float, default=120.0,
                    help="kill one engine/N measurement after this long (120)")
    ap.add_argument("--mem-limit-gb", type=float, default=8.0,
                    help="address-space cap of each measurement process, GiB (8)")
    ap.add_argument("--target-block-s", type=float, default=3.0,
                    help="wall time aimed at for one timed block of steps (3)")
    ap.add_argument("--mujoco-integrator", default="Euler",
                    choices=["Euler", "implicitfast", "implicit", "RK4"],
                    help="MuJoCo integrator for the benchmark (default: MuJoCo's default Euler)")
    # internal: one measurement in a subprocess
    ap.add_argument("--worker", choices=ENGINES, help=argparse.SUPPRESS)
    ap.add_argument("--n", type=int, help=argparse.SUPPRESS)
    ap.add_argument("--mode", choices=["bench", "sanity"], default="bench", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    args.sanity_times = [0.05, 0.3]
    return args


def main():
    argv = sys.argv[1:]
    if not in_venv():
        ensure_venv_and_reexec(argv)   # does not return
    args = parse_args(argv)
    if args.worker:
        worker_main(args)
    else:
        driver_main(args)


if __name__ == "__main__":
    main()
