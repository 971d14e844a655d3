"""Analyses (assembly, dynamics) and their results as NumPy arrays, addressed by name."""

from __future__ import annotations

import dataclasses
import warnings
from typing import Any, Callable, Dict, List, Mapping, NamedTuple, Optional, Tuple, Union

import numpy as np

from . import _core
from ._schema import (SceneError, check_callable, check_choice, check_count, check_number,
                      check_tolerance, fail)
from .model import BaseModel, check_model
from .settings import (AssemblySettings, IntegratorSettings, assembly_settings,
                       integrator_settings, with_keywords)

#: Integrators whose step is fixed unless `adaptive` (error control) is on.
ADAPTIVE_OPTIONAL = ("generalized-alpha", "hht")


def chosen_integrator(settings: Mapping[str, Any]) -> str:
    """The integrator simulate() runs for these settings (a dict of its keyword arguments): the
    one named, else generalized-alpha when a step is given without rtol and atol, or when
    `adaptive` (generalized-alpha's option) is, else auto."""
    chosen = settings.get("integrator")
    if chosen is not None:
        return chosen if isinstance(chosen, str) else integrator_settings(chosen).NAME
    fixed_step = settings.get("step") is not None and settings.get("rtol") is None and \
        settings.get("atol") is None
    return "generalized-alpha" if fixed_step or settings.get("adaptive") is not None else "auto"


def integrators() -> Dict[str, str]:
    """The integrators `simulate` knows, by name, with a description (from the C++ library's
    odyn::integrator_names(), so a new C++ integrator appears here by itself)."""
    return dict(_core.integrators())


#: Integrator names when the package was imported (`integrators()` is the function to call).
INTEGRATORS = tuple(integrators())


class RedundantConstraintsWarning(UserWarning):
    """Some constraint equations repeat others at the assembled pose (the mechanism is
    over-constrained, consistently). The analysis goes on with the minimum-norm multipliers, so
    the reactions of the joints named are one choice among many."""


class AssemblyWarning(UserWarning):
    """Assembly moved bodies farther from the poses they were given than its thresholds (1e-5 m
    or 1e-5 rad): the given poses do not meet the constraints, often because a joint's points
    or axes do not fit the bodies. `Result.assembly["moved_bodies"]` lists how far each moved."""


class ToleranceWarning(UserWarning):
    """rtol was below what double precision can deliver (100 machine epsilons, 2.2e-14) and
    the run used that floor instead."""


#: The warning class of each kind of warning a run reports.
_WARNING_CLASSES = {"assembly": AssemblyWarning, "tolerance": ToleranceWarning}


class Interrupted(KeyboardInterrupt):
    """A run stopped by Ctrl-C (SIGINT). `result` holds the outputs computed before it."""

    def __init__(self, result: "Result") -> None:
        super().__init__(f"run interrupted at t = {result.t[-1] if len(result.t) else 0.0:g} s "
                         f"({len(result.t)} outputs kept)")
        self.result = result


class Reaction(NamedTuple):
    force: np.ndarray   # (n, 3); planar (n, 2)
    torque: np.ndarray  # (n, 3), about the joint point; planar (n,)


class Event(NamedTuple):
    """A located crossing of an event's value (see BaseModel.add_event)."""
    name: str
    time: float       # s
    direction: str    # "rising" or "falling"
    terminal: bool    # it ended the run


class Statistics(NamedTuple):
    """What a dynamic analysis counted (the C++ IntegratorStatistics and RunSummary)."""
    steps: int                  # accepted steps
    rejected_steps: int         # attempts thrown away (error too large or Newton failed)
    newton_iterations: int      # linear solves of Newton iterations (or projections)
    jacobian_evaluations: int   # iteration matrices assembled
    factorizations: int
    residual_evaluations: int   # evaluations of Phi, Phi_q and Q together
    restarts: int               # after discontinuities and at the start
    events: int                 # located switches of force laws
    singular_steps: int         # steps that ended at a singular configuration's rounding floor
    max_error_estimate: float   # largest local error estimate of a step, in units of rtol/atol
    outputs: int
    wall_seconds: float         # the whole run
    setup_seconds: float        # of which assembly (unless reused) and the integrator's setup
    max_position_residual: float  # max |Phi| at the output times
    max_velocity_residual: float  # max |Phi_q v + Phi_t| at the output times


