"""Plots the work-precision table of bench/work_precision.cpp: error against CPU time, log-log,
one line per integrator family, one figure per case.

    python bench/plot_work_precision.py work_precision.csv [--out-dir DIR] [--case NAME]...
                                        [--peers PEERS.csv]...

--peers adds other engines' runs of the same cases (a CSV with the same columns, e.g.
bench/results/peer_engine.csv from bench/peer_engine.py; the family names the engine, e.g.
"MuJoCo RK4"), drawn in black with open markers, one line style per engine, and listed in a
legend of their own, so that they stand apart from odyn's coloured, filled families.
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


PEER_MARKERS = ("s", "^", "D", "v", "o", "P", "X", "<", ">")
PEER_LINESTYLES = ("--", "-.", ":")


def plot_peers(ax, peers: dict[str, list[tuple[float, float, float]]]) -> list:
    """Peers' families in black: one line style per engine (the family's first word), one open
    marker per family."""
    engines: list[str] = []
    lines = []
    for i, (family, runs) in enumerate(sorted(peers.items())):
        engine = family.split()[0]
        if engine not in engines:
            engines.append(engine)
        k = engines.index(engine)
        runs.sort()
        (line,) = ax.loglog([1e3 * c for c, _, _ in runs], [e for _, e, _ in runs],
                            linestyle=PEER_LINESTYLES[k % len(PEER_LINESTYLES)],
                            color="black",
                            marker=PEER_MARKERS[i % len(PEER_MARKERS)], markersize=5,
                            markerfacecolor="none", linewidth=1.2, label=family)
        lines.append(line)
    return lines


def plot(case: str, families: dict[str, list[tuple[float, float, float]]], out: Path,
         peers: dict[str, list[tuple[float, float, float]]] | None = None) -> None:
    fig, ax = plt.subplots(figsize=(10, 5.5) if peers else (7, 5))
    for family, runs in sorted(families.items()):
        runs.sort()
        ax.loglog([1e3 * c for c, _, _ in runs], [e for _, e, _ in runs], "o-", label=family,
                  markersize=4)
    own = ax.get_legend_handles_labels()
    peer_lines = plot_peers(ax, peers) if peers else []
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
    if peer_lines:
        # two legends beside the axes: odyn's families, then the peers'
        first = ax.legend(*own, fontsize=8, title="odyn", title_fontsize=8,
                          loc="upper left", bbox_to_anchor=(1.01, 1.0))
        ax.add_artist(first)
        second = ax.legend(handles=peer_lines, fontsize=8,
                           title="peers (Python force callbacks)", title_fontsize=8,
                           loc="lower left", bbox_to_anchor=(1.01, 0.0))
        # tight_layout leaves legends outside the axes out: the saved box takes them in.
        fig.tight_layout()
        fig.savefig(out, dpi=110, bbox_inches="tight", bbox_extra_artists=[first, second])
        plt.close(fig)
        return
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("table", type=Path)
    parser.add_argument("--out-dir", type=Path, default=Path("."))
    parser.add_argument("--case", action="append", default=[])
    parser.add_argument("--peers", action="append", default=[], type=Path, metavar="PATH",
                        help="a CSV of other engines' runs (same columns) to draw on the same "
                             "figures; may be given several times")
    args = parser.parse_args()
    args.out_dir.mkdir(parents=True, exist_ok=True)
    peers: dict[str, dict[str, list[tuple[float, float, float]]]] = defaultdict(dict)
    for path in args.peers:
        for case, families in read(path).items():
            for family, runs in families.items():
                peers[case].setdefault(family, []).extend(runs)
    for case, families in read(args.table).items():
        if args.case and case not in args.case:
            continue
        out = args.out_dir / f"work_precision_{case}.png"
        plot(case, families, out, peers.get(case))
        print(f"wrote {out}")


if __name__ == "__main__":
    main()
