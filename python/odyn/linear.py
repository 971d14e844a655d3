"""Linearization about a state, at rest or moving: a state-space model for chosen inputs and
outputs, as ADAMS's LINEAR gives one (the C++ analysis/linear_model.hpp)."""

from __future__ import annotations

from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _schema, modules
from ._schema import check_choice, check_flag, check_vector, fail
from .model import BaseModel, check_model
from .results import Result
from .statics import _result, _static_settings

#: The axes an input's force and torque may be given in.
INPUT_AXES = ["global", "body"]

Output = Union[str, Sequence[str]]


class LinearModel:
    """The linearized equations about a state, in a minimal set of coordinates:

        x' = drift + a x + b u,    y = outputs_at_state + c x + d u.

    The state x = (z, z') has 2k entries for the k degrees of freedom: z are the motions the
    joints allow, as the columns of `basis` (n x k, orthonormal) move the velocity coordinates
    named in `coordinates` (body.x, pivot.angle, ...), and z' their rates. u holds the inputs
    (`inputs`, by name: input i is the load given for it, scaled by u[i]) and y the outputs
    (`outputs`, by name). `drift` is x' at the state itself: zero at an equilibrium, about which
    the eigenvalues of a are the damped modes' s (see odyn.modes); about a moving state a holds
    the dynamics to first order in the chart above (as any linearization away from an
    equilibrium depends on its chart). d is zero: the outputs are functions of the positions
    and velocities. `state` is the state linearized about, as one output row."""

    def __init__(self, data: Dict[str, Any], state: Result) -> None:
        self.a: np.ndarray = np.asarray(data["a"])
        self.b: np.ndarray = np.asarray(data["b"])
        self.c: np.ndarray = np.asarray(data["c"])
        self.d: np.ndarray = np.asarray(data["d"])
        self.drift: np.ndarray = np.asarray(data["drift"])
        self.outputs_at_state: np.ndarray = np.asarray(data["outputs"])
        self.basis: np.ndarray = np.asarray(data["basis"])
        self.coordinates: List[str] = list(data["coordinates"])
        self.inputs: List[str] = list(data["input_names"])
        self.outputs: List[str] = list(data["output_names"])
        self.state = state

    @property
    def degrees_of_freedom(self) -> int:
        return self.basis.shape[1]

    @property
    def states(self) -> List[str]:
        """The state's entries by name: z1 ... zk, then z1' ... zk'."""
        k = self.degrees_of_freedom
        return [f"z{i + 1}" for i in range(k)] + [f"z{i + 1}'" for i in range(k)]

    @property
    def eigenvalues(self) -> np.ndarray:
        """The eigenvalues of a (1/s), by size: +-i omega for an undamped mode at an
        equilibrium, a positive real one along an unstable motion."""
        values = np.linalg.eigvals(self.a) if self.a.size else np.zeros(0, complex)
        return values[np.lexsort((values.imag, np.abs(values)))]

    def transfer(self, s: complex) -> np.ndarray:
        """The transfer matrix c (s I - a)^-1 b + d at the complex frequency s (outputs by
        inputs): y(s) / u(s) of a small motion about an equilibrium."""
        identity = np.eye(self.a.shape[0])
        return self.c @ np.linalg.solve(s * identity - self.a, self.b.astype(complex)) + self.d

    def frequency_response(self, frequencies: Sequence[float]) -> np.ndarray:
        """The transfer matrix at s = 2 pi i f for each frequency f (Hz): (len, outputs,
        inputs), complex; its magnitude and angle are a Bode plot's."""
        return np.array([self.transfer(2j * np.pi * f) for f in np.asarray(frequencies, float)])

    def __repr__(self) -> str:
        return (f"LinearModel({self.degrees_of_freedom} degrees of freedom, inputs "
                f"{self.inputs}, outputs {self.outputs})")


