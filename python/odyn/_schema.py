"""Checks and normalizes the parameters of bodies and elements.

One description serves the Python API and scene files: each element type lists its parameters
(named as in C++) with their kind and default. `check_*` return plain, JSON-like values (lists of
floats, dicts) or raise `SceneError` naming the place (``joints[2].axis``) and what was expected.
"""

from __future__ import annotations

import difflib
import itertools
import json
import math
from typing import (Any, Callable, Collection, Dict, List, Mapping, NoReturn, Optional, Sequence,
                    Tuple)

import numpy as np

from . import _core


class SceneError(_core.ModelError):
    """A body, element, analysis or scene file that does not describe a valid model.

    The message starts with the place, for example ``joints[2].on_a.axis: ...``.
    """


REQUIRED = object()


def fail(where: str, message: str) -> NoReturn:
    raise SceneError(f"{where}: {message}")


def _is_number(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) or _is_numpy_scalar(x)


def _is_numpy_scalar(x: Any) -> bool:
    return type(x).__module__ == "numpy" and hasattr(x, "dtype") and getattr(x, "ndim", 1) == 0


def _describe(x: Any) -> str:
    text = repr(x)
    return text if len(text) <= 60 else text[:57] + "..."


def check_number(x: Any, where: str, *, minimum: Optional[float] = None,
                 positive: bool = False) -> float:
    if not _is_number(x):
        fail(where, f"expected a number, got {_describe(x)}")
    try:
        value = float(x)
    except OverflowError:  # an integer beyond a double's range
        fail(where, f"expected a finite number, got an integer of {len(str(abs(int(x))))} digits")
    if not math.isfinite(value):
        fail(where, f"expected a finite number, got {value}")
    if positive and not value > 0.0:
        fail(where, f"expected a positive number, got {value:g}")
    if minimum is not None and value < minimum:
        fail(where, f"expected a number >= {minimum:g}, got {value:g}")
    return value


def check_tolerance(x: Any, where: str, *, relative: bool = False) -> float:
    """A positive tolerance; a relative one (rtol, newton_rtol) also at most 1, since an error
    above 100% of the value controls nothing (1, with a large atol, makes an adaptive method
    that never rejects a step)."""
    value = check_number(x, where, positive=True)
    if relative and not value <= 1.0:
        fail(where, f"a relative tolerance of {value:g} (above 100%) controls nothing; give a "
             "fraction of at most 1, such as 1e-6")
    return value


def check_count(x: Any, where: str, least: int) -> int:
    """A whole number (a Python or NumPy integer, not a bool) of at least `least`."""
    if isinstance(x, bool) or not isinstance(x, (int, np.integer)) or x < least:
        fail(where, f"expected a whole number of at least {least}, got {_describe(x)}")
    return int(x)


def check_vector(x: Any, where: str, size: int = 3, *, nonzero: bool = False) -> List[float]:
    if hasattr(x, "tolist"):  # numpy arrays
        x = x.tolist()
    if not isinstance(x, (list, tuple)) or len(x) != size:
        fail(where, f"expected a list of {size} numbers, got {_describe(x)}")
    values = [check_number(v, f"{where}[{i}]") for i, v in enumerate(x)]
    if nonzero and math.sqrt(sum(v * v for v in values)) <= 1e-12:
        fail(where, "zero-length vector; expected a non-zero direction")
    return values


def check_quaternion(x: Any, where: str) -> List[float]:
    """A unit quaternion (w, x, y, z): one whose length is 1 to within 1e-3, so that a rounded
    one (0.7071, 0, 0, 0.7071) passes (normalized by the core) while (2, 0, 0, 0), which is no
    rotation as given, is refused rather than silently scaled."""
    values = check_vector(x, where, 4, nonzero=True)
    length = math.sqrt(sum(v * v for v in values))
    if abs(length - 1.0) > 1e-3:
        fail(where, f"expected a unit quaternion (w, x, y, z), got {_describe(x)} of length "
             f"{length:.6g}; divide it by its length if its direction is the rotation meant")
    return values


