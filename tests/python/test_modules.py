"""Modules of one's own (odyn.modules): the engine's gas force is compiled in the module
odyn_engine (examples/python/odyn_engine/odyn_engine.cpp), not in odyn. test_engine.py and
test_examples.py check the engine's runs through it against the C++ example; here, how the
models of such a module are built, saved and refused."""

import json
import os
import shutil
import subprocess
import sys

import pytest

import odyn
import odyn_engine
from conftest import ENGINE_SCENE

LOADS = {"gravity", "rsda", "point_force", "point_torque", "tsda", "engine_gas_force",
         "user_force", "user_constraint"}
ENGINE_TYPES = {"revolute", "spherical", "universal", "translational"} | LOADS
PLANAR_ENGINE_TYPES = {"revolute", "translational"} | LOADS


def crank_and_piston(m):
    m.add_body(name="crank", mass=1.4, inertia=[1.5, 1.3, 0.8])
    m.add_body(name="piston", mass=0.6, inertia=[0.5, 0.5, 0.6], position=[0, 0, 0.18])


def test_the_module_compiles_just_the_engines_types():
    assert set(odyn.Model(module=odyn_engine).element_types) == ENGINE_TYPES
    assert set(odyn.PlanarModel(module="odyn_engine").element_types) == PLANAR_ENGINE_TYPES
    assert "engine_gas_force" not in odyn.element_types
    assert "engine_gas_force" not in odyn.planar_element_types
    assert odyn.Model(module=odyn_engine).module is odyn_engine
    assert odyn.Model().module is odyn._core


def test_odyns_own_model_sends_the_gas_force_to_its_module():
    odyn.Model(module=odyn_engine)  # registered: odyn knows who compiles the type
    m = odyn.Model()
    crank_and_piston(m)
    with pytest.raises(odyn.SceneError,
                       match=r"unknown spatial element type 'engine_gas_force' "
                       r"\('engine_gas_force' is compiled by the module odyn_engine: build the model as "
                       r"odyn.Model\(module=odyn_engine\)\)"):
        m.add("engine_gas_force", name="gas", crank="crank", piston="piston")


def test_an_analysis_the_module_does_not_compile_is_refused_by_name():
    """odyn_engine binds the dynamic and kinematic analyses and the model report, not the
    static ones; asking for one names the module, the analysis and the C++ call that adds it."""
    spatial, planar = odyn.Model(module=odyn_engine), odyn.PlanarModel(module=odyn_engine)
    crank_and_piston(spatial)
    planar.add_body(name="crank", mass=1.4, inertia=1.5)
    for model in (spatial, planar):
        for run, what, binder in (
                (odyn.statics, r"the static analysis \(odyn\.statics\)", "bind_statics"),
                (odyn.modes, r"the modal analysis \(odyn\.modes\)", "bind_statics")):
            with pytest.raises(odyn.SceneError,
                               match=r"module odyn_engine: it does not compile " + what +
                               r": .*odyn::python::analysis::" + binder):
                run(model)
        # What it compiles runs: free bodies, 6 (space) or 3 (plane) degrees of freedom each.
        assert odyn.check(model).degrees_of_freedom == (12 if model is spatial else 3)
        assert len(odyn.simulate(model, t_end=0.01, output_interval=0.01).t) == 2


def test_a_type_the_module_does_not_compile_is_refused_by_name():
    m = odyn.Model(module=odyn_engine)
    crank_and_piston(m)
    expected = (r"bushing 'mount': unknown spatial element type 'bushing' \(the module "
                r"odyn_engine does not compile 'bushing'\); expected one of .*engine_gas_force")
    with pytest.raises(odyn.SceneError, match=expected):
        m.add_bushing(name="mount", body_a="ground", body_b="crank")
    assert m.element_names == []


def test_the_modules_element_is_checked_by_its_description_and_its_constructor():
    m = odyn.Model(module=odyn_engine)
    crank_and_piston(m)
    with pytest.raises(odyn.SceneError,
                       match=r"engine_gas_force 'gas'\.bore: unknown key; expected one of name, "
                       r"crank, piston, r, L, D, C, p_atm, kappa, p_comb"):
        m.add("engine_gas_force", name="gas", crank="crank", piston="piston", bore=0.08)
    with pytest.raises(odyn.SceneError, match=r"engine_gas_force 'gas'\.C: expected a positive "
                       r"number, got -9"):
        m.add("engine_gas_force", name="gas", crank="crank", piston="piston", C=-9)
    # The C++ constructor's own check, thrown in the module and reported as odyn's error.
    with pytest.raises(odyn.ModelError, match=r"gas: expected finite r > 0, L > r.*C = 0\.5"):
        m.add("engine_gas_force", name="gas", crank="crank", piston="piston", C=0.5)
    assert m.add("engine_gas_force", name="gas", crank="crank", piston="piston") == "gas"