def _input(model: BaseModel, name: str, given: Any, where: str) -> Dict[str, Any]:
    _schema.check_name(name, where)
    if not isinstance(given, Mapping):
        fail(where, "expected {'body': ..., 'force': ..., 'torque': ..., 'point': ..., "
             f"'axes': ...}}, got {given!r}")
    d = _schema.check_keys(given, where, ("body", "force", "torque", "point", "axes"), ("body",))
    body = _schema._body(d["body"], f"{where}.body", model._body_index)
    if body == "ground":
        fail(f"{where}.body", "an input loads a moving body, not the ground")
    planar = model.space == "planar"
    dim = 2 if planar else 3
    if "force" not in d and "torque" not in d:
        fail(where, "give a force, a torque or both: the load that u = 1 applies")
    force = check_vector(d.get("force", [0.0] * dim), f"{where}.force", dim)
    if planar:
        torque = [_schema.check_number(d.get("torque", 0.0), f"{where}.torque")]
    else:
        torque = check_vector(d.get("torque", [0.0] * 3), f"{where}.torque", 3)
    if not any(force) and not any(torque):
        fail(where, "the force and the torque are both zero: the input would do nothing")
    return {"name": name, "body": model._body_index[body], "force": force, "torque": torque,
            "point": check_vector(d.get("point", [0.0] * dim), f"{where}.point", dim),
            "axes": check_choice(d.get("axes", "global"), f"{where}.axes", INPUT_AXES)}


def _output(model: BaseModel, given: Output, where: str) -> Dict[str, Any]:
    parts: Tuple[str, ...]
    if isinstance(given, str):
        parts = tuple(given.split("."))
    elif isinstance(given, (list, tuple)) and all(isinstance(p, str) for p in given):
        parts = tuple(given)
    else:
        fail(where, "expected 'element.output', 'point.quantity.component' or their tuples, "
             f"got {given!r}")
    if len(parts) == 2:
        element, output = model._event_output(list(parts), where)
        return {"name": f"{element}.{output}", "kind": "output", "element": element,
                "output": output}
    if len(parts) == 3:
        point, quantity, component = model._event_point(list(parts), where)
        return {"name": f"{point}.{quantity}.{component}",
                **model._point_reading(point, quantity, component)}
    fail(where, "expected an element's output ('spring.length') or a named point's position "
         f"or velocity ('tip.velocity.x'), got {given!r}")
    raise AssertionError  # fail() raises


def check_inputs(model: BaseModel, inputs: Any, where: str = "inputs") -> List[Dict[str, Any]]:
    """A linearization's inputs, {name: load}, checked against the model (see linearize)."""
    if not isinstance(inputs, Mapping):
        fail(where, f"expected {{name: load}}, got {inputs!r}")
    return [_input(model, name, given, f"{where}[{name!r}]") for name, given in inputs.items()]


def check_outputs(model: BaseModel, outputs: Any, where: str = "outputs"
                  ) -> List[Dict[str, Any]]:
    """A linearization's outputs, a list, checked against the model (see linearize)."""
    if isinstance(outputs, str) or not isinstance(outputs, (list, tuple)):
        fail(where, f"expected a list of outputs, got {outputs!r}")
    found = [_output(model, given, f"{where}[{i}]") for i, given in enumerate(outputs)]
    names = [o["name"] for o in found]
    repeated = sorted({n for n in names if names.count(n) > 1})
    if repeated:
        fail(where, f"{', '.join(repeated)} listed more than once")
    return found


def linearize(model: BaseModel, *, inputs: Optional[Mapping[str, Mapping[str, Any]]] = None,
              outputs: Sequence[Output] = (), coordinates: str = "absolute",
              find_equilibrium: bool = False, tolerance: float = 1e-12,
              max_iterations: int = 60, load_stepping: bool = True, max_load_steps: int = 64,
              relaxation: bool = True) -> LinearModel:
    """The linearized equations about the model's initial state (assembled: a moving state
    too), or with find_equilibrium=True about the static equilibrium near its pose (found as
    `statics` finds it, with the same settings), as a state-space model (see LinearModel).

    inputs: {name: {"body": ..., "force": ..., "torque": ..., "point": ..., "axes": ...}}, each
    the load that u = 1 applies to a body: a force (N) at `point` (body coordinates, default
    the centre of mass) and a torque (N m; in the plane a number), in "global" axes or the
    body's. outputs: element outputs ("spring.length", or ("spring", "length")) and named
    points' positions or velocities ("tip.velocity.x"). The matrices come from differences of
    the constrained dynamics themselves, independently of odyn.modes' stiffness and damping.
    coordinates: "absolute" or "joint" (the state's chart follows them)."""
    check_model(model)
    settings = _static_settings(coordinates, tolerance, max_iterations, load_stepping,
                                max_load_steps, relaxation, "dense")
    settings["find_equilibrium"] = check_flag(find_equilibrium, "find_equilibrium")
    settings["inputs"] = check_inputs(model, {} if inputs is None else inputs)
    settings["outputs"] = check_outputs(model, outputs)
    data = modules.analysis(model.module, "linearize")(model._core, settings)
    found = data.pop("linear_model")
    return LinearModel(found, _result(model, data))
