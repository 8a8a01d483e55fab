#!/usr/bin/python3
"""Pinned outputs of `codyna linearize` and `codyna simulate`, by hash.

One list of runs (RUNS below) serves two modes:

  generate:  pin_outputs.py CODYNA SOURCE_DIR JSON [WORK_DIR]
      runs every command twice (in WORK_DIR/a and WORK_DIR/b; default: a temporary
      folder), refuses to write if the two differ anywhere (an unnormalised wall time,
      say), and writes JSON: per run its arguments, exit code, stdout and stderr
      (hash and text), and per output file one entry per variable:
        .mat (v5)   every variable via scipy.io.loadmat: numeric arrays by raw bytes,
                    shape and dtype; char arrays and cells of char by their text;
                    structs field by field (info.model_file, ...); the MATLAB header
                    (which names the codyna version) is skipped
        .mat (v7.3) via h5py: numeric datasets by raw bytes, shape and dtype, char
                    datasets by their text; the cell arrays (object references into
                    #refs#) are skipped: v7.3 files repeat every name list as a char
                    matrix (state_names_char, ...), which is pinned
        .h5         every dataset (numeric by raw bytes, shape and dtype; strings by
                    text) and every attribute except /solver wall_time
        .csv        the full text (its header and line count are kept, to print)
        .m          the text without lines holding a date or a clock time (codyna
                    writes none today; the filter is there for a future header)
      plus, for numeric arrays, shape, sum and max |x| (float repr) to print beside a
      failure. The set of files each run writes is pinned too.
      Regenerate (from a binary you trust, e.g. the one before a refactor):
        /usr/bin/python3 tests/cli/pin_outputs.py build/bin/codyna . tests/data/pinned_outputs.json

  check:     pin_outputs.py --check CODYNA SOURCE_DIR JSON WORK_DIR
      runs every command once in WORK_DIR and compares with JSON; prints each run, file
      and variable that differs; exit 1 on any difference, 0 when all match.

Commands run with WORK_DIR as the working folder on a copy of examples/ there, so every
path codyna prints or stores (model file, output files) is relative and the same on
every machine.
"""
import concurrent.futures
import hashlib
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

import h5py
import numpy as np
import scipy.io

# ---------------------------------------------------------------------------- the runs
# name -> (subcommand, model, extra arguments). Outputs go to out/NAME/ (linearize:
# --out out/NAME; simulate: --out out/NAME/MODEL.h5 --csv out/NAME/MODEL.csv).

EXAMPLES = [
    "andrews_squeezer", "bricard", "cart_pendulum", "double_pendulum", "four_bar", "four_bar_held",
    "heavy_top", "iftomm_a01_pendulum", "iftomm_a02_four_bars", "iftomm_a05_flyball", "pendulum",
]

# simulate: end times (short; the model files' own are 0.03 .. 20 s); every example simulates
SIM_T_END = {
    "andrews_squeezer": "0.03",  # its own end time: 1e-4 output step, ~7000 steps in 0.03 s
    "bricard": "2",
    "cart_pendulum": "2",
    "double_pendulum": "2",
    "four_bar": "2",
    "four_bar_held": "2",        # the study's rocker step is at 0.5 s
    "heavy_top": "2",            # 1 ms output step
    "iftomm_a01_pendulum": "2",
    "iftomm_a02_four_bars": "2",  # through the flat (singular) configuration at t = pi/2
    "iftomm_a05_flyball": "2",
    "pendulum": "2",
}


