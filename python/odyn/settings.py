"""Typed settings of the integrators and of the assembly, mirrored from the C++ library's
DynamicsSettings (its sections generalized_alpha, dormand_prince, bdf and adams, and
AssemblySettings), so that every C++ setting is reachable from Python and scene files, documented
and checked by name:

    odyn.simulate(model, t_end=1.0, integrator=odyn.Dop853(rtol=1e-8, atol=1e-8))
    odyn.simulate(model, t_end=1.0, integrator=odyn.Bdf(rtol=1e-6, max_order=3))
    odyn.simulate(model, t_end=1.0, integrator={"name": "dop853", "rtol": 1e-8})

A scene file gives the same object as its analysis' integrator:
``"integrator": {"name": "bdf", "rtol": 1e-6, "max_order": 3}``. `simulate`'s flat keywords
(integrator="dop853", rtol=1e-8, ...) keep working; given beside a settings object, they
override its fields (a command line's --rtol over a scene's object), and one the integrator does
not take is refused. The defaults are the C++ library's (a test holds them equal); step, rtol,
atol and max_step left at None take simulate's (a step of 1e-4 s; tolerances of 1e-6).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, fields
from typing import Any, ClassVar, Dict, Mapping, Optional, Tuple, Type

from ._schema import (SceneError, _describe, check_count, check_flag, check_number,
                      check_tolerance, fail)


def _check(value: Any, where: str, kind: str) -> Any:
    """A field's value checked by its kind (see each class's KINDS)."""
    if value is None:
        return None
    if kind == "relative":  # a relative tolerance, in (0, 1]
        return check_tolerance(value, where, relative=True)
    if kind == "positive":
        return check_number(value, where, positive=True)
    if kind == "fraction":  # in [0, 1]
        x = check_number(value, where, minimum=0.0)
        if x > 1.0:
            fail(where, f"expected a number in [0, 1], got {x:g}")
        return x
    if kind == "flag":
        return check_flag(value, where)
    if kind.startswith("count"):  # count>=N or count:N..M
        if ":" in kind:
            low, high = (int(x) for x in kind.split(":")[1].split(".."))
            if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
                fail(where, f"expected a whole number from {low} to {high}, got "
                     f"{_describe(value)}")
            return value
        return check_count(value, where, int(kind.split(">=")[1]))
    raise AssertionError(kind)


@dataclass(frozen=True)
class IntegratorSettings:
    """What every integrator's settings have: the run's step and tolerances. Subclasses add
    their integrator's own settings (the fields after these), sent to C++ as DynamicsSettings'
    `SECTION`."""

    #: The integrator's name, as `odyn.integrators()` lists it.
    NAME: ClassVar[str] = ""
    #: The DynamicsSettings member that holds the integrator's own settings.
    SECTION: ClassVar[Optional[str]] = None
    #: Each field's kind, which checks it.
    KINDS: ClassVar[Dict[str, str]] = {}

    step: Optional[float] = None
    rtol: Optional[float] = None
    atol: Optional[float] = None
    max_step: Optional[float] = None

    def __post_init__(self) -> None:
        kinds = {"step": "positive", "rtol": "relative", "atol": "positive",
                 "max_step": "positive", **self.KINDS}
        for f in fields(self):
            value = _check(getattr(self, f.name), f"{type(self).__name__}.{f.name}",
                           kinds[f.name])
            object.__setattr__(self, f.name, value)

    @classmethod
    def own_fields(cls) -> Tuple[str, ...]:
        """The fields of the integrator's own section (after step, rtol, atol, max_step)."""
        common = {f.name for f in fields(IntegratorSettings)}
        return tuple(f.name for f in fields(cls) if f.name not in common)

    def section(self) -> Dict[str, Any]:
        """The integrator's own settings that were given, by their C++ names."""
        return {k: getattr(self, k) for k in self.own_fields() if getattr(self, k) is not None}

    def to_dict(self) -> Dict[str, Any]:
        """As a scene file holds it: {"name": ..., and the settings given}."""
        return {"name": self.NAME, **{k: v for k, v in dataclasses.asdict(self).items()
                                      if v is not None}}


_GA_KINDS = {"rho_inf": "fraction", "adaptive": "flag", "newton_rtol": "relative",
             "newton_atol": "positive", "constraint_tolerance": "positive",
             "max_iterations": "count>=1", "reuse_iterations": "count>=0",
             "max_growth": "positive", "consistent_outputs": "flag"}


