#!/usr/bin/env bash
# Installs what odyn needs on Debian 12 and prepares .venv. Idempotent: when everything is already
# there it touches neither apt nor pip.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

packages=(
  build-essential cmake ninja-build ccache pkg-config git ca-certificates
  libeigen3-dev libsuitesparse-dev catch2 libbenchmark-dev
  python3 python3-venv python3-dev
)

# --- System packages -----------------------------------------------------------------------------
missing=()
for pkg in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null || true)
  [[ $status == "install ok installed" ]] || missing+=("$pkg")
done

if ((${#missing[@]})); then
  if [[ $(id -u) -ne 0 ]]; then
    echo "setup.sh: missing Debian packages: ${missing[*]}" >&2
    echo "setup.sh: run as root, or: sudo apt-get install -y ${missing[*]}" >&2
    exit 1
  fi
  echo "setup.sh: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -q
  apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# --- Python virtual environment (for the coming Python bindings and their tests) -----------------
# Debian's interpreter, not whatever python3 comes first on PATH: it matches python3-dev.
python=/usr/bin/python3
[[ -x $python ]] || python=python3
if ! .venv/bin/python -c 'import sys' >/dev/null 2>&1; then
  echo "setup.sh: creating .venv"
  rm -rf .venv
  "$python" -m venv .venv
fi
if ! .venv/bin/python -c 'import numpy, pytest, matplotlib' >/dev/null 2>&1; then
  echo "setup.sh: installing numpy pytest matplotlib into .venv"
  .venv/bin/python -m pip install -q --disable-pip-version-check numpy pytest matplotlib
fi
