#!/usr/bin/env python3
"""A test of the docs harness: one shown number changed in a copy of a page must fail it.

usage: catches_a_change.py CODYNA SOURCE_DIR WORK_DIR

Copies docs/linearization.md, changes the trim torque it shows (53.0037 -> 53.1037), runs
run_docs.py on the copy and requires exit code 1 and a report that names the page, the line and
the difference (the number shown against the number printed).
"""
import os
import subprocess
import sys


def main(argv):
    codyna, source, work = argv[1], os.path.abspath(argv[2]), os.path.abspath(argv[3])
    os.makedirs(work, exist_ok=True)
    with open(os.path.join(source, "docs", "linearization.md"), encoding="utf-8") as f:
        lines = f.read().split("\n")
    shown, changed = "  torque = 53.0037", "  torque = 53.1037"
    hits = [i for i, l in enumerate(lines) if l == shown]
    if len(hits) != 1:
        print(f"FAIL: docs/linearization.md shows {shown!r} {len(hits)} times, expected once")
        return 1
    line = hits[0] + 1
    lines[hits[0]] = changed
    page = os.path.join(work, "linearization.md")
    with open(page, "w", encoding="utf-8") as f:
        f.write("\n".join(lines))
    harness = os.path.join(os.path.dirname(os.path.abspath(__file__)), "run_docs.py")
    p = subprocess.run([sys.executable, harness, codyna, source, os.path.join(work, "run"), page],
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=600)
    out = p.stdout.decode("utf-8", "replace")
    print(out)
    # the harness names a page inside the source tree by its relative path (a build folder may be there)
    name = os.path.relpath(page, source) if page.startswith(source + os.sep) else page
    want = [f"{name}:{line}: number 53.1037 shown, 53.0037 printed", f"shown:   {changed}",
            f"printed: {shown}", "1 difference(s)"]
    missing = [w for w in want if w not in out]
    if p.returncode != 1 or missing:
        print(f"FAIL: the harness exited {p.returncode} (expected 1); missing from its report: {missing}")
        return 1
    print(f"the changed number on line {line} of the copy was caught, with the page, the line and the difference")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
