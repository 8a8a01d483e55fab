#!/usr/bin/env python3
"""Run the documentation: every command shown in README.md and docs/*.md, with the output shown.

usage: run_docs.py CODYNA SOURCE_DIR WORK_DIR [PAGE...]

CODYNA is the built codyna binary (its folder's neighbours, build/bin/*, build/mex/*,
build/python/*, are offered too), SOURCE_DIR the repository, WORK_DIR a scratch folder (emptied). Without PAGE it runs
SOURCE_DIR/README.md and every SOURCE_DIR/docs/*.md. Exit code 0 when every page tells the truth,
1 when one does not (each difference is printed as PAGE:LINE: what was shown, what was printed),
2 on a usage error.

The conventions, for the pages' writers (docs/README.md, "How the docs are checked", says the same
for readers):

* Every fenced block has a language. Blocks in `console` hold `$ ` commands, each followed by the
  output it prints (stdout and stderr as a terminal shows them, both line-buffered); blocks in `sh`
  or `bash` hold commands only; `octave` blocks run as one script through octave-cli, `python`
  blocks through /usr/bin/python3 with PYTHONPATH=build/python (codyna's module). Any other
  language (json, text, csv, ...) is data, not run.
  A fence without a language is an error: it would be unclear whether it runs.
* What an Octave or Python block prints (stdout and stderr, as for a console command) is shown in
  the fenced block right after it, with only blank lines between, whose info string is
  `text output` (GitHub shows it as plain text); it is compared as a console command's output.
  A block with no such output block must print nothing at all (Octave's harmless exit line, HARMLESS
  below, excepted), so a stray warning fails the page. A `text output` block anywhere else is an
  error: it would be checked against nothing.
* A shell, Octave or Python block whose first line is a comment starting `# not run` (`% not run`)
  or `# syntax, not run` is not run: the comment says why (it builds, it opens a window, it is a
  syntax summary with MODEL, NAME).
* A command meant to fail ends with the comment `# fails: MESSAGE` (or `# fails (exit N): MESSAGE`):
  it must exit nonzero (with N) and print MESSAGE. Any other command must exit 0.
* A line `...` in a shown output elides any number of printed lines (none included); `...` inside
  a line elides any text within that line. Runs of spaces compare equal to any run of spaces.
  Text compares exactly; numbers compare to the tolerance below, written once here.
* Each page runs in its own scratch folder WORK_DIR/PAGE holding a copy of examples/ and
  tests/data/, and build/bin/*, build/mex/*, build/python/* linked to the built ones, so the paths shown
  (build/bin/codyna, examples/pendulum.json) work as shown from the repository root. A page's
  blocks run in order in that folder, so a file written by one command is there for the next.
  `/tmp/` in a command is that folder's tmp/ (and shows as /tmp/ in the output compared), so two
  runs never share files.
* A command in an indented (unfenced) code block is an error: fence it.
"""
import os
import re
import shutil
import subprocess
import sys
import time
from difflib import SequenceMatcher

# The tolerance of every number shown in a page: |shown - printed| <= ABS_TOL + REL_TOL * max(|shown|, |printed|).
REL_TOL = 1e-6
ABS_TOL = 1e-9
# One command's time limit (seconds).
COMMAND_TIMEOUT = 300
# Octave 7.3 prints this at exit with no consequence (its exit code stays 0): dropped from outputs.
HARMLESS = {"error: ignoring const execution_exception& while preparing to exit"}

NUM = r"(?<![\w.])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?![\w])"
NUM_RE = re.compile(NUM)
FENCE_RE = re.compile(r"^(\s*)(`{3,}|~{3,})\s*([^\s`]*)(.*)$")
FAILS_RE = re.compile(r"\s#\s*fails(?:\s*\(exit (\d+)\))?:\s*(.*?)\s*$")
HEREDOC_RE = re.compile(r"<<-?\s*(['\"]?)(\w+)\1")
NOT_RUN_RE = re.compile(r"^\s*(#|%)\s*(not run|syntax, not run)")

