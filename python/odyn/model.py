"""Model building: bodies and elements by name, with keyword arguments named as in C++.

`Model` holds spatial bodies (odyn::spatial), `PlanarModel` planar ones (odyn::planar); both
share `BaseModel`: the generic `add(type, ...)`, names, and what scene files store.
"""

from __future__ import annotations

from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union

from . import _core, _schema, composite, modules
from ._elements import PlanarElements, SpatialElements
from ._schema import SceneError

Vector = Sequence[float]
#: A joint frame: a dict {"point": ..., "axis": ..., "reference": ...} (body coordinates), or
#: a tuple (point, axis) / (point, axis, reference). See `frame`. Planar frames have 2-vectors
#: and no reference.
Frame = Union[Mapping[str, Any], Tuple[Vector, ...]]
#: A planar force function: f(t, body) -> 2 numbers (a torque function: one number), with
#: body.position (2), body.angle, body.rotation (2 x 2), body.linear_velocity (2),
#: body.angular_velocity (a float).
PlanarFunction = Callable[[float, Any], Any]
#: A force or torque function: f(t, body) -> 3 numbers, body.position, body.rotation (3 x 3,
#: body to global), body.linear_velocity (global), body.angular_velocity (body axes).
FrameFunction = Callable[[float, Any], Sequence[float]]
#: A matrix over a wrench's components (a bushing's stiffness): 6 x 6 (3 x 3 in the plane), or a
#: list of its diagonal.
ComponentMatrix = Union[Sequence[float], Sequence[Sequence[float]]]
#: A bushing's law: f(t, x, x') -> a wrench, x and x' NumPy arrays of 6 numbers (3 in the plane).
WrenchLaw = Callable[[float, Any, Any], Sequence[float]]
#: Which crossings of its value an event reports (see BaseModel.add_event).
EVENT_DIRECTIONS = ("rising", "falling", "either")


def frame(point: Optional[Vector] = None, axis: Optional[Vector] = None,
          reference: Optional[Vector] = None) -> Dict[str, Any]:
    """A joint frame on a body: a point and an axis in body coordinates, and optionally a
    reference direction perpendicular to the axis (the zero of the joint's angle).

    Spatial frames have 3-vectors; left out, the point is the origin and the axis z. Planar
    frames have 2-vectors; left out, the point is the origin and the axis is taken parallel to
    the other body's axis at the initial pose (the zero of the joint angle)."""
    out: Dict[str, Any] = {}
    if point is not None:
        out["point"] = list(point)
    if axis is not None:
        out["axis"] = list(axis)
    if reference is not None:
        out["reference"] = list(reference)
    return out


def constant_velocity(rate: float, start: float = 0.0) -> Dict[str, Any]:
    """Motion g(t) = start + rate t."""
    return {"type": "constant_velocity", "rate": rate, "start": start}


def polynomial(coefficients: Sequence[float]) -> Dict[str, Any]:
    """Motion g(t) = c0 + c1 t + c2 t^2 + ..."""
    return {"type": "polynomial", "coefficients": list(coefficients)}


def harmonic(amplitude: float, frequency: float, phase: float = 0.0,
             offset: float = 0.0) -> Dict[str, Any]:
    """Motion g(t) = offset + amplitude sin(frequency t + phase), frequency in rad/s."""
    return {"type": "harmonic", "amplitude": amplitude, "frequency": frequency, "phase": phase,
            "offset": offset}


def motion_function(position: Callable[[float], float], velocity: Callable[[float], float],
                    acceleration: Callable[[float], float]) -> Dict[str, Any]:
    """Motion from three Python functions of time: g, g' and g'' (not saved in scenes)."""
    return {"type": "function", "position": position, "velocity": velocity,
            "acceleration": acceleration}


