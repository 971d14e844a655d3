"""A run releases the GIL: other Python threads go on while it computes; the model is locked."""

import threading
import time

import pytest

import odyn
from conftest import ENGINE_SCENE


def test_other_threads_run_during_a_simulation():
    scene = odyn.load(ENGINE_SCENE)
    done = threading.Event()
    box = {}

    def run():
        box["result"] = scene.simulate(t_end=2.0)
        done.set()

    worker = threading.Thread(target=run)
    worker.start()
    time.sleep(0.02)
    ticks = 0
    while not done.is_set():  # busy Python work in the main thread, needing the GIL
        ticks += 1
        if ticks % 1000 == 0:
            time.sleep(0)
    worker.join()
    assert len(box["result"]) == 2001
    # With the GIL held for the ~0.15 s run this loop could not have turned this often.
    assert ticks > 10_000

    # While a run is going, the model cannot change.
    worker = threading.Thread(target=lambda: scene.simulate(t_end=10.0))
    worker.start()
    time.sleep(0.05)
    try:
        with pytest.raises(odyn.ModelError, match="while an analysis runs"):
            scene.model.add_body(name="extra", mass=1.0, inertia=[1, 1, 1])
    finally:
        worker.join()
    assert "extra" not in scene.model.body_names
