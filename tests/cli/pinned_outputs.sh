#!/usr/bin/env bash
# codyna linearize and codyna simulate give the same outputs as the binary the pins
# were made from (tests/data/pinned_outputs.json): exit codes, stdout and stderr
# (wall times normalised), the set of files each run writes, and every array and
# text in them by sha256 (MAT v5/v7.3 variables, HDF5 datasets and attributes, CSV
# and .m text). The list of runs and the hashing are in tests/cli/pin_outputs.py,
# which also regenerates the pins (see its header).
# usage: pinned_outputs.sh CODYNA SOURCE_DIR WORK_DIR
set -euo pipefail
codyna=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
PY=/usr/bin/python3; [ -x "$PY" ] || PY=python3
"$PY" "$src/tests/cli/pin_outputs.py" --check "$codyna" "$src" "$src/tests/data/pinned_outputs.json" "$work"
