"""Static equilibrium and natural modes (the C++ analysis/statics.hpp and modes.hpp)."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any, Callable, Dict, List, Optional, Tuple

import numpy as np

from . import modules
from ._schema import check_callable, check_choice, check_flag, check_number, fail
from .model import BaseModel, check_model
from .results import Result, finished_run

#: The coordinates a static or modal analysis may run in.
STATIC_COORDINATES = ["absolute", "joint"]
#: How a static or modal analysis does its linear algebra: "dense" (every mode, the damped ones
#: too), "sparse" (large models in absolute coordinates, about linear in their size; modes: the
#: lowest `count`, undamped) or "automatic" (sparse above 600 velocity coordinates).
STATIC_METHODS = ["automatic", "dense", "sparse"]


def _static_settings(coordinates: str, tolerance: float, max_iterations: int,
                     load_stepping: bool, max_load_steps: int, relaxation: bool,
                     method: str) -> Dict[str, Any]:
    for name, value in (("max_iterations", max_iterations), ("max_load_steps", max_load_steps)):
        if not isinstance(value, int) or isinstance(value, bool) or value < 1:
            fail(name, f"expected a whole number of at least 1, got {value!r}")
    return {"coordinates": check_choice(coordinates, "coordinates", STATIC_COORDINATES),
            "tolerance": check_number(tolerance, "tolerance", positive=True),
            "max_iterations": max_iterations,
            "load_stepping": check_flag(load_stepping, "load_stepping"),
            "max_load_steps": max_load_steps,
            "relaxation": check_flag(relaxation, "relaxation"),
            "method": check_choice(method, "method", STATIC_METHODS)}


def _result(model: BaseModel, data: Dict[str, Any]) -> Result:
    data["summary"] = None
    data["points"] = model._point_table()
    data["point_axes"] = model._point_axes()
    return Result(data)


def statics(model: BaseModel, *, coordinates: str = "absolute", tolerance: float = 1e-12,
            max_iterations: int = 60, load_stepping: bool = True, max_load_steps: int = 64,
            relaxation: bool = True, method: str = "automatic") -> Result:
    """The static equilibrium near the model's pose, at rest under its loads, as one output row:
    `result.reaction(joint)` holds the mechanism there, a driver's multipliers hold its motion.

    Newton's method on the constraint manifold, with the exact stiffness (the forces' and the
    constraints' geometric stiffness); if it fails from the start pose, the load is applied in
    steps (`load_stepping`), and if that fails too, the iteration relaxes as a heavily damped
    motion would (`relaxation`). Converged when ``|Phi|`` and the force imbalance (relative to the
    loads) are below `tolerance`. `result.statics` says how: "method", "iterations",
    "load_steps", the residuals, and the equilibrium's stability: "stable", "neutral",
    "squared_frequencies" (1/s^2, negative along an unstable direction) and "least_stiff" (the
    coordinates that move most along the least stiff direction, "pivot.angle" say). Raises
    odyn.SolverError when no equilibrium is found, naming a free motion the loads drive.
    coordinates: "absolute" or "joint" (as in `simulate`). method: "automatic", "dense" or
    "sparse" (see STATIC_METHODS; the sparse method judges stability from the lowest six
    squared frequencies)."""
    check_model(model)
    settings = _static_settings(coordinates, tolerance, max_iterations, load_stepping,
                                max_load_steps, relaxation, method)
    return _result(model, modules.analysis(model.module, "statics")(model._core, settings))


def quasi_statics(model: BaseModel, *, t_end: float = 1.0, output_interval: float = 1e-2,
                  coordinates: str = "absolute", tolerance: float = 1e-12,
                  max_iterations: int = 60, load_stepping: bool = True,
                  max_load_steps: int = 64, relaxation: bool = True, method: str = "automatic",
                  max_halvings: int = 8,
                  progress: Optional[Callable[[float], None]] = None) -> Result:
    """A sequence of static equilibria from t = 0 to t_end, a row every `output_interval`: time
    moves the drivers (and any load given as a function of time) so slowly that the mechanism
    rests at every instant. Each equilibrium is found as `statics` finds it (same settings),
    from the last one, so the rows follow one branch of equilibria as a driver turns or a load
    grows; a time whose equilibrium is not found is reached in up to `max_halvings` halves of
    the step. `result.reaction(driver)` is the effort that holds the driver at each row (the
    torque a slowly turned crank needs), and `result.statics` lists each row's summary.
    Raises odyn.SolverError where no equilibrium is found, with the rows up to there as the
    error's `result`; Ctrl-C raises odyn.Interrupted. progress(t) is called about every 0.2 s."""
    check_model(model)
    t_end = check_number(t_end, "t_end")
    if t_end < 0:
        fail("t_end", f"expected an end time >= 0, got {t_end!r}")
    if not isinstance(max_halvings, int) or isinstance(max_halvings, bool) or max_halvings < 0:
        fail("max_halvings", f"expected a whole number of at least 0, got {max_halvings!r}")
    settings = _static_settings(coordinates, tolerance, max_iterations, load_stepping,
                                max_load_steps, relaxation, method)
    settings.update(t_end=t_end, max_halvings=max_halvings,
                    output_interval=check_number(output_interval, "output_interval",
                                                 positive=True))
    if progress is not None:
        check_callable(progress, "progress")
    data = modules.analysis(model.module, "quasi_statics")(model._core, settings, progress)
    data["summary"] = None
    return finished_run(model, data)