def _runs():
    runs = {}
    # default options; heavy_top, iftomm_a01_pendulum and iftomm_a05_flyball have no equilibrium
    # to find (no Plant/In to hold them): those runs pin exit code 2 and the message, and the
    # same models are linearized again at their initial state
    for m in EXAMPLES:
        runs[f"lin_{m}"] = ("linearize", m, [])
    for m in ["heavy_top", "iftomm_a01_pendulum", "iftomm_a05_flyball"]:
        runs[f"lin_initial_{m}"] = ("linearize", m, ["--operating-point", "initial"])
    for m in ["pendulum", "cart_pendulum", "double_pendulum", "four_bar"]:
        runs[f"lin_discrete_{m}"] = ("linearize", m, ["--discrete", "0.01"])
    for m in ["pendulum", "cart_pendulum", "four_bar"]:
        runs[f"lin_fdcentral_{m}"] = ("linearize", m, ["--method", "fd-central"])
    runs["lin_fdcentral_heavy_top"] = ("linearize", "heavy_top", ["--method", "fd-central", "--operating-point", "initial"])
    for m in ["pendulum", "cart_pendulum", "four_bar"]:
        runs[f"lin_v73_{m}"] = ("linearize", m, ["--mat-version", "7.3"])
    for m in ["pendulum", "cart_pendulum"]:
        runs[f"lin_cl_lqr_{m}"] = ("linearize", m, ["--closed-loop", "--lqr"])
    for m in ["pendulum", "cart_pendulum"]:
        runs[f"lin_traj_{m}"] = ("linearize", m, ["--trajectory", "0.5", "--trajectory-step", "0.1"])
    for m in EXAMPLES:
        runs[f"sim_{m}"] = ("simulate", m, ["--t-end", SIM_T_END[m]])
    runs["sim_lqr_compare_cart_pendulum"] = ("simulate", "cart_pendulum", ["--lqr", "--compare-linear", "--t-end", "2"])
    runs["sim_open_loop_pendulum"] = ("simulate", "pendulum", ["--open-loop", "--t-end", "1"])
    # docs/simulation.md: started 56 degrees away from the operating point
    runs["sim_initial_pendulum"] = ("simulate", "pendulum",
                                    ["--initial", "pivot=0.6", "--compare-linear", "--t-end", "1"])
    return runs


RUNS = _runs()


def command(name):
    sub, model, extra = RUNS[name]
    args = [sub, f"examples/{model}.json"]
    if sub == "linearize":
        args += ["--out", f"out/{name}"]
    else:
        args += ["--quiet", "--out", f"out/{name}/{model}.h5", "--csv", f"out/{name}/{model}.csv"]
    return args + extra


# ---------------------------------------------------------------------------- normalising
# Text that changes from run to run of the same binary (found by running everything twice).
STDOUT_NORMALISE = [
    # simulate's summary: "integrator  ... N projections, 0.0123 s" (wall time)
    (re.compile(r"(projections, )[0-9.]+(?:e[-+]?[0-9]+)?( s)$", re.M), r"\1<wall time>\2"),
]
H5_SKIP_ATTRS = {("/solver", "wall_time")}
DATE_TIME_LINE = re.compile(r"\b\d{4}-\d{2}-\d{2}\b|\b\d{1,2}:\d{2}:\d{2}\b|"
                            r"\b(Mon|Tue|Wed|Thu|Fri|Sat|Sun) (Jan|Feb|Mar|Apr|May|Jun|Jul|Aug|Sep|Oct|Nov|Dec)\b")


def normalise_stdout(text):
    for rx, rep in STDOUT_NORMALISE:
        text = rx.sub(rep, text)
    return text


# ---------------------------------------------------------------------------- entries

def sha(b):
    return hashlib.sha256(b).hexdigest()


def numeric_entry(a):
    a = np.ascontiguousarray(np.asarray(a))
    e = {"kind": "numeric", "dtype": a.dtype.str, "shape": list(a.shape), "sha256": sha(a.tobytes())}
    if a.size:
        with np.errstate(all="ignore"):
            e["sum"] = repr(complex(np.sum(a)) if np.iscomplexobj(a) else float(np.sum(a, dtype=np.float64)))
            e["maxabs"] = repr(float(np.max(np.abs(a))))
    else:
        e["sum"] = e["maxabs"] = repr(0.0)
    return e


def text_entry(s):
    b = s.encode("utf-8", "surrogatepass")
    e = {"kind": "text", "sha256": sha(b), "bytes": len(b)}
    if len(b) <= 1000:  # short texts are kept, to print beside a failure
        e["text"] = s
    return e


