#!/usr/bin/env bash
# Builds the core library, the CLI and the core tests with AddressSanitizer +
# UndefinedBehaviorSanitizer into build-asan/ (-O1, assertions on) and runs the
# core GoogleTest suite and the CLI shell tests there (ctest -L "core|cli").
# Any ASan error, leak or undefined behaviour fails the test that hit it.
# Extra arguments go to ctest (e.g. -R ModelFile, -E cli.octave).
# CODYNA_JOBS (default 2) sets the build and test parallelism.
# See docs/reliability.md.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/deps.sh
jobs="${CODYNA_JOBS:-2}"
# -O1 -g0 and no -DNDEBUG: faster to build, and Eigen's size assertions stay
# on (they found an autodiff bug that the NDEBUG build could not see)
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCODYNA_SANITIZE=ON \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g0" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g0" \
  -DCODYNA_BUILD_GUI=OFF -DCODYNA_BUILD_BENCH=OFF > build-asan.log.tmp 2>&1 \
  || { cat build-asan.log.tmp; rm -f build-asan.log.tmp; exit 1; }
rm -f build-asan.log.tmp
# Only what the selected tests run: the CLI and the core test executable (the
# Octave MEX is left out: an instrumented MEX cannot load into Octave).
cmake --build build-asan -j "$jobs" --target codyna codyna_core_tests

# LeakSanitizer is on; UBSan stops at the first finding with a stack trace.
# Settings already in the environment are kept and take precedence.
export ASAN_OPTIONS="detect_leaks=1${ASAN_OPTIONS:+:$ASAN_OPTIONS}"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1${UBSAN_OPTIONS:+:$UBSAN_OPTIONS}"
cd build-asan
ctest --output-on-failure -j "$jobs" -L "core|cli" "$@"