def check_name(x: Any, where: str) -> str:
    if not isinstance(x, str) or not x.strip():
        fail(where, f"expected a non-empty name (a string), got {_describe(x)}")
    try:
        x.encode("utf-8")
    except UnicodeEncodeError:  # a lone surrogate ("\ud800" in JSON): no text the core can hold
        fail(where, f"the name {_describe(x)} holds a lone surrogate, which is not text; use "
             "characters that UTF-8 can encode")
    return x


def check_choice(x: Any, where: str, choices: Sequence[str]) -> str:
    if not isinstance(x, str) or x not in choices:
        fail(where, f"expected one of {', '.join(choices)}, got {_describe(x)}")
    return x


def check_flag(x: Any, where: str) -> bool:
    if not isinstance(x, bool):
        fail(where, f"expected true or false, got {_describe(x)}")
    return x


def check_callable(x: Any, where: str) -> Callable:
    if not callable(x):
        fail(where, f"expected a Python callable, got {_describe(x)}")
    return x


def check_keys(d: Any, where: str, allowed: Sequence[str], required: Sequence[str] = ()) -> Dict:
    if not isinstance(d, Mapping):
        fail(where, f"expected an object (a dict), got {_describe(d)}")
    for key in d:
        if key not in allowed:
            close = difflib.get_close_matches(str(key), [str(a) for a in allowed], n=1)
            hint = f" (did you mean '{close[0]}'?)" if close else ""
            fail(f"{where}.{key}" if where else str(key),
                 f"unknown key; expected one of {', '.join(allowed)}{hint}")
    for key in required:
        if key not in d:
            fail(where, f"missing '{key}'")
    return dict(d)


def check_frame(x: Any, where: str) -> Dict[str, Any]:
    """A joint frame: {point, axis, reference}; point defaults to the origin, axis to z."""
    if isinstance(x, (list, tuple)) and len(x) in (2, 3) and not _is_number(x[0]):
        x = dict(zip(("point", "axis", "reference"), x))
    if isinstance(x, Mapping) and x.get("axis") is None:
        x = {k: v for k, v in x.items() if k != "axis"}
    d = check_keys(x, where, ("point", "axis", "reference"))
    out = {
        "point": check_vector(d.get("point", [0.0, 0.0, 0.0]), f"{where}.point"),
        "axis": check_vector(d.get("axis", [0.0, 0.0, 1.0]), f"{where}.axis", nonzero=True),
    }
    if d.get("reference") is not None:
        out["reference"] = check_vector(d["reference"], f"{where}.reference", nonzero=True)
    return out


def check_planar_frame(x: Any, where: str) -> Dict[str, Any]:
    """A planar joint frame: {point, axis} in body coordinates; the point defaults to the
    origin; an axis left out is taken parallel to the other body's axis at the initial pose."""
    if x is None:
        x = {}
    if isinstance(x, (list, tuple)) and len(x) in (1, 2) and not _is_number(x[0]):
        x = dict(zip(("point", "axis"), x))
    d = check_keys(x, where, ("point", "axis"))
    out: Dict[str, Any] = {
        "point": check_vector(d.get("point", [0.0, 0.0]), f"{where}.point", 2)}
    if d.get("axis") is not None:
        axis = check_vector(d["axis"], f"{where}.axis", 2)
        if math.hypot(*axis) <= 1e-12:
            fail(f"{where}.axis", "zero-length vector; expected a non-zero direction (leave "
                 "'axis' out to take the other body's axis)")
        out["axis"] = axis
    return out


MOTIONS: Dict[str, Dict[str, Any]] = {
    "constant_velocity": {"rate": REQUIRED, "start": 0.0},
    "polynomial": {"coefficients": REQUIRED},
    "harmonic": {"amplitude": REQUIRED, "frequency": REQUIRED, "phase": 0.0, "offset": 0.0},
    "function": {"position": REQUIRED, "velocity": REQUIRED, "acceleration": REQUIRED},
}