def mat_v5_entries(path):
    out = {}
    d = scipy.io.loadmat(path, uint16_codec="utf-16")

    def walk(name, v):
        if isinstance(v, np.ndarray) and v.dtype.names:  # struct (array)
            for i, el in enumerate(v.ravel()):
                sub = name if v.size == 1 else f"{name}({i + 1})"
                for f in v.dtype.names:
                    walk(f"{sub}.{f}", el[f])
        elif isinstance(v, np.ndarray) and v.dtype == object:  # cell
            items = list(v.ravel(order="F"))
            if all(isinstance(x, np.ndarray) and x.dtype.kind == "U" for x in items):
                out[name] = text_entry(json.dumps({"cell": list(v.shape),
                                                   "items": [[str(s) for s in x.ravel()] for x in items]}))
            else:
                for i, x in enumerate(items):
                    walk(f"{name}{{{i + 1}}}", x)
        elif isinstance(v, np.ndarray) and v.dtype.kind == "U":  # char
            out[name] = text_entry(json.dumps({"char": list(v.shape), "rows": [str(s) for s in v.ravel()]}))
        else:
            out[name] = numeric_entry(v)

    for k in sorted(d):
        if k.startswith("__"):  # __header__ (names the version), __version__, __globals__
            continue
        walk(k, d[k])
    return out


def mat_v73_entries(path):
    out = {}
    with h5py.File(path, "r") as f:
        def visit(name, obj):
            if name.startswith("#refs#") or name.startswith("#subsystem#") or not isinstance(obj, h5py.Dataset):
                return
            if h5py.check_dtype(ref=obj.dtype) is not None:
                return  # a cell array: its text is pinned through NAME_char
            a = obj[()]
            cls = obj.attrs.get("MATLAB_class", b"")
            cls = cls.decode() if isinstance(cls, bytes) else str(cls)
            key = name.replace("/", ".")
            if cls == "char":
                if "MATLAB_empty" in obj.attrs and int(np.asarray(obj.attrs["MATLAB_empty"]).ravel()[0]):
                    rows = []
                else:
                    a2 = np.atleast_2d(np.asarray(a)).T
                    rows = ["".join(chr(int(c)) for c in r) for r in a2]
                out[key] = text_entry(json.dumps({"char": rows}))
            else:
                e = numeric_entry(a)
                e["matlab_class"] = cls
                out[key] = e
        f.visititems(visit)
    return out


def h5_attr_value(v):
    if isinstance(v, bytes):
        return v.decode("utf-8", "replace")
    if isinstance(v, str):
        return v
    a = np.asarray(v)
    if a.dtype.kind in "SO":
        return json.dumps([x.decode("utf-8", "replace") if isinstance(x, bytes) else str(x) for x in a.ravel()])
    return json.dumps({"dtype": a.dtype.str, "shape": list(a.shape), "values": [repr(x) for x in a.ravel().tolist()]})


def h5_entries(path):
    out = {}
    with h5py.File(path, "r") as f:
        def attrs(name, obj):
            gname = "/" + name if name else "/"
            for k in sorted(obj.attrs):
                if (gname, k) in H5_SKIP_ATTRS:
                    continue
                out[f"{gname}@{k}"] = text_entry(h5_attr_value(obj.attrs[k]))

        def visit(name, obj):
            attrs(name, obj)
            if isinstance(obj, h5py.Dataset):
                a = obj[()]
                if obj.dtype.kind in "SOU":
                    items = [x.decode("utf-8", "replace") if isinstance(x, bytes) else str(x)
                             for x in np.asarray(a).ravel()]
                    out["/" + name] = text_entry(json.dumps({"shape": list(np.shape(a)), "items": items}))
                else:
                    out["/" + name] = numeric_entry(a)
        attrs("", f)
        f.visititems(visit)
    return out


