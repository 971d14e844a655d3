"""Writes what comes from the element descriptions of the compiled core and the scene loader's
tables: the ``add_*`` methods of `odyn.Model` and `odyn.PlanarModel` (python/odyn/_elements.py),
the element reference (docs/elements.md) and the scene-file reference (docs/scene-files.md).

    python -m odyn._generate [--root REPOSITORY] [--check]

Each element type describes its parameters once, next to its C++ blocks (see
include/odyn/core/description.hpp); this script turns those descriptions into Python source and
Markdown. --check writes nothing and fails if a file differs from what it would write (the test
suite runs it).
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from pathlib import Path
from typing import Any, Dict, List, Mapping, Sequence, Tuple

from . import _schema

SPACES = {"spatial": ("SpatialElements", "odyn.Model"),
          "planar": ("PlanarElements", "odyn.PlanarModel")}

#: The annotation of each kind, per space.
_ANNOTATIONS: Dict[str, Tuple[str, str]] = {
    "name": ("str", "str"),
    "body": ("str", "str"),
    "bodies": ("Sequence[str]", "Sequence[str]"),
    "joint": ("str", "str"),
    "turning_joint": ("str", "str"),
    "sliding_joint": ("str", "str"),
    "coupled_joint": ("str", "str"),
    "optional_coupled_joint": ("Optional[str]", "Optional[str]"),
    "coordinate": ("Optional[str]", "Optional[str]"),
    "vector": ("Vector", "Vector"),
    "frame": ("Frame", "Frame"),
    "number": ("float", "float"),
    "optional_number": ("Optional[float]", "Optional[float]"),
    "flag": ("bool", "bool"),
    "nonnegative": ("float", "float"),
    "positive": ("float", "float"),
    "axes": ("str", "str"),
    "motion": ("Mapping[str, Any]", "Mapping[str, Any]"),
    "vector_or_callable": ("Union[Vector, FrameFunction]", "Union[Vector, PlanarFunction]"),
    "angular_or_callable": ("Union[Vector, FrameFunction]", "Union[float, PlanarFunction]"),
    "optional_callable": ("Callable[[float, float, float], float]",
                          "Callable[[float, float, float], float]"),
    "callable": ("Callable[..., Any]", "Callable[..., Any]"),
    "optional_function": ("Callable[..., Any]", "Callable[..., Any]"),
    "wrench": ("Sequence[float]", "Sequence[float]"),
    "component_matrix": ("ComponentMatrix", "ComponentMatrix"),
    "wrench_law": ("WrenchLaw", "WrenchLaw"),
}


def _python_default(kind: str, text: str, dim: int) -> str:
    value = json.loads(text)
    if value is None:
        return "None"
    if kind == "vector" and value == 0:
        return "(" + ", ".join(["0"] * dim) + ")"
    if kind == "wrench" and value == 0:
        return "(" + ", ".join(["0"] * (6 if dim == 3 else 3)) + ")"
    if kind == "component_matrix" and value == 0:
        return "0"  # the zero matrix
    if kind in ("number", "nonnegative", "positive"):
        return repr(float(value))
    if isinstance(value, list):  # a tuple: a default must not be a mutable list
        return repr(tuple(value))
    return repr(value)


def _signature(parameters: List[Mapping[str, Any]], space: str) -> str:
    """Positional parameters until the first with a default; keyword-only from there on (so
    that required ones may follow optional ones, as in a description's order)."""
    dim = 3 if space == "spatial" else 2
    index = 0 if space == "spatial" else 1
    out = ["self"]
    keyword_only = False
    for p in parameters:
        annotation = _ANNOTATIONS[p["kind"]][index]
        if p["default"] is None:
            out.append(f"{p['name']}: {annotation}")
            continue
        if not keyword_only:
            out.append("*")
            keyword_only = True
        default = _python_default(p["kind"], p["default"], dim)
        if default == "None" and not annotation.startswith("Optional["):
            annotation = f"Optional[{annotation}]"
        out.append(f"{p['name']}: {annotation} = {default}")
    return ", ".join(out)


def _wrap(text: str, indent: str, width: int = 99) -> List[str]:
    lines: List[str] = []
    line = indent
    for word in text.split():
        if len(line) + 1 + len(word) > width and line.strip():
            lines.append(line)
            line = indent
        line = f"{line} {word}" if line.strip() else indent + word
    if line.strip():
        lines.append(line)
    return lines


def _literal_bars(text: str) -> str:
    """`|v_t|` (a magnitude) as a literal in a docstring: reST reads bars as a substitution."""
    return re.sub(r"\|([^|\s][^|]*?)\|", r"``|\1|``", text)


def _method(element: Mapping[str, Any], space: str) -> List[str]:
    name = "add_" + element["type"]
    head = f"    def {name}({_signature(element['parameters'], space)}) -> str:"
    lines = []
    if len(head) <= 99:
        lines.append(head)
    else:
        args = _signature(element["parameters"], space).split(", ")
        lines.append(f"    def {name}(")
        line = "            "
        for i, arg in enumerate(args):
            piece = arg + ("," if i + 1 < len(args) else ") -> str:")
            if len(line) + 1 + len(piece) > 99 and line.strip():
                lines.append(line)
                line = "            "
            line = f"{line} {piece}" if line.strip() else line + piece
        lines.append(line)
    lines.append('        """' + _literal_bars(element["summary"].replace('"', "'")))
    lines[-1:] = _wrap(lines[-1].strip(), "        ")
    lines.append("")
    for p in element["parameters"]:
        unit = f" ({p['unit']})" if p["unit"] else ""
        lines += _wrap(f"{p['name']}{unit}: {_literal_bars(p['doc'])}.", "        ")
    if element["outputs"]:
        listed = ", ".join(f"{o['name']} ({o['unit']})" if o["unit"] else o["name"]
                           for o in element["outputs"])
        lines.append("")
        lines += _wrap(f"Outputs (Result.output(name)): {listed}.", "        ")
    lines.append('        """')
    call = ", ".join(f"{p['name']}={p['name']}" for p in element["parameters"])
    statement = f'        return self._add_given("{element["type"]}", {call})'
    if len(statement) <= 99:
        lines.append(statement)
    else:
        lines.append("        return self._add_given(")
        lines += _wrap(f'"{element["type"]}", {call})', "            ")
    return lines


def elements_source() -> str:
    """The source of python/odyn/_elements.py."""
    out = [
        "# Generated by `python -m odyn._generate` from the element descriptions of the compiled",
        "# core (each element's C++ header); do not edit. tests/python/test_catalogue.py checks",
        "# that it is current.",
        '"""The ``add_*`` methods of `odyn.Model` and `odyn.PlanarModel`: one per element type."""',
        "",
        "from __future__ import annotations",
        "",
        "from typing import TYPE_CHECKING, Any, Callable, Mapping, Optional, Sequence, Union",
        "",
        "if TYPE_CHECKING:",
        "    from .model import (ComponentMatrix, Frame, FrameFunction, PlanarFunction, Vector,",
        "                        WrenchLaw)",
        "",
        "",
        "class _Adds:",
        "    def _add_given(self, type: str, **params: Any) -> str:",
        "        raise NotImplementedError",
    ]
    for space, (cls, model) in SPACES.items():
        out += ["", "", f"class {cls}(_Adds):",
                f'    """The element types of {model}, each added by its own method."""']
        for element in _schema.DESCRIPTIONS[space].values():
            out.append("")
            out += _method(element, space)
    return "\n".join(out) + "\n"


def _cell(text: str) -> str:
    return text.replace("|", "\\|")


def elements_markdown() -> str:
    """The source of docs/elements.md."""
    out = [
        "# Elements",
        "",
        "<!-- Generated by `python -m odyn._generate` from the element descriptions of the "
        "compiled core; do not edit. -->",
        "",
        "Every element type describes its parameters once, next to its C++ blocks "
        "(`include/odyn/core/description.hpp`); this page, the Python `add_*` methods and the "
        "scene-file checks all come from those descriptions. In Python, "
        "`model.add_<type>(name, ...)` or `model.add(\"<type>\", ...)`; in a scene file, an entry "
        "of `joints`, `drivers` or `forces` with `\"type\": \"<type>\"` and the same parameters. "
        "A parameter without a default is required; an unknown one is refused with the list of "
        "valid ones.",
        "",
        "## Adding an element",
        "",
        "1. Write its header: the blocks (see writing-elements.md), then",
        "   `static constexpr ElementDescription description{type, category, summary, "
        "parameters, outputs}` and `template <class Reader> static E from_parameters(Reader& "
        "r)`, which builds it with `parameter<T>(r, \"key\")` for each described key (the lists "
        "in `include/odyn/core/parameter_blocks.hpp` cover two bodies with frames or points, "
        "drivers and spring laws; `include/odyn/spatial/joint_primitives.hpp` is a short "
        "example). An element with outputs lists them (`outputs`, optional) and computes them "
        "in `outputs(in)` (`include/odyn/core/outputs.hpp`; `include/odyn/forces/tsda.hpp` is "
        "an example); a stateful one lists the fields of its state that results record "
        "(`state_fields`, with `state_values(state)`; `include/odyn/core/state_fields.hpp`). "
        "An element that acts on an existing joint's coordinate takes a `joint` parameter and "
        "lists the joint types it may name (`joints`); the front ends hand it that joint's "
        "bodies and frames (`include/odyn/spatial/limits.hpp`).",
        "2. Register it: add the type to `odyn::spatial::DefaultModel` or "
        "`odyn::planar::DefaultModel` and to the matching model type of the Python modules "
        "(`include/odyn/python/models.hpp`; a static_assert there fails until it holds every "
        "type of both catalogues). Nothing else names it.",
        "3. Run `python -m odyn._generate` from the repository (after `bash scripts/setup.sh`): "
        "it writes the Python method and this page. Then a test against an independent "
        "reference (`tests/test_descriptions.cpp` already checks that the description and "
        "`from_parameters` agree).",
        "",
        "## A module of your own",
        "",
        "An element type that is not odyn's (a law of one machine, say) needs no change to "
        "odyn: write its header as above, then a pybind11 module that compiles models with it. "
        "`examples/python/odyn_engine/` is one, the engine's gas force, built outside odyn "
        "against the installed package. Its `engine_models.hpp` names the model types, "
        "each with just the element types an engine needs (the elements written in Python "
        "come with every model):",
        "",
        "```cpp",
        "using Spatial =",
        "    odyn::python::SpatialModelOf<sp::Revolute, sp::Spherical, sp::Universal, "
        "sp::Translational,",
        "                                 sp::Gravity, sp::Rsda, sp::PointForce, sp::PointTorque, "
        "sp::Tsda,",
        "                                 engine::GasForce>;",
        "```",
        "",
        "(`SpatialModelWith<engine::GasForce>` would hold odyn's whole catalogue and the gas "
        "force; the planar twins are `PlanarModelOf` and `PlanarModelWith`), and its "
        "`odyn_engine.cpp` binds them:",
        "",
        "```cpp",
        "#include <odyn/python/module.hpp>",
        "",
        "#include \"engine_models.hpp\"",
        "",
        "PYBIND11_MODULE(odyn_engine, m) {",
        "  namespace python = odyn::python;",
        "  // ...",
        "  python::use_odyn_errors();",
        "  python::bind_model_types<engine_module::Spatial, engine_module::Planar>(m);",
        "  using SpatialBox = python::ModelBox<engine_module::Spatial>;",
        "  python::analysis::bind_dynamics<SpatialBox>(m);",
        "  python::analysis::bind_kinematics<SpatialBox>(m);",
        "  engine_module::bind_planar_analyses(m);  // planar_analyses.cpp",
        "}",
        "```",
        "",
        "The analyses' instantiations dominate a module's build (minutes of CPU each with "
        "GCC 12; docs/benchmarks.md, \"Compile time\"), so a module binds for each model type "
        "only the analyses it is run with (`include/odyn/python/analyses.hpp`): "
        "`bind_dynamics` (assembly and the dynamic analysis, every integrator in both "
        "coordinates), `bind_kinematics` (the kinematic analysis and the model report) and "
        "`bind_statics` (static equilibrium, quasi-statics, modes and linearization, which cost "
        "GCC about as much as the dynamics); `odyn::python::bind_models<Spatial, Planar>(m)` "
        "binds everything in one unit. odyn_engine binds the first two, in two units that two "
        "cores compile side by side; odyn refuses the others on its models by name.",
        "",
        "The odyn package carries its C++ headers and CMake package, so the module builds "
        "against it as `examples/python/odyn_engine/` does: a `CMakeLists.txt` with "
        "`find_package(odyn CONFIG REQUIRED)`, `find_package(pybind11 CONFIG REQUIRED)` and "
        "`pybind11_add_module(my_models MODULE my_models.cpp)` linked to `odyn::odyn`, and a "
        "`pyproject.toml` for scikit-build-core; `pip install --no-build-isolation .` in the "
        "environment where odyn is installed finds both packages there. Plain CMake finds odyn "
        "with `-Dodyn_DIR=$(python -c 'import odyn; print(odyn.cmake_dir())')`.",
        "",
        "The element's description does the rest. In Python, "
        "`odyn.Model(module=my_models)` (or `odyn.PlanarModel`) builds its "
        "models: `model.add(\"my_force\", ...)` checks the parameters against the description, "
        "and an element type the module does not compile is refused by name. A scene file names "
        "the module under `\"module\"` (`examples/engine.json`).",
        "",
        "## Parameter kinds",
        "",
        "| kind | value |",
        "|---|---|",
    ]
    out += [f"| `{kind}` | {_cell(doc)} |" for kind, doc in _schema.KIND_DOCS.items()]
    for space in SPACES:
        out += ["", f"## {space.capitalize()} elements", "",
                "| type | category | what it does |", "|---|---|---|"]
        for t, element in _schema.DESCRIPTIONS[space].items():
            out.append(f"| [`{t}`](#{space}-{t}) | {element['category']} | "
                       f"{_cell(element['summary'])} |")
        for t, element in _schema.DESCRIPTIONS[space].items():
            out += ["", f"### {space}: {t}", "", element["summary"], "",
                    "| parameter | kind | default | unit | meaning |", "|---|---|---|---|---|"]
            for p in element["parameters"]:
                default = "required" if p["default"] is None else f"`{p['default']}`"
                out.append(f"| `{p['name']}` | {p['kind']} | {default} | {p['unit']} | "
                           f"{_cell(p['doc'])} |")
            if element["joints"]:
                out += ["", "`joint` names a " + " or ".join(
                    f"`{j}`" for j in element["joints"]) + " joint."]
            if element["outputs"]:
                out += ["", "Outputs, recorded at every output time (`result.output(name)`, "
                        "or a scene output column `{\"element\": name, \"output\": ...}`):", "",
                        "| output | unit | meaning |", "|---|---|---|"]
                out += [f"| `{o['name']}` | {o['unit']} | {_cell(o['doc'])} |"
                        for o in element["outputs"]]
            if element["state_fields"]:
                out += ["", "State, recorded at every output time (`result.state(name)`):", "",
                        "| field | unit | meaning |", "|---|---|---|"]
                out += [f"| `{o['name']}` | {o['unit']} | {_cell(o['doc'])} |"
                        for o in element["state_fields"]]
    return "\n".join(out) + "\n"


def _keys_table(place: str, required: Sequence[str] = ()) -> List[str]:
    from . import scene
    rows = ["| key | meaning |", "|---|---|"]
    for key, doc in scene.KEYS[place].items():
        mark = " (required)" if key in required else ""
        rows.append(f"| `{key}` | {_cell(doc)}{mark} |")
    return rows


def _compact_json(value: Any) -> str:
    """JSON indented by objects, with each list of numbers or strings on one line."""
    text = json.dumps(value, indent=2)
    return re.sub(r"\[\s+([^\[\]{}]*?)\s+\]",
                  lambda m: "[" + ", ".join(x.strip() for x in m.group(1).split(",")) + "]", text)


def scene_markdown() -> str:
    """The source of docs/scene-files.md: the scene format, from the loader's own tables."""
    from . import scene
    out = [
        "# Scene files",
        "",
        "<!-- Generated by `python -m odyn._generate` from the scene loader's tables "
        "(python/odyn/scene.py, python/odyn/_schema.py); do not edit. -->",
        "",
        "A scene file is a whole model in JSON: its bodies, joints, drivers and forces, the "
        "analysis to run with its settings, the columns to write and the figures to draw. "
        "`odyn run SCENE` runs it ([command-line.md](command-line.md)), `odyn.load(path)` reads "
        "it into Python and `odyn.save(model_or_scene, path)` writes one. Loading checks every "
        "field and names the place of an error (`joints[2].on_a.axis: zero-length vector; "
        "expected a non-zero direction`); a key this page does not list is an error, and so is a "
        "key given twice.",
        "",
        "A pendulum swinging for two seconds, with its hinge's reaction written and drawn:",
        "",
        "```json",
        _compact_json(EXAMPLE_SCENE),
        "```",
        "",
        "## Top level",
        "",
        *_keys_table("scene", scene.REQUIRED_KEYS["scene"]),
        "",
        "## Bodies",
        "",
        "Each entry of `bodies`. The defaults are zero (an identity orientation); `name`, and "
        "`mass` and `inertia` or `parts`, are required.",
        "",
        *_keys_table("bodies"),
        "",
    ]
    out += ["## Joints, drivers and forces", "",
            "Each entry has a `type` and a `name`, and the parameters of its type, named as in "
            "C++ and in Python's `add_<type>` methods: [elements.md](elements.md) lists each "
            "type's parameters, defaults and outputs. The types each section takes:", ""]
    for space in SPACES:
        out += [f"**{space.capitalize()}**", "", "| section | types |", "|---|---|"]
        # odyn's own types: a module of one's own, if one is loaded, adds its types elsewhere.
        own = list(_schema.DESCRIPTIONS[space])
        for section, types in scene.space_sections(space, own).items():
            links = ", ".join(f"[`{t}`](elements.md#{space}-{t.replace('_', '-')})"
                              for t in types)
            out.append(f"| `{section}` | {links} |")
        out.append("")
    out += ["Functions written in Python (`user_force`, `user_constraint`) cannot be held in a "
            "file; a model that has them is built in Python.", "",
            "## Analysis", "",
            "`analysis.type` names the analysis; each takes the settings marked for it "
            "(another is refused, with the list of those it takes). `t_end` and "
            "`output_interval` apply to the timed ones: " + ", ".join(scene.TIMED) + ".", "",
            "| key | meaning | " + " | ".join(scene.ANALYSES) + " |",
            "|---|---|" + "---|" * len(scene.ANALYSES)]
    for key, doc in scene.KEYS["analysis"].items():
        takes = [key == "type" or key in scene.ANALYSIS_DEFAULTS and kind in scene.TIMED
                 or key in scene.ANALYSES[kind] for kind in scene.ANALYSES]
        out.append(f"| `{key}` | {_cell(doc)} | " + " | ".join("✓" if t else "" for t in takes)
                   + " |")
    out += ["", "## Output columns", "",
            "Each entry of `outputs` is one column of the table `odyn run --out` writes (CSV or "
            "NumPy's .npz), told apart by the key it has of `body`, `reaction`, `point`, "
            "`element` and `state`; an entry with none of them is a global quantity.", ""]
    for form in ("body", "reaction", "point", "element", "state", "global"):
        place = f"outputs.{form}"
        out += [f"### {form.capitalize()} columns", "",
                *_keys_table(place, scene.REQUIRED_KEYS[place]), ""]
    out += ["## Figures", "",
            "Each entry of `figures` is a figure of one or more output columns against time.",
            "", *_keys_table("figures", scene.REQUIRED_KEYS["figures"])]
    return "\n".join(out) + "\n"


#: The example at the top of docs/scene-files.md (a test loads and runs it).
EXAMPLE_SCENE: Dict[str, Any] = {
    "odyn": 1,
    "description": "a pendulum of 1 m",
    "bodies": [{"name": "bob", "mass": 1.0, "inertia": [1e-3, 1e-3, 1e-3],
                "position": [1.0, 0.0, 0.0]}],
    "joints": [{"type": "revolute", "name": "hinge", "body_a": "ground",
                "on_a": {"point": [0, 0, 0], "axis": [0, 0, 1]}, "body_b": "bob",
                "on_b": {"point": [-1, 0, 0], "axis": [0, 0, 1]}}],
    "forces": [{"type": "gravity", "name": "gravity", "acceleration": [0, -9.81, 0]}],
    "analysis": {"t_end": 2.0, "output_interval": 0.01, "integrator": "dop853", "rtol": 1e-8,
                 "atol": 1e-8},
    "outputs": [{"name": "x", "body": "bob", "quantity": "position", "component": "x"},
                {"name": "hinge_fy", "reaction": "hinge", "quantity": "force",
                 "component": "y"}],
    "figures": [{"file": "hinge.png", "y": "hinge_fy", "title": "The hinge's vertical force",
                 "ylabel": "N"}],
}


def outputs(root: Path) -> Dict[Path, str]:
    return {root / "python" / "odyn" / "_elements.py": elements_source(),
            root / "docs" / "elements.md": elements_markdown(),
            root / "docs" / "scene-files.md": scene_markdown()}


def main(argv: List[str]) -> int:
    parser = argparse.ArgumentParser(prog="python -m odyn._generate", description=__doc__)
    parser.add_argument("--root", default=".", help="the repository (default: .)")
    parser.add_argument("--check", action="store_true", help="fail if a file is not current")
    args = parser.parse_args(argv)
    stale = []
    for path, text in outputs(Path(args.root)).items():
        current = path.read_text() if path.exists() else None
        if current == text:
            continue
        if args.check:
            stale.append(str(path))
        else:
            path.write_text(text)
            print(f"wrote {path}")
    if stale:
        print("not current (run python -m odyn._generate): " + ", ".join(stale), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
