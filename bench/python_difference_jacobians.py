"""What the stiffness of a Python force by central differences buys an implicit integrator.

A 1 kg block on a rail pulled by a spring written in Python (odyn user_force), run for 1 s by
generalized-alpha at h = 1e-3, with its own stiffness block (`jacobians`), with blocks by
differences (`difference_jacobians`, the default) and without any, for a soft spring
(k h^2/m = 1e-4) and a stiff one (k h^2/m = 1). Prints the median wall time of 5 runs, the
Newton iterations, the Jacobian evaluations and the final position; the C++ spring (tsda, exact
blocks) is the reference.

    .venv/bin/python bench/python_difference_jacobians.py
"""

import statistics
import time

import numpy as np

import odyn


def block_on_rail(k: float, kind: str, differences: bool = True,
                  own_blocks: bool = False) -> odyn.Model:
    m = odyn.Model()
    m.add_body("block", mass=1.0, inertia=[0.1] * 3, position=[1.2, 0, 0])
    m.add_translational("rail", "ground", on_a=odyn.frame([0, 0, 0], [1, 0, 0]), body_b="block",
                        on_b=odyn.frame([0, 0, 0], [1, 0, 0]))
    if kind == "tsda":
        m.add_tsda("spring", "ground", body_b="block", stiffness=k, free_length=1.0)
    else:
        stiffness = np.zeros((6, 6))
        stiffness[0, 0] = k
        m.add_user_force("spring", ["block"], difference_jacobians=differences,
                         function=lambda t, b: (-k * (b.position[0] - 1.0), 0, 0, 0, 0, 0),
                         jacobians=(lambda t, b: (stiffness, None)) if own_blocks else None)
    return m


def main() -> None:
    print("| k (N/m) | spring | median wall | Newton iterations | Jacobians | x(1 s) |")
    print("|---|---|---|---|---|---|")
    for k in (100.0, 1e6):
        for kind, differences, own, label in (
                ("tsda", True, False, "C++ tsda"),
                ("user_force", True, True, "Python, own blocks"),
                ("user_force", True, False, "Python, differences"),
                ("user_force", False, False, "Python, no blocks")):
            times = []
            for _ in range(5):
                model = block_on_rail(k, kind, differences, own)
                start = time.perf_counter()
                r = odyn.simulate(model, t_end=1.0, step=1e-3, output_interval=0.01,
                                  integrator="generalized-alpha")
                times.append(time.perf_counter() - start)
            s = r.statistics
            print(f"| {k:g} | {label} | {statistics.median(times) * 1e3:.1f} ms | "
                  f"{s.newton_iterations} | {s.jacobian_evaluations} | "
                  f"{r.body('block').position[-1, 0]:.6f} |")


if __name__ == "__main__":
    main()
