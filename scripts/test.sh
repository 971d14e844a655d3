#!/usr/bin/env bash
# Full check: ASan/UBSan build + Catch2 tests (allocation count included), the Release engine
# example, install + downstream consumer, the Python package and its tests (the documentation's
# examples included), the documentation site. Exits non-zero on a failure.
# The Catch2 suite's long runs (tests/CMakeLists.txt, ODYN_LONG_RUN_TESTS) are compiled at -O1
# without the sanitizers, its other files at -O0 with them.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
root=$PWD
jobs=$(nproc)
if (($#)); then
  echo "test.sh: no options (see the comment at its top)" >&2
  exit 1
fi

# Let ccache hit across checkouts (CI builds in a fresh clone) and across build directories.
export CCACHE_BASEDIR=$root CCACHE_NOHASHDIR=true

# Each section says when it starts (seconds since CI began, or since this script began), so that
# a run that nears CI's limit shows where its time went.
start=${ODYN_CI_START:-$(date +%s)}
stamp() { echo "$(($(date +%s) - start)) s"; }
section() { printf '\n===== %s (at %s) =====\n' "$*" "$(stamp)"; }
# The builds beside the sanitizer build log to files, shown when they are waited for; their
# milestones also go to the script's own stderr at once, so that a run cut short shows them.
exec 3>&2
milestone() { echo "$*" | tee -a /dev/fd/3; }  # -a: never truncate a log file behind fd 3

# configure <build dir> <cmake args...>: Ninja for a new tree; an existing tree keeps its generator.
configure() {
  local dir=$1; shift
  local gen=(-G Ninja)
  [[ -f $dir/CMakeCache.txt ]] && gen=()
  cmake -S . -B "$dir" "${gen[@]}" "$@"
}

# The sanitizer build's tree. A tree that another compiler configured starts afresh. Line tables
# are enough for sanitizer stack traces. -O1 is the long runs' level; the other files are
# compiled at -O0.
configure_sanitizer_build() {
  local clang=clang++-15
  if [[ -f build-asan/CMakeCache.txt ]] && ! grep -q "^CMAKE_CXX_COMPILER:.*$clang" \
      build-asan/CMakeCache.txt; then
    rm -rf build-asan
  fi
  configure build-asan -DCMAKE_CXX_COMPILER="$clang" -DCMAKE_BUILD_TYPE=Debug \
    -DCMAKE_CXX_FLAGS_DEBUG="-O1 -gline-tables-only" -DODYN_SANITIZE=ON \
    -DODYN_TEST_UNOPTIMIZED_FLAGS=-O0 \
    -DODYN_BUILD_TESTS=ON -DODYN_BUILD_EXAMPLES=OFF -DODYN_BUILD_BENCH=OFF
}

# run_sanitizer_tests <ctest args...>: the sanitizer build's tests with ctest; names the slowest
# cases and repeats the failures last.
run_sanitizer_tests() {
  local rc=0
  (
    export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}
    export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
    ctest --test-dir build-asan --output-on-failure -j "$jobs" "$@"  # the suite in shares
  ) || rc=$?
  # The sanitizer run is the longest step of CI: name the cases that cost it most.
  echo "Slowest cases under the sanitizers (seconds):"
  grep -hE '^[0-9]+\.[0-9]+ s: ' build-asan/Testing/Temporary/LastTest.log |
    sort -rn | head -n 12 || true
  if ((rc != 0)); then
    # The run's log (every case with its time) is long enough to be cut where CI shows only its
    # ends: repeat the failures last, without the timings.
    section "The sanitizer run's failures, again"
    grep -vE '^[0-9]+\.[0-9]+ s: ' build-asan/Testing/Temporary/LastTest.log |
      grep -B 14 -A 16 -E 'FAILED:|ERROR: AddressSanitizer|runtime error:' | tail -n 200 || true
    exit "$rc"
  fi
}

section "Setup"
bash scripts/setup.sh --no-package --tests

# Each test compiles once: the Catch2 suite in the sanitizer build, the engine example (the C++
# twin of the Python tests) and the installed package's consumer in Release, and the Python
# package.
# Template instantiation makes each translation unit cost minutes of CPU. The sanitizer build is
# Clang's: GCC 12 instantiates this library's templates several times slower, and more than
# linearly in a unit's size (a third of its time goes to walking lists of type variants,
# get_qualified_type), so that one unit of the tests took it over an hour. Clang's back end at
# -O1 pays for the volume instead, five times over with the sanitizers: the whole suite took it
# over an hour. At -O0 it takes 10 minutes, and the suite runs about 10 times as long (the long
# runs, 100 times). So the sanitizer build compiles at -O0 the files whose cases run in seconds
# to a minute even so (odyn_tests), and at -O1 without the sanitizers the long runs
# (odyn_tests_long: about 8 minutes of CPU to build, under a minute to run), in one build
# (docs/benchmarks.md, "Compile time").
# The Python package and the engine's module, which instantiate every element and analysis, are
# Clang's too (ODYN_PACKAGE_CXX): it built one of their units in 306 s of CPU where GCC 12 took
# over 850. GCC 12 compiles the engine example and the downstream program (.ci/run adds the
# other examples and the benchmarks, the analyses' included, when its time allows). They run
# beside the sanitizer build and runs at a lower priority, two units at a time, then the Python
# tests. A unit of the tests peaks near 5 GB at -O0 and near 5 GB at -O1 (the long runs), a
# package unit near 3 GB: a machine out of memory does not fail, it crawls.
trap 'jobs -p | xargs -r kill 2>/dev/null' EXIT

# finish <pid> <log> <what>: waits for a background step, shows its output, stops on failure.
finish() {
  local rc=0
  wait "$1" || rc=$?
  cat "$2"
  if ((rc != 0)); then echo "test.sh: $3 failed (exit $rc)" >&2; exit "$rc"; fi
}

section "Beside the sanitizer build: the Python package, the Release engine, the downstream build"
mkdir -p build
python_log=build/python-package.log
# At a lower priority, they take the cores the sanitizer build and runs leave idle (a unit that
# ends before the others, a share of the tests that ends first).
(CMAKE_BUILD_PARALLEL_LEVEL=$jobs ODYN_PACKAGE_CXX=clang++-15 nice -n 10 bash scripts/setup.sh &&
  milestone "test.sh: the Python package and the engine's module built at $(stamp)") \
  >"$python_log" 2>&1 &
python_pid=$!
configure build -DCMAKE_BUILD_TYPE=Release -DODYN_SANITIZE=OFF \
  -DODYN_BUILD_TESTS=ON -DODYN_BUILD_EXAMPLES=ON -DODYN_BUILD_BENCH=ON
# The library is header-only: the configured tree installs before anything is built.
rm -rf build/install build/downstream
cmake --install build --prefix build/install >/dev/null
release_log=build/release.log
(
  while kill -0 "$python_pid" 2>/dev/null; do sleep 5; done  # after the Python package's units
  milestone "test.sh: the Release engine example from $(stamp)"
  # The engine example, which the Python tests run; CI builds the other examples when its time
  # allows (.ci/run).
  nice -n 10 cmake --build build -j "$jobs" --target engine
  launcher=()
  command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  cmake -S tests/downstream -B build/downstream -G Ninja "${launcher[@]}" \
    -DCMAKE_PREFIX_PATH="$root/build/install"
  nice -n 10 cmake --build build/downstream -j "$jobs"
  echo "Install + downstream find_package(odyn) at $(stamp):"
  ./build/downstream/odyn_downstream
  milestone "test.sh: the Release engine example and the downstream build done at $(stamp)"
) >"$release_log" 2>&1 &
release_pid=$!

# The Python tests (the twins of the C++ examples and of the downstream program) run as soon as
# the builds above are done, beside the sanitizer build, which takes longer.
py_dirs=()
for d in python/tests tests/python; do
  if [[ -d $d ]] && find "$d" -name 'test_*.py' -o -name '*_test.py' | grep -q .; then
    py_dirs+=("$d")
  fi
done
pytest_log=build/python-tests.log
(
  while kill -0 "$python_pid" 2>/dev/null || kill -0 "$release_pid" 2>/dev/null; do sleep 5; done
  if ((${#py_dirs[@]})) && [[ -x .venv/bin/python ]]; then
    milestone "test.sh: the Python tests from $(stamp)"
    rc=0
    .venv/bin/python -m pytest -q "${py_dirs[@]}" || rc=$?
    if ((rc == 5)); then echo "pytest: no tests collected"; elif ((rc != 0)); then exit "$rc"; fi
    milestone "test.sh: the Python tests done at $(stamp)"
  fi
) >"$pytest_log" 2>&1 &
pytest_pid=$!

section "ASan + UBSan build of the tests (build-asan/, Clang)"
configure_sanitizer_build
cmake --build build-asan -j "$jobs" --target odyn_tests odyn_tests_long

section "The Catch2 suite: ASan + UBSan (the allocation count included), and the long runs at -O1"
run_sanitizer_tests

section "Release engine example, install + downstream find_package(odyn)"
finish "$release_pid" "$release_log" "the Release engine example or the downstream build"

section "Python package"
finish "$python_pid" "$python_log" "pip install . (the odyn Python package)"

section "Python tests"
finish "$pytest_pid" "$pytest_log" "the Python tests"

section "Documentation site (scripts/docs.sh: warnings are errors)"
bash scripts/docs.sh

section "All checks passed"