class PlanarBodyHistory(NamedTuple):
    position: np.ndarray              # (n, 2) centre of mass
    angle: np.ndarray                 # (n,) rad, counter-clockwise, counting turns
    linear_velocity: np.ndarray       # (n, 2)
    angular_velocity: np.ndarray      # (n,)
    linear_acceleration: np.ndarray   # (n, 2)
    angular_acceleration: np.ndarray  # (n,)


class BodyHistory(NamedTuple):
    position: np.ndarray            # (n, 3) centre of mass, global
    orientation: np.ndarray         # (n, 4) unit quaternion w, x, y, z (body to global)
    linear_velocity: np.ndarray     # (n, 3) global
    angular_velocity: np.ndarray    # (n, 3) body axes
    linear_acceleration: np.ndarray   # (n, 3) global
    angular_acceleration: np.ndarray  # (n, 3) body axes


class PointHistory(NamedTuple):
    """A point's motion (or one point's relative to another), one row per output time."""
    position: np.ndarray      # (n, 3); planar (n, 2)
    velocity: np.ndarray      # (n, 3); planar (n, 2)
    acceleration: np.ndarray  # (n, 3); planar (n, 2)


class Result:
    """Outputs of an analysis, one row per output time.

    Arrays: t (n), q (n x 7 nb; planar n x 3 nb), v and vdot (n x 6 nb; planar n x 3 nb),
    ``lambda_`` (n x m), kinetic_energy, potential_energy, total_energy, phi_norm (``|Phi|``),
    phid_norm (``|Phi_q v + Phi_t|``).
    By name: body(name), point(name), relative(point, to, axes), reaction(joint, side, axes),
    multipliers(joint), output(element, name), state(element).
    events: the model's events in time order (Event: name, time, direction, terminal);
    event_times(name); ended_by: the terminal event that ended the run, or None.
    statistics: steps, rejected steps, Newton iterations, ... (for a run that stopped early,
    what it counted until then); summary: the same as a dict, with the assembly report;
    statics: a static equilibrium's summary (odyn.statics); kinematics: a kinematic
    analysis's (odyn.kinematics).
    A run that stopped early (the rows so far, an exception's `result`) says why:
    `interrupted` is True after Ctrl-C, `error` holds the message of the error that stopped it
    ("SolverError: at t = ..."), and `complete` is False for both.
    """

    def __init__(self, data: Dict[str, Any], interrupted: bool = False,
                 error: Optional[str] = None) -> None:
        self._data = data
        self.t: np.ndarray = data["t"]
        self.q: np.ndarray = data["q"]
        self.v: np.ndarray = data["v"]
        self.vdot: np.ndarray = data["vdot"]
        self.lambda_: np.ndarray = data["lambda"]
        self.kinetic_energy: np.ndarray = data["kinetic_energy"]
        self.potential_energy: np.ndarray = data["potential_energy"]
        self.total_energy: np.ndarray = self.kinetic_energy + self.potential_energy
        self.phi_norm: np.ndarray = data["phi_norm"]
        self.phid_norm: np.ndarray = data["phid_norm"]
        self.space: str = data.get("space", "spatial")
        self.summary: Optional[Dict[str, Any]] = data.get("summary")
        self.statistics: Optional[Statistics] = (
            Statistics(**{k: self.summary[k] for k in Statistics._fields})
            if self.summary else None)
        self.assembly: Optional[Dict[str, Any]] = data.get("assembly") or (
            self.summary["assembly"] if self.summary else None)
        self.interrupted = interrupted
        self.error: Optional[str] = error
        self._bodies: List[str] = list(data["bodies"])
        self._points: Dict[str, Tuple[int, List[float]]] = dict(data.get("points", {}))
        # The markers with axes: name -> their axes in their body's axes.
        self._point_axes: Dict[str, np.ndarray] = {
            name: np.asarray(r, dtype=float) for name, r in data.get("point_axes", {}).items()}
        self.events: List[Event] = [Event(**e) for e in data.get("events", [])]
        self.ended_by: Optional[str] = data.get("ended_by")
        #: A static equilibrium's summary (odyn.statics), a list of one per row
        #: (odyn.quasi_statics), None for other analyses.
        self.statics: Optional[Any] = data.get("statics")
        #: A kinematic analysis's summary (odyn.kinematics), None for other analyses.
        self.kinematics: Optional[Dict[str, Any]] = data.get("kinematics")

    def __len__(self) -> int:
        return len(self.t)

    @property
    def redundant_equations(self) -> List[Dict[str, Any]]:
        """Constraint equations that repeat others at the assembled pose, each {"joint",
        "equation" (its index among the joint's equations), "row" (of Phi)}; empty for an
        ordinary mechanism. Their joints' reactions are the minimum-norm choice."""
        return list((self.assembly or {}).get("redundant_equations", []))

    @property
    def warnings(self) -> List[str]:
        """What the analysis warned about although it succeeded (a tolerance raised to its
        floor, bodies that assembly moved far), as texts; each was also issued as a Python
        warning (`AssemblyWarning`, `ToleranceWarning`)."""
        return [w["text"] for w in self._warnings()]

    def _warnings(self) -> List[Dict[str, str]]:
        return list(self._data.get("warnings") or (self.summary or {}).get("warnings", []))

    def __getitem__(self, key: str) -> np.ndarray:
        """result["lambda"] and the other arrays by name."""
        if key == "total_energy":
            return self.total_energy
        return self._data[key]

    @property
    def body_names(self) -> List[str]:
        return list(self._bodies)

    @property
    def joint_names(self) -> List[str]:
        """Every constraint (joints and drivers) with reactions."""
        return list(self._data["reactions"])

    def body(self, name: str) -> Any:
        """The body's history: a BodyHistory (spatial) or a PlanarBodyHistory (planar)."""
        if name not in self._bodies:
            raise KeyError(f"{name}: no moving body of that name; bodies: "
                           + ", ".join(self._bodies))
        b = self._bodies.index(name)
        if self.space == "planar":
            q, v, a = (x[:, 3 * b:3 * b + 3] for x in (self.q, self.v, self.vdot))
            return PlanarBodyHistory(q[:, :2], q[:, 2], v[:, :2], v[:, 2], a[:, :2], a[:, 2])
        q = self.q[:, 7 * b:7 * b + 7]
        v = self.v[:, 6 * b:6 * b + 6]
        a = self.vdot[:, 6 * b:6 * b + 6]
        return BodyHistory(q[:, :3], q[:, 3:], v[:, :3], v[:, 3:], a[:, :3], a[:, 3:])

    @property
    def point_names(self) -> List[str]:
        return list(self._points)

    def _rotations(self, body: int) -> np.ndarray:
        """(n, 3, 3) body-to-global rotations of body number `body` (planar: (n, 2, 2))."""
        n = len(self.t)
        if body == 0:
            dim = 2 if self.space == "planar" else 3
            return np.broadcast_to(np.eye(dim), (n, dim, dim))
        if self.space == "planar":
            c, s = np.cos(self.q[:, 3 * body - 1]), np.sin(self.q[:, 3 * body - 1])
            return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)
        w, x, y, z = (self.q[:, 7 * (body - 1) + 3 + i] for i in range(4))
        return np.stack([
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
        ], -2)

    def point(self, name: str) -> PointHistory:
        """The global position, velocity and acceleration of a named point (`add_point`)."""
        if name not in self._points:
            raise KeyError(f"{name}: no point of that name; points: "
                           + (", ".join(self._points) or "none (add them with add_point)"))
        body, at = self._points[name]
        local = np.asarray(at, dtype=float)
        n, dim = len(self.t), len(local)
        if body == 0:
            zero = np.zeros((n, dim))
            return PointHistory(np.tile(local, (n, 1)), zero, zero.copy())
        rotations = self._rotations(body)
        arm = np.einsum("nij,j->ni", rotations, local)  # R s, global
        if self.space == "planar":
            q, v, a = (x[:, 3 * (body - 1):3 * body] for x in (self.q, self.v, self.vdot))
            across = np.stack([-arm[:, 1], arm[:, 0]], -1)  # the arm turned a quarter
            omega, alpha = v[:, 2:3], a[:, 2:3]
            return PointHistory(q[:, :2] + arm, v[:, :2] + omega * across,
                                a[:, :2] + alpha * across - omega ** 2 * arm)
        q = self.q[:, 7 * (body - 1):7 * (body - 1) + 3]
        v = self.v[:, 6 * (body - 1):6 * body]
        a = self.vdot[:, 6 * (body - 1):6 * body]
        omega, alpha = v[:, 3:], a[:, 3:]  # body axes
        spin = np.cross(omega, local)

        def to_global(x: np.ndarray) -> np.ndarray:
            return np.einsum("nij,nj->ni", rotations, x)
        return PointHistory(q + arm, v[:, :3] + to_global(spin),
                            a[:, :3] + to_global(np.cross(alpha, local) + np.cross(omega, spin)))

    def _body_of(self, name: str, what: str) -> int:
        """The body number (0: the ground) of a body or a point named `name`."""
        if name in self._points:
            return self._points[name][0]
        if name == "ground":
            return 0
        if name in self._bodies:
            return self._bodies.index(name) + 1
        expected = "'global', a body or a point" if what == "axes" else "a body or a point"
        raise KeyError(f"{what} {name!r}: expected {expected}; bodies: "
                       + ", ".join(["ground"] + self._bodies)
                       + (f"; points: {', '.join(self._points)}" if self._points else ""))

    def _turning(self, body: int) -> Tuple[np.ndarray, np.ndarray]:
        """The global angular velocity and acceleration of a body: (n, 3) each, or (n, 1) in
        the plane."""
        n = len(self.t)
        if body == 0:
            width = 1 if self.space == "planar" else 3
            return np.zeros((n, width)), np.zeros((n, width))
        if self.space == "planar":
            return self.v[:, 3 * body - 1:3 * body], self.vdot[:, 3 * body - 1:3 * body]
        rotations = self._rotations(body)
        omega = self.v[:, 6 * (body - 1) + 3:6 * body]
        alpha = self.vdot[:, 6 * (body - 1) + 3:6 * body]
        return (np.einsum("nij,nj->ni", rotations, omega),
                np.einsum("nij,nj->ni", rotations, alpha))

    def relative(self, point: str, to: Optional[str] = None, axes: str = "global",
                 seen_from: str = "ground") -> PointHistory:
        """The motion of `point` relative to the point `to` (None: the global origin), as
        ADAMS's DX, VX and ACCX: the position of `point` from `to`, and its velocity and
        acceleration as an observer on the body `seen_from` (the ground by default: then the
        differences of the two points' velocities and accelerations) sees them, in global axes
        or in the axes named by `axes`: a body's, or a marker's (a point with an orientation;
        a point without one names its body's axes)."""
        motion = self.point(point)
        if to is not None:
            base = self.point(to)
            motion = PointHistory(*(m - b for m, b in zip(motion, base)))
        frame = self._body_of(seen_from, "seen_from")
        if frame != 0:
            # d' and d'' as seen on a frame turning at W (global) with W' : v = d' - W x d,
            # a = d'' - W' x d - 2 W x v - W x (W x d).
            spin, spin_rate = self._turning(frame)
            if self.space == "planar":
                def cross(w: np.ndarray, x: np.ndarray) -> np.ndarray:
                    return w * np.stack([-x[:, 1], x[:, 0]], -1)
            else:
                cross = np.cross
            d = motion.position
            velocity = motion.velocity - cross(spin, d)
            acceleration = (motion.acceleration - cross(spin_rate, d) - 2 * cross(spin, velocity)
                            - cross(spin, cross(spin, d)))
            motion = PointHistory(d, velocity, acceleration)
        if axes == "global":
            return motion
        rotations = self._rotations(self._body_of(axes, "axes"))
        if axes in self._point_axes:
            rotations = np.einsum("nij,jk->nik", rotations, self._point_axes[axes])
        return PointHistory(*(np.einsum("nji,nj->ni", rotations, m) for m in motion))

    def reaction(self, joint: str, side: str = "b", axes: str = "global") -> Reaction:
        """Force and torque of the joint on body `side` ("a" or "b", exerted by the other),
        at the joint point, in "global" axes or the "joint" frame on that body."""
        if joint not in self._data["reactions"]:
            raise KeyError(f"{joint}: no joint or driver of that name; constraints: "
                           + ", ".join(self._data["reactions"]))
        if side not in ("a", "b"):
            raise ValueError(f"side must be 'a' or 'b', got {side!r}")
        if axes not in ("global", "joint"):
            raise ValueError(f"axes must be 'global' or 'joint', got {axes!r}")
        r = self._data["reactions"][joint][:, "ab".index(side), ("global", "joint").index(axes)]
        if self.space == "planar":
            return Reaction(r[:, :2], r[:, 2])
        return Reaction(r[:, :3], r[:, 3:])

    def multipliers(self, joint: str) -> np.ndarray:
        """The joint's Lagrange multipliers (n x its number of equations)."""
        row, size = self._data["constraint_rows"][joint]
        return self.lambda_[:, row:row + size]

    @property
    def output_names(self) -> Dict[str, List[str]]:
        """Each element that reports outputs, with their names."""
        return {element: list(fields) for element, fields in self._data["outputs"].items()}

    def output(self, element: str, name: Optional[str] = None) -> Any:
        """An element's outputs (a spring's length, rate and tension; a bushing's displacement,
        rate and force components; see `odyn elements TYPE`): all of them as a dict of arrays,
        or the one named."""
        outputs = self._data["outputs"]
        if element not in outputs:
            raise KeyError(f"{element}: no element of that name reports outputs; those that do: "
                           + (", ".join(outputs) or "none"))
        if name is None:
            return dict(outputs[element])
        if name not in outputs[element]:
            raise KeyError(f"{element}: no output {name!r}; its outputs: "
                           + ", ".join(outputs[element]))
        return outputs[element][name]

    def state(self, element: str) -> Dict[str, np.ndarray]:
        """The discrete state of a stateful force at each output, field by field (see `odyn
        elements TYPE`): spatial rsda {angle}; the engine's gas force {theta, half_turn}. A planar
        rsda keeps no state: its angle is a difference of body angles."""
        if element not in self._data["states"]:
            raise KeyError(f"{element}: no stateful force of that name; stateful forces: "
                           + ", ".join(self._data["states"]))
        return dict(self._data["states"][element])

    def save_npz(self, path: str) -> None:
        """Every array in one .npz file: t, q, v, vdot, lambda, energies, residuals,
        reaction/<joint> (n, side a/b, global/joint axes, force xyz + torque xyz),
        state/<element>/<field>, output/<element>/<name>, point/<point>/<position, velocity or
        acceleration>, event/<name> (its times) and bodies (their names, in the order of q
        and v)."""
        arrays = {key: self._data[key] for key in (
            "t", "q", "v", "vdot", "lambda", "kinetic_energy", "potential_energy", "phi_norm",
            "phid_norm")}
        arrays["bodies"] = np.array(self._bodies)
        arrays["space"] = np.array(self.space)
        for name, values in self._data["reactions"].items():
            arrays[f"reaction/{name}"] = values
        for name, fields in self._data["states"].items():
            for field, values in fields.items():
                arrays[f"state/{name}/{field}"] = values
        for name, fields in self._data["outputs"].items():
            for field, values in fields.items():
                arrays[f"output/{name}/{field}"] = values
        for name in self._points:
            for field, values in self.point(name)._asdict().items():
                arrays[f"point/{name}/{field}"] = values
        for name in dict.fromkeys(e.name for e in self.events):
            arrays[f"event/{name}"] = self.event_times(name)
        np.savez(path, **arrays)  # type: ignore[arg-type]

    def event_times(self, name: str) -> np.ndarray:
        """The times of the event's crossings (s), in order (empty if it never crossed)."""
        return np.array([e.time for e in self.events if e.name == name], dtype=float)

    def energy_drift(self) -> float:
        """Largest ``|E(t) - E(0)|`` of kinetic plus potential energy (work of dampers and
        actuators included: only a conservative model keeps it at zero)."""
        e = self.total_energy
        return float(np.max(np.abs(e - e[0]))) if len(e) else 0.0

    @property
    def complete(self) -> bool:
        """False for the rows of a run that Ctrl-C or an error stopped early."""
        return not self.interrupted and self.error is None

    def __repr__(self) -> str:
        end = f"{self.t[-1]:g}" if len(self.t) else "-"
        note = (", interrupted" if self.interrupted else
                f", stopped by {self.error.split(':')[0]}" if self.error is not None else "")
        return f"<odyn.Result: {len(self.t)} outputs, t = 0 .. {end} s{note}>"


