"""Scene files: a whole model, its analysis settings, its output columns and figures, as JSON.

    {
      "odyn": 1,
      "description": "...",
      "space": "spatial",      (or "planar": 2-vectors, angles, planar elements)
      "module": "odyn_engine", (optional: a module of one's own whose models compile the
                                scene's element types; see odyn.modules)
      "bodies":  [{"name": "crank", "mass": 1.4, "inertia": [1.5, 1.3, 0.8], ...}],
      "joints":  [{"type": "revolute", "name": "bearing", "body_a": "ground",
                   "on_a": {"point": [0, 0, 0], "axis": [1, 0, 0]}, "body_b": "crank", ...}],
      "drivers": [{"type": "revolute_driver", "name": "motor", "joint": "bearing",
                   "motion": {"type": "constant_velocity", "rate": 10.0}}],
      "forces":  [{"type": "gravity", "name": "gravity", "acceleration": [0, 0, -9.81}]},
      "points":  [{"name": "pin", "body": "crank", "at": [0, 0.05, 0]}],   (markers; with
                 "orientation", a quaternion or a planar angle, they have axes, and a joint
                 frame may be a marker's name)
      "events":  [{"name": "top", "point": ["pin", "position", "z"], "value": 0.05,
                   "direction": "rising", "terminal": false},
                  {"name": "stretched", "output": ["spring", "length"], "value": 0.3}],
                 (see Model.add_event; Result.events lists their crossings)
      "analysis": {"t_end": 1.0, "output_interval": 1e-3},   (+ integrator, rho_inf, step,
                   rtol, atol, max_step, adaptive, newton_rtol, newton_atol,
                   constraint_tolerance, max_iterations, projection_tolerance, order,
                   coordinates ("auto", "absolute" or "joint"); the integrator is a name of
                   odyn.integrators(); left out, it is simulate()'s choice: auto, or
                   generalized-alpha when a step is given without rtol and atol;
                   "type": "dynamic" (the default), "kinematic" (odyn.kinematics: t_end,
                   output_interval, max_iterations, linear_solver,
                   coordinates "absolute" or "joint"), "static" or "modes"
                   (odyn.statics, odyn.modes: max_iterations, coordinates "absolute" or
                   "joint"),
                   "quasi_static" (odyn.quasi_statics: t_end, output_interval,
                   max_iterations, coordinates, max_halvings) or "linear" (odyn.linearize:
                   "inputs": {name: {"body": ..., "force": ..., "torque": ...}}, "outputs":
                   ["spring.length", "tip.velocity.x"], find_equilibrium, max_iterations,
                   coordinates))
      "outputs": [{"name": "z_piston", "body": "piston", "quantity": "position",
                   "component": "z"},
                  {"name": "pin_vx", "point": "pin", "quantity": "velocity", "component": "x"},
                  (+ "relative_to": a point, "axes": "global", a body or a point,
                   "seen_from": a body or a point; see Result.relative),
                  {"name": "spring_force", "element": "spring", "output": "tension"}
                  (see odyn elements TYPE), ...],
      "figures": [{"file": "piston.png", "y": "z_piston", "title": "...", "ylabel": "..."}]
    }

Loading checks everything and names the place of each error (``joints[2].on_a.axis: ...``);
unknown keys are errors. Parameters are named as in C++ (see the add_* methods of odyn.Model
and odyn.PlanarModel).
"""

from __future__ import annotations

import csv
import json
import os
from typing import (Any, Callable, Dict, List, Mapping, NoReturn, Optional, Sequence, Tuple,
                    Union)

import numpy as np

from . import _schema, modules
from ._schema import (SceneError, check_choice, check_flag, check_keys, check_name,
                      check_number, check_tolerance, fail)
from .model import BaseModel, Model, new_model
from .kinematics import kinematics
from .results import ADAPTIVE_OPTIONAL, COORDINATES, LINEAR_SOLVERS, Result, integrators, simulate
from .linear import LinearModel, check_inputs, check_outputs, linearize
from .statics import STATIC_COORDINATES, Modes, modes, quasi_statics, statics
from .settings import INTEGRATOR_KEYWORDS, IntegratorSettings, integrator_settings

FORMAT_VERSION = 1
SPACES = ("spatial", "planar")
#: Element types written in Python (functions), which a scene file cannot hold.
PYTHON_ONLY = ("user_force", "user_constraint")


def space_sections(space: str, compiled: Optional[Sequence[str]] = None
                   ) -> Dict[str, Tuple[str, ...]]:
    """Element types by section of a scene file in a space (of those in `compiled`, if given:
    a model's element_types)."""
    def kept(types: Sequence[str]) -> Tuple[str, ...]:
        return tuple(t for t in types if t not in PYTHON_ONLY
                     and (compiled is None or t in compiled))
    return {"joints": kept(_schema.SPACE_JOINTS[space]), "drivers": kept(_schema.DRIVERS),
            "forces": kept(_schema.SPACE_FORCES[space])}


