"""The issue's rope through the Python API: model building, assembly and runs against N.

The scaling report (bench/scaling.cpp) times odyn's C++ core. A Python user also pays for
building the model through `odyn.Model` (every argument checked) and for the assembly; this
script times what such a user waits for, on the rope of the scaling report: N links of 1 m and
1 kg (inertia 5e-5, 1/12, 1/12) on ball joints along x from the origin, gravity -z, at rest
or, "moving", with a velocity of 0.1 m/s along y given on every link. For N = 32 ... 16384:

  build_s       the Model built by add_body / add_spherical / add_gravity,
  assemble_s    odyn.assemble(model),
  simulate_s    then odyn.simulate(model, step=1e-3): `steps` steps of generalized-alpha,
                setup included (the run starts from the kept assembly),
  setup_s       the run's own setup (summary["setup_seconds"]),
  fresh_setup_s the setup of the same run on a new copy of the model, which assembles first.

Writes bench/results/python_setup.csv and .md (with the growth exponents of each column over
N = 64 ... 4096). scripts/scaling.sh runs it after the C++ report; alone:

    .venv/bin/python bench/python_setup.py [--max-n 4096]
"""

import argparse
import csv
import math
import os
import time

import odyn


def rope(links, moving):
    model = odyn.Model()
    previous = "ground"
    velocity = dict(linear_velocity=(0, 0.1, 0), velocity_given=[True] * 6) if moving else {}
    for i in range(links):
        name = f"link{i}"
        model.add_body(name, 1.0, (5e-5, 1 / 12, 1 / 12), position=(0.5 + i, 0, 0), **velocity)
        model.add_spherical(f"ball{i}", previous, point_a=(0, 0, 0) if i == 0 else (0.5, 0, 0),
                            body_b=name, point_b=(-0.5, 0, 0))
        previous = name
    model.add_gravity("gravity", (0, 0, -9.81))
    return model


def measure(links, moving):
    steps = 1000 if links <= 1024 else 100
    settings = dict(t_end=steps * 1e-3, step=1e-3, output_interval=steps * 1e-3)
    start = time.perf_counter()
    model = rope(links, moving)
    built = time.perf_counter()
    odyn.assemble(model)
    assembled = time.perf_counter()
    run = odyn.simulate(model, **settings)
    ran = time.perf_counter()
    assert run.summary["assembly"]["reused"]
    fresh = odyn.simulate(rope(links, moving), t_end=0.0, step=1e-3, output_interval=1e-3)
    return dict(case="rope-moving" if moving else "rope", N=links, steps=steps,
                build_s=built - start, assemble_s=assembled - built, simulate_s=ran - assembled,
                setup_s=run.summary["setup_seconds"],
                fresh_setup_s=fresh.summary["setup_seconds"])


COLUMNS = ["build_s", "assemble_s", "simulate_s", "setup_s", "fresh_setup_s"]


def exponent(points):
    """Least-squares slope of log y on log N."""
    logs = [(math.log(n), math.log(y)) for n, y in points if y > 0]
    if len(logs) < 2:
        return float("nan")
    mx = sum(x for x, _ in logs) / len(logs)
    my = sum(y for _, y in logs) / len(logs)
    return (sum((x - mx) * (y - my) for x, y in logs) / sum((x - mx) ** 2 for x, _ in logs))


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max-n", type=int, default=16384)
    parser.add_argument("--out-dir", default=os.path.join(here, "results"))
    args = parser.parse_args()
    rows = []
    for moving in (False, True):
        links = 32
        while links <= args.max_n:
            rows.append(measure(links, moving))
            r = rows[-1]
            print(f"{r['case']:12} N={links:6} " +
                  " ".join(f"{c} {r[c]:.4f}" for c in COLUMNS), flush=True)
            links *= 2
    os.makedirs(args.out_dir, exist_ok=True)
    with open(os.path.join(args.out_dir, "python_setup.csv"), "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=["case", "N", "steps"] + COLUMNS)
        writer.writeheader()
        writer.writerows(rows)
    lines = ["| case | N | steps | build | assemble | simulate | its setup | setup, "
             "assembling |", "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['case']} | {r['N']} | {r['steps']} | " +
                     " | ".join(f"{r[c]:.3g} s" for c in COLUMNS) + " |")
    lines += ["", "Growth exponents over N = 64 ... 4096:", "",
              "| case | " + " | ".join(COLUMNS) + " |", "|---|" + "---|" * len(COLUMNS)]
    for case in ("rope", "rope-moving"):
        chosen = [r for r in rows if r["case"] == case and 64 <= r["N"] <= 4096]
        # simulate_s: per step, since the step count changes with N.
        fits = [exponent([(r["N"], r[c] / (r["steps"] if c == "simulate_s" else 1))
                          for r in chosen]) for c in COLUMNS]
        lines.append(f"| {case} | " + " | ".join(f"{p:.2f}" if math.isfinite(p) else "-"
                                                  for p in fits) + " |")
    with open(os.path.join(args.out_dir, "python_setup.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
