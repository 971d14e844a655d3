"""Model building: bodies and elements by name, with keyword arguments named as in C++.

`Model` holds spatial bodies (odyn::spatial), `PlanarModel` planar ones (odyn::planar); both
share `BaseModel`: the generic `add(type, ...)`, names, and what scene files store.
"""

from __future__ import annotations

from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union

from . import _core, _schema
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
    """Bodies and elements, each with a unique name. The ground is the body named "ground".

    Every ``add_*`` method checks its arguments, then adds the element to the compiled model;
    errors (`odyn.ModelError`, `odyn.SceneError`) name the element and the offending value.
    """

    #: "spatial" or "planar"
    space: str = "spatial"

    def __init__(self) -> None:
        self._core: Any = _core.PlanarModel() if self.space == "planar" else _core.Model()
        self._bodies: List[Dict[str, Any]] = []
        # name -> index in body_names ("ground" is 0): lookups in constant time, so that a
        # model of many thousands of bodies is built in time linear in its size.
        self._body_index: Dict[str, int] = {"ground": 0}
        # name -> (type, normalized parameters, parameters as given): the scene description.
        self._elements: Dict[str, Tuple[str, Dict[str, Any], Dict[str, Any]]] = {}
        # name -> (type, normalized parameters): what check_element resolves drivers against.
        self._checked: Dict[str, Tuple[str, Dict[str, Any]]] = {}

    def _add_body(self, params: Mapping[str, Any], where: str) -> str:
        body = _schema.check_body(params, where, _schema.Names(self._body_index, self._elements),
                                  self.space)
        try:
            self._core.add_body(body)
        except _core.ModelError as e:
            raise SceneError(f"{where}: {e}") from None
        self._body_index[body["name"]] = len(self._body_index)
        self._bodies.append(body)
        return body["name"]

    # --- elements ---------------------------------------------------------------------------
    @property
    def element_types(self) -> Tuple[str, ...]:
        """The element types this model accepts (its space's catalogue)."""
        return tuple(_schema.CATALOGUE[self.space])

    def add(self, type: str, **params: Any) -> str:
        """Adds an element of the given type (see `element_types`); returns its name."""
        return self._add(type, params, f"{type} '{params.get('name', '?')}'")

    def _add(self, kind: str, params: Mapping[str, Any], where: str) -> str:
        catalogue = _schema.CATALOGUE[self.space]
        if kind not in catalogue:
            other = "spatial" if self.space == "planar" else "planar"
            hint = (f" ('{kind}' is a {other} element; this is a {self.space} model)"
                    if kind in _schema.CATALOGUE[other] else "")
            _schema.fail(where, f"unknown {self.space} element type '{kind}'{hint}; expected "
                         "one of " + ", ".join(catalogue))
        checked = _schema.check_element(kind, params, where, self._body_index, self._checked,
                                        self.space)
        try:
            self._core.add_element(kind, checked)
        except _core.ModelError as e:
            raise SceneError(f"{where}: {e}") from None
        self._elements[checked["name"]] = (kind, checked, dict(params))
        self._checked[checked["name"]] = (kind, checked)
        return checked["name"]

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
        index = self._body_index.get(name, 0)
        if index > 0:
            return dict(self._bodies[index - 1])
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


