"""What locating events costs, and how close their times come: a compound pendulum (1.2 kg,
0.03 kg m^2 about its centre, pivoted 0.4 m above it) released at rest 1.4 rad from hanging,
its four turning points in 2.2 periods watched as the zero crossings of its tip's horizontal
velocity, against the half periods from the complete elliptic integral. For each integrator:
the largest error of the event times, the steps, and the median wall time of 5 runs without
and with the event (the same model otherwise).

    .venv/bin/python bench/python_events.py
"""

import math
import statistics
import time

import numpy as np

import odyn

G, MASS, INERTIA, ARM, ANGLE0 = 9.81, 1.2, 0.03, 0.4, 1.4


def elliptic_k(k):
    a, b = 1.0, math.sqrt(1.0 - k * k)
    for _ in range(30):
        a, b = 0.5 * (a + b), math.sqrt(a * b)
    return math.pi / (2.0 * a)


PERIOD = 4.0 * math.sqrt((INERTIA + MASS * ARM ** 2) / (MASS * G * ARM)) * elliptic_k(
    math.sin(0.5 * ANGLE0))


def pendulum(watched):
    m = odyn.PlanarModel()
    m.add_body(name="bar", mass=MASS, inertia=INERTIA, angle=ANGLE0,
               position=[ARM * math.sin(ANGLE0), -ARM * math.cos(ANGLE0)])
    m.add_revolute(name="pivot", body_a="ground", body_b="bar", on_b=odyn.frame([0, ARM]))
    m.add_gravity(name="gravity", acceleration=[0, -G])
    m.add_point("tip", "bar", at=[0, -ARM])
    if watched:
        m.add_event("turn", point=("tip", "velocity", "x"))
    return m


def median_run(model, settings):
    walls, result = [], None
    for _ in range(5):
        start = time.perf_counter()
        result = odyn.simulate(model, t_end=2.2 * PERIOD, output_interval=0.01, **settings)
        walls.append(time.perf_counter() - start)
    return statistics.median(walls), result


CASES = [
    ("dop853", {"rtol": 1e-10, "atol": 1e-10}),
    ("dopri5", {"rtol": 1e-10, "atol": 1e-10}),
    ("bdf", {"rtol": 1e-10, "atol": 1e-10}),
    ("adams", {"step": 2e-4}),
    ("generalized-alpha", {"step": 1e-4}),
    ("generalized-alpha", {"step": 1e-3}),
]

print("| integrator | settings | largest error of the event times | steps | "
      "median wall time, unwatched -> watched |")
print("|---|---|---|---|---|")
for integrator, settings in CASES:
    plain, _ = median_run(pendulum(False), {"integrator": integrator, **settings})
    watched, r = median_run(pendulum(True), {"integrator": integrator, **settings})
    error = np.max(np.abs(r.event_times("turn") - PERIOD / 2 * np.arange(1, 5)))
    shown = ", ".join(f"{k} = {v:g}" for k, v in settings.items())
    print(f"| {integrator} | {shown} | {error:.2g} s | {r.statistics.steps} | "
          f"{1e3 * plain:.2f} -> {1e3 * watched:.2f} ms |")
