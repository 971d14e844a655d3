"""Figures: time histories of scene columns, the engine's two figures, a GIF of a mechanism."""

import numpy as np
import pytest

import odyn
import odyn.plot
from conftest import ENGINE_SCENE

pytest.importorskip("matplotlib")


@pytest.fixture(scope="module")
def engine_run():
    scene = odyn.load(ENGINE_SCENE)
    return scene, scene.simulate(t_end=0.08)


def test_engine_figures_show_the_columns(engine_run, tmp_path):
    scene, result = engine_run
    table = scene.columns(result)
    written = odyn.plot.scene_figures(scene.figures, table, str(tmp_path))
    assert sorted(written) == ["engine_bearing.png", "engine_piston.png"]
    ax = odyn.plot.time_history(table, "z_piston", offset=-0.18, scale=1000.0)
    y = ax.lines[0].get_ydata()
    # The piston travels 2 r = 80 mm from top dead centre.
    assert y[0] == pytest.approx(0.0, abs=1e-9) and np.min(y) == pytest.approx(-80.0, abs=0.2)


def test_gif_of_the_engine(engine_run, tmp_path):
    from PIL import Image
    scene, result = engine_run
    path = tmp_path / "engine.gif"
    odyn.plot.animate(result, scene.model, str(path), frames=5)
    with Image.open(path) as gif:
        assert gif.n_frames == 5
