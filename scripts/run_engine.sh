#!/usr/bin/env bash
# Builds and runs the engine example; writes engine.csv in the repository root.
# Extra arguments are passed on to the example: scripts/run_engine.sh --some-flag value
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

bash scripts/setup.sh
export CCACHE_BASEDIR=$PWD CCACHE_NOHASHDIR=true  # as in test.sh, so the two share ccache entries
gen=(-G Ninja)
[[ -f build/CMakeCache.txt ]] && gen=()  # an existing tree keeps its generator
cmake -S . -B build "${gen[@]}" -DODYN_BUILD_EXAMPLES=ON
cmake --build build --target engine -j "$(nproc)"
./build/examples/engine --out engine.csv "$@"
