#!/usr/bin/python3
"""Compares two knit-macro results.h5 files of the same case (a solver change must leave the
results unchanged): every floating-point dataset (load-strain data, point and reaction
histories, fields), relative to the largest magnitude of that dataset, skipping timings and
Newton iteration data (residuals, iteration counts). Prints the worst datasets and exits 1
if any differs by more than --tol (default 1e-8) or the files have different datasets.
Usage: scripts/bench/compare_results.py BEFORE/results.h5 AFTER/results.h5 [--tol 1e-8]
(Debian's /usr/bin/python3 with python3-h5py, installed by scripts/setup.sh.)"""
import argparse
import sys

import h5py
import numpy as np

SKIP = ("seconds", "residual", "iterations", "time")


def datasets(f):
    out = {}

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset) and obj.dtype.kind == "f":
            if not any(s in name.split("/")[-1] for s in SKIP):
                out[name] = np.asarray(obj[()], dtype=float)

    f.visititems(visit)
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--tol", type=float, default=1e-8)
    a = ap.parse_args()
    with h5py.File(a.before, "r") as fa, h5py.File(a.after, "r") as fb:
        da, db = datasets(fa), datasets(fb)
    if da.keys() != db.keys():
        print("different datasets:", sorted(da.keys() ^ db.keys()))
        return 1
    rows = []
    for k in da:
        x, y = da[k], db[k]
        if x.shape != y.shape:
            print(f"{k}: shapes {x.shape} vs {y.shape}")
            return 1
        scale = np.max(np.abs(x)) if x.size else 0.0
        diff = np.max(np.abs(x - y)) if x.size else 0.0
        rows.append((diff / scale if scale > 0 else diff, k))
    rows.sort(reverse=True)
    for r, k in rows[:5]:
        print(f"  {k:50s} max|diff| / max|value| = {r:.2e}")
    worst = rows[0][0] if rows else 0.0
    print(f"compared {len(rows)} datasets: worst relative difference {worst:.2e} (tol {a.tol:g})")
    return 0 if worst <= a.tol else 1


if __name__ == "__main__":
    sys.exit(main())
