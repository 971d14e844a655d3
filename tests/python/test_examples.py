"""The Python twins of the C++ examples run as scripts and print or write what the C++ does."""

import subprocess
import sys

import pytest

from conftest import ROOT, read_csv
from test_engine import assert_engine_equal

TWINS = ROOT / "examples" / "python"


def test_engine_twin_writes_the_cpp_examples_csv(cpp_engine, tmp_path):
    out = tmp_path / "engine.csv"
    run = subprocess.run([sys.executable, str(TWINS / "engine.py"), "--out", str(out)],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert "steps 10050" in run.stdout
    header, data = read_csv(out)
    assert_engine_equal(header, data, cpp_engine)


def test_pendulum_twin_prints_what_the_cpp_program_prints():
    """README's first program (tests/downstream/main.cpp, with its drag written in C++)."""
    binary = ROOT / "build" / "downstream" / "odyn_downstream"
    if not binary.is_file():
        pytest.skip("tests/downstream is not built (bash scripts/test.sh builds it)")
    cpp = subprocess.run([str(binary)], capture_output=True, text=True, check=True).stdout
    py = subprocess.run([sys.executable, str(TWINS / "pendulum.py")], capture_output=True,
                        text=True, check=True).stdout
    assert py == cpp and py.count("\n") == 5
