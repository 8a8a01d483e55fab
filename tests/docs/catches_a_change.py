#!/usr/bin/env python3
"""A test of the docs harness: one shown number changed in a copy of a page must fail it.

usage: catches_a_change.py CODYNA SOURCE_DIR WORK_DIR

Three changed copies, each run through run_docs.py, each required to exit 1 with a report that
names the copy, the line and the difference:

* docs/linearization.md with the trim torque a console command shows changed (53.0037 -> 53.1037):
  the number shown against the number printed;
* the co-simulation section of docs/simulation.md with the number in its Octave block's shown
  output (`text output`) changed, likewise; and the same section with the Octave block's path
  made relative again (`addpath('build/mex')`, issue 36): Octave's load-path warnings must fail it;
* docs/README.md with the number in its Python block's shown output changed, likewise.
"""
import os
import re
import subprocess
import sys

HARNESS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "run_docs.py")


def read(source, page):
    with open(os.path.join(source, page), encoding="utf-8") as f:
        return f.read().split("\n")


def only(lines, pattern, page):
    """The index of the one line matching pattern (a regex, whole line), or an error."""
    hits = [i for i, l in enumerate(lines) if re.fullmatch(pattern, l)]
    if len(hits) != 1:
        raise LookupError(f"{page} has {len(hits)} lines matching {pattern!r}, expected one")
    return hits[0]


def run_copy(codyna, source, work, name, lines):
    """Writes lines as WORK/NAME, runs the harness on it: (exit code, report, the name it uses)."""
    page = os.path.join(work, name)
    with open(page, "w", encoding="utf-8") as f:
        f.write("\n".join(lines))
    p = subprocess.run([sys.executable, HARNESS, codyna, source, os.path.join(work, "run_" + name.replace(".", "_")),
                        page], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=600)
    out = p.stdout.decode("utf-8", "replace")
    print(out)
    # the harness names a page inside the source tree by its relative path (a build folder may be there)
    shown_name = os.path.relpath(page, source) if page.startswith(source + os.sep) else page
    return p.returncode, out, shown_name


def expect(what, code, out, want):
    missing = [w for w in want if w not in out]
    if code != 1 or missing:
        print(f"FAIL ({what}): the harness exited {code} (expected 1); missing from its report: {missing}")
        return False
    print(f"caught ({what}): the page, the line and the difference named\n")
    return True


def changed_number(codyna, source, work, page, lines, pattern, old, new, name, what, indent=0):
    """Changes old to new in the one line matching pattern; the harness must name it (a block
    indented by indent columns, in a list item, shows its lines without them)."""
    i = only(lines, pattern, page)
    shown = lines[i]
    changed = shown.replace(old, new, 1)
    lines = lines[:i] + [changed] + lines[i + 1:]
    code, out, shown_name = run_copy(codyna, source, work, name, lines)
    return expect(what, code, out, [f"{shown_name}:{i + 1}: number {new} shown, {old} printed",
                                    f"shown:   {changed[indent:].rstrip()}", f"printed: {shown[indent:].rstrip()}",
                                    "1 difference(s)"])


def main(argv):
    codyna, source, work = argv[1], os.path.abspath(argv[2]), os.path.abspath(argv[3])
    os.makedirs(work, exist_ok=True)
    ok = True
    try:
        # a console command's output
        ok &= changed_number(codyna, source, work, "docs/linearization.md", read(source, "docs/linearization.md"),
                             r"  torque = 53\.0037", "53.0037", "53.1037", "linearization.md",
                             "a console command's output")

        # an Octave block's output: the co-simulation section of docs/simulation.md (its export first)
        sim = read(source, "docs/simulation.md")
        start = only(sim, r"## Co-simulation from GNU Octave.*", "docs/simulation.md")
        section = sim[start:]
        i = only(section, r"rod at \S+ rad from upright after 6 s", "docs/simulation.md")
        old = section[i].split()[2]
        new = "%.2g" % (float(old) * 1.5)
        ok &= changed_number(codyna, source, work, "docs/simulation.md", section,
                             r"rod at \S+ rad from upright after 6 s", old, new, "cosimulation.md",
                             "an Octave block's output")

        # issue 36: the relative load path prints Octave's warnings before the output shown, which fails
        # at the shown output's first line
        j = only(section, r"addpath\(fullfile\(pwd, 'build', 'mex'\)\);.*", "docs/simulation.md")
        first = only(section, r"```text output", "docs/simulation.md") + 1
        relative = section[:j] + ["addpath('build/mex');"] + section[j + 1:]
        code, out, shown_name = run_copy(codyna, source, work, "cosimulation_relative.md", relative)
        ok &= expect("Octave's load-path warnings", code, out,
                     [f"{shown_name}:{first + 1}: text differs", f"shown:   {section[first]}",
                      "printed: warning: load_path: build/mex: No such file or directory", "1 difference(s)"])

        # a Python block's output: docs/README.md's example of the convention
        ok &= changed_number(codyna, source, work, "docs/README.md", read(source, "docs/README.md"),
                             r"  DOF 1", "1", "2", "README_docs.md", "a Python block's output", indent=2)
    except LookupError as e:
        print(f"FAIL: {e}")
        return 1
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
