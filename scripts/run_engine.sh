#!/usr/bin/env bash
# The main job: runs the engine scene (examples/engine.json) through the odyn command line and
# writes, in the repository root, engine.csv (the columns of examples/engine.cpp) and the paper's
# two figures (engine_piston.png, engine_bearing.png); prints a summary. scripts/setup.sh first
# installs what is missing (Debian packages, .venv, the odyn package), so the script is safe to
# run twice. Extra arguments go to `odyn run`: scripts/run_engine.sh --h 5e-5 --integrator hht
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

bash scripts/setup.sh
.venv/bin/odyn run examples/engine.json --out engine.csv --figures . "$@"