ANALYSIS_DEFAULTS: Dict[str, Any] = {"t_end": 1.0, "output_interval": 1e-3}
# Left out, integrator, rho_inf and step take simulate()'s defaults: auto at rtol = atol = 1e-6,
# or generalized-alpha (rho_inf 0.9) when a step is given without tolerances.
ANALYSIS_OPTIONAL = ("type", "integrator", "rho_inf", "step", "rtol", "atol", "max_step",
                     "adaptive", "newton_rtol", "newton_atol", "constraint_tolerance",
                     "max_iterations", "projection_tolerance", "order", "coordinates",
                     "linear_solver", "max_halvings", "find_equilibrium", "inputs", "outputs")

#: The analyses a scene may name ("type"), and the settings each takes beyond t_end and
#: output_interval (which only the analyses in TIMED use).
ANALYSES: Dict[str, Tuple[str, ...]] = {
    "dynamic": ANALYSIS_OPTIONAL[1:ANALYSIS_OPTIONAL.index("max_halvings")],
    "kinematic": ("max_iterations", "linear_solver", "coordinates"),
    "quasi_static": ("max_iterations", "coordinates", "max_halvings"),
    "static": ("max_iterations", "coordinates"),
    "modes": ("max_iterations", "coordinates"),
    "linear": ("max_iterations", "coordinates", "find_equilibrium", "inputs", "outputs"),
}
#: The image formats a scene's figure may be written in (by its file name's extension).
FIGURE_FORMATS = (".png", ".pdf", ".svg", ".jpg", ".jpeg")

#: The analyses that run through time, from 0 to t_end (the others give one configuration).
TIMED = ("dynamic", "kinematic", "quasi_static")

BODY_QUANTITIES = ("position", "orientation", "linear_velocity", "angular_velocity",
                   "linear_acceleration", "angular_acceleration")
#: Planar body quantities; the angular ones are numbers (no component).
PLANAR_BODY_QUANTITIES = ("position", "angle", "linear_velocity", "angular_velocity",
                          "linear_acceleration", "angular_acceleration")
PLANAR_SCALARS = ("angle", "angular_velocity", "angular_acceleration", "torque")
POINT_QUANTITIES = ("position", "velocity", "acceleration")
GLOBAL_QUANTITIES = ("phi_norm", "phid_norm", "kinetic_energy", "potential_energy",
                     "total_energy")
COMPONENTS = {"x": 0, "y": 1, "z": 2}
PLANAR_COMPONENTS = {"x": 0, "y": 1}
QUATERNION_COMPONENTS = {"w": 0, "x": 1, "y": 2, "z": 3}