class Model(BaseModel):
    """A spatial model: bodies with 6 velocity coordinates (odyn::spatial). See `BaseModel`."""

    space = "spatial"

    # --- bodies -----------------------------------------------------------------------------
    def add_body(self, name: str, mass: float, inertia: Any, position: Vector = (0, 0, 0),
                 orientation: Vector = (1, 0, 0, 0), linear_velocity: Vector = (0, 0, 0),
                 angular_velocity: Vector = (0, 0, 0),
                 velocity_given: Optional[Sequence[bool]] = None) -> str:
        """Adds a rigid body; returns its name.

        inertia: three principal moments or a 3 x 3 tensor about the centre of mass, body axes.
        position: centre of mass (global); orientation: unit quaternion (w, x, y, z), body to
        global; linear_velocity (global) and angular_velocity (body axes) are the initial
        velocity. velocity_given: which of the 6 components assembly should keep (default: the
        non-zero ones).
        """
        params = dict(name=name, mass=mass, inertia=inertia, position=position,
                      orientation=orientation, linear_velocity=linear_velocity,
                      angular_velocity=angular_velocity, velocity_given=velocity_given)
        return self._add_body(params, f"body '{name}'")

    # --- elements (spatial) -------------------------------------------------------------
    def add_revolute(self, name: str, body_a: str, on_a: Frame, body_b: str, on_b: Frame) -> str:
        """Revolute (hinge): the joint points coincide, the axes stay parallel. 5 equations."""
        return self.add("revolute", name=name, body_a=body_a, on_a=on_a, body_b=body_b, on_b=on_b)

    def add_translational(self, name: str, body_a: str, on_a: Frame, body_b: str,
                          on_b: Frame) -> str:
        """Translational (prismatic): b slides along a's axis without turning. 5 equations."""
        return self.add("translational", name=name, body_a=body_a, on_a=on_a, body_b=body_b,
                        on_b=on_b)

    def add_spherical(self, name: str, body_a: str, point_a: Vector, body_b: str,
                      point_b: Vector) -> str:
        """Spherical (ball): the two points coincide. 3 equations."""
        return self.add("spherical", name=name, body_a=body_a, point_a=point_a, body_b=body_b,
                        point_b=point_b)

    def add_universal(self, name: str, body_a: str, on_a: Frame, body_b: str, on_b: Frame) -> str:
        """Universal (Cardan): points coincide, the two cross axes stay perpendicular. 4 eq."""
        return self.add("universal", name=name, body_a=body_a, on_a=on_a, body_b=body_b,
                        on_b=on_b)

    def add_cylindrical(self, name: str, body_a: str, on_a: Frame, body_b: str,
                        on_b: Frame) -> str:
        """Cylindrical: b slides along and turns about a's axis. 4 equations."""
        return self.add("cylindrical", name=name, body_a=body_a, on_a=on_a, body_b=body_b,
                        on_b=on_b)

    def add_fixed(self, name: str, body_a: str, on_a: Frame, body_b: str, on_b: Frame) -> str:
        """Fixed (weld): the joint frames stay together. 6 equations."""
        return self.add("fixed", name=name, body_a=body_a, on_a=on_a, body_b=body_b, on_b=on_b)

    def add_distance(self, name: str, body_a: str, point_a: Vector, body_b: str,
                     point_b: Vector, length: float = 0.0) -> str:
        """Distance (massless rod): the points keep their distance (length <= 0: the initial
        one). 1 equation."""
        return self.add("distance", name=name, body_a=body_a, point_a=point_a, body_b=body_b,
                        point_b=point_b, length=length)

    def add_revolute_driver(self, name: str, motion: Mapping[str, Any], joint: Optional[str] = None,
                            **bodies_and_frames: Any) -> str:
        """The angle of b about a's axis follows motion g(t). Give `joint` (a revolute joint's
        name) or body_a, on_a, body_b, on_b. 1 equation."""
        params = dict(name=name, motion=motion, **bodies_and_frames)
        if joint is not None:
            params["joint"] = joint
        return self.add("revolute_driver", **params)

    def add_translational_driver(self, name: str, motion: Mapping[str, Any],
                                 joint: Optional[str] = None, **bodies_and_frames: Any) -> str:
        """The slide of b along a's axis follows motion g(t). Give `joint` (a translational or
        cylindrical joint's name) or body_a, on_a, body_b, on_b. 1 equation."""
        params = dict(name=name, motion=motion, **bodies_and_frames)
        if joint is not None:
            params["joint"] = joint
        return self.add("translational_driver", **params)

    def add_gravity(self, name: str, acceleration: Vector) -> str:
        """Uniform gravity on every body (m/s^2)."""
        return self.add("gravity", name=name, acceleration=acceleration)

    def add_point_force(self, name: str, body: str, force: Union[Vector, FrameFunction],
                        point: Vector = (0, 0, 0), axes: str = "global") -> str:
        """A force at a body point: constant, or force(t, body) -> 3 numbers, in "global" or
        "body" axes. A Python function costs 0.2 to 0.6 us per call (bench/python_user_force.py)."""
        return self.add("point_force", name=name, body=body, point=point, force=force, axes=axes)

    def add_point_torque(self, name: str, body: str, torque: Union[Vector, FrameFunction],
                         axes: str = "global") -> str:
        """A torque on a body: constant, or torque(t, body) -> 3 numbers."""
        return self.add("point_torque", name=name, body=body, torque=torque, axes=axes)

    def add_tsda(self, name: str, body_a: str, point_a: Vector, body_b: str, point_b: Vector,
                 stiffness: float = 0.0, damping: float = 0.0, free_length: float = 0.0,
                 actuator: Optional[Callable[[float, float, float], float]] = None) -> str:
        """Translational spring-damper-actuator; tension k (L - free_length) + c L' +
        actuator(t, L, L') pulls the points together."""
        return self.add("tsda", name=name, body_a=body_a, point_a=point_a, body_b=body_b,
                        point_b=point_b, stiffness=stiffness, damping=damping,
                        free_length=free_length, actuator=actuator)

    def add_rsda(self, name: str, body_a: str, on_a: Frame, body_b: str, on_b: Frame,
                 stiffness: float = 0.0, damping: float = 0.0, free_angle: float = 0.0,
                 actuator: Optional[Callable[[float, float, float], float]] = None) -> str:
        """Rotational spring-damper-actuator about a's axis; torque on b
        -(k (theta - free_angle) + c theta') + actuator(t, theta, theta')."""
        return self.add("rsda", name=name, body_a=body_a, on_a=on_a, body_b=body_b, on_b=on_b,
                        stiffness=stiffness, damping=damping, free_angle=free_angle,
                        actuator=actuator)

    def add_engine_gas_force(self, name: str, crank: str, piston: str, r: float = 0.04,
                             L: float = 0.14, D: float = 0.08, C: float = 9.0,
                             p_atm: float = 101325.0, kappa: float = 1.4,
                             p_comb: float = 3.0e6) -> str:
        """The engine's Otto-cycle gas force on the piston along Z (shared/specs/engine.md),
        with the crank angle read from the crank's rotation about X. Events at each half turn."""
        return self.add("engine_gas_force", name=name, crank=crank, piston=piston, r=r, L=L, D=D,
                        C=C, p_atm=p_atm, kappa=kappa, p_comb=p_comb)

    def add_user_force(self, name: str, bodies: Sequence[str],
                       function: Callable[..., Any]) -> str:
        """A force written in Python on one or two bodies: function(t, body_0[, body_1])
        returns, per body, 6 numbers: the global force at the centre of mass, then the global
        torque. The body views are refreshed before each call (copy them to keep them)."""
        return self.add("user_force", name=name, bodies=list(bodies), function=function)


