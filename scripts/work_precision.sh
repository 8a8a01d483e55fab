#!/usr/bin/env bash
# Regenerates the work-precision study (docs/work-precision.md): builds the bench
# program if needed, runs it over every problem and integrator, writes the CSV and
# the plots into docs/work_precision/. Extra arguments go to the program
# (e.g. --kmax 12 --repeats 1 --problems a01).
set -euo pipefail
cd "$(dirname "$0")/.."
[ -d build ] || cmake -S . -B build -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build build -j "${CODYNA_JOBS:-2}" --target codyna_work_precision
mkdir -p docs/work_precision
build/bin/codyna_work_precision --repeats 3 --max-cpu 20 --csv docs/work_precision/work_precision.csv \
  --table docs/work_precision/table.md "$@" \
  | tee docs/work_precision/work_precision.txt
/usr/bin/python3 scripts/plot_work_precision.py docs/work_precision/work_precision.csv docs/work_precision
