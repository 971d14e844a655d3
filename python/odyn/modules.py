"""Modules of one's own: element types compiled outside odyn.

odyn's element types are compiled into its models (a model type lists them, so that evaluating
one costs no virtual call). An element type of one's own (a C++ class that describes itself, see
docs/elements.md) reaches Python through a module of one's own that compiles models with it:
a pybind11 module that calls ``odyn::python::bind_models`` (include/odyn/python/module.hpp).
``odyn.Model(module=that_module)`` then builds its models, and scene files name it under
"module". The engine's gas force is such a type: ``examples/python/odyn_engine/``, a project
built against the installed odyn (find_package(odyn); see cmake_dir).
"""

import importlib
import os
from types import ModuleType
from typing import Any, Dict

from . import _core, _schema
from ._schema import fail

#: What a module of models must have (bind_models gives all of it).
REQUIRED = ("Model", "PlanarModel", "element_types", "planar_element_types",
            "element_catalogue", "planar_element_catalogue", "joint_kinds",
            "planar_joint_kinds", "assemble", "simulate")

#: The analyses a module may leave out, each with the C++ function that binds it
#: (include/odyn/python/analyses.hpp) and what it is.
OPTIONAL_ANALYSES = {
    "kinematics": ("bind_kinematics", "the kinematic analysis (odyn.kinematics)"),
    "check": ("bind_kinematics", "the model report (odyn.check)"),
    "statics": ("bind_statics", "the static analysis (odyn.statics)"),
    "quasi_statics": ("bind_statics", "the quasi-static analysis (odyn.quasi_statics)"),
    "modes": ("bind_statics", "the modal analysis (odyn.modes)"),
    "linearize": ("bind_statics", "the linearization (odyn.linearize)"),
}


def analysis(module: ModuleType, name: str) -> Any:
    """The function of `module` that runs the analysis `name` (a key of OPTIONAL_ANALYSES);
    a clear error if the module does not compile it."""
    function = getattr(module, name, None)
    if function is None:
        binder, what = OPTIONAL_ANALYSES[name]
        fail(f"module {module.__name__}",
             f"it does not compile {what}: its C++ source binds only some analyses; add "
             f"odyn::python::analysis::{binder} (or bind, every analysis) for its model types "
             "and rebuild it (docs/elements.md, 'A module of your own')")
    return function

_registered: Dict[str, ModuleType] = {"odyn._core": _core}


def register(module: Any) -> ModuleType:
    """Checks that `module` (a module, or the name of one to import) compiles odyn models and
    adds the descriptions of its element types to odyn's (once); returns it."""
    if isinstance(module, str):
        return load(module)
    if not isinstance(module, ModuleType):
        fail("module", f"expected a Python module of odyn models, got {type(module).__name__}")
    name = module.__name__
    if _registered.get(name) is module:
        return module
    missing = [attribute for attribute in REQUIRED if not hasattr(module, attribute)]
    if missing:
        fail(f"module {name}", "not a module of odyn models: it lacks " + ", ".join(missing) +
             " (a pybind11 module that calls odyn::python::bind_models has them)")
    _schema.add_descriptions("spatial", module.element_catalogue, module.joint_kinds, name)
    _schema.add_descriptions("planar", module.planar_element_catalogue,
                             module.planar_joint_kinds, name)
    _registered[name] = module
    return module


def load(name: str, where: str = "module") -> ModuleType:
    """Imports the module of odyn models called `name` and registers it."""
    try:
        module = importlib.import_module(name)
    except ImportError as e:
        fail(where, f"cannot import the module of odyn models '{name}' ({e}); build and install "
             "it first (docs/elements.md, 'A module of your own')")
    return register(module)


def is_core(module: ModuleType) -> bool:
    """True for odyn's own compiled models."""
    return module is _core


def cmake_dir() -> str:
    """The directory of the installed odyn's CMake package (odynConfig.cmake, with the C++
    headers it points to): a module of one's own finds it with find_package(odyn). A
    scikit-build-core build in the same environment finds it by itself; plain CMake is given
    -DCMAKE_PREFIX_PATH=<this directory> (or -Dodyn_DIR=<this directory>)."""
    return os.path.join(os.path.dirname(os.path.abspath(__file__)), "share", "cmake", "odyn")
