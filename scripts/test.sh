#!/usr/bin/env bash
# The whole test suite, from a fresh machine: Debian packages, a Release build (profile-guided, as
# scripts/demo.sh builds it: cmake/Pgo.cmake) and every test
# (unit, statistical, whole-image comparisons, MPI with 2 and 3 ranks), the Python module's pytest
# suite in the repository's .venv, then an ASan+UBSan build
# with Clang of the whole tree running the unit tests, then a short run of each libFuzzer target (fuzz/run.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup-deps.sh
jobs=$(nproc)

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DEMBER_PGO=ON >/dev/null
cmake --build build -j "$jobs"
ctest --test-dir build --output-on-failure -j "$jobs"

# The Python module (pyproject.toml), built into the repository's .venv, and its pytest suite.
[ -x .venv/bin/pip ] || python3 -m venv .venv
.venv/bin/pip install -q --disable-pip-version-check pytest OpenEXR matplotlib
.venv/bin/pip install -q --disable-pip-version-check -Ccmake.define.EMBER_LTO=OFF .
EMBER_BINARY="$PWD/build/app/ember" .venv/bin/python -m pytest -q python/tests
# The examples run as a user would run them, and check what they show.
.venv/bin/python examples/ior_sweep.py --out build/examples/ior-sweep

# The sanitizer build uses Clang, so that the whole tree, tests included, builds with both compilers.
if [ "${EMBER_SKIP_SANITIZERS:-0}" != 1 ]; then
  CXX=clang++-14 cmake -S . -B build-sanitize -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DEMBER_SANITIZE=ON >/dev/null
  cmake --build build-sanitize -j "$jobs"
  # intercept_tls_get_addr=0: clang 14's LeakSanitizer misreads glibc 2.36's dynamic TLS once a
  # dlopened library (the OpenImageIO plugin) enlarges it, and crashes at exit scanning a bogus range
  # (google/sanitizers#1322); heap, stacks and static TLS are still scanned.
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:intercept_tls_get_addr=0 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    LSAN_OPTIONS=suppressions="$PWD/scripts/lsan-suppressions.txt" ctest --test-dir build-sanitize --output-on-failure -j "$jobs" -L unit
fi

if [ "${EMBER_SKIP_FUZZ:-0}" != 1 ]; then
  fuzz/run.sh "${EMBER_FUZZ_SECONDS:-20}"
fi