#: The smallest step (a run starts at t = 0): about 5 machine epsilons of 1 s, below which
#: t + step rounds back to t (the C++ core refuses it too, relative to its start time).
STEP_RESOLUTION = 1e-15

#: The tolerances of simulate() besides rtol and atol: positive, newton_rtol below 1 too.
RUN_TOLERANCES = ("newton_rtol", "newton_atol", "constraint_tolerance", "projection_tolerance")


def _settings(step: float, t_end: float, output_interval: float, integrator: str,
              rho_inf: float, rtol: Optional[float], atol: Optional[float],
              max_step: Optional[float], adaptive: Optional[bool], **extra: Any) -> Dict[str, Any]:
    """The settings dict of _core.simulate, checked. `adaptive` None: error control for
    generalized-alpha and hht exactly when rtol or atol is given (as the C++ examples do)."""
    names = integrators()
    step = check_number(step, "step", positive=True)
    t_end = check_number(t_end, "t_end", minimum=0.0)
    if step < STEP_RESOLUTION:
        fail("step", f"a step of {step:g} s is below what double precision resolves at t = 0 s, "
             f"so time would not advance; give a step of at least {STEP_RESOLUTION:g} s")
    settings: Dict[str, Any] = {
        "step": step,
        "t_end": t_end,
        "output_interval": check_number(output_interval, "output_interval", positive=True),
        "integrator": check_choice(integrator, "integrator", list(names)),
        "rho_inf": check_number(rho_inf, "rho_inf", minimum=0.0),
    }
    if rtol is not None:
        settings["rtol"] = check_tolerance(rtol, "rtol", relative=True)
    for key, value in (("atol", atol), ("max_step", max_step)):
        if value is not None:
            settings[key] = check_number(value, key, positive=True)
    if adaptive is not None and not isinstance(adaptive, bool):
        raise SceneError(f"adaptive: expected true or false, got {adaptive!r}")
    if integrator in ADAPTIVE_OPTIONAL:
        settings["adaptive"] = (rtol is not None or atol is not None) if adaptive is None \
            else adaptive
    elif adaptive is not None:
        raise SceneError(f"adaptive: applies to {' and '.join(ADAPTIVE_OPTIONAL)}; {integrator} "
                         "chooses its steps itself (leave 'adaptive' out)")
    for key, value in extra.items():
        if value is None:
            continue
        if key in RUN_TOLERANCES:
            value = check_tolerance(value, key, relative=key == "newton_rtol")
        elif key == "max_iterations":
            value = check_count(value, key, 1)
        settings[key] = value
    return settings


