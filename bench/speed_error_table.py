"""The speed-against-error table that bench/python_contact.py, python_limits.py and
python_gears.py print: for each integrator setting, each problem's relative error against its
closed form, its steps and the median wall time of 5 runs."""

import statistics
import time

import odyn


#: The settings a table starts with: the defaults, dop853 at two tolerances, and bdf.
COMMON_CASES = [
    ("auto (defaults)", {}),
    ("dop853, rtol = atol = 1e-6", {"integrator": "dop853", "rtol": 1e-6, "atol": 1e-6}),
    ("dop853, 1e-9", {"integrator": "dop853", "rtol": 1e-9, "atol": 1e-9}),
    ("bdf, 1e-6", {"integrator": "bdf", "rtol": 1e-6, "atol": 1e-6}),
]


def median_run(build, t_end, settings):
    """The median wall time of 5 runs of a freshly built model, and the last run's result."""
    walls, result = [], None
    for _ in range(5):
        model = build()
        start = time.perf_counter()
        result = odyn.simulate(model, t_end=t_end, output_interval=0.01, **settings)
        walls.append(time.perf_counter() - start)
    return statistics.median(walls), result


def print_table(problems, cases):
    """problems: (heading, build, t_end, error(result)); cases: (label, simulate's settings)."""
    header = ["integrator"]
    for heading, *_ in problems:
        header += [heading, "steps", "median wall"]
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for label, settings in cases:
        row = [label]
        for _, build, t_end, error in problems:
            try:
                wall, r = median_run(build, t_end, settings)
                row += [f"{error(r):.1e}", str(r.statistics.steps), f"{1e3 * wall:.1f} ms"]
            except odyn.Error as failure:
                row += [f"failed: {str(failure)[:60]}", "", ""]
        print("| " + " | ".join(row) + " |")
