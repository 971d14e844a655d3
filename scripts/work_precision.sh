#!/usr/bin/env bash
# Work-precision report: builds bench/work_precision, runs every integrator over its ladder on the
# engine and the hard cases, runs the peer engines (MuJoCo, Exudyn) on the engine with
# bench/peer_engine.py, and plots error against CPU time, the peers on the engine's figure.
# Writes bench/results/work_precision.csv, bench/results/peer_engine.csv,
# bench/results/work_precision_<case>.png and the tables they print to
# bench/results/work_precision.txt and bench/results/peer_engine.txt, and the peers next to odyn
# (bench/compare_work_precision.py) to bench/results/peer_comparison.md. Extra arguments go to
# the C++ program (for example --case engine --repeat 5). See docs/work-precision.md.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

bash scripts/setup.sh
export CCACHE_BASEDIR=$PWD CCACHE_NOHASHDIR=true
gen=(-G Ninja)
[[ -f build/CMakeCache.txt ]] && gen=()
cmake -S . -B build "${gen[@]}" -DCMAKE_BUILD_TYPE=Release -DODYN_BUILD_BENCH=ON
cmake --build build --target work_precision -j "$(nproc)"
mkdir -p bench/results
./build/bench/work_precision --out bench/results/work_precision.csv "$@" |
  tee bench/results/work_precision.txt
# The peers (about a minute; their packages live in build/peer-venv, created on first use). A
# failure here leaves odyn's figures without the peers instead of stopping the report.
peers=()
if nice -n 10 python3 bench/peer_engine.py | tee bench/results/peer_engine.txt; then
  peers=(--peers bench/results/peer_engine.csv)
  # Each peer run next to odyn's cheapest run at least as accurate (docs/work-precision.md).
  nice -n 10 python3 bench/compare_work_precision.py bench/results/work_precision.csv \
    bench/results/peer_engine.csv --out bench/results/peer_comparison.md
else
  echo "bench/peer_engine.py failed: plotting odyn's runs only" >&2
fi
.venv/bin/python bench/plot_work_precision.py bench/results/work_precision.csv \
  "${peers[@]}" --out-dir bench/results
