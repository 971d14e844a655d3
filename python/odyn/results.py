"""Analyses (assembly, dynamics) and their results as NumPy arrays, addressed by name."""

from __future__ import annotations

from typing import Any, Callable, Dict, List, NamedTuple, Optional

import numpy as np

from . import _core
from .model import Model

INTEGRATORS = ("generalized-alpha", "hht")


class Interrupted(KeyboardInterrupt):
    """A run stopped by Ctrl-C (SIGINT). `result` holds the outputs computed before it."""

    def __init__(self, result: "Result") -> None:
        super().__init__(f"run interrupted at t = {result.t[-1] if len(result.t) else 0.0:g} s "
                         f"({len(result.t)} outputs kept)")
        self.result = result


class Reaction(NamedTuple):
    force: np.ndarray   # (n, 3)
    torque: np.ndarray  # (n, 3), about the joint point


class BodyHistory(NamedTuple):
    position: np.ndarray            # (n, 3) centre of mass, global
    orientation: np.ndarray         # (n, 4) unit quaternion w, x, y, z (body to global)
    linear_velocity: np.ndarray     # (n, 3) global
    angular_velocity: np.ndarray    # (n, 3) body axes
    linear_acceleration: np.ndarray   # (n, 3) global
    angular_acceleration: np.ndarray  # (n, 3) body axes


class Result:
    """Outputs of an analysis, one row per output time.

    Arrays: t (n), q (n x 7 nb), v and vdot (n x 6 nb), lambda_ (n x m), kinetic_energy,
    potential_energy, total_energy, phi_norm (|Phi|), phid_norm (|Phi_q v + Phi_t|).
    By name: body(name), reaction(joint, side, axes), multipliers(joint), state(element).
    summary: steps, Newton iterations, wall time, ... (None when the run stopped early).
    """

    def __init__(self, data: Dict[str, Any], interrupted: bool = False) -> None:
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
        self.summary: Optional[Dict[str, Any]] = data.get("summary")
        self.assembly: Optional[Dict[str, Any]] = data.get("assembly") or (
            self.summary["assembly"] if self.summary else None)
        self.interrupted = interrupted
        self._bodies: List[str] = list(data["bodies"])

    def __len__(self) -> int:
        return len(self.t)

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

    def body(self, name: str) -> BodyHistory:
        if name not in self._bodies:
            raise KeyError(f"{name}: no moving body of that name; bodies: "
                           + ", ".join(self._bodies))
        b = self._bodies.index(name)
        q = self.q[:, 7 * b:7 * b + 7]
        v = self.v[:, 6 * b:6 * b + 6]
        a = self.vdot[:, 6 * b:6 * b + 6]
        return BodyHistory(q[:, :3], q[:, 3:], v[:, :3], v[:, 3:], a[:, :3], a[:, 3:])

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
        return Reaction(r[:, :3], r[:, 3:])

    def multipliers(self, joint: str) -> np.ndarray:
        """The joint's Lagrange multipliers (n x its number of equations)."""
        row, size = self._data["constraint_rows"][joint]
        return self.lambda_[:, row:row + size]

    def state(self, element: str) -> Dict[str, np.ndarray]:
        """The discrete state of a stateful force: rsda {angle}, engine_gas_force {theta,
        half_turn} (theta: the cumulative crank angle)."""
        if element not in self._data["states"]:
            raise KeyError(f"{element}: no stateful force of that name; stateful forces: "
                           + ", ".join(self._data["states"]))
        return dict(self._data["states"][element])

    def save_npz(self, path: str) -> None:
        """Every array in one .npz file: t, q, v, vdot, lambda, energies, residuals,
        reaction/<joint> (n, side a/b, global/joint axes, force xyz + torque xyz),
        state/<element>/<field> and bodies (their names, in the order of q and v)."""
        arrays = {key: self._data[key] for key in (
            "t", "q", "v", "vdot", "lambda", "kinetic_energy", "potential_energy", "phi_norm",
            "phid_norm")}
        arrays["bodies"] = np.array(self._bodies)
        for name, values in self._data["reactions"].items():
            arrays[f"reaction/{name}"] = values
        for name, fields in self._data["states"].items():
            for field, values in fields.items():
                arrays[f"state/{name}/{field}"] = values
        np.savez(path, **arrays)  # type: ignore[arg-type]

    def energy_drift(self) -> float:
        """Largest |E(t) - E(0)| of kinetic plus potential energy (work of dampers and
        actuators included: only a conservative model keeps it at zero)."""
        e = self.total_energy
        return float(np.max(np.abs(e - e[0]))) if len(e) else 0.0

    def __repr__(self) -> str:
        end = f"{self.t[-1]:g}" if len(self.t) else "-"
        note = ", interrupted" if self.interrupted else ""
        return f"<odyn.Result: {len(self.t)} outputs, t = 0 .. {end} s{note}>"


def _settings(step: float, t_end: float, output_interval: float, integrator: str,
              rho_inf: float, **extra: Any) -> Dict[str, Any]:
    from ._schema import check_choice, check_number
    settings = {
        "step": check_number(step, "step", positive=True),
        "t_end": check_number(t_end, "t_end", minimum=0.0),
        "output_interval": check_number(output_interval, "output_interval", positive=True),
        "integrator": check_choice(integrator, "integrator", INTEGRATORS),
        "rho_inf": check_number(rho_inf, "rho_inf", minimum=0.0),
    }
    for key, value in extra.items():
        if value is not None:
            settings[key] = value
    return settings


def assemble(model: Model, tolerance: float = 1e-12, max_iterations: int = 50) -> Result:
    """Consistent initial positions, velocities, accelerations and multipliers (one row)."""
    data = _core.assemble(model._core, {"assembly_tolerance": tolerance,
                                        "assembly_max_iterations": max_iterations})
    data["summary"] = None
    return Result(data)


def simulate(model: Model, *, t_end: float = 1.0, step: float = 1e-4,
             output_interval: float = 1e-3, integrator: str = "generalized-alpha",
             rho_inf: float = 0.9, progress: Optional[Callable[[float], None]] = None,
             newton_rtol: Optional[float] = None, newton_atol: Optional[float] = None,
             constraint_tolerance: Optional[float] = None,
             max_iterations: Optional[int] = None) -> Result:
    """Assembles, then integrates from t = 0 to t_end with fixed steps (at most `step`) that
    land on every output time; "generalized-alpha" (Chung-Hulbert) or "hht", both from
    rho_inf. The GIL is released during the run (Python callables take it back per call).

    progress(t) is called about every 0.2 s of wall time. Ctrl-C raises `odyn.Interrupted`,
    whose `result` holds the outputs so far; an error during the run gets the partial result
    as its `result` attribute.
    """
    settings = _settings(step, t_end, output_interval, integrator, rho_inf,
                         newton_rtol=newton_rtol, newton_atol=newton_atol,
                         constraint_tolerance=constraint_tolerance,
                         max_iterations=max_iterations)
    data = _core.simulate(model._core, settings, progress)
    error = data.pop("error")
    if error is None:
        return Result(data)
    result = Result(data, interrupted=True)
    if isinstance(error, KeyboardInterrupt):
        raise Interrupted(result) from error
    try:
        error.result = result
    except AttributeError:
        pass
    raise error
