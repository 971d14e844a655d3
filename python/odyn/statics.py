"""Static equilibrium and natural modes (the C++ analysis/statics.hpp and modes.hpp)."""

from __future__ import annotations

from typing import Any, Dict, List, Optional

import numpy as np

from ._schema import check_choice, check_flag, check_number, fail
from .model import BaseModel
from .results import Result

#: The coordinates a static or modal analysis may run in.
STATIC_COORDINATES = ["absolute", "joint"]


def _static_settings(coordinates: str, tolerance: float, max_iterations: int,
                     load_stepping: bool, max_load_steps: int,
                     relaxation: bool) -> Dict[str, Any]:
    for name, value in (("max_iterations", max_iterations), ("max_load_steps", max_load_steps)):
        if not isinstance(value, int) or isinstance(value, bool) or value < 1:
            fail(name, f"expected a whole number of at least 1, got {value!r}")
    return {"coordinates": check_choice(coordinates, "coordinates", STATIC_COORDINATES),
            "tolerance": check_number(tolerance, "tolerance", positive=True),
            "max_iterations": max_iterations,
            "load_stepping": check_flag(load_stepping, "load_stepping"),
            "max_load_steps": max_load_steps,
            "relaxation": check_flag(relaxation, "relaxation")}


def _result(model: BaseModel, data: Dict[str, Any]) -> Result:
    data["summary"] = None
    data["points"] = model._point_table()
    data["point_axes"] = model._point_axes()
    return Result(data)


def statics(model: BaseModel, *, coordinates: str = "absolute", tolerance: float = 1e-12,
            max_iterations: int = 60, load_stepping: bool = True, max_load_steps: int = 64,
            relaxation: bool = True) -> Result:
    """The static equilibrium near the model's pose, at rest under its loads, as one output row:
    `result.reaction(joint)` holds the mechanism there, a driver's multipliers hold its motion.

    Newton's method on the constraint manifold, with the exact stiffness (the forces' and the
    constraints' geometric stiffness); if it fails from the start pose, the load is applied in
    steps (`load_stepping`), and if that fails too, the iteration relaxes as a heavily damped
    motion would (`relaxation`). Converged when |Phi| and the force imbalance (relative to the
    loads) are below `tolerance`. `result.statics` says how: "method", "iterations",
    "load_steps", the residuals, and the equilibrium's stability: "stable", "neutral",
    "squared_frequencies" (1/s^2, negative along an unstable direction) and "least_stiff" (the
    coordinates that move most along the least stiff direction, "pivot.angle" say). Raises
    odyn.SolverError when no equilibrium is found, naming a free motion the loads drive.
    coordinates: "absolute" or "joint" (as in `simulate`)."""
    settings = _static_settings(coordinates, tolerance, max_iterations, load_stepping,
                                max_load_steps, relaxation)
    return _result(model, model.module.statics(model._core, settings))


class Modes:
    """A mechanism's natural modes about a static equilibrium, lowest first.

    Undamped (K_r x = omega^2 M_r x on the motions the joints allow): squared_frequencies
    (1/s^2), frequencies (Hz), shapes (n x k: each mode's motion in the velocity coordinates,
    whose names are `coordinates`, mass-normalized). Damped (the state matrix's eigenvalues s,
    one of each conjugate pair): eigenvalues (complex, 1/s), natural_frequencies (|s|, Hz),
    damped_frequencies (Im s, Hz), damping_ratios (-Re s / |s|). The linearization: basis
    (n x k, the minimal coordinates' motions), mass, damping, stiffness (k x k) and
    state_matrix (2k x 2k, for (z, z')). equilibrium: the pose they are about, a Result."""

    def __init__(self, data: Dict[str, Any], equilibrium: Result) -> None:
        self.equilibrium = equilibrium
        self.squared_frequencies: np.ndarray = np.asarray(data["squared_frequencies"])
        self.frequencies: np.ndarray = np.asarray(data["frequencies"])
        self.shapes: np.ndarray = np.asarray(data["shapes"])
        self.eigenvalues: np.ndarray = np.asarray(data["eigenvalues"])
        self.natural_frequencies: np.ndarray = np.asarray(data["natural_frequencies"])
        self.damped_frequencies: np.ndarray = np.asarray(data["damped_frequencies"])
        self.damping_ratios: np.ndarray = np.asarray(data["damping_ratios"])
        self.coordinates: List[str] = list(data["coordinates"])
        self.basis: np.ndarray = np.asarray(data["basis"])
        self.mass: np.ndarray = np.asarray(data["mass"])
        self.damping: np.ndarray = np.asarray(data["damping"])
        self.stiffness: np.ndarray = np.asarray(data["stiffness"])
        self.state_matrix: np.ndarray = np.asarray(data["state_matrix"])

    def __len__(self) -> int:
        return len(self.frequencies)

    def shape(self, mode: int, coordinate: Optional[str] = None) -> Any:
        """Mode `mode`'s shape (0 is the lowest): every coordinate's share, or one coordinate's
        by name ("pivot.angle", "bar.x")."""
        if not isinstance(mode, int) or not 0 <= mode < len(self):
            fail("mode", f"expected a mode number from 0 to {len(self) - 1}, got {mode!r}")
        column = self.shapes[:, mode]
        if coordinate is None:
            return column
        if coordinate not in self.coordinates:
            fail("coordinate", f"no coordinate '{coordinate}'; the modes' coordinates are "
                 f"{', '.join(self.coordinates)}")
        return float(column[self.coordinates.index(coordinate)])


def modes(model: BaseModel, *, coordinates: str = "absolute", find_equilibrium: bool = True,
          tolerance: float = 1e-12, max_iterations: int = 60, load_stepping: bool = True,
          max_load_steps: int = 64, relaxation: bool = True) -> Modes:
    """The natural modes about the static equilibrium near the model's pose (found as
    `statics` finds it, with the same settings), or, with find_equilibrium=False, about the
    pose as it is (its joints closed), which must then balance its loads (odyn.SolverError
    names the coordinate that it does not). The stiffness holds the forces' and the constraints' geometric
    stiffness, from differences of the equations of motion; dense, for models of up to a few
    hundred coordinates. See `Modes`."""
    settings = _static_settings(coordinates, tolerance, max_iterations, load_stepping,
                                max_load_steps, relaxation)
    settings["find_equilibrium"] = check_flag(find_equilibrium, "find_equilibrium")
    data = model.module.modes(model._core, settings)
    found = data.pop("modes")
    return Modes(found, _result(model, data))
