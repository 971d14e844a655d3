#!/usr/bin/env bash
# Full check: ASan/UBSan build + Catch2 tests (allocation count included), Release examples,
# install + downstream consumer, the Python package and its tests. Exits non-zero on the first
# failure.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
root=$PWD
jobs=$(nproc)

# Let ccache hit across checkouts (CI builds in a fresh clone) and across build directories.
export CCACHE_BASEDIR=$root CCACHE_NOHASHDIR=true

section() { printf '\n===== %s =====\n' "$*"; }

# configure <build dir> <cmake args...>: Ninja for a new tree; an existing tree keeps its generator.
configure() {
  local dir=$1; shift
  local gen=(-G Ninja)
  [[ -f $dir/CMakeCache.txt ]] && gen=()
  cmake -S . -B "$dir" "${gen[@]}" "$@"
}

section "Setup"
bash scripts/setup.sh --no-package

# Each test compiles once: the Catch2 suite in the sanitizer build, the examples (the C++ twins
# of the Python tests) and the installed package's consumer in Release, and the Python package.
# Template instantiation makes each translation unit cost tens of seconds of CPU, so the builds
# run side by side and keep both cores busy: the Python package beside the sanitizer build, the
# test run and the one-file downstream build beside the Release build.
trap 'jobs -p | xargs -r kill 2>/dev/null' EXIT

# finish <pid> <log> <what>: waits for a background step, shows its output, stops on failure.
finish() {
  local rc=0
  wait "$1" || rc=$?
  cat "$2"
  if ((rc != 0)); then echo "test.sh: $3 failed (exit $rc)" >&2; exit "$rc"; fi
}

section "Python package (pip install .), built beside the C++ builds"
# At a lower priority: the sanitizer build is the longest chain (its test run waits for it), so
# it gets the cores first and the package fills the gaps.
mkdir -p build
python_log=build/python-package.log
CMAKE_BUILD_PARALLEL_LEVEL=$jobs nice -n 10 bash scripts/setup.sh >"$python_log" 2>&1 &
python_pid=$!

section "ASan + UBSan build of the tests (build-asan/)"
# -Og -g1 (line tables: enough for sanitizer stack traces) compiles twice as fast as -O1 -g here.
configure build-asan -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-Og -g1" -DODYN_SANITIZE=ON \
  -DODYN_BUILD_TESTS=ON -DODYN_BUILD_EXAMPLES=OFF -DODYN_BUILD_BENCH=OFF
cmake --build build-asan -j "$jobs"

section "Release build of the examples (build/); the ASan + UBSan tests and downstream beside it"
configure build -DCMAKE_BUILD_TYPE=Release -DODYN_SANITIZE=OFF \
  -DODYN_BUILD_TESTS=ON -DODYN_BUILD_EXAMPLES=ON -DODYN_BUILD_BENCH=ON
asan_log=build-asan/odyn_tests.log
(
  export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}
  export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
  ctest --test-dir build-asan --output-on-failure
) >"$asan_log" 2>&1 &
asan_pid=$!
# The library is header-only: the configured tree installs before anything is built.
rm -rf build/install build/downstream
cmake --install build --prefix build/install >/dev/null
downstream_log=build/downstream.log
(
  launcher=()
  command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  cmake -S tests/downstream -B build/downstream -G Ninja "${launcher[@]}" \
    -DCMAKE_PREFIX_PATH="$root/build/install"
  cmake --build build/downstream -j 1
  ./build/downstream/odyn_downstream
) >"$downstream_log" 2>&1 &
downstream_pid=$!
cmake --build build -j "$jobs" --target engine slider_crank_planar four_bar andrews

section "ASan + UBSan tests (the Catch2 suite, the allocation count included)"
finish "$asan_pid" "$asan_log" "the ASan + UBSan tests"

section "Install + downstream find_package(odyn)"
finish "$downstream_pid" "$downstream_log" "the downstream build"

section "Python package"
finish "$python_pid" "$python_log" "pip install . (the odyn Python package)"

# Python tests: the twins of the C++ examples and of the downstream program need the above.
py_dirs=()
for d in python/tests tests/python; do
  if [[ -d $d ]] && find "$d" -name 'test_*.py' -o -name '*_test.py' | grep -q .; then
    py_dirs+=("$d")
  fi
done
if ((${#py_dirs[@]})) && [[ -x .venv/bin/python ]]; then
  section "Python tests"
  rc=0
  .venv/bin/python -m pytest -q "${py_dirs[@]}" || rc=$?
  if ((rc == 5)); then echo "pytest: no tests collected"; elif ((rc != 0)); then exit "$rc"; fi
fi

section "All checks passed"