SHELL_LANGS = {"sh", "bash", "shell"}
SCRIPT_LANGS = {"octave", "matlab", "python", "python3"}
RUN_LANGS = {"console"} | SHELL_LANGS | SCRIPT_LANGS


class Page:
    def __init__(self, path, name):
        self.path = path
        self.name = name
        self.problems = []
        self.commands = 0
        self.failing_commands = 0
        self.outputs = 0
        self.output_lines = 0
        self.blocks_run = 0
        self.blocks_not_run = 0
        self.blocks_data = 0
        self.seconds = 0.0

    def problem(self, line, text):
        self.problems.append(f"{self.name}:{line}: {text}")


class Command:
    def __init__(self, line, text, shown=None, shown_line=None):
        self.line = line          # page line of the command
        self.text = text          # shell text (may span lines)
        self.shown = shown        # list of shown output lines, or None
        self.shown_line = shown_line
        self.fails = None         # (exit code or None, message) when it is meant to fail
        self.quiet = False        # an Octave or Python block without an output block: prints nothing
        m = None
        for physical in text.split("\n"):
            m = FAILS_RE.search(physical) or m
            if HEREDOC_RE.search(physical):
                break
        if m:
            self.fails = (int(m.group(1)) if m.group(1) else None, m.group(2))


def blocks(page, lines):
    """Yields (line number of the opening fence, language, the info string's other words, block
    lines, line number of the closing fence) for each fenced block."""
    i = 0
    while i < len(lines):
        m = FENCE_RE.match(lines[i])
        if not m:
            if re.match(r"^( {4,}|\t)\$ ", lines[i]):
                page.problem(i + 1, "a command in an indented code block: fence it (```console)")
            i += 1
            continue
        indent, fence, lang = len(m.group(1)), m.group(2), m.group(3).lower()
        tags = m.group(4).lower().split()
        start = i
        body = []
        i += 1
        while i < len(lines):
            c = re.match(r"^(\s*)(`{3,}|~{3,})\s*$", lines[i])
            if c and c.group(2)[0] == fence[0] and len(c.group(2)) >= len(fence):
                break
            line = lines[i]
            body.append(line[indent:] if line[:indent].strip() == "" else line.lstrip())
            i += 1
        if i >= len(lines):
            page.problem(start + 1, "a fence that is never closed")
        i += 1
        yield start + 1, lang, tags, body, i


def first_text(body):
    """The first line of a block that is not blank."""
    return next((l for l in body if l.strip()), "")


def split_commands(first_line, body, prompt):
    """Splits a console block (prompt True) or a shell block into Commands."""
    cmds = []
    i = 0
    stray = []
    while i < len(body):
        line = body[i]
        if prompt:
            if not line.startswith("$ ") and line.strip() != "$":
                if line.strip():
                    stray.append(first_line + 1 + i)
                i += 1
                continue
            line = line[2:]
        elif not line.strip() or line.lstrip().startswith("#"):
            i += 1
            continue
        at = first_line + 1 + i
        parts = [line]
        i += 1
        while parts[-1].endswith("\\") and i < len(body):
            parts.append(body[i])
            i += 1
        here = HEREDOC_RE.search("\n".join(parts))
        if here:
            end = here.group(2)
            while i < len(body):
                parts.append(body[i])
                i += 1
                if parts[-1].strip() == end:
                    break
        text = "\n".join(parts)
        if prompt:
            shown = []
            shown_line = first_line + 1 + i
            while i < len(body) and not body[i].startswith("$ ") and body[i].strip() != "$":
                shown.append(body[i])
                i += 1
            while shown and not shown[-1].strip():
                shown.pop()
            cmds.append(Command(at, text, shown, shown_line))
        else:
            cmds.append(Command(at, text))
    return cmds, stray


def numbers_close(a, b):
    x, y = float(a), float(b)
    if x == y:
        return True
    return abs(x - y) <= ABS_TOL + REL_TOL * max(abs(x), abs(y))