#: Every key a scene file may hold, by place, with what it means: the loader accepts these and no
#: others, and `python -m odyn._generate` writes docs/scene-files.md from them.
KEYS: Dict[str, Dict[str, str]] = {
    "scene": {
        "odyn": "the format's version, 1 (optional)",
        "description": "free text",
        "space": '"spatial" (the default: 3-vectors, quaternions) or "planar" (2-vectors, '
                 "angles, the planar elements)",
        "module": "a module of one's own whose models compile the scene's element types "
                  "(`odyn.modules`); left out, odyn's own catalogue",
        "bodies": "the moving bodies, at least one; the ground is `ground`",
        "joints": "joints, and the gears and couplers between joints, each with its `type`",
        "drivers": "drivers, each with its `type` and parameters",
        "forces": "forces, contacts, joint limits and joint friction, each with its `type`",
        "points": "named points (markers) fixed on bodies: `name`, `body`, `at`, optionally "
                  "`orientation` (see `Model.add_point`)",
        "events": "crossings to locate: `name`, `output` or `point`, `value`, `direction`, "
                  "`terminal` (see `Model.add_event`)",
        "analysis": "the analysis and its settings (below); left out, a dynamic run to 1 s",
        "outputs": "the columns written by `odyn run --out` (below)",
        "figures": "figures drawn by `odyn run --figures DIR` (below)",
    },
    "bodies": {
        "name": "a name of its own (not `ground`)",
        "mass": "kg, positive (left out with `parts`)",
        "inertia": "kg m^2 about the centre of mass: in space 3 principal moments in body axes "
                   "or a 3 x 3 tensor; in the plane a number (left out with `parts`)",
        "parts": "instead of mass and inertia, the parts odyn combines ([bodies.md](bodies.md))",
        "position": "m, the centre of mass (with `parts`, the parts frame's origin), global",
        "orientation": "space: a unit quaternion (w, x, y, z), body to global",
        "angle": "plane: rad, the body's angle",
        "linear_velocity": "m/s, global",
        "angular_velocity": "rad/s; in space in the body's own axes",
        "velocity_given": "booleans, one per velocity component (space: linear x y z, angular x "
                          "y z; plane: x', y', phi'): those assembly must keep; the others it "
                          "may change to meet the constraints",
    },
    "analysis": {
        "t_end": "end time in s (default 1.0; timed analyses)",
        "output_interval": "time between output rows in s (default 1e-3; timed analyses)",
        "type": '"dynamic" (the default), "kinematic", "static", "quasi_static", "modes" or '
                '"linear"',
        "integrator": "a name of `odyn integrators`, or an object with the `name` and any of "
                      "its settings (`{\"name\": \"bdf\", \"rtol\": 1e-6, \"max_order\": 3}`: "
                      "[python.md](python.md#settings-objects)); left out, `simulate`'s choice",
        "rho_inf": "generalized-alpha's and HHT's spectral radius at infinity, in [0, 1]",
        "step": "the (first) step size in s",
        "rtol": "relative error tolerance, in (0, 1]",
        "atol": "absolute error tolerance",
        "max_step": "the largest step in s",
        "adaptive": "step control for generalized-alpha and HHT (true or false)",
        "newton_rtol": "relative tolerance of the implicit integrators' Newton iterations",
        "newton_atol": "absolute tolerance of the implicit integrators' Newton iterations",
        "constraint_tolerance": "tolerance on the constraints' residual of a Newton step",
        "max_iterations": "Newton iterations allowed per step or configuration (at least 1)",
        "projection_tolerance": "explicit methods' tolerance of the projection onto the "
                                "constraints",
        "order": "the Adams and BDF methods' (largest) order, 1 to 6",
        "coordinates": '"auto", "absolute" or "joint" (dynamic); "absolute" or "joint" (the '
                       "others)",
        "linear_solver": '"auto", "dense", "cholmod" or "klu"',
        "max_halvings": "quasi-static load-step halvings allowed (at least 0)",
        "find_equilibrium": "linear: linearize about the static equilibrium (true) or the "
                            "given state",
        "inputs": 'linear: named inputs, `{name: {"body": ..., "force": ..., "torque": ...}}`',
        "outputs": 'linear: named outputs such as "spring.length" or "tip.velocity.x"',
    },
    "outputs.body": {
        "name": "the column's name", "body": "a moving body",
        "quantity": ", ".join(BODY_QUANTITIES) + " (planar: angle instead of orientation)",
        "component": "x, y or z (orientation: w, x, y or z; none for a planar angle or rate)",
    },
    "outputs.reaction": {
        "name": "the column's name", "reaction": "a joint or driver",
        "side": '"b" (the default: on body_b) or "a"',
        "axes": '"global" (the default) or "joint"', "quantity": "force or torque",
        "component": "x, y or z (none for a planar torque)",
    },
    "outputs.point": {
        "name": "the column's name", "point": "a named point",
        "relative_to": "another named point (default: the global origin)",
        "axes": '"global" (the default), a body or a point', "seen_from": "a body or a point "
        "(default: the ground)", "quantity": ", ".join(POINT_QUANTITIES),
        "component": "x, y or z",
    },
    "outputs.element": {
        "name": "the column's name", "element": "an element that reports outputs",
        "output": "one of its outputs (`odyn elements TYPE`)",
    },
    "outputs.state": {
        "name": "the column's name", "state": "a force with a state of its own",
        "field": "one of its state's fields",
    },
    "outputs.global": {
        "name": "the column's name", "quantity": ", ".join(GLOBAL_QUANTITIES),
    },
    "figures": {
        "file": "a file name in the folder given to --figures, ending in "
                + ", ".join(FIGURE_FORMATS),
        "y": "an output column's name, or a list of them", "title": "the figure's title",
        "ylabel": "the y axis' label", "offset": "added to the values drawn",
        "scale": "multiplies the values drawn (after the offset)",
    },
}
#: The keys each form of output column needs (the form is told by the first key it has of
#: body, reaction, point, element, state; else a global quantity).
REQUIRED_KEYS: Dict[str, Tuple[str, ...]] = {
    "scene": ("bodies",),
    "outputs.body": ("name", "body", "quantity"),
    "outputs.reaction": ("name", "reaction", "quantity"),
    "outputs.point": ("name", "point", "quantity"),
    "outputs.element": ("name", "element", "output"),
    "outputs.state": ("name", "state", "field"),
    "outputs.global": ("name", "quantity"),
    "figures": ("file", "y"),
}
TOP_KEYS = tuple(KEYS["scene"])