@dataclass(frozen=True)
class GeneralizedAlpha(IntegratorSettings):
    """Index-3 generalized-alpha on the rotation group: a fixed `step`, or error control from
    `rtol` and `atol` (`adaptive`, on by itself when a tolerance is given).

    rho_inf: spectral radius at infinite frequency, in [0, 1] (1: no numerical damping).
    newton_rtol, newton_atol: the Newton iteration's tolerances on the correction.
    constraint_tolerance: the constraints' residual a Newton iteration must reach.
    max_iterations: Newton iterations per step before the step fails.
    reuse_iterations: iterations that reuse the last factorization before a new one.
    max_growth: the largest ratio of one step to the last, with error control.
    consistent_outputs: solve v' and the multipliers at each output from the index-1
    equations (reactions then converge at second order).
    """

    NAME: ClassVar[str] = "generalized-alpha"
    SECTION: ClassVar[Optional[str]] = "generalized_alpha"
    KINDS: ClassVar[Dict[str, str]] = _GA_KINDS

    rho_inf: float = 0.9
    adaptive: Optional[bool] = None
    newton_rtol: float = 1e-9
    newton_atol: float = 1e-10
    constraint_tolerance: float = 1e-11
    max_iterations: int = 8
    reuse_iterations: int = 2
    max_growth: float = 1.2
    consistent_outputs: bool = True


@dataclass(frozen=True)
class Hht(GeneralizedAlpha):
    """HHT-alpha: generalized-alpha's settings, with HHT's weights (rho_inf in [0.5, 1])."""

    NAME: ClassVar[str] = "hht"

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.rho_inf < 0.5:
            fail("Hht.rho_inf", f"expected a number in [0.5, 1] for HHT-alpha, got "
                 f"{self.rho_inf:g}")


@dataclass(frozen=True)
class Bdf(IntegratorSettings):
    """Variable-order BDF (DASSL's order and step selection) on the stabilized index-2 form,
    under error control from `rtol` and `atol`; `step` is the first step.

    max_order: the highest order, 1 to 5.
    local_error_fraction: the share of the tolerance the corrector may leave.
    newton_tolerance: the Newton iteration's tolerance, relative to the error tolerance.
    constraint_tolerance: the constraints' residual a Newton iteration must reach.
    max_iterations: Newton iterations per step before the step is retried shorter.
    reuse_iterations: iterations that reuse the last factorization before a new one.
    reuse_band: the change of step size within which the factorization is kept.
    max_growth: the largest ratio of one step to the last.
    """

    NAME: ClassVar[str] = "bdf"
    SECTION: ClassVar[Optional[str]] = "bdf"
    KINDS: ClassVar[Dict[str, str]] = {
        "max_order": "count:1..5", "local_error_fraction": "positive",
        "newton_tolerance": "positive", "constraint_tolerance": "positive",
        "max_iterations": "count>=1", "reuse_iterations": "count>=0", "reuse_band": "positive",
        "max_growth": "positive"}

    max_order: int = 5
    local_error_fraction: float = 0.03
    newton_tolerance: float = 0.01
    constraint_tolerance: float = 1e-10
    max_iterations: int = 5
    reuse_iterations: int = 3
    reuse_band: float = 1.3
    max_growth: float = 2.0


_DP_KINDS = {"projection_tolerance": "positive", "max_projection_iterations": "count>=1",
             "singular_threshold": "positive"}


@dataclass(frozen=True)
class Dopri5(IntegratorSettings):
    """Explicit Dormand-Prince 5(4) on the index-1 form, the positions and velocities projected
    onto the constraints after every step, under error control from `rtol` and `atol`.

    projection_tolerance: the constraints' residual the projection reaches.
    max_projection_iterations: the projection's Newton iterations.
    singular_threshold: the relative pivot below which the mass-constraint matrix counts as
    singular (a lock-up) rather than ill-conditioned.
    """

    NAME: ClassVar[str] = "dopri5"
    SECTION: ClassVar[Optional[str]] = "dormand_prince"
    KINDS: ClassVar[Dict[str, str]] = _DP_KINDS

    projection_tolerance: float = 1e-12
    max_projection_iterations: int = 6
    singular_threshold: float = 0.05


@dataclass(frozen=True)
class Dop853(Dopri5):
    """Explicit Dormand-Prince 8(5,3): Dopri5's settings."""

    NAME: ClassVar[str] = "dop853"


@dataclass(frozen=True)
class Adams(IntegratorSettings):
    """Explicit Adams-Bashforth at a fixed `step` (rtol, atol and max_step do not apply).

    order: 1 to 6.
    projection_tolerance, velocity_tolerance: the drift of the positions and velocities from
    the constraints beyond which they are projected back.
    max_projection_iterations: the projection's Newton iterations.
    """

    NAME: ClassVar[str] = "adams"
    SECTION: ClassVar[Optional[str]] = "adams"
    KINDS: ClassVar[Dict[str, str]] = {
        "order": "count:1..6", "projection_tolerance": "positive",
        "velocity_tolerance": "positive", "max_projection_iterations": "count>=1"}

    order: int = 5
    projection_tolerance: float = 1e-11
    velocity_tolerance: float = 1e-8
    max_projection_iterations: int = 6

    def __post_init__(self) -> None:
        for name in ("rtol", "atol", "max_step"):
            if getattr(self, name) is not None:
                fail(f"Adams.{name}", "adams steps at a fixed step and has no error control; "
                     "leave it out, or choose an integrator with error control")
        super().__post_init__()


