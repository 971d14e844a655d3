#!/usr/bin/env bash
# Scaling report: builds bench/scaling, runs it (odyn's chains, ropes with springs, trees and
# ladders of loops, N = 1 ... 4096, and the spherical and hinged chains and the hinged ladder
# to 16384), runs the peers' script (Exudyn, MuJoCo and Pinocchio from PyPI in
# build/peer-venv) in the same run, and the Python API's building, assembly and runs of the
# rope (bench/python_setup.py), and writes bench/results/scaling.{csv,md,png},
# bench/results/peer_scaling.csv and bench/results/python_setup.{csv,md}.
# Extra arguments go to the peers' script (for example --engines exudyn).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

bash scripts/setup.sh
export CCACHE_BASEDIR=$PWD CCACHE_NOHASHDIR=true
gen=(-G Ninja)
[[ -f build/CMakeCache.txt ]] && gen=()
cmake -S . -B build "${gen[@]}" -DCMAKE_BUILD_TYPE=Release -DODYN_BUILD_BENCH=ON
cmake --build build --target scaling -j "$(nproc)"
mkdir -p bench/results
./build/bench/scaling --out bench/results/scaling.csv
./build/bench/scaling --case spherical-chain --case revolute-chain --case four-bar-ladder-hinged \
  --min-n 8192 --max-n 16384 --out bench/results/scaling_16384.csv
tail -n +2 bench/results/scaling_16384.csv >> bench/results/scaling.csv
rm bench/results/scaling_16384.csv
python3 bench/peer_scaling.py "$@"
.venv/bin/python bench/python_setup.py
.venv/bin/python bench/plot_scaling.py