class Scene:
    """A model with its analysis settings, output columns and figures."""

    def __init__(self, model: Optional[BaseModel] = None, analysis: Optional[Mapping] = None,
                 outputs: Optional[List[Dict[str, Any]]] = None,
                 figures: Optional[List[Dict[str, Any]]] = None, description: str = "") -> None:
        self.model: BaseModel = model if model is not None else Model()
        if analysis is not None and not isinstance(analysis, Mapping):  # 0, [], "", false
            given = json.dumps(analysis) if _jsonable(analysis) else repr(analysis)
            fail("analysis", f"expected an object of settings, got {given}; leave it out for "
                 "the defaults")
        self.analysis: Dict[str, Any] = _check_analysis(dict(analysis or {}), "analysis")
        if "inputs" in self.analysis:  # a linear analysis's loads and outputs name the model's
            check_inputs(self.model, self.analysis["inputs"], "analysis.inputs")
        if "outputs" in self.analysis:
            check_outputs(self.model, self.analysis["outputs"], "analysis.outputs")
        self.outputs: List[Dict[str, Any]] = [
            _check_output(o, f"outputs[{i}]", self.model) for i, o in enumerate(outputs or [])]
        _check_unique([o["name"] for o in self.outputs], "outputs", extra=["t"])
        names = ["t"] + [o["name"] for o in self.outputs]
        self.figures: List[Dict[str, Any]] = [
            _check_figure(f, f"figures[{i}]", names) for i, f in enumerate(figures or [])]
        self.description = description

    def simulate(self, **overrides: Any) -> Result:
        """Runs the scene's dynamic analysis; keyword arguments override its settings."""
        settings = {**self.analysis, **{k: v for k, v in overrides.items() if v is not None}}
        settings.pop("type", None)
        return simulate(self.model, **settings)

    @property
    def analysis_type(self) -> str:
        """The analysis the scene names: "dynamic" (the default), "kinematic",
        "quasi_static", "static", "modes" or "linear"."""
        return self.analysis.get("type", "dynamic")

    def run(self, analysis: Optional[str] = None,
            progress: Optional[Callable[[float], None]] = None,
            **overrides: Any) -> Union[Result, Modes, LinearModel]:
        """Runs the scene's analysis, or `analysis` instead (one of ANALYSES, whose settings
        the scene's do not then need to fit: those of another analysis are left out); keyword
        arguments override its settings. Returns a Result, Modes for "modes" or a LinearModel
        for "linear"."""
        kind = check_choice(analysis or self.analysis_type, "analysis", list(ANALYSES))
        settings = {**self.analysis, **{k: v for k, v in overrides.items() if v is not None}}
        kept = {k: v for k, v in settings.items()
                if k in ANALYSES[kind] or k in ANALYSIS_DEFAULTS}
        if kind == "dynamic":
            return simulate(self.model, progress=progress, **kept)
        kept = {k: v for k, v in kept.items() if k != "coordinates" or v != "auto"}
        if kind == "kinematic":
            return kinematics(self.model, progress=progress, **kept)
        if kind == "quasi_static":
            return quasi_statics(self.model, progress=progress, **kept)
        kept = {k: v for k, v in kept.items() if k not in ANALYSIS_DEFAULTS}
        return {"static": statics, "modes": modes, "linear": linearize}[kind](self.model, **kept)

    def columns(self, result: Result) -> Dict[str, np.ndarray]:
        """t and every output column of the scene, from a result."""
        table = {"t": result.t}
        for o in self.outputs:
            table[o["name"]] = column(result, o)
        return table

    def to_dict(self) -> Dict[str, Any]:
        out: Dict[str, Any] = {"odyn": FORMAT_VERSION}
        if self.description:
            out["description"] = self.description
        out["space"] = self.model.space
        if not modules.is_core(self.model.module):
            out["module"] = self.model.module.__name__
        out["bodies"] = [_plain(b, f"bodies[{i}]") for i, b in enumerate(self.model._bodies)]
        for section, kinds in space_sections(self.model.space).items():
            entries = []
            for name, (kind, params, _) in self.model._elements.items():
                if kind in PYTHON_ONLY and section == "forces":
                    fail(f"{'joints' if kind == 'user_constraint' else 'forces'}: '{name}'",
                         f"a {kind.replace('_', ' ')} is a Python function and cannot be saved "
                         "in a scene file")
                if kind in kinds:
                    entries.append({"type": kind, **_plain(params, f"{section}: '{name}'")})
            out[section] = entries
        if self.model._points:
            out["points"] = [dict(p) for p in self.model._points.values()]
        if self.model._events:
            for name, e in self.model._events.items():
                if "function" in e:
                    fail(f"events: '{name}'", "a function event is a Python function and "
                         "cannot be saved in a scene file")
            out["events"] = [dict(e) for e in self.model._events.values()]
        out["analysis"] = {k: v.to_dict() if isinstance(v, IntegratorSettings) else v
                           for k, v in self.analysis.items()}
        out["outputs"] = [dict(o) for o in self.outputs]
        out["figures"] = [dict(f) for f in self.figures]
        return out