class Modes:
    """A mechanism's natural modes about a static equilibrium, lowest first.

    Undamped (K_r x = omega^2 M_r x on the motions the joints allow): squared_frequencies
    (1/s^2), frequencies (Hz), shapes (n x k: each mode's motion in the velocity coordinates,
    whose names are `coordinates`, mass-normalized). Damped (the state matrix's eigenvalues s,
    one of each conjugate pair): eigenvalues (complex, 1/s), natural_frequencies (``|s|``, Hz),
    damped_frequencies (Im s, Hz), damping_ratios (``-Re s / |s|``). The linearization: basis
    (n x k, the minimal coordinates' motions), mass, damping, stiffness (k x k) and
    state_matrix (2k x 2k, for (z, z')); the sparse method leaves these empty, and the damped
    modes too where something damps. equilibrium: the pose they are about, a Result.
    body_shapes, body_motion(mode, body): the modes as the bodies' motions; animate(mode,
    path): a GIF of one."""

    def __init__(self, data: Dict[str, Any], equilibrium: Result, model: BaseModel) -> None:
        self.equilibrium = equilibrium
        self._model = model
        #: (nv x k) each mode's motion as the bodies' velocities (per body: travel in global
        #: axes, then turn in the body's axes, as Result.v), whatever the coordinates.
        self.body_shapes: np.ndarray = np.asarray(data["body_shapes"])
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

    def body_motion(self, mode: int, body: str) -> Tuple[np.ndarray, Any]:
        """How mode `mode` moves a body: (travel of its centre, global axes; turn, about its
        own axes in space, a number in the plane), in the mode's mass-normalized units."""
        self.shape(mode)  # checks the number
        names = self.equilibrium.body_names
        if body not in names:
            fail("body", f"no moving body '{body}'; bodies: {', '.join(names)}")
        planar = self.equilibrium.space == "planar"
        width, dim = (3, 2) if planar else (6, 3)
        column = self.body_shapes[width * names.index(body):width * (names.index(body) + 1),
                                  mode]
        return column[:dim], (float(column[2]) if planar else column[dim:])

    def animate(self, mode: int, path: str, *, amplitude: Optional[float] = None,
                frames: int = 30, fps: int = 15) -> None:
        """A GIF of mode `mode` (0 is the lowest): one period of the bodies swinging along it
        about the equilibrium, drawn as odyn.plot.animate draws a run. amplitude: the largest
        travel of a body's centre or turn times the model's size, m (default: a tenth of the
        model's size). The motion is the linearized one: large amplitudes stretch the links."""
        from .plot import animate
        self.shape(mode)
        motion = _ModeMotion(self, mode, amplitude, frames)
        animate(motion, self._model, path, frames=frames, fps=fps,
                title=f"mode {mode + 1}, {self.frequencies[mode]:.4g} Hz")