class BaseModel:
    """Bodies, elements and points, each with a unique name. The ground is the body named
    "ground".

    Every ``add_*`` method checks its arguments, then adds the element to the compiled model;
    errors (`odyn.ModelError`, `odyn.SceneError`) name the element and the offending value.

    module: a module of one's own (or its name) that compiles models with element types of its
    own (see `odyn.modules`); they are added with `add`. Default: odyn's own models.
    """

    #: "spatial" or "planar"
    space: str = "spatial"

    def __init__(self, module: Any = None) -> None:
        #: The compiled module whose model this is (odyn's own, or one of one's own).
        self.module: Any = _core if module is None else modules.register(module)
        planar = self.space == "planar"
        self._core: Any = self.module.PlanarModel() if planar else self.module.Model()
        self._compiled = frozenset(self.module.planar_element_types if planar
                                   else self.module.element_types)
        self._bodies: List[Dict[str, Any]] = []
        # name -> index in body_names ("ground" is 0): lookups in constant time, so that a
        # model of many thousands of bodies is built in time linear in its size.
        self._body_index: Dict[str, int] = {"ground": 0}
        # name -> (type, normalized parameters, parameters as given): the scene description.
        self._elements: Dict[str, Tuple[str, Dict[str, Any], Dict[str, Any]]] = {}
        # name -> (type, normalized parameters): what check_element resolves drivers against.
        self._checked: Dict[str, Tuple[str, Dict[str, Any]]] = {}
        # name -> {"name", "body", "at"}: the named points (markers), in the order added.
        self._points: Dict[str, Dict[str, Any]] = {}
        # body name -> its parts' combined mass, inertia and centre (in the parts frame), for
        # the bodies built from parts.
        self._composites: Dict[str, Dict[str, Any]] = {}
        # name -> the event as added and checked (see add_event), in the order added.
        self._events: Dict[str, Dict[str, Any]] = {}

    def _add_body(self, params: Mapping[str, Any], where: str) -> str:
        body = _schema.check_body(params, where,
                                  _schema.Names(self._body_index, self._elements, self._points),
                                  self.space)
        try:
            # A body built from parts: odyn's Composite combines them (python/src/parts.hpp).
            at_centre = _core.combined_body(body, self.space) if "parts" in body else body
            self._core.add_body(at_centre)
        except _core.ModelError as e:
            raise SceneError(f"{where}: {e}") from None
        self._body_index[body["name"]] = len(self._body_index)
        self._bodies.append(body)
        if "parts" in body:
            self._composites[body["name"]] = {
                key: at_centre[key] for key in ("mass", "inertia", "center_of_mass")}
        return body["name"]

    def at(self, body: str, point: Vector, part: Optional[str] = None) -> List[float]:
        """The body coordinates of a point given in the frame the body's parts are placed in,
        or, with `part`, in that part's own frame (its centre and axes). A body built from
        parts has its coordinates' origin at the parts' combined centre of mass: give joints,
        forces and named points there, for example ``on_b={"point": m.at("arm", [0, 0, 0.5])}``.
        A body without parts has its coordinates in that frame already."""
        if body not in self._body_index or body == "ground":
            raise SceneError(f"{body}: no moving body of that name in the model")
        given = self._bodies[self._body_index[body] - 1]
        return composite.point_in_body(point, body, given.get("parts"),
                                       self._composites.get(body), part, self.space)

    # --- elements ---------------------------------------------------------------------------
    @property
    def element_types(self) -> Tuple[str, ...]:
        """The element types this model accepts (those its module compiles)."""
        return tuple(t for t in _schema.CATALOGUE[self.space] if t in self._compiled)

    def add(self, type: str, **params: Any) -> str:
        """Adds an element of the given type (see `element_types`); returns its name."""
        return self._add(type, params, f"{type} '{params.get('name', '?')}'")

    def _add_given(self, type: str, **params: Any) -> str:
        """`add` with the parameters left at None dropped (the generated add_* methods)."""
        return self.add(type, **{k: v for k, v in params.items() if v is not None})

    def _add(self, kind: str, params: Mapping[str, Any], where: str) -> str:
        catalogue = _schema.CATALOGUE[self.space]
        if kind not in catalogue or kind not in self._compiled:
            other = "spatial" if self.space == "planar" else "planar"
            owner = _schema.MODULE_OF.get((self.space, kind))
            if kind in catalogue and owner is not None:
                hint = (f" ('{kind}' is compiled by the module {owner}: build the model as "
                        f"odyn.{type(self).__name__}(module={owner}))")
            elif kind in catalogue:
                hint = f" (the module {self.module.__name__} does not compile '{kind}')"
            elif kind in _schema.CATALOGUE[other]:
                hint = f" ('{kind}' is a {other} element; this is a {self.space} model)"
            else:
                hint = ""
            _schema.fail(where, f"unknown {self.space} element type '{kind}'{hint}; expected "
                         "one of " + ", ".join(self.element_types))
        checked = _schema.check_element(kind, params, where, self._body_index, self._checked,
                                        self.space, self._points)
        if checked["name"] in self._points:
            _schema.fail(f"{where}.name", f"the name '{checked['name']}' is already used (by a "
                         "point); names must be unique")
        try:
            self._core.add_element(kind, checked)
        except _core.ModelError as e:
            raise SceneError(f"{where}: {e}") from None
        self._elements[checked["name"]] = (kind, checked, dict(params))
        self._checked[checked["name"]] = (kind, checked)
        return checked["name"]

    # --- points ----------------------------------------------------------------------------
    def add_point(self, name: str, body: str, at: Optional[Vector] = None,
                  orientation: Any = None) -> str:
        """Adds a named point (a marker) fixed on a body, at `at` in body coordinates (default:
        the origin, the body's centre of mass); returns its name. Results give its position,
        velocity and acceleration (`Result.point`) and its motion relative to another point
        (`Result.relative`); scene files list points under "points" and name them in outputs.

        orientation: the marker's axes relative to the body's, a unit quaternion (w, x, y, z)
        in space, an angle (rad) in the plane; default: the body's axes. A joint frame given as
        the marker's name takes its point and axes (in space its z axis is the joint's axis and
        its x axis the reference; in the plane its x axis), and results may give motion in its
        axes (`Result.relative(..., axes=marker)`)."""
        return self._add_point({"name": name, "body": body,
                                **({} if at is None else {"at": at}),
                                **({} if orientation is None else {"orientation": orientation})},
                               f"point '{name}'")

    def _add_point(self, params: Mapping[str, Any], where: str) -> str:
        dim = 2 if self.space == "planar" else 3
        d = _schema.check_keys(params, where, ("name", "body", "at", "orientation"),
                               ("name", "body"))
        name = _schema.check_name(d["name"], f"{where}.name")
        if name in _schema.Names(self._body_index, self._elements, self._points):
            _schema.fail(f"{where}.name", f"the name '{name}' is already used; names must be "
                         "unique")
        body = _schema._body(d["body"], f"{where}.body", self._body_index)
        at = _schema.check_vector(d.get("at", [0.0] * dim), f"{where}.at", dim)
        point: Dict[str, Any] = {"name": name, "body": body, "at": at}
        if d.get("orientation") is not None:
            point["orientation"] = (
                _schema.check_number(d["orientation"], f"{where}.orientation")
                if self.space == "planar" else
                _schema.check_quaternion(d["orientation"], f"{where}.orientation"))
        self._points[name] = point
        return name

    @property
    def point_names(self) -> List[str]:
        return list(self._points)

    def point(self, name: str) -> Dict[str, Any]:
        """The point's {"name", "body", "at"} and, for a marker with axes, its "orientation"."""
        if name not in self._points:
            raise SceneError(f"{name}: no point of that name in the model"
                             + (f"; points: {', '.join(self._points)}" if self._points else ""))
        return dict(self._points[name])

    def _point_table(self) -> Dict[str, Tuple[int, List[float]]]:
        """name -> (body index, 0 for the ground; point in body coordinates), for results."""
        return {n: (self._body_index[p["body"]], p["at"]) for n, p in self._points.items()}

    def _point_axes(self) -> Dict[str, List[List[float]]]:
        """name -> the marker's axes in body axes (a rotation), for the markers that have
        them."""
        return {n: _schema.marker_rotation(p, self.space) for n, p in self._points.items()
                if "orientation" in p}

    # --- events ----------------------------------------------------------------------------
    def add_event(self, name: str, *, output: Optional[Sequence[str]] = None,
                  point: Optional[Sequence[str]] = None,
                  function: Optional[Callable[..., float]] = None,
                  bodies: Sequence[str] = (), value: float = 0.0, direction: str = "either",
                  terminal: bool = False) -> str:
        """Adds an event (ADAMS's sensor): the times at which a quantity crosses `value`,
        located within each step to the integrator's accuracy and listed in `Result.events`.
        A terminal event ends the run at its first crossing (the last output row is there).
        Returns its name. The quantity is one of:

        output: (element, output), one of an element's outputs (`odyn elements TYPE`);
        point: (point, "position" or "velocity", "x", "y" or "z"), a named point's, global;
        function: function(t, body_0[, body_1]) -> float, of the `bodies` named (zero to two;
        their views as a user force gets them). It may not keep the views between calls.

        direction: "rising" (from below `value` to above it), "falling" or "either". Scene
        files list events under "events" (all but functions)."""
        given = {"name": name, "value": value, "direction": direction, "terminal": terminal}
        for key, x in (("output", output), ("point", point), ("function", function)):
            if x is not None:
                given[key] = x
        if function is not None or bodies:
            given["bodies"] = bodies
        return self._add_event(given, f"event '{name}'")

    def _add_event(self, params: Mapping[str, Any], where: str) -> str:
        d = _schema.check_keys(params, where, ("name", "output", "point", "function", "bodies",
                                               "value", "direction", "terminal"), ("name",))
        name = _schema.check_name(d["name"], f"{where}.name")
        if name in self._events:
            _schema.fail(f"{where}.name", f"there is already an event '{name}'")
        kinds = [k for k in ("output", "point", "function") if k in d]
        if len(kinds) != 1:
            _schema.fail(where, "give one quantity to watch: output (element, output), point "
                         "(point, quantity, component) or function, got "
                         + (", ".join(kinds) or "none"))
        event: Dict[str, Any] = {"name": name}
        if "output" in d:
            event["output"] = self._event_output(d["output"], f"{where}.output")
        elif "point" in d:
            event["point"] = self._event_point(d["point"], f"{where}.point")
        else:
            event["function"] = _schema.check_callable(d["function"], f"{where}.function")
        if "bodies" in d:
            if "function" not in d:
                _schema.fail(f"{where}.bodies", "only a function event names bodies")
            bodies = d["bodies"]
            if not isinstance(bodies, (list, tuple)) or len(bodies) > 2:
                _schema.fail(f"{where}.bodies", "expected a list of up to two body names, got "
                             f"{bodies!r}")
            event["bodies"] = [_schema._body(b, f"{where}.bodies[{i}]", self._body_index)
                               for i, b in enumerate(bodies)]
        elif "function" in d:
            event["bodies"] = []
        event["value"] = _schema.check_number(d.get("value", 0.0), f"{where}.value")
        event["direction"] = _schema.check_choice(d.get("direction", "either"),
                                                  f"{where}.direction", EVENT_DIRECTIONS)
        event["terminal"] = _schema.check_flag(d.get("terminal", False), f"{where}.terminal")
        self._events[name] = event
        return name

    def _event_output(self, x: Any, where: str) -> List[str]:
        if not isinstance(x, (list, tuple)) or len(x) != 2:
            _schema.fail(where, f"expected (element, output), got {x!r}")
        element, output = x
        if element not in self._elements:
            _schema.fail(where, f"no element named {element!r}")
        kind = self._elements[element][0]
        outputs = [o["name"] for o in
                   _schema.KNOWN[self.space].get(kind, {}).get("outputs", [])]
        if not outputs:
            _schema.fail(where, f"'{element}' ({kind}) reports no outputs")
        return [element, _schema.check_choice(output, f"{where}[1]", outputs)]

    def _event_point(self, x: Any, where: str) -> List[str]:
        if not isinstance(x, (list, tuple)) or len(x) != 3:
            _schema.fail(where, f"expected (point, quantity, component), got {x!r}")
        point, quantity, component = x
        if point not in self._points:
            _schema.fail(where, f"no point named {point!r}; points: "
                         + (", ".join(self._points) or "none (add them with add_point)"))
        if quantity == "acceleration":
            _schema.fail(f"{where}[1]", "an event watches a point's position or velocity "
                         "(accelerations are not kept current while a crossing is located); "
                         "watch a force's output instead")
        _schema.check_choice(quantity, f"{where}[1]", ("position", "velocity"))
        axes = ("x", "y") if self.space == "planar" else ("x", "y", "z")
        _schema.check_choice(component, f"{where}[2]", axes)
        return [point, quantity, component]

    @property
    def event_names(self) -> List[str]:
        return list(self._events)

    def event(self, name: str) -> Dict[str, Any]:
        """The event as added: {"name", one of "output", "point" or "function" (with
        "bodies"), "value", "direction", "terminal"}."""
        if name not in self._events:
            raise SceneError(f"{name}: no event of that name in the model"
                             + (f"; events: {', '.join(self._events)}" if self._events else ""))
        return dict(self._events[name])

    def _point_reading(self, point: str, quantity: str, component: str) -> Dict[str, Any]:
        """A named point's position or velocity component as the C++ side reads it: the body
        by index, the point in its coordinates, the component by index."""
        body, at = self._point_table()[point]
        return {"kind": "point", "body": body, "at": at, "quantity": quantity,
                "component": "xyz".index(component)}

    def _event_table(self) -> List[Dict[str, Any]]:
        """The events as the run takes them: points and bodies by index."""
        table = []
        for e in self._events.values():
            row = {k: e[k] for k in ("name", "value", "direction", "terminal")}
            if "output" in e:
                row.update(kind="output", element=e["output"][0], output=e["output"][1])
            elif "point" in e:
                row.update(self._point_reading(*e["point"]))
            else:
                row.update(kind="function", function=e["function"],
                           bodies=[self._body_index[b] for b in e["bodies"]])
            table.append(row)
        return table

    # --- what is in it ----------------------------------------------------------------------
    @property
    def body_names(self) -> List[str]:
        """"ground" and the moving bodies, in the order they were added."""
        return list(self._body_index)

    @property
    def element_names(self) -> List[str]:
        return list(self._elements)

    def element_type(self, name: str) -> str:
        if name not in self._elements:
            raise SceneError(f"{name}: no element of that name in the model")
        return self._elements[name][0]

    def element(self, name: str) -> Dict[str, Any]:
        """The element's parameters, normalized (as a scene file stores them)."""
        self.element_type(name)
        return dict(self._elements[name][1])

    def body(self, name: str) -> Dict[str, Any]:
        """The body as added (as a scene file stores it). A body built from parts also has
        the combined "mass", "inertia" and "center_of_mass" (in the parts frame)."""
        index = self._body_index.get(name, 0)
        if index > 0:
            return {**self._bodies[index - 1], **self._composites.get(name, {})}
        raise SceneError(f"{name}: no body of that name in the model")

    @property
    def num_bodies(self) -> int:
        """Moving bodies (the ground not counted)."""
        return len(self._bodies)

    @property
    def num_velocities(self) -> int:
        """Velocity coordinates: 6 per spatial body, 3 per planar body."""
        return (3 if self.space == "planar" else 6) * self.num_bodies

    @property
    def num_equations(self) -> int:
        return self._core.num_equations

    def __repr__(self) -> str:
        kind = "PlanarModel" if self.space == "planar" else "Model"
        return (f"<odyn.{kind}: {self.num_bodies} bodies, {len(self._elements)} elements, "
                f"{self.num_equations} constraint equations>")


