#!/usr/bin/env python3
"""Peer reader for codyna's HDF5 results files (io/results_file.hpp), run by
tests/core/results_file_test.cpp.

    read_results.py FILE.h5 [EXPECTED.json]

Reads FILE.h5 with h5py and checks the documented layout: every dataset is
float64 with one row per sample of /time, every name and unit list is a
1-D array of fixed-length byte strings (UTF-8) with one entry per column, and
the /solver, /status, /provenance attributes and the root format_version are
there. With EXPECTED.json (written by the test) it also checks that the file
holds exactly the expected datasets, their shapes and values (to 1e-15), the
string lists and the attributes:

    {"datasets": [{"path": "q", "shape": [N, 2], "data": [row-major values]}, ...],
     "strings":  [{"path": "names/q", "values": ["...", ...]}, ...],
     "attributes": {"solver": {"rtol": 1e-8, ...}, "status": {...}, "provenance": {...}, "/": {...}}}

Prints "CODYNA_RESULTS_H5PY_OK <numeric datasets> <string lists>" and exits 0, or prints what
is wrong and exits 1.
"""
import json
import sys

import h5py
import numpy as np

TOL = 1e-15
MATRICES = {"q": "names/q", "v": "names/v", "u": "names/inputs", "y": "names/outputs",
            "xc": "names/controller_states"}
SERIES = ["time", "energy/kinetic", "energy/potential",
          "constraints/position_violation", "constraints/velocity_violation"]
UNITS = {"units/inputs": "names/inputs", "units/outputs": "names/outputs"}
ATTRIBUTES = {
    "solver": ["integrator", "rtol", "atol", "max_step", "steps", "rhs_evals", "jac_evals",
               "error_test_failures", "nonlinear_iterations", "nonlinear_failures", "projections",
               "restarts", "wall_time"],
    "status": ["completed", "cancelled", "failure"],
    "provenance": ["model_name", "model_file", "controller", "codyna_version", "settings_json"],
    "/": ["format_version"],
}


class Mismatch(Exception):
    pass


def require(condition, message):
    if not condition:
        raise Mismatch(message)


def strings(f, path):
    ds = f[path]
    require(ds.ndim == 1, f"{path}: {ds.ndim} dimensions, expected 1")
    require(ds.dtype.kind == "S", f"{path}: dtype {ds.dtype}, expected fixed-length byte strings")
    return [s.decode("utf-8") for s in ds[()]]


def close(a, b):
    return abs(a - b) <= TOL * max(1.0, abs(b))


def check_layout(f):
    n = f["time"].shape[0]
    for path in SERIES:
        require(f[path].dtype == np.float64, f"{path}: dtype {f[path].dtype}")
        require(f[path].shape == (n,), f"{path}: shape {f[path].shape}, expected ({n},)")
    for path, names in MATRICES.items():
        cols = len(strings(f, names))
        require(f[path].dtype == np.float64, f"{path}: dtype {f[path].dtype}")
        require(f[path].shape == (n, cols), f"{path}: shape {f[path].shape}, expected ({n}, {cols})")
    if "y_linear" in f:
        require(f["y_linear"].shape == f["y"].shape, f"y_linear: shape {f['y_linear'].shape}, y {f['y'].shape}")
        require(f["y_linear"].shape[1] > 0, "y_linear is written although it is empty")
    for path, names in UNITS.items():
        units, count = len(strings(f, path)), len(strings(f, names))
        require(units in (0, count), f"{path}: {units} entries for {count} names")
    for group, names in ATTRIBUTES.items():
        missing = sorted(set(names) - set(f[group].attrs))
        require(not missing, f"/{group.strip('/')}: missing attributes {missing}")
    require(f["status"].attrs["completed"] in (0, 1), "status/completed is not 0 or 1")


def dataset_paths(f):
    paths = []
    f.visititems(lambda name, obj: paths.append(name) if isinstance(obj, h5py.Dataset) else None)
    return paths


def check_expected(f, expected):
    string_paths = [s["path"] for s in expected["strings"]]
    wanted = sorted([d["path"] for d in expected["datasets"]] + string_paths)
    require(sorted(dataset_paths(f)) == wanted, f"datasets {sorted(dataset_paths(f))}, expected {wanted}")
    for d in expected["datasets"]:
        data = f[d["path"]][()]
        require(list(data.shape) == d["shape"], f"{d['path']}: shape {data.shape}, expected {d['shape']}")
        flat = data.reshape(-1)  # row-major, as the test wrote it
        require(flat.size == len(d["data"]), f"{d['path']}: {flat.size} values, expected {len(d['data'])}")
        for k, (got, want) in enumerate(zip(flat, d["data"])):
            require(close(float(got), want), f"{d['path']}: element {k} is {got!r}, expected {want!r}")
    for s in expected["strings"]:
        got = strings(f, s["path"])
        require(got == s["values"], f"{s['path']}: {got}, expected {s['values']}")
    for group, attributes in expected["attributes"].items():
        for name, want in attributes.items():
            got = f[group].attrs[name]
            if isinstance(want, str):
                require(isinstance(got, str) and got == want, f"{group}/{name}: {got!r}, expected {want!r}")
            else:
                require(close(float(got), want), f"{group}/{name}: {got!r}, expected {want!r}")


def main(argv):
    if len(argv) not in (2, 3):
        print(__doc__)
        return 2
    try:
        with h5py.File(argv[1], "r") as f:
            check_layout(f)
            if len(argv) == 3:
                with open(argv[2], encoding="utf-8") as e:
                    check_expected(f, json.load(e))
            kinds = [f[path].dtype.kind for path in dataset_paths(f)]
    except Mismatch as m:
        print(f"{argv[1]}: {m}")
        return 1
    print(f"CODYNA_RESULTS_H5PY_OK {kinds.count('f')} {kinds.count('S')}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
