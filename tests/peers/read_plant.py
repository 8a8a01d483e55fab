#!/usr/bin/env python3
"""Peer reader for codyna's MAT export, run by tests/core/mat_export_test.cpp.

    read_plant.py scipy FILE.mat   # MAT v5, with scipy.io.loadmat
    read_plant.py h5py  FILE.mat   # MAT v7.3, with h5py (plain HDF5)

Prints JSON: {"A": [[...]], "B": ..., "C": ..., "D": ..., "Ts": x,
"state_names": [...], ... (the six name and unit lists)}
Floats are printed with repr, so they read back exactly.
"""
import json
import sys

import numpy as np

MATRICES = ["A", "B", "C", "D"]
LISTS = ["state_names", "input_names", "output_names", "state_units", "input_units", "output_units"]


def read_scipy(path):
    import scipy.io
    # codyna writes text as UTF-16 (as MATLAB does); scipy's default codec would mangle non-ASCII
    d = scipy.io.loadmat(path, uint16_codec="utf-16")
    out = {k: np.asarray(d[k], dtype=float) for k in MATRICES}
    out["Ts"] = float(d["Ts"][0, 0])
    for k in LISTS:
        out[k] = [str(c[0]) if c.size else "" for c in d[k].flatten(order="F")]
    return out


def h5_array(f, ds):
    """A MATLAB v7.3 dataset as MATLAB sees it (HDF5 holds the transpose)."""
    if ds.attrs.get("MATLAB_empty", 0):
        return np.zeros(tuple(int(n) for n in ds[()]))  # the dataset holds the size
    return np.asarray(ds[()]).T


def h5_string(f, ds):
    a = h5_array(f, ds)
    return "" if a.size == 0 else a.astype(np.uint16).flatten(order="F").tobytes().decode("utf-16-le")


def read_h5py(path):
    import h5py
    with h5py.File(path, "r") as f:
        out = {k: h5_array(f, f[k]).astype(float) for k in MATRICES}
        out["Ts"] = float(h5_array(f, f["Ts"])[0, 0])
        for k in LISTS:
            refs = h5_array(f, f[k])
            out[k] = [h5_string(f, f[r]) for r in refs.flatten(order="F")] if refs.size else []
    return out


def main():
    reader, path = sys.argv[1], sys.argv[2]
    out = {"scipy": read_scipy, "h5py": read_h5py}[reader](path)
    for k in MATRICES:
        out[k] = {"rows": out[k].shape[0], "cols": out[k].shape[1], "data": out[k].tolist()}
    json.dump(out, sys.stdout)
    print()


if __name__ == "__main__":
    main()
