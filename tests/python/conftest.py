"""Shared fixtures: paths of the repository, the engine scene and the C++ engine example."""

import csv
import importlib.util
import pathlib
import shutil
import signal
import subprocess

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]

# A shell without job control starts its background commands (`cmd &`, nohup, a CI runner, the
# test command's own side builds) with SIGINT ignored, which Python and the CLI processes the
# tests start would inherit: the tests of Ctrl-C need its default handler.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)


def python_example(name):
    """examples/python/<name>.py imported as a module (its model builders and helpers)."""
    path = ROOT / "examples" / "python" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


ENGINE_SCENE = ROOT / "examples" / "engine.json"


def find_engine_binary():
    """The C++ engine example built by scripts/test.sh (build/examples/engine), if any."""
    for candidate in (ROOT / "build" / "examples" / "engine",):
        if candidate.is_file():
            return candidate
    found = shutil.which("engine")
    return pathlib.Path(found) if found else None


@pytest.fixture(scope="session")
def engine_binary():
    binary = find_engine_binary()
    if binary is None:
        pytest.skip("the C++ engine example is not built (bash scripts/test.sh builds it)")
    return binary


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], np.array(rows[1:], dtype=float)


@pytest.fixture(scope="session")
def cpp_engine(engine_binary, tmp_path_factory):
    """The C++ example's standard run: 0..1 s, h = 1e-4, output every 1e-3 s."""
    out = tmp_path_factory.mktemp("cpp") / "engine.csv"
    subprocess.run([str(engine_binary), "--out", str(out)], check=True, capture_output=True)
    return read_csv(out)