def line_pattern(shown):
    """The regex of a shown line: its text literal (space runs as any run), numbers and `...` as groups."""
    out = []
    pos = 0
    tokens = []
    for m in re.finditer(NUM + r"|\.\.\.", shown):
        tokens.append((m.start(), m.end(), m.group(0)))
    for start, end, tok in tokens:
        out.append(literal(shown[pos:start]))
        out.append("(.*?)" if tok == "..." else "(" + NUM + ")")
        pos = end
    out.append(literal(shown[pos:]))
    return "".join(out), [t for _, _, t in tokens]


def literal(text):
    return "".join(r"[ \t]+" if p.isspace() else re.escape(p) for p in re.split(r"(\s+)", text) if p)


def compare_line(shown, printed):
    """None when the printed line shows as shown; else the difference in words."""
    if shown.rstrip() == printed.rstrip():
        return None
    pattern, tokens = line_pattern(shown.rstrip())
    m = re.fullmatch(pattern, printed.rstrip())
    if not m:
        # the same text with other numbers: name the first number that differs
        s_nums = NUM_RE.findall(shown)
        p_nums = NUM_RE.findall(printed)
        if NUM_RE.sub("#", shown).split() == NUM_RE.sub("#", printed).split():
            for a, b in zip(s_nums, p_nums):
                if not numbers_close(a, b):
                    return f"number {a} shown, {b} printed (tolerance rel {REL_TOL:g}, abs {ABS_TOL:g})"
        return "text differs"
    for tok, got in zip(tokens, m.groups()):
        if tok != "..." and not numbers_close(tok, got):
            return f"number {tok} shown, {got} printed (tolerance rel {REL_TOL:g}, abs {ABS_TOL:g})"
    return None


def compare_output(shown, printed):
    """None when printed (list of lines) matches shown (with `...`); else (index in shown, message)."""
    # the furthest shown line reached, and of the differences there the most telling:
    # a number off (rank 3), a text difference (2), a line missing (1), lines too many (0)
    # (among equals, the printed line most like the shown one)
    best = [(-1, -1, -1.0, None)]
    memo = {}

    def note(i, rank, message, likeness=0.0):
        if (i, rank, likeness) > best[0][:3]:
            best[0] = (i, rank, likeness, message)

    def match(i, j):
        key = (i, j)
        if key in memo:
            return memo[key]
        if i == len(shown):
            ok = j == len(printed)
            if not ok:
                note(i - 1, 0, f"printed more lines than shown, from: {printed[j]!r}")
        elif shown[i].strip() == "...":
            ok = any(match(i + 1, k) for k in range(j, len(printed) + 1))
        elif j == len(printed):
            ok = False
            note(i, 1, f"shown but not printed: {shown[i].rstrip()!r}")
        else:
            diff = compare_line(shown[i], printed[j])
            ok = diff is None and match(i + 1, j + 1)
            if diff is not None:
                note(i, 3 if diff.startswith("number") else 2,
                     f"{diff}\n    shown:   {shown[i].rstrip()}\n    printed: {printed[j].rstrip()}",
                     SequenceMatcher(None, shown[i], printed[j]).ratio())
        memo[key] = ok
        return ok

    sys.setrecursionlimit(100000)
    if match(0, 0):
        return None
    return best[0][0], best[0][3]


def link_build(codyna, scratch):
    bin_dir = os.path.dirname(os.path.abspath(codyna))
    build = os.path.dirname(bin_dir)
    for sub, real in (("bin", bin_dir), ("mex", os.path.join(build, "mex")), ("python", os.path.join(build, "python"))):
        dst = os.path.join(scratch, "build", sub)
        os.makedirs(dst, exist_ok=True)
        if os.path.isdir(real):
            for f in os.listdir(real):
                os.symlink(os.path.join(real, f), os.path.join(dst, f))
    # the binary handed in is build/bin/codyna whatever its real folder
    target = os.path.join(scratch, "build", "bin", "codyna")
    if os.path.lexists(target):
        os.remove(target)
    os.symlink(os.path.abspath(codyna), target)


