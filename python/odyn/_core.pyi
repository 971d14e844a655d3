"""Type stubs of odyn's compiled core (python/src). Use the odyn package; this is its engine."""

from typing import Any, Callable, Dict, List, Optional, Tuple, Union

class Error(RuntimeError): ...
class ModelError(Error): ...
class AssemblyError(Error): ...
class SolverError(Error): ...

#: Element type names in the order of the compiled spatial model's element list.
element_types: List[str]
#: Element type names in the order of the compiled planar model's element list.
planar_element_types: List[str]

class Model:
    """The C++ spatial model (odyn.Model wraps it and checks parameters first)."""

    def __init__(self) -> None: ...
    def add_body(self, parameters: Dict[str, Any]) -> None: ...
    def add_element(self, type: str, parameters: Dict[str, Any]) -> None: ...
    @property
    def space(self) -> str: ...
    @property
    def num_bodies(self) -> int: ...
    @property
    def num_equations(self) -> int: ...
    def body_index(self, name: str) -> int: ...
    def element_type(self, name: str) -> str: ...

class PlanarModel:
    """The C++ planar model (odyn.PlanarModel wraps it and checks parameters first)."""

    def __init__(self) -> None: ...
    def add_body(self, parameters: Dict[str, Any]) -> None: ...
    def add_element(self, type: str, parameters: Dict[str, Any]) -> None: ...
    @property
    def space(self) -> str: ...
    @property
    def num_bodies(self) -> int: ...
    @property
    def num_equations(self) -> int: ...
    def body_index(self, name: str) -> int: ...
    def element_type(self, name: str) -> str: ...

def integrators() -> List[Tuple[str, str]]:
    """(name, description) of every integrator that simulate knows (odyn::integrator_names())."""

def assemble(model: Union[Model, PlanarModel], settings: Dict[str, Any]) -> Dict[str, Any]:
    """Assembles; returns the recorded arrays for one output row and "assembly" (a report)."""

def kinematics(model: Union[Model, PlanarModel], settings: Dict[str, Any],
               progress: Optional[Callable[[float], None]] = None,
               progress_interval: float = 0.2) -> Dict[str, Any]:
    """A kinematic analysis: the recorded arrays, "kinematics" (its summary, None if it stopped
    early) and "error" (the exception that stopped it, or None)."""

def quasi_statics(model: Union[Model, PlanarModel], settings: Dict[str, Any],
                  progress: Optional[Callable[[float], None]] = None,
                  progress_interval: float = 0.2) -> Dict[str, Any]:
    """A quasi-static analysis: the recorded arrays, "statics" (each row's summary) and
    "error" (the exception that stopped it, or None)."""

def check(model: Union[Model, PlanarModel], settings: Dict[str, Any]) -> Dict[str, Any]:
    """Assembles and reports: the recorded arrays for one output row, "assembly" (a report),
    "given_velocities" (before assembly) and "mobility" (velocities, equations, rank,
    redundant_equations, drivers)."""

def statics(model: Union[Model, PlanarModel], settings: Dict[str, Any]) -> Dict[str, Any]:
    """The static equilibrium: the recorded arrays for one output row and "statics" (its
    summary)."""

def modes(model: Union[Model, PlanarModel], settings: Dict[str, Any]) -> Dict[str, Any]:
    """The natural modes about the static equilibrium: the equilibrium's arrays for one output
    row and "modes" (frequencies, shapes, the damped eigenvalues, the linearization)."""

def linearize(model: Union[Model, PlanarModel], settings: Dict[str, Any]) -> Dict[str, Any]:
    """A state-space model about the model's state or its equilibrium: the state's arrays for
    one output row and "linear_model" (a, b, c, d, drift, outputs, basis, coordinates,
    input_names, output_names)."""

def simulate(model: Union[Model, PlanarModel], settings: Dict[str, Any],
             progress: Optional[Callable[[float], None]] = None,
             progress_interval: float = 0.2) -> Dict[str, Any]:
    """Runs a dynamic analysis with the GIL released. Returns "t", "q", "v", "vdot",
    "lambda", "phi_norm", "phid_norm", "kinetic_energy", "potential_energy", "bodies",
    "space", "reactions" (name -> (n, 2, 2, 6), planar (n, 2, 2, 3)), "constraint_rows",
    "states", "summary" (None if the run stopped early) and "error" (the exception that
    stopped it, or None)."""