def _check_order(order: Optional[int]) -> Optional[int]:
    """The order of "adams": an integer from 1 to 6, or None for its default."""
    if order is None:
        return None
    if isinstance(order, bool) or not isinstance(order, int) or not 1 <= order <= 6:
        raise SceneError(f"order: expected an integer from 1 to 6, got {order!r}")
    return order


def _warn(result: Result, depth: int = 0) -> None:
    """Issues the result's warnings as Python warnings, where the user's code called (`depth`
    frames above _warn's caller)."""
    for warning in result._warnings():
        warnings.warn(_WARNING_CLASSES.get(warning["kind"], UserWarning)(warning["text"]),
                      stacklevel=3 + depth)
    equations = result.redundant_equations
    if equations:
        named = ", ".join(f"{e['joint']} (equation {e['equation']})" for e in equations)
        warnings.warn(RedundantConstraintsWarning(
            f"{named}: constraint equations are redundant (they repeat what other joints "
            "already impose); the analysis uses the minimum-norm multipliers (large models: "
            "zero for these equations), so these reactions are one choice among many. Replace "
            "a joint by one with fewer equations if you need them."), stacklevel=3 + depth)


#: The factorizations `linear_solver` may name (see `simulate`).
LINEAR_SOLVERS = ["auto", "dense", "cholmod", "klu"]
COORDINATES = ["auto", "absolute", "joint"]