def file_entries(path):
    if path.endswith(".mat"):
        with open(path, "rb") as fh:
            head = fh.read(128)
        if head.startswith(b"MATLAB 7.3"):
            return "mat v7.3", mat_v73_entries(path)
        return "mat v5", mat_v5_entries(path)
    if path.endswith(".h5"):
        return "hdf5", h5_entries(path)
    with open(path, "rb") as fh:
        data = fh.read()
    if path.endswith(".m"):
        text = data.decode("utf-8", "surrogateescape")
        kept = "".join(l for l in text.splitlines(keepends=True) if not DATE_TIME_LINE.search(l))
        return "m", {"text": text_entry(kept)}
    if path.endswith(".csv"):  # the header and line count only to print beside a failure
        return "csv", {"text": {"kind": "text", "sha256": sha(data), "bytes": len(data), "lines": data.count(b"\n"),
                                "header": data.split(b"\n", 1)[0].decode("utf-8", "replace")}}
    return "bytes", {"bytes": {"kind": "text", "sha256": sha(data), "bytes": len(data)}}


# ---------------------------------------------------------------------------- running

def prepare(work, src):
    os.makedirs(work, exist_ok=True)
    for d in ("out", "examples"):
        shutil.rmtree(os.path.join(work, d), ignore_errors=True)
    shutil.copytree(os.path.join(src, "examples"), os.path.join(work, "examples"),
                    ignore=lambda d, names: [n for n in names if not n.endswith(".json")])
    os.makedirs(os.path.join(work, "out"))


def run_one(codyna, work, name):
    os.makedirs(os.path.join(work, "out", name), exist_ok=True)
    args = command(name)
    env = dict(os.environ, LC_ALL="C", LANG="C")
    p = subprocess.run([codyna] + args, cwd=work, capture_output=True, env=env)
    stdout = normalise_stdout(p.stdout.decode("utf-8", "surrogateescape"))
    stderr = normalise_stdout(p.stderr.decode("utf-8", "surrogateescape"))
    rec = {"args": args, "exit_code": p.returncode,
           "stdout_sha256": sha(stdout.encode("utf-8", "surrogateescape")), "stdout": stdout,
           "stderr_sha256": sha(stderr.encode("utf-8", "surrogateescape")), "stderr": stderr, "files": {}}
    d = os.path.join(work, "out", name)
    for root, _, files in os.walk(d):
        for fn in sorted(files):
            full = os.path.join(root, fn)
            rel = os.path.relpath(full, d)
            fmt, entries = file_entries(full)
            rec["files"][rel] = {"format": fmt, "entries": entries}
    rec["files"] = dict(sorted(rec["files"].items()))
    return name, rec


def run_all(codyna, src, work, jobs=2):
    prepare(work, src)
    codyna = os.path.abspath(codyna)
    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as ex:
        results = dict(ex.map(lambda n: run_one(codyna, work, n), RUNS))
    return {n: results[n] for n in RUNS}


# ---------------------------------------------------------------------------- comparing

def describe(e):
    if e is None:
        return "(absent)"
    if e["kind"] == "numeric":
        return (f"{e['dtype']} shape {tuple(e['shape'])} sum {e['sum']} max|x| {e['maxabs']} "
                f"sha256 {e['sha256'][:12]}")
    if "text" in e:
        return f"text {e['text']!r}"
    extra = f", {e['lines']} lines, header {e['header']!r}" if "lines" in e else ""
    return f"text of {e['bytes']} bytes{extra}, sha256 {e['sha256'][:12]}"


def same(a, b):
    if a is None or b is None or a["kind"] != b["kind"] or a["sha256"] != b["sha256"]:
        return False
    if a["kind"] == "numeric":
        return a["dtype"] == b["dtype"] and a["shape"] == b["shape"]
    return True


