"""The element catalogue: what the Python layer, scene files and the documentation know of each
element type comes from the element's own C++ description, and fails here when it drifts."""

import inspect
import math
import subprocess
import sys
from pathlib import Path

import pytest

import odyn
from odyn import _core, _generate, _schema

ROOT = Path(__file__).resolve().parents[2]


def test_generated_files_are_current():
    # python/odyn/_elements.py and docs/elements.md, as the compiled core describes its elements
    for path, text in _generate.outputs(ROOT).items():
        assert path.read_text() == text, (
            f"{path.relative_to(ROOT)} is stale: run `python -m odyn._generate` from the "
            "repository")


def test_generate_check_fails_on_a_stale_file(tmp_path):
    for path, text in _generate.outputs(tmp_path).items():
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    run = [sys.executable, "-m", "odyn._generate", "--check", "--root", str(tmp_path)]
    assert subprocess.run(run, capture_output=True).returncode == 0
    (tmp_path / "docs" / "elements.md").write_text("# Elements\n")
    result = subprocess.run(run, capture_output=True, text=True)
    assert result.returncode == 1 and "elements.md" in result.stderr


@pytest.mark.parametrize("space,model_type,core_types", [
    ("spatial", odyn.Model, _core.element_types),
    ("planar", odyn.PlanarModel, _core.planar_element_types)])
def test_every_compiled_element_has_a_method_with_its_described_parameters(space, model_type,
                                                                          core_types):
    described = _schema.DESCRIPTIONS[space]
    assert set(described) == set(core_types) - {"signal_watch"}
    for element_type, description in described.items():
        method = getattr(model_type, "add_" + element_type)
        names = [p for p in inspect.signature(method).parameters if p != "self"]
        assert names == [p["name"] for p in description["parameters"]], element_type
        assert description["summary"].split()[0] in method.__doc__
        for p in description["parameters"]:
            assert p["kind"] in _schema.KIND_DOCS
            default = inspect.signature(method).parameters[p["name"]].default
            assert (default is inspect.Parameter.empty) == (p["default"] is None), p["name"]


def test_planar_and_spatial_twins_share_their_parameters():
    spatial, planar = _schema.DESCRIPTIONS["spatial"], _schema.DESCRIPTIONS["planar"]
    for element_type in set(spatial) & set(planar):
        names = [p["name"] for p in spatial[element_type]["parameters"]]
        planar_names = [p["name"] for p in planar[element_type]["parameters"]]
        if element_type == "point_torque":  # a planar torque has no axes to be given in
            assert planar_names == [n for n in names if n != "axes"]
        else:
            assert planar_names == names, element_type


def test_unknown_keys_are_refused_with_the_valid_ones():
    m = odyn.Model()
    m.add_body("bar", mass=1.0, inertia=[1, 1, 1])
    with pytest.raises(odyn.SceneError, match=r"gravity 'g'\.accelaration: unknown key; "
                       r"expected one of name, acceleration"):
        m.add("gravity", name="g", accelaration=[0, 0, -9.81])
    with pytest.raises(odyn.SceneError, match=r"\(did you mean 'acceleration'\?\)"):
        m.add("gravity", name="g", accelaration=[0, 0, -9.81])
    with pytest.raises(TypeError, match="accelaration"):
        m.add_gravity("g", accelaration=[0, 0, -9.81])
    with pytest.raises(odyn.SceneError, match=r"forces\[0\]\.stifness: unknown key; expected "
                       r"one of name, body_a, point_a, body_b, point_b, stiffness"):
        odyn.loads('{"bodies": [{"name": "b", "mass": 1, "inertia": [1, 1, 1]}], '
                   '"forces": [{"type": "tsda", "name": "s", "body_a": "ground", '
                   '"body_b": "b", "stifness": 10}]}')


def test_the_compiled_core_refuses_unknown_keys_too():
    # What crosses from Python into C++ is read key by key; a key no parameter reads is named.
    core = _core.Model()
    with pytest.raises(_core.ModelError, match=r"gravity 'g'.*unknown parameter 'bogus'; "
                       r"expected one of name, acceleration"):
        core.add_element("gravity", {"name": "g", "acceleration": [0, 0, -9.81], "bogus": 1})
    with pytest.raises(_core.ModelError, match="unknown spatial element type"):
        core.add_element("worm_drive", {"name": "g"})


def test_spatial_joint_frames_default_to_the_body_origin_and_z():
    # Frames are optional in both spaces now (one description): a spatial hinge left without
    # frames turns about z through both bodies' origins.
    m = odyn.Model()
    m.add_body("bar", mass=1.0, inertia=[1, 1, 1], angular_velocity=[0, 0, 2.0])
    m.add_revolute("hinge", "ground", body_b="bar")
    assert m.element("hinge")["on_a"] == {"point": [0.0, 0.0, 0.0], "axis": [0.0, 0.0, 1.0]}
    result = odyn.simulate(m, t_end=0.5, output_interval=0.5)
    # No force: the bar keeps turning about z at 2 rad/s about its fixed centre.
    assert result.q[-1, 0:3] == pytest.approx([0, 0, 0], abs=1e-12)
    half = 2.0 * 0.5 / 2
    assert result.q[-1, 3:7] == pytest.approx([math.cos(half), 0, 0, math.sin(half)], abs=1e-8)


def test_drivers_need_a_joint_or_both_bodies():
    m = odyn.PlanarModel()
    m.add_body("crank", mass=1.0, inertia=0.1)
    with pytest.raises(odyn.SceneError, match=r"revolute_driver 'motor': missing 'body_a'"):
        m.add_revolute_driver("motor", odyn.constant_velocity(1.0))
    m.add_revolute("pin", "ground", body_b="crank")
    m.add_revolute_driver("motor", odyn.constant_velocity(1.0), joint="pin")
    assert m.element("motor")["body_b"] == "crank"
    assert "joint" not in m.element("motor")


def test_the_command_line_lists_the_catalogue(capsys):
    from odyn import cli
    assert cli.main(["elements"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [line.split()[0] for line in lines] == list(_schema.DESCRIPTIONS["spatial"])
    assert cli.main(["elements", "inline", "--planar"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("inline (planar joint): In-line primitive")
    assert "on_a" in out and "frame, m; default null" in out
    assert cli.main(["elements", "worm_drive"]) == 1
    assert "no spatial element type 'worm_drive'" in capsys.readouterr().err


def test_a_new_element_reaches_scene_files_with_no_code_of_its_own():
    # The joint primitives were added by their C++ descriptions alone: a scene names them as it
    # names any joint, and a scene's planar pin-in-slot runs.
    scene = odyn.loads("""{
        "space": "planar",
        "bodies": [{"name": "block", "mass": 2, "inertia": 0.1}],
        "joints": [{"type": "inline", "name": "slot", "body_a": "ground", "body_b": "block",
                    "on_a": {"axis": [1, 0]}}],
        "forces": [{"type": "gravity", "name": "g", "acceleration": [0, -9.81]}],
        "analysis": {"t_end": 0.5, "output_interval": 0.5}
    }""")
    result = scene.simulate()
    # The slot is horizontal: the block stays on it, at rest.
    assert result.body("block").position[-1] == pytest.approx([0, 0], abs=1e-12)
    assert result.reaction("slot").force[-1] == pytest.approx([0, 2 * 9.81], abs=1e-9)
