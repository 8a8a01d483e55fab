#!/usr/bin/env bash
# codyna import never writes over its input (issue 20), for URDF and MJCF inputs named in every
# way that reaches the same file: the same name, a path through another folder, a symbolic link, a
# hard link; each refused with exit 1, the input byte for byte unchanged and nothing else written.
# A refused import (a tendon that acts) writes no output either.
# usage: import_never_over_input.sh CODYNA SOURCE_DIR WORK_DIR
set -uo pipefail
codyna="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work/sub"; cd "$work"
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
data="$src/tests/data/import"

if "$codyna" import "$data/arm7.urdf" --out probe.json > /dev/null 2> probe.txt || ! grep -q "built without" probe.txt; then :; else
  echo "import_never_over_input: this codyna was built without urdfdom; skipped"; exit 77
fi

# refused CODE-1 for: the input file FILE reached as OUT; FILE unchanged, no other file appears
refused() {
  local file="$1" out="$2"; shift 2
  local sum0; sum0=$(sha256sum "$file" | cut -d' ' -f1)
  local before; before=$(find . ! -name out.txt ! -name err.txt | sort)
  "$codyna" import "$file" "$@" --out "$out" > out.txt 2> err.txt
  local rc=$?
  [ "$rc" -eq 1 ] || fail "import $file --out $out exited $rc, expected 1"
  grep -qF "this is the input file" err.txt || fail "import $file --out $out: no 'this is the input file': $(cat err.txt)"
  [ "$(sha256sum "$file" | cut -d' ' -f1)" = "$sum0" ] || fail "$file changed by import --out $out"
  [ "$(find . ! -name out.txt ! -name err.txt | sort)" = "$before" ] || fail "import --out $out left files: $(find . | sort)"
  rm -f out.txt err.txt
}

cp "$data/arm7.urdf" arm7.urdf
refused arm7.urdf arm7.urdf
refused arm7.urdf sub/../arm7.urdf
refused arm7.urdf "$work/arm7.urdf"
ln -s arm7.urdf arm7_link.json
refused arm7.urdf arm7_link.json
ln arm7.urdf arm7_hard.json
refused arm7.urdf arm7_hard.json
rm -f arm7_link.json arm7_hard.json

if "$codyna" import "$data/four_bar_connect.xml" --out probe.json > /dev/null 2>&1; then
  cp "$data/four_bar_connect.xml" four_bar.xml
  refused four_bar.xml four_bar.xml
  refused four_bar.xml ./sub/../four_bar.xml
  ln four_bar.xml four_bar_hard.json
  refused four_bar.xml four_bar_hard.json
  rm -f four_bar_hard.json
  # a tendon with a spring changes the dynamics: refused, naming it, and nothing written
  "$codyna" import "$data/tendon_spring.xml" --out ts.json > out.txt 2> err.txt
  rc=$?
  [ "$rc" -eq 1 ] || fail "tendon_spring.xml imported (exit $rc)"
  grep -qF "tendons (changes the dynamics: refused): tendons with stiffness, damping, friction or limits have no codyna equivalent: coupling" out.txt ||
    fail "no tendons line: $(cat out.txt)"
  grep -qF -- "(to import without them: --ignore tendons)" err.txt || fail "no --ignore tendons advice: $(cat err.txt)"
  [ ! -e ts.json ] || fail "ts.json written by a refused import"
  "$codyna" import "$data/tendon_spring.xml" --ignore tendons --out ts.json > out.txt 2> err.txt || fail "--ignore tendons: $(cat err.txt)"
  grep -qF "tendons (changes the dynamics; ignored by --ignore tendons)" out.txt || fail "no ignored tendons line: $(cat out.txt)"
else
  echo "import_never_over_input: no MJCF import in this build; MJCF checks skipped"
fi

if [ "$fails" -eq 0 ]; then echo "import_never_over_input: all checks passed"; else echo "import_never_over_input: $fails failed"; exit 1; fi