def test_a_scene_names_its_module_and_keeps_it(tmp_path):
    scene = odyn.load(ENGINE_SCENE)
    assert scene.model.module is odyn_engine
    path = tmp_path / "engine.json"
    odyn.save(scene, path)
    assert json.loads(path.read_text())["module"] == "odyn_engine"
    again = odyn.load(path)
    assert again.model.module is odyn_engine
    assert again.model.element_names == scene.model.element_names
    # A scene of odyn's own models has no module key.
    m = odyn.Model()
    crank_and_piston(m)
    odyn.save(m, tmp_path / "plain.json")
    assert "module" not in json.loads((tmp_path / "plain.json").read_text())


def test_a_scene_without_its_module_or_with_a_missing_one_is_refused():
    d = json.loads(ENGINE_SCENE.read_text())
    odyn.Model(module=odyn_engine)  # registered: odyn can name the module
    del d["module"]
    with pytest.raises(odyn.SceneError,
                       match=r"forces\[2\]\.type: unknown force type 'engine_gas_force' "
                       r"\('engine_gas_force' is compiled by the module odyn_engine: name it "
                       r"under \"module\"\)"):
        odyn.loads(json.dumps(d))
    d["module"] = "no_such_odyn_module"
    with pytest.raises(odyn.SceneError, match=r"module: cannot import the module of odyn "
                       r"models 'no_such_odyn_module'"):
        odyn.loads(json.dumps(d))


def test_only_a_module_of_odyn_models_is_taken():
    with pytest.raises(odyn.SceneError, match=r"module json: not a module of odyn models: it "
                       r"lacks Model, PlanarModel"):
        odyn.Model(module=json)
    with pytest.raises(odyn.SceneError, match=r"expected a Python module of odyn models, got "
                       r"int"):
        odyn.Model(module=3)


def test_the_command_line_lists_a_modules_types():
    def cli(*args):
        return subprocess.run([sys.executable, "-m", "odyn", "elements", *args],
                              capture_output=True, text=True)
    run = cli("--module", "odyn_engine")
    assert run.returncode == 0, run.stderr
    listed = {line.split()[0] for line in run.stdout.splitlines()}
    assert listed == ENGINE_TYPES
    run = cli("engine_gas_force", "--planar", "--module", "odyn_engine")
    assert run.returncode == 0, run.stderr
    assert run.stdout.startswith("engine_gas_force (planar force): The engine's Otto-cycle")
    assert "  C                      positive; default 9.0. compression ratio" in run.stdout
    assert "  half_turn" in run.stdout  # its state fields
    run = cli("--module", "no_such_odyn_module")
    assert run.returncode == 1 and run.stdout == ""
    assert run.stderr.startswith("odyn: --module: cannot import the module of odyn models "
                                 "'no_such_odyn_module'") and run.stderr.count("\n") == 1
    assert "engine_gas_force" not in cli().stdout


def test_the_installed_package_carries_the_cmake_package_a_module_builds_against(tmp_path):
    """odyn_engine was built by its own project against this installation (scripts/setup.sh);
    here, that find_package(odyn) in a fresh project finds the headers it needs."""
    if shutil.which("cmake") is None:
        pytest.skip("no cmake")
    config = os.path.join(odyn.cmake_dir(), "odynConfig.cmake")
    assert os.path.isfile(config)
    (tmp_path / "CMakeLists.txt").write_text(
        "cmake_minimum_required(VERSION 3.20)\nproject(probe LANGUAGES CXX)\n"
        "find_package(odyn 0.1 CONFIG REQUIRED)\n"
        "get_target_property(dirs odyn::odyn INTERFACE_INCLUDE_DIRECTORIES)\n"
        "message(STATUS \"odyn headers: ${dirs}\")\n")
    run = subprocess.run(["cmake", "-S", str(tmp_path), "-B", str(tmp_path / "build"),
                          f"-Dodyn_DIR={odyn.cmake_dir()}"], capture_output=True, text=True)
    assert run.returncode == 0, run.stdout + run.stderr
    headers = [line.split("odyn headers: ", 1)[1] for line in run.stdout.splitlines()
               if "odyn headers: " in line]
    assert len(headers) == 1
    include = headers[0].split(";")[0]
    assert os.path.isfile(os.path.join(include, "odyn", "python", "module.hpp"))
    assert os.path.isfile(os.path.join(include, "odyn", "odyn.hpp"))
    # The engine's module is not part of the odyn package: it was installed on its own.
    assert os.path.dirname(odyn_engine.__file__) != os.path.dirname(odyn.__file__)