class Model(BaseModel, SpatialElements):
    """A spatial model: bodies with 6 velocity coordinates (odyn::spatial). See `BaseModel`."""

    space = "spatial"

    # --- bodies -----------------------------------------------------------------------------
    def add_body(self, name: str, mass: Optional[float] = None, inertia: Any = None,
                 position: Vector = (0, 0, 0), orientation: Vector = (1, 0, 0, 0),
                 linear_velocity: Vector = (0, 0, 0), angular_velocity: Vector = (0, 0, 0),
                 velocity_given: Optional[Sequence[bool]] = None,
                 parts: Optional[Sequence[Mapping[str, Any]]] = None) -> str:
        """Adds a rigid body; returns its name.

        inertia: three principal moments or a 3 x 3 tensor about the centre of mass, body axes;
        zero for a point mass, [I, I, 0] for a slender rod along body z (docs/bodies.md).
        position: centre of mass (global); orientation: unit quaternion (w, x, y, z), body to
        global; linear_velocity (global) and angular_velocity (body axes) are the initial
        velocity. velocity_given: which of the 6 components assembly should keep (default: the
        non-zero ones).

        parts: instead of mass and inertia, the parts the body is made of, each {"name",
        "mass", "inertia" (about the part's centre, in its axes), "at" (its centre), and
        "orientation" (its axes)} in the body's parts frame; odyn combines them. position,
        orientation and the velocities are then the parts frame's; the body's coordinates have
        their origin at the combined centre of mass (see `at`).
        """
        params = dict(name=name, mass=mass, inertia=inertia, position=position,
                      orientation=orientation, linear_velocity=linear_velocity,
                      angular_velocity=angular_velocity, velocity_given=velocity_given,
                      parts=parts)
        return self._add_body({k: v for k, v in params.items() if v is not None},
                              f"body '{name}'")


