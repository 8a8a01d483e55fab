#!/usr/bin/python3
"""h5_equal.py REF.h5 OTHER.h5 ...: every dataset and attribute of each OTHER equal to REF's, bit for
bit (shape, dtype and bytes; NaN included), the same names in both. Prints the count; exit 1 naming
the first difference. Used by tests/cli/sweep.sh and sweep_mpi.sh."""
import sys

import h5py
import numpy as np


def items(path):
    out = {}

    def visit(name, obj):
        for k, v in obj.attrs.items():
            out[name + "@" + k] = v
        if isinstance(obj, h5py.Dataset):
            out[name] = obj[()]

    with h5py.File(path, "r") as f:
        for k, v in f.attrs.items():
            out["@" + k] = v
        f.visititems(visit)
    return out


def main(ref, others):
    a = items(ref)
    for path in others:
        b = items(path)
        if a.keys() != b.keys():
            sys.exit("h5_equal: %s and %s hold other variables: %s" % (ref, path, sorted(a.keys() ^ b.keys())))
        for k in a:
            x, y = np.asarray(a[k]), np.asarray(b[k])
            if x.shape != y.shape or x.dtype != y.dtype or x.tobytes() != y.tobytes():
                sys.exit("h5_equal: %s differs between %s and %s" % (k, ref, path))
    print("%d variables equal bit for bit (%s and %s)" % (len(a), ref, ", ".join(others)))


if __name__ == "__main__":
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2:])
