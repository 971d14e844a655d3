"""Puts the peer engines' work-precision runs next to odyn's: for each peer run (MuJoCo, Exudyn;
bench/results/peer_engine.csv from bench/peer_engine.py), odyn's cheapest run of the same case
(bench/results/work_precision.csv from bench/work_precision.cpp) whose error is no larger.

    python3 bench/compare_work_precision.py [WORK_PRECISION.csv] [PEERS.csv] [--out PATH]

The defaults are bench/results/work_precision.csv and bench/results/peer_engine.csv (relative to
the repository). The markdown table is printed to stdout and, with --out, also written to PATH;
scripts/work_precision.sh writes bench/results/peer_comparison.md, which docs/work-precision.md
quotes. Standard library only.

Both CSVs have the columns case,family,integrator,adaptive,value,error,...,cpu_seconds,...,
max_phi,status (value = the tolerance of an adaptive run, else the step h; max_phi of a peer run
= the largest pin gap [m], the violation of the loop-closing joint). Only runs with status "ok",
a finite positive error and a finite CPU time take part. For each peer run, in the peers' CSV
order, the table gives:

  * the peer's step h, error, CPU time [ms] and pin gap;
  * odyn's run of the same case with the lowest cpu_seconds among those with error <= the
    peer's, as "family, tol|h value: error, CPU ms (ratio)" where the ratio is the peer's CPU
    time over odyn's, rounded, e.g. "(4x)"; a family "X, joint coordinates" is written
    "X (joint)"; "none" when no odyn run is that accurate;
  * the same among odyn's absolute-coordinate runs only (families whose name does not contain
    "joint coordinates"), the same formulation as Exudyn's.
"""

from __future__ import annotations

import argparse
import csv
import math
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
DEFAULT_ODYN = REPO / "bench" / "results" / "work_precision.csv"
DEFAULT_PEERS = REPO / "bench" / "results" / "peer_engine.csv"
JOINT = "joint coordinates"

HEADER = ("| peer | h [s] | error [rad] | CPU [ms] | pin gap [m] "
          "| odyn's cheapest run at least as accurate "
          "| the same among odyn's absolute-coordinate runs |\n"
          "|---|---:|---:|---:|---:|---|---|")


def number(text: str) -> float:
    try:
        return float(text)
    except (TypeError, ValueError):
        return math.nan


def usable_runs(path: Path) -> list[dict]:
    """The runs with status ok, a finite positive error and a finite CPU time, in file order."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    runs = []
    for r in rows:
        error, cpu = number(r.get("error")), number(r.get("cpu_seconds"))
        if (r.get("status") == "ok" and math.isfinite(error) and error > 0
                and math.isfinite(cpu)):
            runs.append({**r, "error": error, "cpu_seconds": cpu})
    return runs


def cheapest(odyn: list[dict], case: str, error: float, absolute_only: bool) -> dict | None:
    """odyn's run of `case` with the lowest CPU time whose error is <= `error` (the first in file
    order on a tie), or None."""
    candidates = [r for r in odyn if r["case"] == case and r["error"] <= error
                  and not (absolute_only and JOINT in r["family"])]
    return min(candidates, key=lambda r: r["cpu_seconds"], default=None)


def family_label(run: dict) -> str:
    family = run["family"]
    if JOINT in family:
        family = family.replace(f", {JOINT}", "").replace(JOINT, "").strip(" ,") + " (joint)"
    knob = "tol" if run["adaptive"].strip() == "1" else "h"
    return f"{family}, {knob} {number(run['value']):g}"


def ratio_text(peer_cpu: float, odyn_cpu: float) -> str:
    ratio = peer_cpu / odyn_cpu if odyn_cpu > 0 else math.inf
    if not math.isfinite(ratio):
        return "(inf)"
    if ratio >= 0.95:
        return f"({math.floor(ratio + 0.5)}x)"  # half up, not Python's half-to-even
    return f"({ratio:.1g}x)"


def odyn_cell(peer: dict, run: dict | None) -> str:
    if run is None:
        return "none"
    return (f"{family_label(run)}: {run['error']:.1e}, {1e3 * run['cpu_seconds']:.1f} ms "
            f"{ratio_text(peer['cpu_seconds'], run['cpu_seconds'])}")


def pin_gap(peer: dict) -> str:
    gap = number(peer.get("max_phi"))
    return f"{gap:.0e}" if math.isfinite(gap) else "n/a"


def table(odyn: list[dict], peers: list[dict]) -> str:
    lines = [HEADER]
    for p in peers:
        best = cheapest(odyn, p["case"], p["error"], absolute_only=False)
        best_absolute = cheapest(odyn, p["case"], p["error"], absolute_only=True)
        lines.append(f"| {p['family']} | {number(p['value']):g} | {p['error']:.2e} "
                     f"| {1e3 * p['cpu_seconds']:.1f} | {pin_gap(p)} "
                     f"| {odyn_cell(p, best)} | {odyn_cell(p, best_absolute)} |")
    return "\n".join(lines) + "\n"


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("odyn_csv", nargs="?", default=str(DEFAULT_ODYN),
                    help="odyn's runs (default bench/results/work_precision.csv)")
    ap.add_argument("peers_csv", nargs="?", default=str(DEFAULT_PEERS),
                    help="the peers' runs (default bench/results/peer_engine.csv)")
    ap.add_argument("--out", metavar="PATH", help="also write the table to PATH")
    args = ap.parse_args(argv)

    odyn = usable_runs(Path(args.odyn_csv))
    peers = usable_runs(Path(args.peers_csv))
    if not peers:  # e.g. every peer failed its physics check: an empty table, not a failure
        print(f"{args.peers_csv}: no usable peer runs (status ok, finite positive error)",
              file=sys.stderr)
    text = table(odyn, peers)
    sys.stdout.write(text)
    if args.out:
        out = Path(args.out)
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
