"""Kinematic analysis and the model report (the C++ analysis/kinematics.hpp)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Dict, List, Optional

import numpy as np

from . import modules
from ._schema import check_callable, check_choice, check_number, fail
from .model import BaseModel, check_model
from .results import LINEAR_SOLVERS, Result, finished_run


def _whole(value: Any, name: str, least: int) -> int:
    if not isinstance(value, int) or isinstance(value, bool) or value < least:
        fail(name, f"expected a whole number of at least {least}, got {value!r}")
    return value


def kinematics(model: BaseModel, *, t_end: float = 1.0, output_interval: float = 1e-3,
               tolerance: float = 1e-12, max_iterations: int = 25, max_halvings: int = 12,
               linear_solver: str = "auto", coordinates: str = "absolute",
               progress: Optional[Callable[[float], None]] = None) -> Result:
    """Moves a fully driven mechanism (as many drivers as degrees of freedom) as its drivers
    prescribe, from t = 0 to t_end, whatever its masses; a row every `output_interval`.

    At each output time: positions by Newton's method on the constraints and drivers,
    Phi(q, t) = 0, to `tolerance` (from the last time's solution, extrapolated); velocities and
    accelerations from the constraint equations alone; then the multipliers from the equations
    of motion, which makes this the inverse dynamics too: `result.reaction(driver).torque` (or
    `.force`, for a translational driver) is the effort the driver must apply to its body b, and
    every joint's reaction is there. A time whose Newton iteration
    fails is reached in up to `max_halvings` halves of the step. linear_solver: "dense" (a
    rank-revealing QR of whole matrices), "klu" or "cholmod" (the same here: sparse rows and a
    sparse LU, linear in the model's size) or "auto" (dense for small models, sparse above
    100 velocities plus equations). coordinates: "absolute" (every body's pose; every joint
    an equation) or "joint" (a spanning tree's joint coordinates, only the joints that close
    loops and the drivers as equations: the same motion and reactions, solved with the
    closures' Jacobian; the checks at the start use linear_solver).

    Raises odyn.ModelError before it starts if the mechanism is not fully driven (how many
    degrees of freedom remain, and its drivers) or over-driven (which driver repeats the
    others); odyn.AssemblyError where it locks up (the time and the equations that became
    dependent), with the rows up to there as the error's `result`. Ctrl-C raises
    odyn.Interrupted with the rows so far. progress(t) is called about every 0.2 s.
    `result.kinematics`: {"outputs", "wall_seconds"}."""
    check_model(model)
    t_end = check_number(t_end, "t_end")
    if t_end < 0:
        fail("t_end", f"expected an end time >= 0, got {t_end!r}")
    settings = {"t_end": t_end,
                "output_interval": check_number(output_interval, "output_interval",
                                                positive=True),
                "tolerance": check_number(tolerance, "tolerance", positive=True),
                "max_iterations": _whole(max_iterations, "max_iterations", 1),
                "max_halvings": _whole(max_halvings, "max_halvings", 0),
                "linear_solver": check_choice(linear_solver, "linear_solver", LINEAR_SOLVERS),
                "coordinates": check_choice(coordinates, "coordinates", ["absolute", "joint"])}
    if progress is not None:
        check_callable(progress, "progress")
    data = modules.analysis(model.module, "kinematics")(model._core, settings, progress)
    data["summary"] = None
    return finished_run(model, data)


@dataclass
class ModelReport:
    """What a model's constraints leave free, at its assembled configuration (odyn.check).

    gruebler: Gruebler's (Kutzbach's) count, velocities - equations: the degrees of freedom if
    no equation repeats another. degrees_of_freedom: the true mobility, velocities - rank of
    the constraint Jacobian there. redundant_equations: the equations that repeat others,
    each {"joint", "equation", "row"}; overconstraining: their joints, each once. drivers: the
    drivers' names. assembly: the assembly's report (iterations, residuals, the moved bodies,
    the velocity components it held as given). kept_velocities: those components by name;
    adjusted_velocities: the given ones it had to change (a given component that it did not
    hold but that the constraints bring back to its value is in neither). state: the assembled
    state, a one-row Result."""

    space: str
    bodies: int
    velocities: int
    equations: int
    rank: int
    drivers: List[str]
    redundant_equations: List[Dict[str, Any]]
    assembly: Dict[str, Any]
    kept_velocities: List[str] = field(default_factory=list)
    adjusted_velocities: List[str] = field(default_factory=list)
    state: Optional[Result] = None

    @property
    def gruebler(self) -> int:
        return self.velocities - self.equations

    @property
    def degrees_of_freedom(self) -> int:
        return self.velocities - self.rank

    @property
    def overconstraining(self) -> List[str]:
        return list(dict.fromkeys(e["joint"] for e in self.redundant_equations))

    @property
    def fully_driven(self) -> bool:
        """True when the drivers leave no degree of freedom (odyn.kinematics can run it)."""
        return self.degrees_of_freedom == 0

    def lines(self) -> List[str]:
        dof = self.degrees_of_freedom
        out = [f"{self.space} model: {self.bodies} moving bodies, {self.velocities} velocity "
               f"coordinates, {self.equations} constraint equations"
               + (f" ({len(self.drivers)} from its driver{'s' if len(self.drivers) > 1 else ''}"
                  f": {', '.join(self.drivers)})" if self.drivers else ""),
               f"degrees of freedom: {dof} (Gruebler's count {self.gruebler}; the constraint "
               f"Jacobian's rank {self.rank})"]
        if self.redundant_equations:
            out.append(f"redundant equations ({len(self.redundant_equations)}): " + ", ".join(
                f"{e['joint']} (equation {e['equation']})" for e in self.redundant_equations)
                + f"; joints that over-constrain: {', '.join(self.overconstraining)}")
        if self.drivers:
            out.append("fully driven: a kinematic analysis can run it" if dof == 0 else
                       f"not fully driven: {dof} more driver{'s' if dof > 1 else ''} needed for "
                       "a kinematic analysis" if dof > 0 else "")
        a = self.assembly
        out.append(f"assembly: {a['iterations']} iterations, |Phi| {a['position_residual']:.2e},"
                   f" |Phi_q v + Phi_t| {a['velocity_residual']:.2e}")
        moved = a.get("moved_bodies") or []
        if moved:
            out.append("  moved: " + ", ".join(
                f"{b['body']} by {b['translation']:.3g} m, {b['rotation']:.3g} rad"
                for b in moved))
        if self.kept_velocities:
            out.append("  velocities kept as given: " + ", ".join(self.kept_velocities))
        if self.adjusted_velocities:
            out.append("  given velocities changed to meet the constraints: "
                       + ", ".join(self.adjusted_velocities))
        return [line for line in out if line]

    def __str__(self) -> str:
        return "\n".join(self.lines())


def check(model: BaseModel, *, tolerance: float = 1e-12, max_iterations: int = 50,
          linear_solver: str = "auto") -> ModelReport:
    """Assembles the model and reports what its constraints leave free there: Gruebler's count
    and the true degrees of freedom (from the constraint Jacobian's rank), the redundant
    equations and the joints that over-constrain, the drivers, and what the assembly did (the
    bodies it moved, the given velocity components it kept or changed). `print(report)` gives
    it as text. Raises odyn.AssemblyError if the model does not assemble. linear_solver: as
    in `kinematics` (the rank of large models' Jacobians by sparse elimination)."""
    check_model(model)
    data = modules.analysis(model.module, "check")(model._core, {
        "assembly_tolerance": check_number(tolerance, "tolerance", positive=True),
        "assembly_max_iterations": _whole(max_iterations, "max_iterations", 1),
        "linear_solver": check_choice(linear_solver, "linear_solver", LINEAR_SOLVERS)})
    data["summary"] = None
    data["points"] = model._point_table()
    data["point_axes"] = model._point_axes()
    mobility = data.pop("mobility")
    given = np.asarray(data.pop("given_velocities"))
    state = Result(data)
    names = velocity_names(model)
    assembly = data["assembly"]
    # A given component that assembly did not hold may still keep its value: the kept ones and
    # the constraints fix it to what was given.
    changed = [i for i in assembly["adjusted_velocity_components"]
               if abs(state.v[0, i] - given[i]) > 1e-9 * max(1.0, abs(given[i]))]
    return ModelReport(
        space=model.space, bodies=model.num_bodies, velocities=mobility["velocities"],
        equations=mobility["equations"], rank=mobility["rank"],
        drivers=list(mobility["drivers"]),
        redundant_equations=list(mobility["redundant_equations"]), assembly=assembly,
        kept_velocities=[names[i] for i in assembly["kept_velocity_components"]],
        adjusted_velocities=[names[i] for i in changed],
        state=state)


def velocity_names(model: BaseModel) -> List[str]:
    """The velocity coordinates of absolute coordinates by name: body.x, body.y, body.z,
    body.rx, body.ry, body.rz (angular velocity components in the body's axes) in space, and
    body.x, body.y, body.angle in the plane."""
    labels = (["x", "y", "angle"] if model.space == "planar"
              else ["x", "y", "z", "rx", "ry", "rz"])
    return [f"{body}.{label}" for body in model.body_names[1:] for label in labels]