def run(text, scratch, env):
    """Runs shell text in scratch: (exit code, output lines as a terminal shows them)."""
    text = text.replace("/tmp/", os.path.join(scratch, "tmp") + "/")
    try:
        p = subprocess.run(["stdbuf", "-oL", "-eL", "bash", "-c", text], cwd=scratch, env=env,
                           stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                           timeout=COMMAND_TIMEOUT)
        code, out = p.returncode, p.stdout.decode("utf-8", "replace")
    except subprocess.TimeoutExpired as e:
        code, out = None, (e.stdout or b"").decode("utf-8", "replace")
    out = out.replace(os.path.join(scratch, "tmp") + "/", "/tmp/")
    lines = [l.rstrip() for l in out.replace("\r\n", "\n").split("\n") if l.strip() not in HARMLESS]
    while lines and not lines[-1]:
        lines.pop()
    return code, lines


def check(page, cmd, code, printed):
    where = cmd.line
    tail = "\n    " + "\n    ".join(printed[-15:]) if printed else " (nothing printed)"
    if code is None:
        page.problem(where, f"did not end within {COMMAND_TIMEOUT} s:{tail}")
        return
    if cmd.fails:
        want_code, message = cmd.fails
        page.failing_commands += 1
        if code == 0:
            page.problem(where, f"meant to fail ({message}) but exited 0:{tail}")
            return
        if want_code is not None and code != want_code:
            page.problem(where, f"meant to fail with exit code {want_code}, exited {code}:{tail}")
            return
        flat = " ".join(" ".join(printed).split())
        if " ".join(message.split()) not in flat:
            page.problem(where, f"failed (exit {code}) without the message shown, {message!r}:{tail}")
            return
    elif code != 0:
        page.problem(where, f"exited {code}:{tail}")
        return
    if cmd.quiet and printed:
        page.problem(where, f"printed {len(printed)} line(s) but the page shows no output: show it in a "
                            f"```text output block right after this one, or make the block quiet:{tail}")
        return
    if cmd.shown:
        page.outputs += 1
        page.output_lines += sum(1 for l in cmd.shown if l.strip() != "...")
        diff = compare_output(cmd.shown, printed)
        if diff:
            i, message = diff
            page.problem(cmd.shown_line + i if i < len(cmd.shown) else cmd.shown_line + len(cmd.shown) - 1,
                         f"{message}" + ("" if "\n" in message else f"\n    printed:{tail}"))


