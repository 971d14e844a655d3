"""Tables, fitted growth exponents and the log-log figure of the scaling report.

Reads bench/results/scaling.csv (odyn, from build/bench/scaling) and, if present,
bench/results/peer_scaling.csv (Exudyn, MuJoCo, Pinocchio, from bench/peer_scaling.py), and
writes bench/results/scaling.md and bench/results/scaling.png. scripts/scaling.sh runs the
whole report.

The growth exponent p of a time t(N) is the least-squares slope of log t against log N over
the sizes from --fit-from to --fit-to (64 ... 4096 by default): t ~ N^p.
"""

import argparse
import csv
import math
import os
from collections import defaultdict


def read(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def exponent(points, low, high):
    """Least-squares slope of log y on log x over low <= x <= high (None if < 2 points)."""
    chosen = [(math.log(x), math.log(y)) for x, y in points if low <= x <= high and y > 0]
    if len(chosen) < 2:
        return None
    mx = sum(x for x, _ in chosen) / len(chosen)
    my = sum(y for _, y in chosen) / len(chosen)
    sxx = sum((x - mx) ** 2 for x, _ in chosen)
    return sum((x - mx) * (y - my) for x, y in chosen) / sxx if sxx > 0 else None


def fmt(value, scale=1e3, digits=3):
    return "" if value is None else f"{scale * value:.{digits}g}"


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--odyn", default=os.path.join(here, "results", "scaling.csv"))
    parser.add_argument("--peers", default=os.path.join(here, "results", "peer_scaling.csv"))
    parser.add_argument("--out-dir", default=os.path.join(here, "results"))
    parser.add_argument("--fit-from", type=int, default=64)
    parser.add_argument("--fit-to", type=int, default=4096)
    args = parser.parse_args()

    # series[label] = list of (N, setup_s, step_s)
    series = defaultdict(list)
    for row in read(args.odyn):
        if row["status"] != "ok":
            continue
        series[f"odyn {row['case']}"].append(
            (int(row["N"]), float(row["setup_s"]), float(row["step_s"])))
    peer_rows = read(args.peers) if os.path.exists(args.peers) else []
    for row in peer_rows:
        if not row["status"].startswith("ok") or not row["step_s"]:
            continue
        method = row["method"].split("/")[0]
        series[f"{row['engine']} ({method})"].append(
            (int(row["N"]), float(row["setup_s"]), float(row["step_s"])))

    lines = ["# Scaling: time per step and setup time against the number of bodies", "",
             "Regenerate with `bash scripts/scaling.sh` (one run of odyn's `build/bench/scaling` "
             "and `bench/peer_scaling.py`, then this script). Times are wall-clock medians on "
             "the machine of that run; exponents p are least-squares fits of t ~ N^p over "
             f"N = {args.fit_from} ... {args.fit_to}.", "",
             "| series | p (step) | p (setup) | largest N | step at largest N (ms) | "
             "setup at largest N (ms) |", "|---|---|---|---|---|---|"]
    for label, points in series.items():
        points.sort()
        p_step = exponent([(n, s) for n, _, s in points], args.fit_from, args.fit_to)
        p_setup = exponent([(n, u) for n, u, _ in points], args.fit_from, args.fit_to)
        n, setup, step = points[-1]
        lines.append(f"| {label} | {'' if p_step is None else f'{p_step:.2f}'} | "
                     f"{'' if p_setup is None else f'{p_setup:.2f}'} | {n} | {fmt(step)} | "
                     f"{fmt(setup)} |")
    sizes = sorted({n for points in series.values() for n, _, _ in points})
    lines += ["", "Time per step (ms; Pinocchio: one articulated-body evaluation, no step):", "",
              "| N | " + " | ".join(series) + " |",
              "|---|" + "---|" * len(series)]
    for n in sizes:
        cells = []
        for points in series.values():
            match = [s for m, _, s in points if m == n]
            cells.append(fmt(match[0]) if match else "")
        lines.append(f"| {n} | " + " | ".join(cells) + " |")
    lines += ["", "Setup time (ms; odyn: assembly with a velocity given on every link, and the "
              "integrator's analysis):", "",
              "| N | " + " | ".join(series) + " |", "|---|" + "---|" * len(series)]
    for n in sizes:
        cells = []
        for points in series.values():
            match = [u for m, u, _ in points if m == n]
            cells.append(fmt(match[0]) if match else "")
        lines.append(f"| {n} | " + " | ".join(cells) + " |")
    failures = [row for row in peer_rows if not row["status"].startswith(("ok", "skipped"))]
    if failures:
        lines += ["", "Where the peers stopped:", ""]
        lines += [f"- {row['engine']} at N = {row['N']}: {row['status']}" for row in failures]
    os.makedirs(args.out_dir, exist_ok=True)
    with open(os.path.join(args.out_dir, "scaling.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(12, 5))
    for label, points in series.items():
        style = "-o" if label.startswith("odyn") else "--s"
        n = [p[0] for p in points]
        axes[0].loglog(n, [p[2] for p in points], style, ms=3, label=label)
        axes[1].loglog(n, [p[1] for p in points], style, ms=3, label=label)
    for ax, title in zip(axes, ("time per step (s)", "setup time (s)")):
        ax.set_xlabel("bodies N")
        ax.set_title(title)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(args.out_dir, "scaling.png"), dpi=110)


if __name__ == "__main__":
    main()
