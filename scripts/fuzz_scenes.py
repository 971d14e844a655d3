"""A mutation fuzzer of odyn's scene loader and model builder.

Each input is one of the example scenes (examples/*.json) with one to three random mutations.
Half of them change a number (negated, zeroed, scaled by 1e-9 or 1e9, nudged, drawn at random,
or made NaN, infinite or huge). The rest replace any value by one of another kind (NaN,
infinities, huge integers, empty and odd strings, lists and objects, another node's value),
delete or duplicate a key or list item, or add an unknown key. The mutant is loaded
(odyn.loads) and, if it loads, assembled (odyn.assemble, which runs the core's checks and
Newton's method on the joints).

A mutant passes when it loads and assembles, or fails with an odyn error (odyn.Error, which
SceneError, ModelError, AssemblyError and SolverError derive from). Anything else (another
exception type, a crash of the process) is a finding: the mutant is written to
`--findings DIR` as JSON, to be kept as a regression case. Before each attempt the mutant is
also written to DIR/last.json, so that a crash of the process leaves it behind.

    .venv/bin/python scripts/fuzz_scenes.py --count 100000 --seed 1   # the long run
    .venv/bin/python scripts/fuzz_scenes.py --count 300                # a short one

tests/python/test_fuzz.py runs a short one, and replays the inputs kept as regression cases
(tests/python/fuzz_regressions/).
"""

from __future__ import annotations

import argparse
import copy
import json
import math
import pathlib
import random
import sys
import time
import warnings
from typing import Any, Dict, List, Tuple

ROOT = pathlib.Path(__file__).resolve().parents[1]
SCENES = sorted((ROOT / "examples").glob("*.json"))

# Values of every kind that a scene's fields may be given by mistake.
ODD_VALUES: List[Any] = [
    None, True, False, 0, -1, 1, 0.0, -0.0, 1e-300, -1e-300, 1e308, -1e308, math.nan, math.inf,
    -math.inf, 10 ** 400, 2 ** 63, "", " ", "x", "\ud800", "ground", "nan", "1", [], [1],
    [0, 0, 0], [math.nan, 0, 0], [1, 2, 3, 4, 5, 6, 7], {}, {"x": 1}, [[1, 0], [0, 1]],
]


def paths(node: Any, prefix: Tuple = ()) -> List[Tuple]:
    """Every place in a JSON tree, as a tuple of keys and indices."""
    out = [prefix]
    if isinstance(node, dict):
        for key, value in node.items():
            out += paths(value, prefix + (key,))
    elif isinstance(node, list):
        for i, value in enumerate(node):
            out += paths(value, prefix + (i,))
    return out


def at(node: Any, path: Tuple) -> Any:
    for key in path:
        node = node[key]
    return node


def mutate(scene: Dict[str, Any], rng: random.Random) -> Dict[str, Any]:
    """One mutation of a copy of `scene`."""
    scene = copy.deepcopy(scene)
    places = paths(scene)[1:]  # not the root
    numbers = [p for p in places if isinstance(at(scene, p), (int, float))
               and not isinstance(at(scene, p), bool)]
    # Half the mutations change a number (which the checks let through more often, so that
    # the core's own checks and the assembly see odd models), half anything.
    numeric = numbers and rng.random() < 0.5
    path = rng.choice(numbers if numeric else places)
    parent, key = at(scene, path[:-1]), path[-1]
    if numeric:
        try:
            value = float(parent[key])
        except OverflowError:  # a huge integer from an earlier mutation
            value = 1.0
        parent[key] = rng.choice([-value, 0, value * 1e-9, value * 1e9, value + 1e-3,
                                  rng.uniform(-10, 10), rng.choice(ODD_VALUES[3:15])])
        return scene
    kind = rng.random()
    if kind < 0.55:
        parent[key] = copy.deepcopy(rng.choice(ODD_VALUES))
    elif kind < 0.70:
        parent[key] = copy.deepcopy(at(scene, rng.choice(places)))  # another node's value
    elif kind < 0.80:
        del parent[key]
    elif kind < 0.88 and isinstance(parent, list):
        parent.insert(key, copy.deepcopy(parent[key]))  # a duplicate (names repeat)
    elif isinstance(parent, dict):
        parent[rng.choice(["typo", key + "s" if isinstance(key, str) else "x", "Mass"])] = 1.0
    return scene


def attempt(text: str) -> str:
    """'' if the mutant passes; else the finding's description."""
    import odyn
    try:
        scene = odyn.loads(text, "mutant.json")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            odyn.assemble(scene.model, max_iterations=20)
    except odyn.Error:
        return ""
    except RecursionError:
        return "RecursionError"
    except Exception as e:  # noqa: BLE001 - any other type is what the fuzzer looks for
        return f"{type(e).__name__}: {e}"[:400]
    return ""


def run(count: int, seed: int, findings: pathlib.Path, quiet: bool = False) -> List[str]:
    rng = random.Random(seed)
    originals = [json.loads(path.read_text()) for path in SCENES]
    findings.mkdir(parents=True, exist_ok=True)
    last = findings / "last.json"
    found: List[str] = []
    started = time.monotonic()
    for n in range(count):
        mutant = rng.choice(originals)
        for _ in range(rng.randint(1, 3)):
            mutant = mutate(mutant, rng)
        text = json.dumps(mutant)  # NaN and Infinity written as JSON extensions, as odyn reads
        last.write_text(text)
        problem = attempt(text)
        if problem:
            path = findings / f"finding_{seed}_{n}.json"
            path.write_text(text)
            found.append(f"{path.name}: {problem}")
            if not quiet:
                print(f"finding {path}: {problem}", flush=True)
        if not quiet and (n + 1) % 1000 == 0:
            rate = (n + 1) / (time.monotonic() - started)
            print(f"{n + 1} inputs, {len(found)} findings, {rate:.0f} inputs/s", flush=True)
    last.unlink()
    return found


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--count", type=int, default=1000, help="inputs to try")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--findings", default="build/fuzz_findings",
                        help="folder for the mutants that fail (and last.json)")
    args = parser.parse_args()
    started = time.monotonic()
    found = run(args.count, args.seed, pathlib.Path(args.findings))
    print(f"{args.count} inputs in {time.monotonic() - started:.0f} s: {len(found)} findings")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