def compare(expected, actual, a_label="pinned", b_label="now"):
    """Returns a list of difference lines; counts in a dict."""
    diffs = []
    counts = {"runs": 0, "files": 0, "arrays": 0, "texts": 0}
    for name in expected:
        exp, act = expected[name], actual.get(name)
        counts["runs"] += 1
        if act is None:
            diffs.append(f"run {name}: not run")
            continue
        if exp["args"] != act["args"]:
            diffs.append(f"run {name}: arguments changed ({exp['args']} -> {act['args']}); regenerate the pins")
        if exp["exit_code"] != act["exit_code"]:
            diffs.append(f"run {name}: exit code {a_label} {exp['exit_code']}, {b_label} {act['exit_code']}")
        for stream in ("stdout", "stderr"):
            if exp[f"{stream}_sha256"] != act[f"{stream}_sha256"]:
                import difflib
                d = "".join(difflib.unified_diff(exp[stream].splitlines(True), act[stream].splitlines(True),
                                                 f"{a_label} {stream}", f"{b_label} {stream}", n=1))
                diffs.append(f"run {name}: {stream} differs\n" + "\n".join("    " + l for l in d.splitlines()))
        for fn in sorted(set(exp["files"]) | set(act["files"])):
            ef, af = exp["files"].get(fn), act["files"].get(fn)
            if ef is None or af is None:
                diffs.append(f"run {name}: file {fn} {'not written' if af is None else 'written, not pinned'}")
                continue
            counts["files"] += 1
            for var in sorted(set(ef["entries"]) | set(af["entries"])):
                ee, ae = ef["entries"].get(var), af["entries"].get(var)
                if ee is not None:
                    counts["arrays" if ee["kind"] == "numeric" else "texts"] += 1
                if not same(ee, ae):
                    diffs.append(f"run {name}: file {fn}: variable {var} differs\n"
                                 f"    {a_label}: {describe(ee)}\n    {b_label}: {describe(ae)}")
    for name in actual:
        if name not in expected:
            diffs.append(f"run {name}: in the run list, not pinned; regenerate the pins")
    return diffs, counts


# ---------------------------------------------------------------------------- main

def git_head(src):
    try:
        return subprocess.run(["git", "-C", src, "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True).stdout.strip()
    except OSError:
        return ""


def main(argv):
    if argv and argv[0] == "--check":
        if len(argv) != 5:
            sys.exit("usage: pin_outputs.py --check CODYNA SOURCE_DIR JSON WORK_DIR")
        codyna, src, js, work = argv[1:]
        with open(js) as fh:
            pinned = json.load(fh)
        actual = run_all(codyna, src, work)
        extra = sorted(set(f[:-5] for f in os.listdir(os.path.join(src, "examples")) if f.endswith(".json"))
                       - set(EXAMPLES))
        if extra:
            print(f"note: examples not in the run list (not pinned): {', '.join(extra)}")
        diffs, c = compare(pinned["runs"], actual)
        for d in diffs:
            print("MISMATCH " + d)
        print(f"pinned_outputs: checked {c['runs']} runs, {c['files']} files, {c['arrays']} numeric arrays, "
              f"{c['texts']} text entries (+ exit code, stdout, stderr of each run) against {js}")
        if diffs:
            print(f"pinned_outputs: FAIL, {len(diffs)} difference(s)")
            return 1
        print("pinned_outputs: all match")
        return 0
    if len(argv) not in (3, 4):
        sys.exit(__doc__)
    codyna, src, js = argv[:3]
    work = argv[3] if len(argv) == 4 else tempfile.mkdtemp(prefix="pin_outputs_")
    first = run_all(codyna, src, os.path.join(work, "a"))
    second = run_all(codyna, src, os.path.join(work, "b"))
    diffs, c = compare(first, second, "first run", "second run")
    if diffs:
        for d in diffs:
            print("NOT REPRODUCIBLE " + d)
        sys.exit("pin_outputs: two runs of the same binary differ: normalise those fields first; nothing written")
    failed = [n for n, r in first.items() if r["exit_code"] != 0]
    for n in failed:
        print(f"note: run {n} exits with {first[n]['exit_code']}: {first[n]['stderr'].strip()}")
    doc = {"about": "pinned outputs of codyna linearize/simulate; tests/cli/pin_outputs.py writes and checks them",
           "generated_from": {"codyna": os.path.abspath(codyna), "codyna_sha256": sha(open(codyna, "rb").read()),
                              "source_commit": git_head(src)},
           "runs": first}
    with open(js, "w") as fh:
        json.dump(doc, fh, indent=1, sort_keys=False)
        fh.write("\n")
    print(f"pin_outputs: wrote {js}: {c['runs']} runs, {c['files']} files, {c['arrays']} numeric arrays, "
          f"{c['texts']} text entries (two runs agreed)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
