#!/usr/bin/env bash
# codyna against MuJoCo on the same mechanisms (docs/performance.md): builds
# the benchmark (Release, -j2, without the GUI) into ${CODYNA_BUILD_DIR:-build}
# and runs it; arguments go to the benchmark, e.g.
#   scripts/bench_mujoco.sh --table perf_table.md
#   scripts/bench_mujoco.sh --models chain_7,tree28 --benchmark_filter='^fd/'
set -euo pipefail
cd "$(dirname "$0")/.."
build="${CODYNA_BUILD_DIR:-build}"
log="$(mktemp)"
trap 'rm -f "$log"' EXIT
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DCODYNA_BUILD_GUI=OFF > "$log" 2>&1 || { cat "$log"; exit 1; }
cmake --build "$build" -j "${CODYNA_JOBS:-2}" --target codyna_bench_mujoco
"$build/bin/codyna_bench_mujoco" "$@"