def check_motion(x: Any, where: str) -> Dict[str, Any]:
    if not isinstance(x, Mapping) or "type" not in x:
        fail(where, "expected a motion: an object with 'type' (one of "
             + ", ".join(MOTIONS) + ") and its parameters")
    kind = check_choice(x["type"], f"{where}.type", list(MOTIONS))
    spec = MOTIONS[kind]
    d = check_keys(x, where, ["type", *spec], [k for k, v in spec.items() if v is REQUIRED])
    out: Dict[str, Any] = {"type": kind}
    for key, default in spec.items():
        value = d.get(key, default)
        if kind == "function":
            out[key] = check_callable(value, f"{where}.{key}")
        elif key == "coefficients":
            if hasattr(value, "tolist"):
                value = value.tolist()
            if not isinstance(value, (list, tuple)) or not value:
                fail(f"{where}.{key}", f"expected a non-empty list of numbers, got "
                     f"{_describe(value)}")
            out[key] = [check_number(c, f"{where}.{key}[{i}]") for i, c in enumerate(value)]
        else:
            out[key] = check_number(value, f"{where}.{key}")
    return out


# --- Parameter kinds ----------------------------------------------------------------------------
# Each kind checks one value: (value, where, model) -> normalized value. `model` resolves bodies.

class Names:
    """The names in use in a model, from several mappings or sets (bodies, elements): tests
    membership in constant time."""

    def __init__(self, *groups: Collection[str]) -> None:
        self._groups = groups

    def __contains__(self, name: object) -> bool:
        return any(name in group for group in self._groups)


def _body(x, where, bodies):
    name = check_name(x, where)
    if name not in bodies:
        first = list(itertools.islice(bodies, 13))
        known = ", ".join(first[:12]) + (", ..." if len(first) > 12 else "")
        fail(where, f"no body named '{name}'; the model has: {known}")
    return name


def _bodies(x, where, bodies):
    if not isinstance(x, (list, tuple)) or len(x) not in (1, 2):
        fail(where, f"expected a list of one or two body names, got {_describe(x)}")
    return [_body(b, f"{where}[{i}]", bodies) for i, b in enumerate(x)]


def check_component_matrix(x: Any, where: str, size: int) -> List[List[float]]:
    """A matrix over a wrench's `size` components: the full matrix, a list of its diagonal, or
    0 (symmetry and definiteness are the element's to check)."""
    if hasattr(x, "tolist"):  # numpy arrays
        x = x.tolist()
    if _is_number(x) and x == 0:
        return [[0.0] * size for _ in range(size)]
    if isinstance(x, (list, tuple)) and len(x) == size and all(_is_number(v) for v in x):
        diagonal = check_vector(x, where, size)
        return [[diagonal[i] if i == j else 0.0 for j in range(size)] for i in range(size)]
    if not isinstance(x, (list, tuple)) or len(x) != size:
        fail(where, f"expected {size} numbers (a diagonal) or a {size} x {size} matrix, got "
             f"{_describe(x)}")
    return [check_vector(row, f"{where}[{i}]", size) for i, row in enumerate(x)]


#: The coordinates of a joint a coupler may take.
COORDINATES = ("angle", "slide")
#: The coordinate each joint type has, where it has one only.
OWN_COORDINATE = {"revolute": "angle", "translational": "slide"}