def _plain(params: Mapping[str, Any], where: str) -> Dict[str, Any]:
    """Parameters as JSON values; None (an optional value left out) is dropped."""
    out = {}
    for key, value in params.items():
        if value is None:
            continue
        if callable(value):
            fail(f"{where}.{key}", "a Python function cannot be saved in a scene file")
        if isinstance(value, Mapping):
            value = _plain(value, f"{where}.{key}")
        out[key] = value
    return out


def _check_unique(names: List[str], where: str, extra: Sequence[str] = ()) -> None:
    seen = set(extra)
    for i, name in enumerate(names):
        if name in seen:
            fail(f"{where}[{i}].name", f"the name '{name}' is used twice; names must be unique")
        seen.add(name)


def _check_analysis(d: Any, where: str) -> Dict[str, Any]:
    d = check_keys(d, where, list(ANALYSIS_DEFAULTS) + list(ANALYSIS_OPTIONAL))
    out: Dict[str, Any] = {}
    for key, default in ANALYSIS_DEFAULTS.items():
        value = d.get(key, default)
        w = f"{where}.{key}"
        if key == "t_end":
            out[key] = check_number(value, w, minimum=0.0)
        else:
            out[key] = check_number(value, w, positive=True)
    kind = check_choice(d.get("type", "dynamic"), f"{where}.type", list(ANALYSES))
    if "type" in d:
        out["type"] = kind
    for key in ANALYSIS_OPTIONAL[1:]:
        if key in d and key not in ANALYSES[kind]:
            takes = ", ".join(["t_end", "output_interval"] * (kind in TIMED[1:])
                              + list(ANALYSES[kind]))
            fail(f"{where}.{key}", f"does not apply to a {kind} analysis, which takes {takes}; "
                 "leave it out")
    for key in ANALYSIS_OPTIONAL[1:]:
        if key in d:
            if key == "integrator" and isinstance(d[key], (Mapping, IntegratorSettings)):
                out[key] = integrator_settings(d[key], f"{where}.{key}")
                beside = [k for k in INTEGRATOR_KEYWORDS if k in d]
                if beside:
                    fail(f"{where}.{beside[0]}", "give the integrator's settings in its object "
                         f"({where}.integrator), not beside it")
            elif key == "integrator":
                out[key] = check_choice(d[key], f"{where}.{key}", list(integrators()))
            elif key == "rho_inf":
                out[key] = check_number(d[key], f"{where}.{key}", minimum=0.0)
                if out[key] > 1.0:
                    fail(f"{where}.{key}", f"expected a number in [0, 1], got {out[key]:g}")
            elif key == "adaptive":
                if not isinstance(d[key], bool):
                    fail(f"{where}.{key}", f"expected true or false, got {d[key]!r}")
                if out.get("integrator", "generalized-alpha") not in ADAPTIVE_OPTIONAL:
                    fail(f"{where}.{key}", f"applies to {' and '.join(ADAPTIVE_OPTIONAL)}; "
                         f"{out['integrator']} chooses its steps itself (leave it out)")
                out[key] = d[key]
            elif key in ("max_iterations", "max_halvings"):
                least = 1 if key == "max_iterations" else 0
                if not isinstance(d[key], int) or isinstance(d[key], bool) or d[key] < least:
                    fail(f"{where}.{key}", f"expected a whole number of at least {least}, "
                         f"got {d[key]!r}")
                out[key] = d[key]
            elif key == "find_equilibrium":
                out[key] = check_flag(d[key], f"{where}.{key}")
            elif key in ("inputs", "outputs"):
                out[key] = d[key]  # checked against the model (Scene.__init__)
            elif key == "coordinates":
                out[key] = check_choice(d[key], f"{where}.{key}",
                                        COORDINATES if kind == "dynamic" else STATIC_COORDINATES)
            elif key == "linear_solver":
                out[key] = check_choice(d[key], f"{where}.{key}", LINEAR_SOLVERS)
            elif key == "order":
                if not isinstance(d[key], int) or isinstance(d[key], bool) or \
                        not 1 <= d[key] <= 6:
                    fail(f"{where}.{key}", f"expected an integer from 1 to 6, got {d[key]!r}")
                out[key] = d[key]
            elif key in ("rtol", "newton_rtol"):
                out[key] = check_tolerance(d[key], f"{where}.{key}", relative=True)
            else:
                out[key] = check_number(d[key], f"{where}.{key}", positive=True)
    return out


