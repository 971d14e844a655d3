#!/usr/bin/env bash
# The same as scripts/run_engine.sh (the engine scene through the Python command line), kept
# under its earlier name.
set -euo pipefail
exec bash "$(dirname "${BASH_SOURCE[0]}")/run_engine.sh" "$@"
