#!/usr/bin/env bash
# codyna info on every example, and bad model files: a clear message naming
# the file and the field, exit code 1, never a crash.
# usage: info_and_errors.sh CODYNA SOURCE_DIR WORK_DIR
set -euo pipefail
codyna=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*"; exit 1; }

for f in "$src"/examples/*.json; do
  "$codyna" info "$f" > "$work/info.txt" || fail "info $f"
  grep -q '^DOF' "$work/info.txt" || fail "no DOF line for $f"
done
"$codyna" info "$src/examples/bricard.json" | grep -q '^DOF          1' || fail "bricard DOF"
"$codyna" info "$src/examples/bricard.json" | grep -q '^redundant    joint_F' || fail "bricard redundant row not named"
"$codyna" info "$src/examples/andrews_squeezer.json" | grep -q '^DOF          1' || fail "andrews DOF"

expect_error() {  # file, text expected in the message
  local rc=0
  "$codyna" info "$1" > /dev/null 2> "$work/err.txt" || rc=$?
  [ "$rc" -eq 1 ] || fail "$1: exit code $rc, expected 1 ($(cat "$work/err.txt"))"
  grep -qF "$2" "$work/err.txt" || fail "$1: message '$(cat "$work/err.txt")' lacks '$2'"
  grep -qF "$1" "$work/err.txt" || fail "$1: message does not name the file"
}
printf '{"name": "x", "bodies": [,]}' > "$work/malformed.json"
expect_error "$work/malformed.json" "line 1"
sed 's/"mass": 10/"mass": -10/' "$src/examples/pendulum.json" > "$work/negative_mass.json"
expect_error "$work/negative_mass.json" "/bodies/0/mass: expected a non-negative mass"
sed 's/"type": "revolute"/"type": "hinge"/' "$src/examples/pendulum.json" > "$work/unknown_type.json"
expect_error "$work/unknown_type.json" "/joints/0/type"
sed 's/"parent": "ground"/"parent": "nowhere"/' "$src/examples/pendulum.json" > "$work/missing_body.json"
expect_error "$work/missing_body.json" "/joints/0/parent: unknown body \"nowhere\""
expect_error "$work/does_not_exist.json" "cannot open"
echo "info_and_errors: all checks passed"