def run_page(page, source, codyna, scratch):
    t0 = time.monotonic()
    shutil.rmtree(scratch, ignore_errors=True)
    os.makedirs(os.path.join(scratch, "tmp"))
    shutil.copytree(os.path.join(source, "examples"), os.path.join(scratch, "examples"))
    shutil.copytree(os.path.join(source, "tests", "data"), os.path.join(scratch, "tests", "data"))
    link_build(codyna, scratch)
    env = dict(os.environ, PYTHONUNBUFFERED="1", PYTHONDONTWRITEBYTECODE="1", LC_NUMERIC="C",
               TMPDIR=os.path.join(scratch, "tmp"))
    with open(page.path, encoding="utf-8") as f:
        lines = f.read().split("\n")
    found = list(blocks(page, lines))
    # the `text output` block right after an Octave or Python block (only blank lines between) is its output
    output_of = {}
    for k, (first, lang, tags, body, last) in enumerate(found):
        if lang == "text" and "output" in tags and k:
            prev = found[k - 1]
            if (prev[1] in SCRIPT_LANGS and not NOT_RUN_RE.match(first_text(prev[3]))
                    and not any(l.strip() for l in lines[prev[4]:first - 1])):
                output_of[k - 1] = (first, body)
    shown_outputs = {first for first, _ in output_of.values()}
    n = 0
    for k, (first, lang, tags, body, last) in enumerate(found):
        n += 1
        if lang == "text" and "output" in tags and first not in shown_outputs:
            page.problem(first, "a `text output` block that does not follow a run Octave or Python block "
                                "(only blank lines between): it would be checked against nothing")
        if lang == "":
            page.problem(first, "a fenced block without a language: say console, sh, octave, python "
                                "(run) or text, json, ... (not run)")
            continue
        if lang not in RUN_LANGS:
            page.blocks_data += 1
            continue
        if NOT_RUN_RE.match(first_text(body)):
            page.blocks_not_run += 1
            continue
        page.blocks_run += 1
        if lang in SCRIPT_LANGS:
            ext = ".m" if lang in ("octave", "matlab") else ".py"
            script = os.path.join(scratch, f"docs_block_{n}{ext}")
            with open(script, "w", encoding="utf-8") as f:
                f.write("\n".join(body).replace("/tmp/", os.path.join(scratch, "tmp") + "/") + "\n")
            runner = "octave-cli --no-gui --quiet" if ext == ".m" else "PYTHONPATH=build/python /usr/bin/python3"
            cmd = Command(first, f"{runner} {os.path.basename(script)}")
            if k in output_of:
                out_first, out_body = output_of[k]
                shown = list(out_body)
                while shown and not shown[-1].strip():
                    shown.pop()
                if not shown:
                    page.problem(out_first, "an empty `text output` block: drop it (the block must then print nothing)")
                cmd.shown, cmd.shown_line = shown, out_first + 1
            else:
                cmd.quiet = True
            page.commands += 1
            code, printed = run(cmd.text, scratch, env)
            check(page, cmd, code, printed)
            continue
        cmds, stray = split_commands(first, body, lang == "console")
        for s in stray:
            page.problem(s, "a line before the first `$ ` command of a console block")
        for cmd in cmds:
            page.commands += 1
            code, printed = run(cmd.text, scratch, env)
            check(page, cmd, code, printed)
    page.seconds = time.monotonic() - t0


def main(argv):
    if len(argv) < 4:
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        return 2
    codyna, source, work = argv[1], os.path.abspath(argv[2]), os.path.abspath(argv[3])
    paths = argv[4:]
    if not paths:
        paths = [os.path.join(source, "README.md")]
        docs = os.path.join(source, "docs")
        paths += sorted(os.path.join(docs, f) for f in os.listdir(docs) if f.endswith(".md"))
    os.makedirs(work, exist_ok=True)
    pages = []
    t0 = time.monotonic()
    for path in paths:
        path = os.path.abspath(path)
        name = os.path.relpath(path, source) if path.startswith(source + os.sep) else path
        page = Page(path, name)
        scratch = os.path.join(work, re.sub(r"[^\w.-]", "_", name))
        run_page(page, source, codyna, scratch)
        pages.append(page)
        status = "ok" if not page.problems else f"{len(page.problems)} difference(s)"
        print(f"{name}: {page.commands} commands ({page.failing_commands} meant to fail), "
              f"{page.outputs} outputs compared ({page.output_lines} lines), "
              f"blocks: {page.blocks_run} run, {page.blocks_not_run} marked not run, {page.blocks_data} data; "
              f"{page.seconds:.1f} s: {status}", flush=True)
        for p in page.problems:
            print("  " + p.replace("\n", "\n  "), flush=True)
    seconds = time.monotonic() - t0
    problems = sum(len(p.problems) for p in pages)
    print(f"docs: {len(pages)} pages, {sum(p.commands for p in pages)} commands run "
          f"({sum(p.failing_commands for p in pages)} meant to fail), "
          f"{sum(p.outputs for p in pages)} shown outputs compared "
          f"({sum(p.output_lines for p in pages)} lines), "
          f"{sum(p.blocks_not_run for p in pages)} blocks marked not run, "
          f"in {seconds:.1f} s: " + ("all pages tell the truth" if not problems else f"{problems} difference(s)"))
    return 0 if not problems else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