def _kinds(dim: int, frame: Callable[[Any, str], Any]) -> Dict[str, Callable[[Any, str, Any],
                                                                          Any]]:
    """How each parameter kind (odyn/core/description.hpp) checks a value in a space whose
    vectors have `dim` components."""
    wrench = 6 if dim == 3 else 3  # a force and a torque

    def vector_or_callable(x, where, bodies):
        return x if callable(x) else check_vector(x, where, dim)

    def angular_or_callable(x, where, bodies):
        if callable(x):
            return x
        return check_vector(x, where) if dim == 3 else check_number(x, where)

    def joint_reference(x, where, bodies):
        # check_element resolved a joint's name into its bodies and frames; a scene saved
        # from a model holds them so.
        if isinstance(x, str):
            fail(where, f"no joint named '{x}' before this element")
        check_keys(x, where, ["body_a", "on_a", "body_b", "on_b"], ["body_a", "body_b"])
        return {"body_a": _body(x["body_a"], f"{where}.body_a", bodies),
                "on_a": frame(x.get("on_a") or {}, f"{where}.on_a"),
                "body_b": _body(x["body_b"], f"{where}.body_b", bodies),
                "on_b": frame(x.get("on_b") or {}, f"{where}.on_b")}

    return {
        "name": lambda x, w, b: check_name(x, w),
        "body": _body,
        "bodies": _bodies,
        "joint": lambda x, w, b: check_name(x, w),
        "turning_joint": joint_reference,
        "sliding_joint": joint_reference,
        "coupled_joint": joint_reference,
        "optional_coupled_joint": lambda x, w, b: None if x is None else joint_reference(x, w, b),
        "coordinate": lambda x, w, b: None if x is None else check_choice(x, w, COORDINATES),
        "vector": lambda x, w, b: check_vector(x, w, dim),
        "frame": lambda x, w, b: frame({} if x is None else x, w),
        "number": lambda x, w, b: check_number(x, w),
        "optional_number": lambda x, w, b: None if x is None else check_number(x, w),
        "flag": lambda x, w, b: check_flag(x, w),
        "nonnegative": lambda x, w, b: check_number(x, w, minimum=0.0),
        "positive": lambda x, w, b: check_number(x, w, positive=True),
        "axes": lambda x, w, b: check_choice(x, w, ("global", "body")),
        "motion": lambda x, w, b: check_motion(x, w),
        "vector_or_callable": vector_or_callable,
        "angular_or_callable": angular_or_callable,
        "optional_callable": lambda x, w, b: None if x is None else check_callable(x, w),
        "callable": lambda x, w, b: check_callable(x, w),
        "optional_function": lambda x, w, b: None if x is None else check_callable(x, w),
        "wrench": lambda x, w, b: check_vector(x, w, wrench),
        "component_matrix": lambda x, w, b: check_component_matrix(x, w, wrench),
        "wrench_law": lambda x, w, b: None if x is None else check_callable(x, w),
    }


#: Each space's parameter kinds: kind -> check(value, where, bodies) -> normalized value.
SPACE_KINDS = {"spatial": _kinds(3, check_frame), "planar": _kinds(2, check_planar_frame)}

#: What each kind means, from the compiled core (for the documentation).
KIND_DOCS: Dict[str, str] = dict(_core.parameter_kinds)
assert set(KIND_DOCS) == set(SPACE_KINDS["spatial"]), "a kind without its check, or the reverse"


def _default(kind: str, text: Optional[str], dim: int) -> Any:
    """A parameter's default from its JSON text; a vector's, a wrench's or a matrix's 0 is
    zero."""
    if text is None:
        return REQUIRED
    value = json.loads(text)
    wrench = 6 if dim == 3 else 3
    if kind == "vector" and value == 0:
        return [0.0] * dim
    if kind == "wrench" and value == 0:
        return [0.0] * wrench
    if kind == "component_matrix" and value == 0:
        return [[0.0] * wrench for _ in range(wrench)]
    return value


def _catalogue(described: Sequence[Mapping[str, Any]], dim: int) -> Dict[str, Dict[str, Any]]:
    """type -> its description (from the compiled core), with `spec`: parameter -> (kind,
    default) in the description's order."""
    out: Dict[str, Dict[str, Any]] = {}
    for element in described:
        spec = {p["name"]: (p["kind"], _default(p["kind"], p["default"], dim))
                for p in element["parameters"]}
        out[element["type"]] = {**element, "spec": spec}
    return out


#: Every element type of each space, as the compiled core describes it: type -> {type,
#: category ("joint", "driver", "force"), summary, parameters, spec}.
DESCRIPTIONS = {"spatial": _catalogue(_core.element_catalogue, 3),
                "planar": _catalogue(_core.planar_element_catalogue, 2)}

#: DESCRIPTIONS and those of the modules of one's own that were registered (odyn.modules).
KNOWN = {space: dict(described) for space, described in DESCRIPTIONS.items()}