class PlanarModel(BaseModel):
    """A planar model: bodies of x, y, phi in the x-y plane (odyn::planar). See `BaseModel`.

    Joint frames are a point and an axis per body (2-vectors, body coordinates); both may be
    left out: the point is then the body's centre of mass and the axis is taken parallel to the
    other body's at the initial pose. A joint angle is a difference of body angles, so it counts
    whole turns. Forces are 2-vectors, torques numbers.
    """

    space = "planar"

    # --- bodies -----------------------------------------------------------------------------
    def add_body(self, name: str, mass: float, inertia: float, position: Vector = (0, 0),
                 angle: float = 0.0, linear_velocity: Vector = (0, 0),
                 angular_velocity: float = 0.0,
                 velocity_given: Optional[Sequence[bool]] = None) -> str:
        """Adds a planar rigid body; returns its name.

        inertia: moment of inertia about the centre of mass (kg m^2). position: centre of mass;
        angle: rad, counter-clockwise (it may exceed a turn). linear_velocity and
        angular_velocity: the initial velocity. velocity_given: which of (x', y', phi')
        assembly should keep (default: the non-zero ones).
        """
        params = dict(name=name, mass=mass, inertia=inertia, position=position, angle=angle,
                      linear_velocity=linear_velocity, angular_velocity=angular_velocity,
                      velocity_given=velocity_given)
        return self._add_body(params, f"body '{name}'")

    # --- elements (planar) --------------------------------------------------------------------
    def add_revolute(self, name: str, *, body_a: str, body_b: str, on_a: Optional[Frame] = None,
                     on_b: Optional[Frame] = None) -> str:
        """Revolute (pin): the joint points coincide. 2 equations. Its axes fix the zero of
        the joint angle that a revolute driver prescribes."""
        return self.add("revolute", name=name, body_a=body_a, on_a=on_a, body_b=body_b,
                        on_b=on_b)

    def add_translational(self, name: str, *, body_a: str, body_b: str,
                          on_a: Optional[Frame] = None, on_b: Optional[Frame] = None) -> str:
        """Translational (slider): b's point moves along the line through a's point with a's
        axis, and the bodies do not turn relative to each other. 2 equations."""
        return self.add("translational", name=name, body_a=body_a, on_a=on_a, body_b=body_b,
                        on_b=on_b)

    def add_fixed(self, name: str, *, body_a: str, body_b: str, on_a: Optional[Frame] = None,
                  on_b: Optional[Frame] = None) -> str:
        """Fixed (weld): the points coincide and the joint angle stays as it starts. 3 eq."""
        return self.add("fixed", name=name, body_a=body_a, on_a=on_a, body_b=body_b, on_b=on_b)

    def add_distance(self, name: str, *, body_a: str, body_b: str, point_a: Vector = (0, 0),
                     point_b: Vector = (0, 0), length: float = 0.0) -> str:
        """Distance (massless rod): the points keep their distance (length <= 0: the initial
        one). 1 equation."""
        return self.add("distance", name=name, body_a=body_a, point_a=point_a, body_b=body_b,
                        point_b=point_b, length=length)

    def add_revolute_driver(self, name: str, motion: Mapping[str, Any],
                            joint: Optional[str] = None, **bodies_and_frames: Any) -> str:
        """The joint angle (b's angle minus a's, from the axes) follows motion g(t). Give
        `joint` (a revolute joint's name) or body_a, body_b and optionally on_a, on_b. 1 eq."""
        params = dict(name=name, motion=motion, **bodies_and_frames)
        if joint is not None:
            params["joint"] = joint
        return self.add("revolute_driver", **params)

    def add_translational_driver(self, name: str, motion: Mapping[str, Any],
                                 joint: Optional[str] = None, **bodies_and_frames: Any) -> str:
        """The slide of b's point along a's axis, from a's point, follows motion g(t). Give
        `joint` (a translational joint's name) or body_a, on_a, body_b, on_b. 1 equation."""
        params = dict(name=name, motion=motion, **bodies_and_frames)
        if joint is not None:
            params["joint"] = joint
        return self.add("translational_driver", **params)

    def add_gravity(self, name: str, acceleration: Vector) -> str:
        """Uniform gravity on every body (m/s^2, 2 numbers)."""
        return self.add("gravity", name=name, acceleration=acceleration)

    def add_point_force(self, name: str, body: str, force: Union[Vector, PlanarFunction],
                        point: Vector = (0, 0), axes: str = "global") -> str:
        """A force at a body point: constant (2 numbers), or force(t, body) -> 2 numbers, in
        "global" or "body" axes."""
        return self.add("point_force", name=name, body=body, point=point, force=force, axes=axes)

    def add_point_torque(self, name: str, body: str,
                         torque: Union[float, PlanarFunction]) -> str:
        """A torque on a body (N m, counter-clockwise): a number, or torque(t, body) -> a
        number."""
        return self.add("point_torque", name=name, body=body, torque=torque)

    def add_tsda(self, name: str, *, body_a: str, body_b: str, point_a: Vector = (0, 0),
                 point_b: Vector = (0, 0), stiffness: float = 0.0, damping: float = 0.0,
                 free_length: float = 0.0,
                 actuator: Optional[Callable[[float, float, float], float]] = None) -> str:
        """Translational spring-damper-actuator; tension k (L - free_length) + c L' +
        actuator(t, L, L') pulls the points together."""
        return self.add("tsda", name=name, body_a=body_a, point_a=point_a, body_b=body_b,
                        point_b=point_b, stiffness=stiffness, damping=damping,
                        free_length=free_length, actuator=actuator)

    def add_rsda(self, name: str, *, body_a: str, body_b: str, on_a: Optional[Frame] = None,
                 on_b: Optional[Frame] = None, stiffness: float = 0.0, damping: float = 0.0,
                 free_angle: float = 0.0,
                 actuator: Optional[Callable[[float, float, float], float]] = None) -> str:
        """Rotational spring-damper-actuator on the joint angle theta (zero at the initial
        pose unless both axes are given); torque on b -(k (theta - free_angle) + c theta') +
        actuator(t, theta, theta'), and its opposite on a."""
        return self.add("rsda", name=name, body_a=body_a, on_a=on_a, body_b=body_b, on_b=on_b,
                        stiffness=stiffness, damping=damping, free_angle=free_angle,
                        actuator=actuator)

    def add_engine_gas_force(self, name: str, crank: str, piston: str, r: float = 0.04,
                             L: float = 0.14, D: float = 0.08, C: float = 9.0,
                             p_atm: float = 101325.0, kappa: float = 1.4,
                             p_comb: float = 3.0e6) -> str:
        """The engine's Otto-cycle gas force on the piston along y (shared/specs/engine.md),
        with the crank angle read from the crank's angle. Events at each half turn."""
        return self.add("engine_gas_force", name=name, crank=crank, piston=piston, r=r, L=L, D=D,
                        C=C, p_atm=p_atm, kappa=kappa, p_comb=p_comb)

    def add_user_force(self, name: str, bodies: Sequence[str],
                       function: Callable[..., Any]) -> str:
        """A force written in Python on one or two bodies: function(t, body_0[, body_1])
        returns, per body, 3 numbers: the global force (x, y) at the centre of mass, then the
        torque. The body views are refreshed before each call (copy them to keep them)."""
        return self.add("user_force", name=name, bodies=list(bodies), function=function)


def new_model(space: str = "spatial") -> BaseModel:
    """An empty model of the given space ("spatial" or "planar")."""
    if space == "planar":
        return PlanarModel()
    if space == "spatial":
        return Model()
    raise SceneError(f"space: expected spatial or planar, got {space!r}")
