#!/usr/bin/env python3
"""Are two HDF5 files the same? Every group, dataset and attribute of one is
in the other, with the same type, shape and bytes (floats compared bit for
bit, so NaN equals NaN and 0.0 differs from -0.0), except the attributes
named with --ignore (PATH@NAME, e.g. /@shard), which must exist in both but
may differ. Read with h5py, a reader independent of the cosserat binary.

Exit 0 and one summary line when the files are the same; exit 1 and every
difference otherwise.

    scripts/same_hdf5.py merged.h5 single.h5 --ignore /@shard
"""

import argparse
import sys

import h5py
import numpy as np


def objects(f):
    """Every group and dataset of an open file by path, the root included."""
    found = {"/": f}
    f.visititems(lambda name, obj: found.__setitem__("/" + name, obj))
    return found


def as_bytes(value):
    """The value's type and bytes, strings decoded to bytes."""
    a = np.asarray(value)
    if a.dtype.kind == "O":
        items = [x.encode() if isinstance(x, str) else bytes(x) for x in a.ravel()]
        return ("strings", a.shape, tuple(items))
    return (a.dtype.str, a.shape, a.tobytes())


def compare(a, b, ignore):
    """The differences between two open files, and what was compared."""
    diffs = []
    counts = {"datasets": 0, "attributes": 0, "ignored": 0}
    oa, ob = objects(a), objects(b)
    for path in sorted(set(oa) ^ set(ob)):
        diffs.append(f"{path}: only in {'the first' if path in oa else 'the second'} file")
    for path in sorted(set(oa) & set(ob)):
        x, y = oa[path], ob[path]
        if isinstance(x, h5py.Dataset) != isinstance(y, h5py.Dataset):
            diffs.append(f"{path}: a dataset in one file, a group in the other")
            continue
        if isinstance(x, h5py.Dataset):
            counts["datasets"] += 1
            if as_bytes(x[()]) != as_bytes(y[()]):
                diffs.append(f"{path}: values differ")
        for name in sorted(set(x.attrs) | set(y.attrs)):
            where = f"{path}@{name}"
            if name not in x.attrs or name not in y.attrs:
                diffs.append(f"{where}: only in one file")
            elif where in ignore:
                counts["ignored"] += 1
            else:
                counts["attributes"] += 1
                if as_bytes(x.attrs[name]) != as_bytes(y.attrs[name]):
                    diffs.append(f"{where}: {x.attrs[name]!r} != {y.attrs[name]!r}")
    return diffs, counts


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("first")
    parser.add_argument("second")
    parser.add_argument("--ignore", action="append", default=[], metavar="PATH@NAME")
    args = parser.parse_args()
    with h5py.File(args.first, "r") as a, h5py.File(args.second, "r") as b:
        diffs, counts = compare(a, b, set(args.ignore))
    for d in diffs:
        print(f"differs: {d}", file=sys.stderr)
    if diffs or counts["datasets"] == 0:
        print(f"{args.first} and {args.second} differ ({len(diffs)} differences)", file=sys.stderr)
        return 1
    print(
        f"identical: {counts['datasets']} datasets and {counts['attributes']} attributes "
        f"bit for bit; {counts['ignored']} attribute(s) allowed to differ: {', '.join(sorted(args.ignore)) or 'none'}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