#: Every element type: parameter -> (kind, default). Names and order follow the C++ descriptions.
ELEMENTS: Dict[str, Dict[str, Tuple[str, Any]]] = {
    t: d["spec"] for t, d in DESCRIPTIONS["spatial"].items()}
PLANAR_ELEMENTS: Dict[str, Dict[str, Tuple[str, Any]]] = {
    t: d["spec"] for t, d in DESCRIPTIONS["planar"].items()}


def _of(space: str, category: str) -> Tuple[str, ...]:
    return tuple(t for t, d in KNOWN[space].items() if d["category"] == category)


JOINTS = _of("spatial", "joint")
PLANAR_JOINTS = _of("planar", "joint")
DRIVERS = _of("spatial", "driver")
FORCES = _of("spatial", "force")
PLANAR_FORCES = _of("planar", "force")  # the contacts' planar twins have their own names
assert _of("planar", "driver") == DRIVERS

#: The element catalogue of each space.
CATALOGUE = {"spatial": ELEMENTS, "planar": PLANAR_ELEMENTS}
SPACE_JOINTS = {"spatial": JOINTS, "planar": PLANAR_JOINTS}
SPACE_FORCES = {"spatial": FORCES, "planar": PLANAR_FORCES}

#: Which joint types a turning_joint (its angle) or a sliding_joint (its slide) parameter may
#: name, in each space: from the compiled core.
JOINT_KINDS = {space: {kind: tuple(types) for kind, types in kinds.items()}
               for space, kinds in (("spatial", _core.joint_kinds),
                                    ("planar", _core.planar_joint_kinds))}

#: Which joints a driver or a stop may name with `joint=` (it takes their bodies and frames), in
#: each space: from the descriptions.
DRIVEN_JOINTS = {space: {t: tuple(d["joints"]) for t, d in DESCRIPTIONS[space].items()
                         if d["joints"]} for space in DESCRIPTIONS}


#: Element types that a module of one's own compiles (odyn.modules): type -> the module's name.
MODULE_OF: Dict[Tuple[str, str], str] = {}


def _refresh_categories() -> None:
    """Rebuilds the tuples of element types by category after add_descriptions."""
    global JOINTS, PLANAR_JOINTS, DRIVERS, FORCES, PLANAR_FORCES
    JOINTS, PLANAR_JOINTS = _of("spatial", "joint"), _of("planar", "joint")
    DRIVERS = _of("spatial", "driver")
    FORCES, PLANAR_FORCES = _of("spatial", "force"), _of("planar", "force")
    SPACE_JOINTS.update(spatial=JOINTS, planar=PLANAR_JOINTS)
    SPACE_FORCES.update(spatial=FORCES, planar=PLANAR_FORCES)


def add_descriptions(space: str, described: Sequence[Mapping[str, Any]],
                     joint_kinds: Mapping[str, Sequence[str]], module: str) -> None:
    """Adds the element types a compiled module describes (its element_catalogue) to `space`'s
    tables (not to DESCRIPTIONS, odyn's own); a type known already must be described the same way
    (the library's own types are)."""
    for t, d in _catalogue(described, 3 if space == "spatial" else 2).items():
        known = KNOWN[space].get(t)
        if known is not None:
            if known["parameters"] != d["parameters"] or known["category"] != d["category"]:
                owner = MODULE_OF.get((space, t), "odyn")
                fail(f"module {module}", f"its {space} element type '{t}' differs from the one "
                     f"of the same name in {owner}; give one of them another name")
            continue
        KNOWN[space][t] = d
        CATALOGUE[space][t] = d["spec"]
        MODULE_OF[(space, t)] = module
        if d["joints"]:
            DRIVEN_JOINTS[space][t] = tuple(d["joints"])
    for kind, types in joint_kinds.items():
        JOINT_KINDS[space][kind] = tuple(dict.fromkeys((*JOINT_KINDS[space].get(kind, ()),
                                                        *types)))
    _refresh_categories()