@dataclass(frozen=True)
class Auto(IntegratorSettings):
    """The default: dop853 under error control, switching to bdf where the problem is stiff and
    to generalized-alpha (at `step`) where both fail."""

    NAME: ClassVar[str] = "auto"


@dataclass(frozen=True)
class AssemblySettings:
    """The assembly of the initial state (Newton on the constraints).

    tolerance: the constraints' residual to reach, in every equation.
    max_iterations: Newton iterations allowed.
    warn_translation, warn_rotation: how far (m, rad) assembly may move a body from the pose
    it was given before an AssemblyWarning says so.
    """

    tolerance: float = 1e-12
    max_iterations: int = 50
    warn_translation: float = 1e-5
    warn_rotation: float = 1e-5

    def __post_init__(self) -> None:
        kinds = {"tolerance": "positive", "max_iterations": "count>=1",
                 "warn_translation": "positive", "warn_rotation": "positive"}
        for f in fields(self):
            object.__setattr__(self, f.name, _check(getattr(self, f.name),
                                                    f"AssemblySettings.{f.name}", kinds[f.name]))


#: The settings class of each integrator, by name.
INTEGRATOR_SETTINGS: Dict[str, Type[IntegratorSettings]] = {
    cls.NAME: cls for cls in (GeneralizedAlpha, Hht, Bdf, Dopri5, Dop853, Adams, Auto)}


def integrator_settings(value: Any, where: str = "integrator") -> IntegratorSettings:
    """A settings object from one, or from a dict {"name": ..., settings...} (a scene's)."""
    if isinstance(value, IntegratorSettings):
        return value
    if not isinstance(value, Mapping):
        fail(where, f"expected an integrator's name, a settings object such as "
             f"odyn.Dop853(rtol=1e-8), or {{\"name\": ..., ...}}, got {_describe(value)}")
    if "name" not in value:
        fail(where, "missing 'name', the integrator's (" + ", ".join(INTEGRATOR_SETTINGS) + ")")
    name = value["name"]
    if name not in INTEGRATOR_SETTINGS:
        fail(f"{where}.name", f"unknown integrator {name!r}; known: "
             + ", ".join(INTEGRATOR_SETTINGS))
    return _built(INTEGRATOR_SETTINGS[name], {k: v for k, v in value.items() if k != "name"},
                  where, name)


def assembly_settings(value: Any, where: str = "assembly") -> AssemblySettings:
    """An AssemblySettings from one or from a dict of its fields."""
    if isinstance(value, AssemblySettings):
        return value
    if not isinstance(value, Mapping):
        fail(where, f"expected odyn.AssemblySettings(...) or a dict of its fields, got "
             f"{_describe(value)}")
    return _built(AssemblySettings, value, where, "the assembly")


def _built(cls: Type[Any], params: Mapping[str, Any], where: str, owner: str) -> Any:
    """cls(**params), its errors named by their place `where`.field (a scene's place)."""
    known = [f.name for f in fields(cls)]
    for key in params:
        if key not in known:
            fail(f"{where}.{key}", f"{owner} has no setting {key!r}; its settings: "
                 + ", ".join(known))
    try:
        return cls(**params)
    except SceneError as error:  # "Bdf.max_order: ..." -> "<where>.max_order: ..."
        place, message = str(error).split(": ", 1)
        raise SceneError(f"{where}.{place.split('.', 1)[-1]}: {message}") from None


#: simulate()'s keywords that a settings object holds instead (see with_keywords).
INTEGRATOR_KEYWORDS = ("step", "rtol", "atol", "max_step", "rho_inf", "adaptive", "newton_rtol",
                       "newton_atol", "constraint_tolerance", "max_iterations",
                       "projection_tolerance", "order")


def with_keywords(settings: IntegratorSettings, keywords: Mapping[str, Any]
                  ) -> IntegratorSettings:
    """The settings with simulate()-style keywords folded in (a command line's --rtol over a
    scene's integrator object); a keyword the integrator does not take is refused."""
    known = {f.name for f in fields(settings)}
    given = {k: v for k, v in keywords.items() if v is not None}
    for key in given:
        if key not in known:
            fail(key, f"{settings.NAME} has no setting {key!r}; its settings: "
                 + ", ".join(sorted(known)))
    return dataclasses.replace(settings, **given) if given else settings