class PlanarModel(BaseModel, PlanarElements):
    """A planar model: bodies of x, y, phi in the x-y plane (odyn::planar). See `BaseModel`.

    Joint frames are a point and an axis per body (2-vectors, body coordinates); both may be
    left out: the point is then the body's centre of mass and the axis is taken parallel to the
    other body's at the initial pose. A joint angle is a difference of body angles, so it counts
    whole turns. Forces are 2-vectors, torques numbers.
    """

    space = "planar"

    # --- bodies -----------------------------------------------------------------------------
    def add_body(self, name: str, mass: Optional[float] = None, inertia: Optional[float] = None,
                 position: Vector = (0, 0), angle: float = 0.0, linear_velocity: Vector = (0, 0),
                 angular_velocity: float = 0.0,
                 velocity_given: Optional[Sequence[bool]] = None,
                 parts: Optional[Sequence[Mapping[str, Any]]] = None) -> str:
        """Adds a planar rigid body; returns its name.

        inertia: moment of inertia about the centre of mass (kg m^2); zero for a point mass
        (docs/bodies.md). position: centre of mass; angle: rad, counter-clockwise (it may
        exceed a turn). linear_velocity and angular_velocity: the initial velocity.
        velocity_given: which of (x', y', phi') assembly should keep (default: the non-zero
        ones).

        parts: instead of mass and inertia, the parts the body is made of, each {"name",
        "mass", "inertia" (about its centre), "at" (its centre)} in the body's parts frame;
        odyn combines them. position, angle and the velocities are then the parts frame's; the
        body's coordinates have their origin at the combined centre of mass (see `at`).
        """
        params = dict(name=name, mass=mass, inertia=inertia, position=position, angle=angle,
                      linear_velocity=linear_velocity, angular_velocity=angular_velocity,
                      velocity_given=velocity_given, parts=parts)
        return self._add_body({k: v for k, v in params.items() if v is not None},
                              f"body '{name}'")


def check_model(model: Any) -> None:
    """Refuses, before any work, an analysis's first argument that is not a model."""
    if not isinstance(model, BaseModel):
        raise TypeError("model: expected an odyn.Model or odyn.PlanarModel (or a module's "
                        f"model), got {_schema._describe(model)}")


def new_model(space: str = "spatial", module: Any = None) -> BaseModel:
    """An empty model of the given space ("spatial" or "planar"), of odyn's own compiled
    models or of `module`'s (see `BaseModel`)."""
    if space == "planar":
        return PlanarModel(module)
    if space == "spatial":
        return Model(module)
    raise SceneError(f"space: expected spatial or planar, got {space!r}")