def check_element(kind: str, params: Mapping[str, Any], where: str, bodies: Collection[str],
                  elements: Mapping[str, Tuple[str, Dict[str, Any]]],
                  space: str = "spatial",
                  points: Optional[Mapping[str, Mapping[str, Any]]] = None) -> Dict[str, Any]:
    """Normalized parameters of an element of type `kind` in `space`; `elements`: name ->
    (type, params); `points`: the named points (name -> {"body", "at"}) that a point parameter
    may name instead of giving coordinates."""
    spec = CATALOGUE[space][kind]
    kinds = SPACE_KINDS[space]
    params = {k: v for k, v in params.items() if not (k == "joint" and v is None)}
    required = [k for k, (_, default) in spec.items() if default is REQUIRED]
    driven = DRIVEN_JOINTS[space]
    # An element on a joint's bodies and frames (a driver, a stop) takes them from `joint`; one
    # that sits on the joint itself (friction) keeps its name, checked here.
    takes_frames = kind in driven and "body_a" in spec
    if kind in driven and not takes_frames and isinstance(params.get("joint"), str):
        joint = check_name(params["joint"], f"{where}.joint")
        if joint not in elements or elements[joint][0] not in driven[kind]:
            fail(f"{where}.joint", f"no {' or '.join(driven[kind])} joint named '{joint}' "
                 f"before this {kind}")
    if takes_frames:
        if "joint" in params:
            # Drive or stop an existing joint: take its bodies and frames.
            joint = check_name(params.pop("joint"), f"{where}.joint")
            if joint not in elements or elements[joint][0] not in driven[kind]:
                fail(f"{where}.joint", f"no {' or '.join(driven[kind])} joint named "
                     f"'{joint}' before this {'driver' if kind in DRIVERS else 'stop'}")
            for key in ("body_a", "on_a", "body_b", "on_b"):
                if params.get(key) is not None:
                    fail(f"{where}.{key}",
                         "give either 'joint' or the bodies and frames, not both")
                params[key] = elements[joint][1][key]
        else:
            required += ["body_a", "body_b"]
    for key, (param_kind, _) in spec.items():
        if param_kind in JOINT_KINDS[space] and isinstance(params.get(key), str):
            # The name of a joint added before: the element takes its bodies and frames.
            joint = check_name(params[key], f"{where}.{key}")
            types = JOINT_KINDS[space][param_kind]
            if joint not in elements or elements[joint][0] not in types:
                either = " or ".join([", ".join(types[:-1]), types[-1]] if len(types) > 1
                                     else types)
                fail(f"{where}.{key}", f"no {either} joint named '{joint}' before this {kind}")
            _check_coordinate(params, spec, key, joint, elements[joint][0], where)
            params[key] = {k: elements[joint][1][k] for k in ("body_a", "on_a", "body_b", "on_b")}
    check_keys(params, where, list(spec), required)
    _resolve_points(params, spec, points or {}, where)
    out: Dict[str, Any] = {}
    for key, (param_kind, default) in spec.items():
        if key == "joint" and takes_frames:
            continue  # resolved above into the bodies and frames
        value = params.get(key, default)
        out[key] = kinds[param_kind](value, f"{where}.{key}", bodies)
    if out["name"] in elements or out["name"] in bodies:
        fail(f"{where}.name", f"the name '{out['name']}' is already used; names must be unique")
    named = [key for key, (param_kind, _) in spec.items() if param_kind == "body"]
    for i, key in enumerate(named):
        for other in named[:i]:
            if out[key] == out[other]:
                fail(f"{where}.{key}", f"{other} and {key} are both '{out[key]}'; expected "
                     "two different bodies")
    if "bodies" in out and len(set(out["bodies"])) != len(out["bodies"]):
        fail(f"{where}.bodies", "the bodies must be different")
    return out


#: The body each point parameter lies on: a joint frame's point, a point, a sphere's centre.
#: A point parameter may name a point (a marker) on that body instead of giving coordinates.
POINT_BODIES = {"on_a": "body_a", "on_b": "body_b", "point_a": "body_a", "point_b": "body_b",
                "center_a": "body_a", "center_b": "body_b", "point": "body"}


