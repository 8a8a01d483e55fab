#!/usr/bin/env bash
# Fuzzes the model loader with libFuzzer for SECONDS (default 60):
#   scripts/fuzz.sh [SECONDS] [libFuzzer flags...]  (e.g. -fork=1 -ignore_crashes=1)
# Builds tests/fuzz/model_loader_fuzz with clang into build-fuzz/ (ASan +
# UBSan + coverage), seeds it with examples/*.json (copied at run time) and
# tests/data/fuzz_regressions/*, uses the dictionary tests/fuzz/model.dict,
# and keeps what it finds (crash-*, leak-*, timeout-*, oom-*) in
# tests/data/fuzz_findings/. Exit status: 0 when nothing was found.
# CODYNA_JOBS (default 2) sets the build parallelism; CODYNA_FUZZ_BUILD=DIR
# reuses an existing CODYNA_FUZZ build (.ci/run: build-asan of scripts/sanitize.sh).
# See docs/reliability.md.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
shift $(( $# > 0 ? 1 : 0 ))
case "$seconds" in ''|*[!0-9]*) echo "usage: $0 [SECONDS]" >&2; exit 2;; esac
./scripts/deps.sh
command -v clang++ > /dev/null || { echo "fuzz: clang++ not found (Debian: clang libclang-rt-14-dev)" >&2; exit 1; }

src="$(pwd)"
if [ -n "${CODYNA_FUZZ_BUILD:-}" ]; then
  # an existing CODYNA_FUZZ build (scripts/sanitize.sh's build-asan, as .ci/run uses)
  build="$(cd "$CODYNA_FUZZ_BUILD" && pwd)"
  grep -q '^CODYNA_FUZZ:BOOL=ON' "$build/CMakeCache.txt" \
    || { echo "fuzz: $build is not a CODYNA_FUZZ build (configure it with scripts/sanitize.sh)" >&2; exit 1; }
else
  build="$src/build-fuzz"
  # -O1 with line tables, as fuzzing builds usually are, and without NDEBUG: the
  # assert()s and Eigen's bounds checks stay on and count as findings.
  generator=()
  if [ ! -f "$build/CMakeCache.txt" ] && command -v ninja > /dev/null; then generator=(-G Ninja); fi
  CC=clang CXX=clang++ cmake -S . -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCODYNA_FUZZ=ON \
    -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" \
    -DCODYNA_BUILD_GUI=OFF -DCODYNA_BUILD_TESTS=OFF -DCODYNA_BUILD_BENCH=OFF > "$build.log.tmp" 2>&1 \
    || { cat "$build.log.tmp"; rm -f "$build.log.tmp"; exit 1; }
  rm -f "$build.log.tmp"
fi
cmake --build "$build" -j "${CODYNA_JOBS:-2}" --target model_loader_fuzz

# Corpus: the examples and the known regression inputs as seeds (copied, so
# the fuzzer's additions stay in build-fuzz/), plus what earlier runs learnt.
corpus="$build/corpus"
seeds="$build/seeds"
findings="$src/tests/data/fuzz_findings"
rm -rf "$seeds" && mkdir -p "$seeds" "$corpus" "$findings"
cp "$src"/examples/*.json "$seeds"/
if [ -d "$src/tests/data/fuzz_regressions" ]; then
  find "$src/tests/data/fuzz_regressions" -maxdepth 1 -type f ! -name '.*' ! -name 'README*' -exec cp {} "$seeds"/ \;
fi

export ASAN_OPTIONS="detect_leaks=1${ASAN_OPTIONS:+:$ASAN_OPTIONS}"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1${UBSAN_OPTIONS:+:$UBSAN_OPTIONS}"
before=$(find "$findings" -maxdepth 1 -type f | wc -l)
rc=0
"$build/bin/model_loader_fuzz" "$corpus" "$seeds" \
  -dict="$src/tests/fuzz/model.dict" \
  -max_total_time="$seconds" -max_len=65536 -rss_limit_mb=2048 -timeout=10 \
  -artifact_prefix="$findings/" -print_final_stats=1 "$@" || rc=$?
after=$(find "$findings" -maxdepth 1 -type f | wc -l)

if [ "$rc" -ne 0 ] || [ "$after" -gt "$before" ]; then
  echo "fuzz: FINDINGS (exit code $rc) in $findings:"
  ls -l "$findings"
  echo "reproduce one with: $build/bin/model_loader_fuzz FILE"
  echo "once understood, move the input to tests/data/fuzz_regressions/ as a regression test"
  exit 1
fi
echo "fuzz: nothing found in $seconds s ($(find "$corpus" -type f | wc -l) inputs in $corpus)"
