"""Plots the work-precision table of bench/work_precision.cpp: error against CPU time, log-log,
one line per integrator family, one figure per case.

    python bench/plot_work_precision.py work_precision.csv [--out-dir DIR] [--case NAME]...
"""
from __future__ import annotations

import argparse
import csv
import math
from collections import defaultdict
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import LogLocator, NullFormatter, ScalarFormatter  # noqa: E402

ERROR_LABELS = {
    "engine": "|theta(1) error| [rad]",
    "engine-planar": "|theta(1) error| [rad]",
    "andrews": "largest relative error of the 7 angles at t = 0.03",
}
# The targets: (error, CPU milliseconds), drawn as a box to reach into.
TARGETS = {
    "engine": (1e-7, 10.0),
    "engine-planar": (1e-7, 10.0),
    "andrews": (1e-10, 50.0),
}
TITLES = {
    "engine": "Engine (spatial, 18 coordinates), 1 s",
    "engine-planar": "Engine as a planar slider-crank (9 coordinates), 1 s",
    "andrews": "Andrews' squeezing mechanism, t = 0.03 s",
}


def read(path: Path) -> dict[str, dict[str, list[tuple[float, float, float]]]]:
    """case -> family -> [(cpu seconds, error, setting)] of the runs that succeeded."""
    table: dict[str, dict[str, list[tuple[float, float, float]]]] = defaultdict(
        lambda: defaultdict(list))
    with path.open(newline="") as f:
        for row in csv.DictReader(f):
            error = float(row["error"])
            if row["status"] != "ok" or not math.isfinite(error) or error <= 0.0:
                continue
            table[row["case"]][row["family"]].append(
                (float(row["cpu_seconds"]), error, float(row["value"])))
    return table


def plot(case: str, families: dict[str, list[tuple[float, float, float]]], out: Path) -> None:
    fig, ax = plt.subplots(figsize=(7, 5))
    for family, runs in sorted(families.items()):
        runs.sort()
        ax.loglog([1e3 * c for c, _, _ in runs], [e for _, e, _ in runs], "o-", label=family,
                  markersize=4)
    if case in TARGETS:
        error, milliseconds = TARGETS[case]
        ax.axhline(error, color="grey", linestyle="--", linewidth=0.8)
        ax.axvline(milliseconds, color="grey", linestyle="--", linewidth=0.8)
        ax.text(milliseconds, error, " target", color="grey", fontsize=8, va="top")
    ax.xaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
    ax.xaxis.set_major_formatter(ScalarFormatter())
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.set_xlabel("CPU time of the run [ms]")
    ax.set_ylabel(ERROR_LABELS.get(case, "error"))
    ax.set_title(TITLES.get(case, case))
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("table", type=Path)
    parser.add_argument("--out-dir", type=Path, default=Path("."))
    parser.add_argument("--case", action="append", default=[])
    args = parser.parse_args()
    args.out_dir.mkdir(parents=True, exist_ok=True)
    for case, families in read(args.table).items():
        if args.case and case not in args.case:
            continue
        out = args.out_dir / f"work_precision_{case}.png"
        plot(case, families, out)
        print(f"wrote {out}")


if __name__ == "__main__":
    main()