def _check_component(d: Dict[str, Any], where: str, quantity: str, planar: bool) -> None:
    """The component of a vector quantity; none for a planar angle, rate or torque."""
    if planar and quantity in PLANAR_SCALARS:
        if "component" in d:
            fail(f"{where}.component", f"a planar {quantity} is a number; leave 'component' out")
        return
    if "component" not in d:
        fail(where, "missing 'component'")
    comps = (QUATERNION_COMPONENTS if quantity == "orientation"
             else PLANAR_COMPONENTS if planar else COMPONENTS)
    check_choice(d["component"], f"{where}.component", list(comps))


def _check_form(o: Mapping[str, Any], where: str, form: str) -> Dict[str, Any]:
    place = f"outputs.{form}"
    return check_keys(o, where, tuple(KEYS[place]), REQUIRED_KEYS[place])


def _check_output(o: Any, where: str, model: BaseModel) -> Dict[str, Any]:
    if not isinstance(o, Mapping):
        fail(where, f"expected an output column (an object), got {o!r}")
    planar = model.space == "planar"
    if "body" in o:
        d = _check_form(o, where, "body")
        if d["body"] not in model.body_names[1:]:
            fail(f"{where}.body", f"no moving body named {d['body']!r}")
        check_choice(d["quantity"], f"{where}.quantity",
                     PLANAR_BODY_QUANTITIES if planar else BODY_QUANTITIES)
        _check_component(d, where, d["quantity"], planar)
    elif "reaction" in o:
        d = _check_form(o, where, "reaction")
        d.setdefault("side", "b")
        d.setdefault("axes", "global")
        name = d["reaction"]
        if name not in model.element_names or (
                model.element_type(name) not in _schema.JOINTS + _schema.DRIVERS):
            fail(f"{where}.reaction", f"no joint or driver named {name!r}")
        check_choice(d["side"], f"{where}.side", ("a", "b"))
        check_choice(d["axes"], f"{where}.axes", ("global", "joint"))
        check_choice(d["quantity"], f"{where}.quantity", ("force", "torque"))
        _check_component(d, where, d["quantity"], planar)
    elif "point" in o:
        d = _check_form(o, where, "point")
        points = model.point_names
        for key in ("point", "relative_to"):
            if key in d and d[key] not in points:
                fail(f"{where}.{key}", f"no point named {d[key]!r}; points: "
                     + (", ".join(points) or "none (list them under 'points')"))
        if "axes" in d:
            check_choice(d["axes"], f"{where}.axes", ["global"] + model.body_names + points)
        if "seen_from" in d:
            check_choice(d["seen_from"], f"{where}.seen_from", model.body_names + points)
        check_choice(d["quantity"], f"{where}.quantity", POINT_QUANTITIES)
        _check_component(d, where, d["quantity"], planar)
    elif "element" in o:
        d = _check_form(o, where, "element")
        name = d["element"]
        if name not in model.element_names:
            fail(f"{where}.element", f"no element named {name!r}")
        kind = model.element_type(name)
        outputs = [x["name"] for x in
                   _schema.KNOWN[model.space].get(kind, {}).get("outputs", [])]
        if not outputs:
            fail(f"{where}.element", f"'{name}' ({kind}) reports no outputs")
        check_choice(d["output"], f"{where}.output", outputs)
    elif "state" in o:
        d = _check_form(o, where, "state")
        fields = {t: [f["name"] for f in e["state_fields"]]
                  for t, e in _schema.KNOWN[model.space].items()
                  if e["state_fields"] and t in model.element_types}
        name = d["state"]
        if name not in model.element_names or model.element_type(name) not in fields:
            kinds = ", ".join(fields) or "none of its types"
            fail(f"{where}.state", f"no stateful force ({kinds}) named {name!r}")
        check_choice(d["field"], f"{where}.field", fields[model.element_type(name)])
    else:
        d = _check_form(o, where, "global")
        check_choice(d["quantity"], f"{where}.quantity", GLOBAL_QUANTITIES)
    check_name(d["name"], f"{where}.name")
    return d


def _check_figure(f: Any, where: str, columns: List[str]) -> Dict[str, Any]:
    d = check_keys(f, where, tuple(KEYS["figures"]), REQUIRED_KEYS["figures"])
    check_name(d["file"], f"{where}.file")
    # A name inside the figures' folder: a scene from elsewhere writes nowhere else.
    if os.path.basename(d["file"]) != d["file"] or d["file"] in (".", ".."):
        fail(f"{where}.file", f"{d['file']!r} is not a file name; a figure is written into the "
             "folder given to --figures, so give its name alone (\"piston.png\")")
    extension = os.path.splitext(d["file"])[1].lower()
    if extension not in FIGURE_FORMATS:
        fail(f"{where}.file", f"{d['file']!r}: expected a file name ending in "
             f"{', '.join(FIGURE_FORMATS)}")
    ys = d["y"] if isinstance(d["y"], list) else [d["y"]]
    for i, y in enumerate(ys):
        if y not in columns:
            fail(f"{where}.y", f"no output column {y!r}; columns: {', '.join(columns)}")
    for key in ("offset", "scale"):
        if key in d:
            check_number(d[key], f"{where}.{key}")
    for key in ("title", "ylabel"):
        if key in d and not isinstance(d[key], str):
            fail(f"{where}.{key}", f"expected a string, got {d[key]!r}")
    return d


