"""A short run of the scene fuzzer (scripts/fuzz_scenes.py; its long run is 1e5 inputs): random
mutations of the example scenes either load and assemble or fail with an odyn error, never
another exception or a crash. The inputs that once crashed, raised another exception or were
accepted silently are kept in tests/python/fuzz_regressions/ and replayed here: each must be
refused."""

import importlib.util
import pathlib

import pytest

import odyn
from conftest import ROOT

spec = importlib.util.spec_from_file_location("fuzz_scenes", ROOT / "scripts" / "fuzz_scenes.py")
fuzz_scenes = importlib.util.module_from_spec(spec)
spec.loader.exec_module(fuzz_scenes)

REGRESSIONS = sorted((pathlib.Path(__file__).parent / "fuzz_regressions").glob("*.json"))


def test_a_short_fuzzing_run_finds_nothing(tmp_path):
    found = fuzz_scenes.run(400, seed=20261202, findings=tmp_path, quiet=True)
    assert found == []
    assert not (tmp_path / "last.json").exists()


def test_the_fuzzer_reports_an_exception_that_is_not_odyns(tmp_path, monkeypatch):
    # The check above could not fail if the fuzzer swallowed every exception.
    def broken(text, source="<string>"):
        raise KeyError("a bug")
    monkeypatch.setattr(odyn, "loads", broken)
    found = fuzz_scenes.run(3, seed=1, findings=tmp_path, quiet=True)
    assert len(found) == 3 and "KeyError" in found[0]
    assert len(list(tmp_path.glob("finding_*.json"))) == 3


@pytest.mark.parametrize("path", REGRESSIONS, ids=[p.name for p in REGRESSIONS])
def test_kept_cases_are_refused_with_an_odyn_error(path):
    # Each was a crash, a traceback or a silent acceptance once (issue 28's list): an empty
    # body list, a lone surrogate in a name, a huge integer, "analysis": [1], a key twice.
    assert fuzz_scenes.attempt(path.read_text()) == ""
    with pytest.raises(odyn.Error):
        odyn.assemble(odyn.loads(path.read_text(), path.name).model)