def assemble(model: BaseModel, tolerance: float = 1e-12, max_iterations: int = 50,
             linear_solver: str = "auto") -> Result:
    """Consistent initial positions, velocities, accelerations and multipliers (one row).
    Redundant constraint equations are listed in `result.redundant_equations` and give a
    `RedundantConstraintsWarning`. linear_solver: as in `simulate`. The model keeps the
    assembled state until it changes: `simulate` with the same assembly settings starts from
    it instead of assembling again."""
    check_model(model)
    data = model.module.assemble(model._core, {
        "assembly_tolerance": tolerance, "assembly_max_iterations": max_iterations,
        "linear_solver": check_choice(linear_solver, "linear_solver", LINEAR_SOLVERS)})
    data["summary"] = None
    data["points"] = model._point_table()
    data["point_axes"] = model._point_axes()
    result = Result(data)
    _warn(result)
    return result


def simulate(model: BaseModel, *, t_end: float = 1.0, step: Optional[float] = None,
             output_interval: float = 1e-3,
             integrator: Union[str, IntegratorSettings, Mapping[str, Any], None] = None,
             rho_inf: Optional[float] = None, rtol: Optional[float] = None,
             atol: Optional[float] = None,
             max_step: Optional[float] = None, adaptive: Optional[bool] = None,
             progress: Optional[Callable[[float], None]] = None,
             newton_rtol: Optional[float] = None, newton_atol: Optional[float] = None,
             constraint_tolerance: Optional[float] = None,
             max_iterations: Optional[int] = None,
             projection_tolerance: Optional[float] = None,
             order: Optional[int] = None, coordinates: str = "auto",
             linear_solver: str = "auto",
             assembly: Union[AssemblySettings, Mapping[str, Any], None] = None) -> Result:
    """Assembles, then integrates from t = 0 to t_end, landing on every output time.

    The assembly runs once per model: a later `simulate` (or one after `assemble`) of the
    unchanged model starts from the state the first one assembled, checked against the
    constraints and the equations of motion (accelerations are solved again if a Python force
    changed); `summary["assembly"]["reused"]` says which happened, and `setup_seconds` then
    counts the integrator's setup only.

    integrator: by default "auto", or "generalized-alpha" when `step` is given without rtol
    or atol (a fixed step) or when `adaptive` is given. "auto" controls the error to rtol and
    atol (default 1e-6): dop853 while it does well, bdf from where the problem turns stiff (if
    bdf's steps are longer), and generalized-alpha at `step` (default 1e-4 s) from the start
    if either fails, at a singular configuration say; `summary["integrator"]` says what ran
    and `summary["integrator_choice"]` why. Or a name of `odyn.integrators()`:
    "generalized-alpha" (Chung-Hulbert, from rho_inf) or "hht" take fixed steps of at most
    `step` (a step whose Newton iteration fails is tried again in halves, down to step / 16,
    and grows back after a few good steps), or, with error control (`adaptive`; on by default
    when rtol or atol is given), steps from the local error estimate starting at `step`; "dopri5" and "dop853" (explicit Dormand-Prince 5(4) and 8(5,3), positions projected
    onto the constraints to `projection_tolerance`) and "bdf" always control their error;
    "adams" (explicit Adams-Bashforth of `order` 1 to 6, default 5) takes fixed steps of at most
    `step`, for problems that are not stiff. rtol and atol (default 1e-6) are the local error
    tolerances per component of (q, v); max_step bounds an adaptive step.
    newton_rtol, newton_atol, constraint_tolerance and max_iterations tune the Newton
    iteration of generalized-alpha and hht.

    Every setting of each integrator, those above and the rest (BDF's highest order, the reuse
    of factorizations, the projection's iterations), is reachable through a typed settings
    object: integrator=odyn.Dop853(rtol=1e-8, atol=1e-8), odyn.Bdf(max_order=3),
    odyn.GeneralizedAlpha(step=1e-3, rho_inf=0.8), or a dict {"name": "dop853", "rtol": 1e-8}
    (see odyn.settings); simulate's keywords given beside it override its fields, and one that
    the integrator does not take is refused.
    assembly: odyn.AssemblySettings(...) (or a dict of its fields): the assembly's tolerance,
    iterations and the thresholds of its warning.

    coordinates: "auto" (the default) picks joint coordinates for a spatial model whose
    spanning tree leaves few closure equations (at most 30: the engine's 3), run by auto, dop853,
    dopri5 or adams, unless it has redundant constraints or, for auto, a spring, damper or
    bushing between two moving bodies; absolute coordinates otherwise (planar models, the
    implicit methods named, many loops). `summary["coordinates"]` says which ran and
    `summary["coordinates_choice"]` why. "absolute": every body's position and orientation,
    every joint a constraint. "joint", with any integrator: the bodies located through a
    spanning tree of revolute, translational, cylindrical, universal, fixed and spherical
    joints (planar models: revolute, translational and fixed), only the joints that close
    loops (distances, drivers, the rest) as constraints. Fewer unknowns, and each evaluation costs time linear in the number of bodies (recursive
    dynamics); reactions and outputs are the same as in absolute coordinates. Generalized-alpha,
    hht and bdf there leave the spring and damper blocks that join two bodies out of Newton's
    matrix: stiff ones converge better in absolute coordinates. Redundant loop closures are
    pinned (their multipliers stay zero; absolute coordinates report minimum-norm ones).

    linear_solver: the factorization of the linear systems of the assembly and the steps.
    "auto" (the default) picks by size and pattern: dense kernels for small models (tens of
    bodies), sparse ones for large models, whose cost grows linearly on chains and trees:
    "cholmod" (the Schur complement of the constraints, when no force element joins two moving
    bodies) or "klu" (the whole matrix, when springs, dampers or bushings join bodies).
    "dense", "cholmod" and "klu" force one.

    The model's events (`Model.add_event`) are located within every step: `Result.events`
    lists their crossings, and a terminal one ends the run on it (`Result.ended_by`).

    The GIL is released during the run (Python callables take it back per call).
    progress(t) is called about every 0.2 s of wall time. Ctrl-C raises `odyn.Interrupted`,
    whose `result` holds the outputs so far; an error during the run gets the partial result
    as its `result` attribute. A consistently over-constrained mechanism runs with minimum-norm
    multipliers and a `RedundantConstraintsWarning` (see `Result.redundant_equations`).
    """
    check_model(model)
    typed: Optional[IntegratorSettings] = None
    if integrator is not None and not isinstance(integrator, str):
        typed = integrator_settings(integrator)
        keywords = {"step": step, "rtol": rtol, "atol": atol, "max_step": max_step,
                    "rho_inf": rho_inf, "adaptive": adaptive, "newton_rtol": newton_rtol,
                    "newton_atol": newton_atol, "constraint_tolerance": constraint_tolerance,
                    "max_iterations": max_iterations,
                    "projection_tolerance": projection_tolerance, "order": order}
        typed = with_keywords(typed, keywords)  # a keyword beside it overrides its field
        integrator = typed.NAME
        step, rtol, atol, max_step = (typed.step, typed.rtol, typed.atol, typed.max_step)
        rho_inf = getattr(typed, "rho_inf", None)
        adaptive = getattr(typed, "adaptive", None)
    if integrator is None:
        integrator = chosen_integrator({"step": step, "rtol": rtol, "atol": atol,
                                        "adaptive": adaptive})
    if step is None:
        step = 1e-4
    if rho_inf is None:
        rho_inf = 0.9
    settings = _settings(step, t_end, output_interval, integrator, rho_inf, rtol, atol,
                         max_step, adaptive, newton_rtol=newton_rtol, newton_atol=newton_atol,
                         constraint_tolerance=constraint_tolerance,
                         max_iterations=max_iterations,
                         projection_tolerance=projection_tolerance,
                         order=_check_order(order),
                         coordinates=check_choice(coordinates, "coordinates", COORDINATES),
                         linear_solver=check_choice(linear_solver, "linear_solver",
                                                    LINEAR_SOLVERS))
    if typed is not None and typed.SECTION is not None:
        settings[typed.SECTION] = typed.section()
    if assembly is not None:
        settings["assembly"] = dataclasses.asdict(assembly_settings(assembly))
    settings["events"] = model._event_table()
    if progress is not None:
        check_callable(progress, "progress")
    return finished_run(model, model.module.simulate(model._core, settings, progress))


def finished_run(model: BaseModel, data: Dict[str, Any]) -> Result:
    """A run's Result from what the module recorded; raises the error that stopped it, with
    the rows so far as its `result` (odyn.Interrupted for Ctrl-C)."""
    data["points"] = model._point_table()
    data["point_axes"] = model._point_axes()
    error = data.pop("error")
    if error is None:
        result = Result(data)
        _warn(result, depth=1)
        return result
    if isinstance(error, KeyboardInterrupt):
        raise Interrupted(Result(data, interrupted=True)) from error
    result = Result(data, error=f"{type(error).__name__}: {error}")
    try:
        error.result = result
    except AttributeError:
        pass
    raise error