def rotation(quaternion: Sequence[float]) -> np.ndarray:
    """The 3 x 3 rotation of a quaternion (w, x, y, z), normalized."""
    w, x, y, z = np.asarray(quaternion, dtype=float) / np.linalg.norm(quaternion)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def marker_rotation(point: Mapping[str, Any], space: str) -> List[List[float]]:
    """A marker's axes in its body's axes: the rotation of its orientation (identity if it has
    none), 3 x 3 from a quaternion (w, x, y, z) in space, 2 x 2 from an angle in the plane."""
    if space == "planar":
        c, s = math.cos(point.get("orientation", 0.0)), math.sin(point.get("orientation", 0.0))
        return [[c, -s], [s, c]]
    return rotation(point.get("orientation", [1.0, 0.0, 0.0, 0.0])).tolist()


def _marker_frame(point: Mapping[str, Any]) -> Dict[str, Any]:
    """The joint frame of a marker: its point, its z axis and x axis as the frame's axis and
    reference in space, its x axis as the axis in the plane."""
    at = list(point["at"])
    if len(at) == 2:
        r = marker_rotation(point, "planar")
        return {"point": at, "axis": [r[0][0], r[1][0]]}
    r = marker_rotation(point, "spatial")
    return {"point": at, "axis": [row[2] for row in r], "reference": [row[0] for row in r]}


def _resolve_points(params: Dict[str, Any], spec: Mapping[str, Tuple[str, Any]],
                    points: Mapping[str, Mapping[str, Any]], where: str) -> None:
    """Replaces a point's name, given for a point parameter (or a joint frame's point), by its
    coordinates on the parameter's body, which must be the point's; a joint frame given as a
    marker's name becomes the marker's point and axes."""
    for key, (kind, _) in spec.items():
        if key not in POINT_BODIES or kind not in ("frame", "vector"):
            continue
        value = params.get(key)
        whole_frame = kind == "frame" and isinstance(value, str)
        if whole_frame:
            name, w = value, f"{where}.{key}"
        elif kind == "frame":
            if isinstance(value, (list, tuple)) and value and isinstance(value[0], str):
                value = dict(zip(("point", "axis", "reference"), value))
            if not (isinstance(value, Mapping) and isinstance(value.get("point"), str)):
                continue
            name, w = value["point"], f"{where}.{key}.point"
        elif isinstance(value, str):
            name, w = value, f"{where}.{key}"
        else:
            continue
        # A plain `point` lies on the element's `body`, or on body_a where it has none (the
        # plane of a contact).
        body_key = POINT_BODIES[key] if POINT_BODIES[key] in spec else "body_a"
        if name not in points:
            fail(w, f"no point named '{name}'; points: "
                 + (", ".join(points) or "none (add them with add_point before this element)"))
        body = params.get(body_key)
        if points[name]["body"] != body:
            fail(w, f"the point '{name}' is on '{points[name]['body']}', but {key} is a point "
                 f"on {body_key}, '{body}'")
        at = list(points[name]["at"])
        if whole_frame:
            params[key] = _marker_frame(points[name])
        else:
            params[key] = {**value, "point": at} if kind == "frame" else at


def _check_coordinate(params: Dict[str, Any], spec: Mapping[str, Tuple[str, Any]], key: str,
                      joint: str, joint_type: str, where: str) -> None:
    """Fills in or checks the coordinate that goes with a coupled joint named by `key`
    (coordinate_1 with joint_1): a revolute joint's is its angle, a translational joint's its
    slide; a cylindrical joint's must be given."""
    coordinate = "coordinate" + key[len("joint"):]
    if spec.get(coordinate, ("",))[0] != "coordinate":
        return
    given = params.get(coordinate)
    own = OWN_COORDINATE.get(joint_type)
    if given is None:
        if own is None:
            fail(f"{where}.{coordinate}", f"'{joint}' is a {joint_type} joint, which both turns "
                 "and slides; give \"angle\" or \"slide\"")
        params[coordinate] = own
    elif own is not None and given != own and given in COORDINATES:
        fail(f"{where}.{coordinate}", f"'{joint}' is a {joint_type} joint, which has no "
             f"{given}; its coordinate is its {own}")


