#!/usr/bin/env bash
# Work-precision report: builds bench/work_precision, runs every integrator over its ladder on the
# engine and the hard cases, and plots error against CPU time.
# Writes bench/results/work_precision.csv, bench/results/work_precision_<case>.png and the table
# it prints to bench/results/work_precision.txt. Extra arguments go to the program
# (for example --case engine --repeat 5).
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
.venv/bin/python bench/plot_work_precision.py bench/results/work_precision.csv \
  --out-dir bench/results
