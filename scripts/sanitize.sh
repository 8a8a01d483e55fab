#!/usr/bin/env bash
# Builds the core library, the CLI, the core tests and the loader's fuzz target
# with clang, AddressSanitizer + UndefinedBehaviorSanitizer (+ libFuzzer's
# coverage of the core, CODYNA_FUZZ) into build-asan/ (-O2, assertions on), and runs the
# core GoogleTest suite and the CLI shell tests there (ctest -L "core|cli"),
# then every offscreen GUI test program (tests/gui/*_test.cpp: they drive the
# widgets as a person does; the monkey test with 5 seeds x 4000 random events).
# Any ASan error, leak or undefined behaviour fails the test that hit it.
# The same build then serves scripts/fuzz.sh (CODYNA_FUZZ_BUILD=build-asan);
# .ci/run has it run beside the GUI tests (CODYNA_SANITIZE_FUZZ=60). Extra arguments go to ctest (e.g. -R ModelFile).
# CODYNA_JOBS (default 2) sets the build and test parallelism.
# See docs/reliability.md.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/deps.sh
command -v clang++ > /dev/null || { echo "sanitize: clang++ not found (Debian: clang libclang-rt-14-dev)" >&2; exit 1; }
jobs="${CODYNA_JOBS:-2}"
build=build-asan
# A directory configured by another compiler or set of options (an older
# gcc-based build-asan) cannot be reused: start it afresh.
if [ -f "$build/CMakeCache.txt" ] && ! grep -q '^CODYNA_FUZZ:BOOL=ON' "$build/CMakeCache.txt"; then
  rm -rf "$build"
fi
# -O2 -g0 and no -DNDEBUG: Eigen's size assertions stay on (they found an
# autodiff bug that an NDEBUG build could not see). -O2 rather than -O1: at -O1
# clang leaves Eigen's small fixed-size products as calls, each access checked
# (docs/performance.md, "Build time")
# a new tree is made with Ninja when it is installed (an existing one keeps its generator)
generator=()
if [ ! -f "$build/CMakeCache.txt" ] && command -v ninja > /dev/null; then generator=(-G Ninja); fi
CC=clang CXX=clang++ cmake -S . -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCODYNA_FUZZ=ON \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g0" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O2 -g0" \
  -DCODYNA_BUILD_GUI=ON -DCODYNA_BUILD_BENCH=OFF > "$build.log.tmp" 2>&1 \
  || { cat "$build.log.tmp"; rm -f "$build.log.tmp"; exit 1; }
rm -f "$build.log.tmp"
# Only what the selected tests run, and the fuzz target (the Octave MEX is
# left out: an instrumented MEX cannot load into Octave).
# One build command for all of them: Ninja then keeps both cores busy to the end.
gui_tests=$(cd tests/gui && ls *_test.cpp | sed 's/\.cpp$//')
# shellcheck disable=SC2086
cmake --build "$build" -j "$jobs" --target codyna codyna_core_tests model_loader_fuzz ubsan_probe $gui_tests

# LeakSanitizer is on; UBSan stops at the first finding with a stack trace.
# Settings already in the environment are kept and take precedence.
export ASAN_OPTIONS="detect_leaks=1${ASAN_OPTIONS:+:$ASAN_OPTIONS}"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1${UBSAN_OPTIONS:+:$UBSAN_OPTIONS}"
cd "$build"
# The sedan's longest maneuver runs (2-3 minutes each here, 5-10 s in the Release run of
# scripts/test.sh, which keeps them) are left out: the same code runs here on shorter sedan
# maneuvers (step steer, sine with dwell at 0.3 g, constant radius, constant speed, the tall
# car's rollover) and on the single-track car.
slow_here='^(Maneuver\.SweptSineOnTheSedanIsItsLinearModelAtSmallSteer|YawControl\.TheSedanSpinsOutInTheSineWithDwellWithoutItAndPassesWithIt|ManeuverRamp\.TheSedansFishhookKeepsItsWheelsOnTheRoadAndItsLoadsAreItsSensors|ManeuverRamp\.TheFishhooksRollRateDwellEndsWhereTheRollRateFallsBack|Maneuver\.AutoGoesOnStiffWhereItsChoiceFailsInTheSedansSineWithDwell|Maneuver\.TheSedansDoubleLaneChangeErrorAndConesAreTheRunsOwn|Maneuver\.TheSedanTooFastForTheDoubleLaneChangeHitsTheCones)$'
ctest --output-on-failure -j "$jobs" -L "core|cli" -E "$slow_here" "$@"
# the GUI under the sanitizers: Qt and the libraries under it are not
# instrumented; what they keep until exit (fonts, the platform plugin) is
# suppressed by name in tests/data/lsan_qt.supp, nothing of codyna's
# (only in the full run: extra arguments select among the core and CLI tests)
# CODYNA_SANITIZE_FUZZ=SECONDS runs scripts/fuzz.sh on this build beside them
# (-seed=1; .ci/run): the GUI tests run one at a time, so the second core is free.
if [ $# -eq 0 ]; then
  fuzz_pid=
  if [ -n "${CODYNA_SANITIZE_FUZZ:-}" ]; then
    ( cd .. && CODYNA_FUZZ_BUILD="$build" ./scripts/fuzz.sh "$CODYNA_SANITIZE_FUZZ" -seed=1 ) > fuzz.log 2>&1 &
    fuzz_pid=$!
  fi
  gui_rc=0
  LSAN_OPTIONS="suppressions=$PWD/../tests/data/lsan_qt.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}" \
    ctest --output-on-failure -j 1 -R '^gui\.[a-z0-9_]+_test$' || gui_rc=$?
  fuzz_rc=0
  if [ -n "$fuzz_pid" ]; then
    wait "$fuzz_pid" || fuzz_rc=$?
    cat fuzz.log
  fi
  [ "$gui_rc" -eq 0 ] && [ "$fuzz_rc" -eq 0 ] || exit 1
fi