BODY: Dict[str, Tuple[str, Any]] = {
    "name": ("name", REQUIRED),
    "mass": ("positive", REQUIRED),
    "inertia": ("inertia", REQUIRED),
    "position": ("vector", [0.0, 0.0, 0.0]),
    "orientation": ("quaternion", [1.0, 0.0, 0.0, 0.0]),
    "linear_velocity": ("vector", [0.0, 0.0, 0.0]),
    "angular_velocity": ("vector", [0.0, 0.0, 0.0]),
    "velocity_given": ("flags", None),
}


def check_inertia(x: Any, where: str) -> List[List[float]]:
    """Three principal moments, or a 3 x 3 tensor, about the centre of mass in body axes."""
    if hasattr(x, "tolist"):
        x = x.tolist()
    if isinstance(x, (list, tuple)) and len(x) == 3 and all(_is_number(v) for v in x):
        moments = check_vector(x, where)
        return [[moments[i] if i == j else 0.0 for j in range(3)] for i in range(3)]
    if (isinstance(x, (list, tuple)) and len(x) == 3
            and all(isinstance(row, (list, tuple)) for row in x)):
        return [check_vector(row, f"{where}[{i}]") for i, row in enumerate(x)]
    fail(where, f"expected 3 principal moments or a 3 x 3 tensor, got {_describe(x)}")
    raise AssertionError


PLANAR_BODY: Dict[str, Tuple[str, Any]] = {
    "name": ("name", REQUIRED),
    "mass": ("positive", REQUIRED),
    "inertia": ("nonnegative", REQUIRED),
    "position": ("vector", [0.0, 0.0]),
    "angle": ("number", 0.0),
    "linear_velocity": ("vector", [0.0, 0.0]),
    "angular_velocity": ("number", 0.0),
    "velocity_given": ("flags", None),
}


def check_body(params: Mapping[str, Any], where: str, names: Sequence[str],
               space: str = "spatial") -> Dict[str, Any]:
    """The body as given, checked and normalized. A body built from `parts` (composite.py)
    takes its mass and inertia from them and gives neither."""
    spec = PLANAR_BODY if space == "planar" else BODY
    flags = 3 if space == "planar" else 6
    own = ("mass", "inertia")  # what parts replace
    composite = isinstance(params, Mapping) and params.get("parts") is not None
    if composite:
        for key in own:
            if params.get(key) is not None:
                fail(f"{where}.{key}", "give either mass and inertia or parts, not both: the "
                     "parts' masses and inertias make the body's")
        params = {k: v for k, v in params.items() if k not in own}
    check_keys(params, where, list(spec) + ["parts"],
               [k for k, (_, d) in spec.items() if d is REQUIRED and not (composite and k in own)])
    out: Dict[str, Any] = {}
    for key, (kind, default) in spec.items():
        if composite and key in own:
            continue
        value = params.get(key, default)
        w = f"{where}.{key}"
        if kind == "inertia":
            out[key] = check_inertia(value, w)
        elif kind == "quaternion":
            out[key] = check_quaternion(value, w)
        elif kind == "flags":
            if value is not None and (not isinstance(value, (list, tuple)) or len(value) != flags
                                      or not all(isinstance(f, bool) for f in value)):
                what = "x', y', phi'" if space == "planar" else "linear x y z, angular x y z"
                fail(w, f"expected a list of {flags} booleans ({what}), got {_describe(value)}")
            out[key] = None if value is None else list(value)
        else:
            out[key] = SPACE_KINDS[space][kind](value, w, [])
    if out["name"] in names or out["name"] == "ground":
        fail(f"{where}.name", f"the name '{out['name']}' is already used; names must be unique")
    if composite:
        from .composite import check_parts  # composite.py builds on this module
        out["parts"] = check_parts(params["parts"], f"{where}.parts", space)
    return out