def column(result: Result, spec: Mapping[str, Any]) -> np.ndarray:
    """One output column of a result, from a scene's column description."""
    if "body" in spec:
        history = result.body(spec["body"])
        values = getattr(history, spec["quantity"])
        if values.ndim == 1:  # a planar angle or rate
            return values
        comps = QUATERNION_COMPONENTS if spec["quantity"] == "orientation" else COMPONENTS
        return values[:, comps[spec["component"]]]
    if "reaction" in spec:
        r = result.reaction(spec["reaction"], spec.get("side", "b"), spec.get("axes", "global"))
        values = getattr(r, spec["quantity"])
        return values if values.ndim == 1 else values[:, COMPONENTS[spec["component"]]]
    if "point" in spec:
        motion = result.relative(spec["point"], spec.get("relative_to"),
                                 spec.get("axes", "global"), spec.get("seen_from", "ground"))
        return getattr(motion, spec["quantity"])[:, COMPONENTS[spec["component"]]]
    if "element" in spec:
        return result.output(spec["element"], spec["output"])
    if "state" in spec:
        return result.state(spec["state"])[spec["field"]]
    return result[spec["quantity"]]


# --- files --------------------------------------------------------------------------------------

def from_dict(d: Any, where: str = "") -> Scene:
    """A scene from parsed JSON; errors name the place in it."""
    if not isinstance(d, Mapping):
        fail(where or "scene", "expected a JSON object ({\"bodies\": [...], ...}) at the top, "
             f"got {_schema._describe(d)}")
    d = check_keys(d, where, TOP_KEYS, REQUIRED_KEYS["scene"])
    prefix = f"{where}." if where else ""
    if "odyn" in d and d["odyn"] != FORMAT_VERSION:
        fail(f"{prefix}odyn", f"unsupported scene format version {d['odyn']!r}; expected "
             f"{FORMAT_VERSION}")
    space = check_choice(d.get("space", "spatial"), f"{prefix}space", SPACES)
    module = (modules.load(check_name(d["module"], f"{prefix}module"), f"{prefix}module")
              if "module" in d else None)
    model = new_model(space, module)
    sections = space_sections(space, model.element_types)
    bodies = d["bodies"]
    if not isinstance(bodies, list):
        fail(f"{prefix}bodies", f"expected a list of bodies, got {type(bodies).__name__}")
    if not bodies:
        fail(f"{prefix}bodies", "the list is empty: a model needs at least one moving body")
    for i, b in enumerate(bodies):
        if not isinstance(b, Mapping):
            _not_object(b, f"{prefix}bodies[{i}]")
        model._add_body(b, f"{prefix}bodies[{i}]")
    # Points before the elements, which may name them for their points.
    for where, p in _objects(d, "points", prefix):
        model._add_point(p, where)
    for section, kinds in sections.items():
        entries = d.get(section, [])
        if not isinstance(entries, list):
            fail(f"{prefix}{section}", f"expected a list, got {type(entries).__name__}")
        for i, e in enumerate(entries):
            w = f"{prefix}{section}[{i}]"
            if not isinstance(e, Mapping):
                _not_object(e, w)
            if "type" not in e:
                fail(w, f"missing 'type'; expected one of {', '.join(kinds)}")
            kind = e["type"]
            if not isinstance(kind, str) or kind not in kinds:
                hint = ""
                for other, other_kinds in sections.items():
                    if kind in other_kinds:
                        hint = f" ('{kind}' belongs in '{other}')"
                owner = _schema.MODULE_OF.get((space, kind)) if isinstance(kind, str) else None
                if not hint and owner is not None and owner != model.module.__name__:
                    hint = (f" ('{kind}' is compiled by the module {owner}: name it under "
                            '"module")')
                other_space = "spatial" if space == "planar" else "planar"
                if not hint and kind in space_sections(other_space)[section]:
                    hint = (f" ('{kind}' is a {other_space} {section[:-1]}; this scene's space "
                            f"is {space})")
                fail(f"{w}.type", f"unknown {section[:-1]} type {kind!r}{hint}; expected one of "
                     f"{', '.join(kinds)}")
            model._add(kind, {k: v for k, v in e.items() if k != "type"}, w)
    for where, e in _objects(d, "events", prefix):
        if "function" in e or "bodies" in e:
            fail(where, "a scene's event watches an output or a point; a function event is "
                 "Python only (Model.add_event)")
        model._add_event(e, where)
    description = d.get("description", "")
    if not isinstance(description, str):
        fail(f"{prefix}description", "expected a string")
    outputs = d.get("outputs", [])
    figures = d.get("figures", [])
    for key, value in (("outputs", outputs), ("figures", figures)):
        if not isinstance(value, list):
            fail(f"{prefix}{key}", f"expected a list, got {type(value).__name__}")
    if d.get("analysis", {}) is None:
        fail(f"{prefix}analysis", "expected an object of settings, got null; leave it out for "
             "the defaults")
    return Scene(model, d.get("analysis", {}), outputs, figures, description)


