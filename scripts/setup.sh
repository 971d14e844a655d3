#!/usr/bin/env bash
# Installs what odyn needs on Debian 12 and prepares .venv. Idempotent: when everything is already
# there it touches neither apt nor pip.
#   bash scripts/setup.sh                 everything, the odyn Python package included
#   bash scripts/setup.sh --no-package    the dependencies only (test.sh builds the package
#                                         beside its C++ builds)
#   bash scripts/setup.sh --tests ...     also what scripts/test.sh needs beyond that: clang, whose
#                                         sanitizers build the test suite, and Sphinx
#   bash scripts/setup.sh --docs ...      also what scripts/docs.sh needs: Sphinx with MyST
# ODYN_PACKAGE_CXX=<compiler> builds the Python package and the engine's module with that compiler
# (default: CMake's choice, g++); scripts/test.sh uses clang++-15, several times faster on them.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
package=1
docs=0
packages=(
  build-essential cmake ninja-build ccache pkg-config git ca-certificates
  libeigen3-dev libsuitesparse-dev catch2 libbenchmark-dev
  python3 python3-venv python3-dev
)
for arg in "$@"; do
  case $arg in
    --no-package) package=0 ;;
    --tests) packages+=(clang-15); docs=1 ;;  # its ASan and UBSan runtimes come with it
    --docs) docs=1 ;;
    *) echo "setup.sh: unknown option $arg (see the comment at its top)" >&2; exit 1 ;;
  esac
done

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

# --- Python virtual environment (the Python bindings and their tests) -----------------------------
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

# The package's build backend: the venv's scikit-build-core and pybind11 (no build isolation, so
# no download per build).
if ! .venv/bin/python -c 'import scikit_build_core, pybind11' >/dev/null 2>&1; then
  echo "setup.sh: installing scikit-build-core pybind11 into .venv"
  .venv/bin/python -m pip install -q --disable-pip-version-check scikit-build-core pybind11
fi

# The documentation site's builder (scripts/docs.sh).
if ((docs)) && ! .venv/bin/python -c 'import sphinx, myst_parser' >/dev/null 2>&1; then
  echo "setup.sh: installing sphinx myst-parser into .venv"
  .venv/bin/python -m pip install -q --disable-pip-version-check "sphinx>=7.2" "myst-parser>=2"
fi

((package)) || exit 0

# --- The Python package odyn (pip install .) -----------------------------------------------------
# Built in build-python/, so a rebuild compiles only what changed; skipped when the sources are
# those of the last install.
export CCACHE_BASEDIR=$PWD CCACHE_NOHASHDIR=true
pip_install() { .venv/bin/python -m pip install -q --disable-pip-version-check --no-build-isolation "$@"; }
if [[ -n ${ODYN_PACKAGE_CXX:-} ]]; then export CXX=$ODYN_PACKAGE_CXX; fi
# CMake cannot change a configured build's compiler: another compiler starts build-python/ afresh.
if [[ -d build-python && $(cat build-python/compiler 2>/dev/null) != "${CXX:-default}" ]]; then
  rm -rf build-python
fi
mkdir -p build-python && echo "${CXX:-default}" > build-python/compiler
stamp=.venv/odyn-sources.sha256
sources=$( (echo "compiler: ${CXX:-default}"; find pyproject.toml CMakeLists.txt cmake include \
             python -type f ! -name '*.pyc' -print0 | sort -z | xargs -0 sha256sum) | sha256sum)
if [[ ! -f $stamp || $(cat "$stamp") != "$sources" ]] || ! .venv/bin/python -c 'import odyn' 2>/dev/null; then
  echo "setup.sh: pip install . (the odyn Python package)"
  pip_install .
  echo "$sources" > "$stamp"
fi

# --- The engine's module odyn_engine: a module of one's own, built against the installed odyn ---
# (examples/python/odyn_engine/), as a project outside odyn builds one. The engine's examples,
# scene and tests use it. Rebuilt when it or odyn changed.
stamp=.venv/odyn-engine-sources.sha256
sources=$( (cat .venv/odyn-sources.sha256; find examples/python/odyn_engine \
            examples/engine_model.hpp -type f -print0 | sort -z | xargs -0 sha256sum) | sha256sum)
if [[ ! -f $stamp || $(cat "$stamp") != "$sources" ]] || ! .venv/bin/python -c 'import odyn_engine' 2>/dev/null; then
  echo "setup.sh: pip install examples/python/odyn_engine (the engine's module)"
  command -v ccache >/dev/null && export CMAKE_CXX_COMPILER_LAUNCHER=ccache
  pip_install --config-settings=build-dir="$PWD/build-python/odyn_engine" examples/python/odyn_engine
  echo "$sources" > "$stamp"
fi
