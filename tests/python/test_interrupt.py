"""Ctrl-C stops a long run cleanly and keeps the outputs computed so far."""

import _thread
import csv
import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import odyn
from conftest import ENGINE_SCENE


def test_keyboard_interrupt_in_process_keeps_partial_results():
    scene = odyn.load(ENGINE_SCENE)
    timer = threading.Timer(0.5, _thread.interrupt_main)  # as Ctrl-C would: SIGINT's flag
    timer.start()
    start = time.monotonic()
    with pytest.raises(odyn.Interrupted) as info:
        scene.simulate(t_end=1000.0)  # about a minute and a half if nobody stopped it
    stopped_after = time.monotonic() - start
    timer.join()
    assert isinstance(info.value, KeyboardInterrupt)
    r = info.value.result
    # What it counted until then comes with it (once None).
    assert r.interrupted and r.statistics.outputs == len(r) and r.statistics.steps > 0
    assert 10 < len(r) < 1_000_000 and stopped_after < 5.0
    assert np.all(np.diff(r.t) > 0) and r.q.shape == (len(r), 21)
    # What was kept is a valid run: the constraints hold at every kept output.
    assert np.max(r.phi_norm) < 1e-10
    np.testing.assert_allclose(r.t, 1e-3 * np.arange(len(r)), atol=1e-9)


def wait_for_cpu_seconds(pid, seconds, timeout=30.0):
    """Waits until process `pid` has used `seconds` of CPU time (user + system)."""
    ticks = os.sysconf("SC_CLK_TCK")
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        with open(f"/proc/{pid}/stat") as f:
            fields = f.read().rsplit(")", 1)[1].split()
        if (int(fields[11]) + int(fields[12])) / ticks >= seconds:
            return
        time.sleep(0.05)
    raise AssertionError(f"process {pid} did not use {seconds} s of CPU in {timeout} s")


def test_sigint_to_the_cli_writes_the_outputs_so_far(tmp_path):
    out = tmp_path / "partial.csv"
    proc = subprocess.Popen([sys.executable, "-m", "odyn", "run", str(ENGINE_SCENE), "--t-end",
                             "1000", "--out", str(out)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    wait_for_cpu_seconds(proc.pid, 1.5)  # imports take a few tenths: the run has begun
    proc.send_signal(signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=30)
    assert proc.returncode == 130, stderr
    assert "Traceback" not in stderr and "interrupted; kept" in stderr
    assert "[INTERRUPTED]" in stdout
    with open(out, newline="") as f:
        rows = list(csv.reader(f))
    assert rows[0] == ["t", "theta", "omega", "z_piston", "R_z", "phi_norm", "phid_norm"]
    t = np.array([float(row[0]) for row in rows[1:]])
    assert 10 < len(t) < 1_000_000 and t[-1] < 1000.0


def test_ctrl_c_is_seen_inside_a_long_output_interval():
    """With one output at the end, Ctrl-C still stops the run within a fraction of a second."""
    scene = odyn.load(ENGINE_SCENE)
    timer = threading.Timer(0.5, _thread.interrupt_main)
    timer.start()
    start = time.monotonic()
    with pytest.raises(odyn.Interrupted) as info:
        scene.simulate(t_end=1000.0, output_interval=1000.0)
    timer.join()
    assert time.monotonic() - start < 2.0
    assert len(info.value.result) == 1 and info.value.result.t[0] == 0.0