def _objects(d: Mapping[str, Any], key: str, prefix: str) -> List[Tuple[str, Mapping[str, Any]]]:
    """The entries of the optional list d[key], each an object, with their places."""
    entries = d.get(key, [])
    if not isinstance(entries, list):
        fail(f"{prefix}{key}", f"expected a list, got {type(entries).__name__}")
    for i, entry in enumerate(entries):
        if not isinstance(entry, Mapping):
            _not_object(entry, f"{prefix}{key}[{i}]")
    return [(f"{prefix}{key}[{i}]", entry) for i, entry in enumerate(entries)]


def _not_object(x: Any, where: str) -> NoReturn:
    fail(where, f"expected an object, got {json.dumps(x) if _jsonable(x) else repr(x)}")
    raise AssertionError  # fail() raised


def _jsonable(x: Any) -> bool:
    try:
        json.dumps(x)
        return True
    except (TypeError, ValueError):
        return False


def _unique_keys(pairs: List[Tuple[str, Any]]) -> Dict[str, Any]:
    """A JSON object's members, refusing a key given twice (json would keep the last)."""
    d: Dict[str, Any] = {}
    for key, value in pairs:
        if key in d:
            others = ", ".join(repr(k) for k, _ in pairs[:6]) + (", ..." if len(pairs) > 6 else "")
            raise SceneError(f"the key {key!r} appears twice in one object (its keys: {others}); "
                             "JSON would keep the last silently: remove one")
        d[key] = value
    return d


def loads(text: str, source: str = "<string>") -> Scene:
    """A scene from JSON text."""
    try:
        # NaN and Infinity parse, and the checks name their place.
        d = json.loads(text, object_pairs_hook=_unique_keys)
    except SceneError as e:
        raise SceneError(f"{source}: {e}") from None
    except ValueError as e:  # json.JSONDecodeError included
        raise SceneError(f"{source}: not valid JSON: {e}") from None
    except RecursionError:
        raise SceneError(f"{source}: nested too deeply to read (thousands of levels of lists "
                         "or objects); a scene needs a few") from None
    return from_dict(d)


def load(path: Union[str, os.PathLike]) -> Scene:
    """Reads and checks a scene file. Raises SceneError naming the place of any error."""
    try:
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except OSError as e:
        raise SceneError(f"{path}: cannot read: {e.strerror}") from None
    except UnicodeDecodeError as e:
        raise SceneError(f"{path}: not UTF-8 text (byte 0x{e.object[e.start]:02x} at offset "
                         f"{e.start}); save the scene as UTF-8") from None
    try:
        return loads(text, str(path))
    except SceneError as e:
        message = str(e)
        if message.startswith(f"{path}:"):
            raise
        raise SceneError(f"{path}: {message}") from None


def save(scene: Union[Scene, BaseModel], path: Union[str, os.PathLike]) -> None:
    """Writes a scene (or a model with default analysis settings) as JSON."""
    if isinstance(scene, BaseModel):
        scene = Scene(scene)
    text = json.dumps(scene.to_dict(), indent=2, allow_nan=False)
    with open(path, "w", encoding="utf-8") as f:
        f.write(text + "\n")


def write_table(table: Mapping[str, np.ndarray], path: Union[str, os.PathLike]) -> None:
    """Writes columns as CSV (12 significant digits, like the C++ example) or .npz. The file
    appears whole or not at all (written beside it, then renamed), so that an interrupted write
    leaves no truncated table in its place."""
    path = os.fspath(path)
    partial = path + ".part"
    try:
        if path.endswith(".npz"):
            with open(partial, "wb") as f:
                np.savez(f, **{k: np.asarray(v) for k, v in table.items()})  # type: ignore
        else:
            names = list(table)
            data: Any = (np.column_stack([np.asarray(table[n], dtype=float) for n in names])
                         if names else [])
            with open(partial, "w", newline="", encoding="utf-8") as f:
                writer = csv.writer(f, lineterminator="\n")
                writer.writerow(names)
                for row in data:
                    writer.writerow(["%.12g" % x for x in row])
        os.replace(partial, path)
    except BaseException:
        if os.path.exists(partial):
            os.remove(partial)
        raise
