#!/usr/bin/env python3
"""Names local to one source file must be unique across a unity-built target.

A unity (jumbo) build (cmake/unity.cmake) compiles several .cpp files of a
target as one translation unit. Two files that each define a helper of the same
name in an anonymous namespace (or `static`) then meet: an identical signature is
a compile error, but a different one is an overload, and a call in one file can
silently resolve to the other file's helper (a `number(double)` beside a
`number(std::complex<double>)`), computing something else without a word.
Types and constants of one name in two files stop the compiler (a redefinition)
when the two land in one batch, which depends on the batch size and the files'
order; functions may not stop it at all. This check reads the sources (the
project's layout: a namespace's contents start at column 0) and lists every
internal-linkage function, type and constant name defined in more than one file
of the same target (aliases may repeat: `using cd = std::complex<double>;` twice
is legal, and a different one stops the compiler whatever the batches).

usage: unity_names.py LIST_FILE...   (one file per target: its sources separated by ';')
exit 1 with each clash named (the name and the files), 0 when none.
"""
import re
import sys

KEYWORDS = {"if", "for", "while", "switch", "return", "sizeof", "decltype", "alignof",
            "static_assert", "operator", "namespace", "using", "template", "else", "do", "case"}
TYPE_RE = re.compile(r"^(?:template\s*<.*>\s*)?(?:struct|class|union|enum(?:\s+class)?)\s+(\w+)\b(?!\s*;)")
ALIAS_RE = re.compile(r"^using\s+(\w+)\s*=")
VAR_RE = re.compile(r"^(?:static\s+)?(?:inline\s+)?(?:constexpr|const)\s+[\w:<>,\s\*&]+?\b(\w+)\s*(?:=|\{|\[|;)")
FUNC_RE = re.compile(r"^(?:static\s+)?(?:inline\s+)?(?:constexpr\s+)?(?:[\w:]+(?:<[^()]*>)?[\s\*&]+)+(\w+)\s*\(")


def internal_names(path):
    """Functions, types and constants defined at namespace level inside `namespace {` or with `static`."""
    names = set()
    anon_depth = 0  # anonymous namespaces open at this point
    stack = []      # for each open namespace: is it anonymous
    with open(path, encoding="utf-8", errors="replace") as f:
        for raw in f:
            line = raw.rstrip("\n")
            if not line or line[0] in " \t#/}*":
                if line.startswith("}") and "namespace" in line and stack:
                    if stack.pop():
                        anon_depth -= 1
                continue
            m = re.match(r"^namespace\s*([\w:]*)\s*\{", line)
            if m:
                anonymous = m.group(1) == ""
                # a one-line namespace block `namespace x { ... }` closes on the same line
                if line.rstrip().endswith("}"):
                    continue
                stack.append(anonymous)
                anon_depth += anonymous
                continue
            # `template <...>` on a line of its own: the declaration follows on the next
            if line.startswith("template") and not line.rstrip().endswith((";", "}")):
                continue
            if anon_depth == 0 and not line.startswith("static "):
                continue
            # a type, an alias or a constant first: their lines can look like a call
            if ALIAS_RE.match(line):
                continue
            m = TYPE_RE.match(line)
            if m:
                names.add(m.group(1))
                continue
            m = VAR_RE.match(line)
            if m:
                # and the further names of `constexpr double a = 1, b = 2;`
                names.add(m.group(1))
                names.update(re.findall(r",\s*(\w+)\s*=", line.split(";")[0]))
                continue
            m = FUNC_RE.match(line)
            if m and m.group(1) not in KEYWORDS:
                names.add(m.group(1))
    return names


def main(argv):
    clashes = []
    for list_file in argv[1:]:
        with open(list_file, encoding="utf-8") as f:
            sources = [s for s in f.read().strip().split(";") if s.endswith((".cpp", ".cc", ".cxx"))]
        seen = {}
        for src in sources:
            for name in internal_names(src):
                seen.setdefault(name, []).append(src)
        for name, files in sorted(seen.items()):
            if len(files) > 1:
                clashes.append(f"{list_file}: '{name}' is local to {len(files)} files of one unity target: "
                               + ", ".join(files))
    for c in clashes:
        print(c)
    if clashes:
        print(f"{len(clashes)} clash(es): rename the helper in all but one file (docs/performance.md, Build time)")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