class _ModeMotion:
    """One period of a mode about the equilibrium, as a Result that odyn.plot.animate draws."""

    def __init__(self, found: Modes, mode: int, amplitude: Optional[float], frames: int) -> None:
        rest = found.equilibrium
        self.space, self.body_names = rest.space, rest.body_names
        period = 1.0 / found.frequencies[mode] if found.frequencies[mode] > 0 else 1.0
        self.t = np.linspace(0.0, period, frames, endpoint=False)
        centres = np.array([rest.body(b).position[0] for b in self.body_names])
        size = max(1e-3, float(np.max(np.abs(centres - centres.mean(axis=0)))) * 2)
        motions = [found.body_motion(mode, b) for b in self.body_names]
        largest = max(max(float(np.max(np.abs(t))), float(np.max(np.abs(r)) * size))
                      for t, r in motions)
        scale = (amplitude if amplitude is not None else 0.1 * size) / max(largest, 1e-300)
        swing = scale * np.sin(2 * np.pi * self.t / period)
        self._bodies: Dict[str, SimpleNamespace] = {}
        for b, (travel, turn) in zip(self.body_names, motions):
            at = rest.body(b)
            position = at.position[0] + np.outer(swing, travel)
            if self.space == "planar":
                self._bodies[b] = SimpleNamespace(position=position,
                                                  angle=at.angle[0] + swing * turn)
            else:
                self._bodies[b] = SimpleNamespace(
                    position=position,
                    orientation=np.array([_turned(at.orientation[0], s * turn) for s in swing]))

    def body(self, name: str) -> SimpleNamespace:
        return self._bodies[name]


def _turned(quaternion: np.ndarray, turn: np.ndarray) -> np.ndarray:
    """The unit quaternion (w, x, y, z) turned further by the rotation vector `turn` (body
    axes)."""
    angle = float(np.linalg.norm(turn))
    axis = turn / angle if angle > 0 else np.zeros(3)
    w2, v2 = np.cos(angle / 2), np.sin(angle / 2) * axis
    w1, v1 = quaternion[0], np.asarray(quaternion[1:])
    return np.concatenate([[w1 * w2 - v1 @ v2], w1 * v2 + w2 * v1 + np.cross(v1, v2)])


def modes(model: BaseModel, *, coordinates: str = "absolute", find_equilibrium: bool = True,
          tolerance: float = 1e-12, max_iterations: int = 60, load_stepping: bool = True,
          max_load_steps: int = 64, relaxation: bool = True, method: str = "automatic",
          count: int = 0) -> Modes:
    """The natural modes about the static equilibrium near the model's pose (found as
    `statics` finds it, with the same settings), or, with find_equilibrium=False, about the
    pose as it is (its joints closed), which must then balance its loads (odyn.SolverError
    names the coordinate that it does not). The stiffness holds the forces' and the
    constraints' geometric stiffness, from differences of the equations of motion. count: how
    many of the lowest modes (0: all of them by the dense method, the lowest 20 by the sparse
    one). method (see STATIC_METHODS): "dense" gives every mode, damped ones too; "sparse"
    (large models in absolute coordinates, the default above 600 velocity coordinates) the
    lowest `count` undamped ones by shift-invert Lanczos, the damped ones only where nothing
    damps, and no `linearization` matrices. See `Modes`."""
    check_model(model)
    if not isinstance(count, int) or isinstance(count, bool) or count < 0:
        fail("count", f"expected a whole number of at least 0 (0: all), got {count!r}")
    settings = _static_settings(coordinates, tolerance, max_iterations, load_stepping,
                                max_load_steps, relaxation, method)
    settings["find_equilibrium"] = check_flag(find_equilibrium, "find_equilibrium")
    settings["count"] = count
    data = modules.analysis(model.module, "modes")(model._core, settings)
    found = data.pop("modes")
    return Modes(found, _result(model, data), model)
