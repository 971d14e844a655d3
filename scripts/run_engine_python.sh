#!/usr/bin/env bash
# Runs the engine scene (examples/engine.json) through the Python command line: writes engine.csv
# (the columns of examples/engine.cpp) and the paper's two figures in the repository root.
# Extra arguments go to `odyn run`: scripts/run_engine_python.sh --h 5e-5
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

bash scripts/setup.sh
.venv/bin/odyn run examples/engine.json --out engine.csv --figures . "$@"
