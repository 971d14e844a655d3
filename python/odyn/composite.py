"""Composite bodies: parts (a rod and a ball, a wheel and its hub) whose mass, centre of mass and
inertia odyn combines into one rigid body.

The parts are placed in the body's own frame, the *parts frame*: each part's centre `at` and,
in space, its axes `orientation` relative to that frame. The body keeps the frame's axes, but
its coordinates have their origin at the combined centre of mass, as every odyn body's do;
`BaseModel.at` converts points from the parts frame (or from a part's own frame) into them.
A body's `position`, `orientation` and velocities given with parts are those of the parts
frame: odyn puts the centre of mass where the parts put it. This module checks the parts as
given; the C++ library's Composite combines them (odyn._core.combined_body). See
docs/bodies.md.
"""

from __future__ import annotations

from typing import Any, Dict, List, Mapping, Optional, Sequence

import numpy as np

from . import _schema
from ._schema import REQUIRED, SceneError, fail

#: A part's keys: kind, default. The inertia is about the part's own centre, in its own axes.
PART = {"name": REQUIRED, "mass": REQUIRED, "inertia": REQUIRED, "at": None, "orientation": None}
PLANAR_PART = {"name": REQUIRED, "mass": REQUIRED, "inertia": REQUIRED, "at": None}


def check_parts(x: Any, where: str, space: str) -> List[Dict[str, Any]]:
    """The parts as given, checked and normalized: a non-empty list of {name, mass, inertia,
    at, orientation (space only)} with unique names."""
    if not isinstance(x, (list, tuple)) or not x:
        fail(where, f"expected a non-empty list of parts, got {_schema._describe(x)}")
    spec = PLANAR_PART if space == "planar" else PART
    dim = 2 if space == "planar" else 3
    out: List[Dict[str, Any]] = []
    for i, given in enumerate(x):
        w = f"{where}[{i}]"
        d = _schema.check_keys(given, w, list(spec),
                               [k for k, default in spec.items() if default is REQUIRED])
        part: Dict[str, Any] = {"name": _schema.check_name(d["name"], f"{w}.name")}
        w = f"{where}[{i}] ('{part['name']}')"
        if any(p["name"] == part["name"] for p in out):
            fail(f"{w}.name", "another part has that name; a body's parts need different names")
        part["mass"] = _schema.check_number(d["mass"], f"{w}.mass", positive=True)
        if space == "planar":
            part["inertia"] = _schema.check_number(d["inertia"], f"{w}.inertia", minimum=0.0)
        else:
            # Its moments are checked with the combination (odyn::spatial::Composite).
            part["inertia"] = _schema.check_inertia(d["inertia"], f"{w}.inertia")
        part["at"] = _schema.check_vector(d.get("at", [0.0] * dim), f"{w}.at", dim)
        if space != "planar":
            part["orientation"] = _schema.check_quaternion(
                d.get("orientation", [1.0, 0.0, 0.0, 0.0]), f"{w}.orientation")
        out.append(part)
    return out


def point_in_body(point: Sequence[float], body: str, parts: Optional[Sequence[Mapping[str, Any]]],
                  combined: Optional[Mapping[str, Any]], part: Optional[str],
                  space: str) -> List[float]:
    """Body coordinates of a point given in the parts frame, or in part `part`'s own frame (its
    centre and axes)."""
    dim = 2 if space == "planar" else 3
    where = f"point on '{body}'"
    p = np.array(_schema.check_vector(point, where, dim))
    if part is not None:
        named = [q for q in parts or () if q["name"] == part]
        if not named:
            raise SceneError(f"{where}: '{body}' has no part named {part!r}; its parts: "
                             + (", ".join(q["name"] for q in parts) if parts else
                                "none (it was not built from parts)"))
        if space != "planar":
            p = _schema.rotation(named[0]["orientation"]) @ p
        p = p + np.array(named[0]["at"])
    if combined is not None:
        p = p - np.array(combined["center_of_mass"])
    return p.tolist()
