#!/usr/bin/env bash
# Configures and builds codyna into build/ (Release, -j2; Ninja when installed).
#   scripts/build.sh [cmake args...]        everything: the CLI, the GUI, the tests, the
#                                           benchmarks, the Python module (scripts/test.sh)
#   scripts/build.sh --cli [cmake args...]  the command-line program `codyna` and what it links
#                                           only (scripts/demo.sh)
# A tree built with --cli and then without builds only the rest: the objects already made are
# made with the same flags and stay. CODYNA_JOBS (default 2) sets the parallelism.
set -euo pipefail
cd "$(dirname "$0")/.."
cli=0
if [ "${1:-}" = "--cli" ]; then cli=1; shift; fi
args=(-DCMAKE_BUILD_TYPE=Release)
if [ ! -f build/CMakeCache.txt ]; then
  # a new tree: Ninja schedules the objects of every target together (make waits for each
  # target's dependencies to finish); an existing tree keeps the generator it was made with
  if command -v ninja > /dev/null; then args+=(-G Ninja); fi
  # clang when installed (scripts/deps.sh installs it) and no compiler is asked for (CC, CXX or
  # -DCMAKE_CXX_COMPILER=...): clang 14 compiles codyna in about half GCC 12's CPU time, and its
  # Release build writes the same bytes (cli.pinned_outputs passes with either; docs/performance.md)
  if [ -z "${CXX:-}" ] && [ -z "${CC:-}" ] && command -v clang++ > /dev/null && command -v clang > /dev/null; then
    export CC=clang CXX=clang++
  fi
  # the first --cli configuration leaves the rest out; a later full build turns it on
  if [ "$cli" = 1 ]; then
    args+=(-DCODYNA_BUILD_GUI=OFF -DCODYNA_BUILD_TESTS=OFF -DCODYNA_BUILD_BENCH=OFF -DCODYNA_BUILD_PYTHON=OFF)
  fi
fi
if [ "$cli" = 0 ]; then
  args+=(-DCODYNA_BUILD_GUI=ON -DCODYNA_BUILD_TESTS=ON -DCODYNA_BUILD_BENCH=ON -DCODYNA_BUILD_PYTHON=ON)
fi
cmake -S . -B build "${args[@]}" "$@" > build.log.tmp 2>&1 || { cat build.log.tmp; rm -f build.log.tmp; exit 1; }
rm -f build.log.tmp
if [ "$cli" = 1 ]; then
  cmake --build build -j "${CODYNA_JOBS:-2}" --target codyna
else
  cmake --build build -j "${CODYNA_JOBS:-2}"
fi
