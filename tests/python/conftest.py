"""Shared fixtures: paths of the repository, the engine scene and the C++ engine example."""

import pathlib
import shutil

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
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
