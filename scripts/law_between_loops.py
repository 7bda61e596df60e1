#!/usr/bin/python3
"""Is the energy law valid between the loop lengths it was fitted at?

The law of a material database is fitted to cell runs at its loop lengths (the knots) and
interpolated between them (attribute l_interpolation of /energy_law; docs/database.md
"Interpolation in l"). This script runs the database's own load paths (every set, or one) on
the same cell at loop lengths between the knots, which no fit has seen, and compares the stored
law there with the cell: a held-out check in l, beside the held-out strain states at the knots.

For each new loop length it prints how many converged states the stored law meets within 5 %
of the stress range, and the largest error; for a network law also the same with the other
interpolation (theta piecewise linear against W piecewise linear), so the two can be compared
on the same cell runs. The stress range between two knots is the linear interpolation of the
two knots' ranges (docs/database.md: the largest max - min of a stress component over the
loop length's fit data).

Usage: /usr/bin/python3 scripts/law_between_loops.py DB.h5 [--per-span 1] [--set all]
           [--work DIR] [--knit-meso PATH] [--threads 2] [--between RUNS.h5]
Runs `knit-meso sweep` once with the database's stored sweep input (/sweep input_json), its
loop lengths replaced by --per-span points inside every span (1: the midpoints) and no fit;
writes nothing into DB.h5. --between reuses such a run instead. numpy and h5py only
(tests/report/test_law_between_loops.py).
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "figures"))
from cell_paths import (load_paths, open_database, run_sweep,  # noqa: E402
                        stored_sweep_input, stress_range)

THRESHOLD = 0.05


def _text(v):
    return v.decode() if isinstance(v, bytes) else str(v)


def between_points(knots, per_span):
    """per_span loop lengths inside every span of the sorted knots, evenly spaced."""
    if per_span < 1:
        raise ValueError("per_span must be >= 1")
    out = []
    for a, b in zip(knots[:-1], knots[1:]):
        out.extend(a + (b - a) * i / (per_span + 1.0) for i in range(1, per_span + 1))
    return [round(x, 9) for x in out]


def sweep_input(stored, loop_lengths):
    """The stored sweep input at other loop lengths, without any fit."""
    s = dict(stored)
    s["description"] = "law_between_loops.py: the database's paths between its loop lengths"
    s["loop_lengths"] = loop_lengths
    s["fit"] = False
    s["energy_fit"] = False
    return s


def laws_at(g, l):
    """(stored law, the other interpolation's law or None, the stored mode) at loop length l."""
    from energy_law import load_law, network_law, stored_l_interpolation
    stored = load_law(g, l)
    if _text(g.attrs.get("family", "ridge")) != "network":
        return stored, None, "ridge"
    mode = stored_l_interpolation(g)
    other = {"energy": "parameters", "parameters": "energy"}[mode]
    return stored, network_law(g, l, other), mode


def compare(db, runs, which="all"):
    """Rows (l, states, within, largest, other within, other largest) over the loop lengths of
    `runs` (an open HDF5 database of cell runs between db's knots)."""
    knots = np.array(db["loop_lengths"], dtype=float)
    ranges = [stress_range(load_paths(db, k)) for k in range(len(knots))]
    rows = []
    for k, l in enumerate(np.array(runs["loop_lengths"], dtype=float)):
        if not knots[0] <= l <= knots[-1]:
            raise SystemExit("error: loop length %g of the runs lies outside the database's "
                             "range [%g, %g]" % (l, knots[0], knots[-1]))
        R = float(np.interp(l, knots, ranges))
        paths = [p for p in load_paths(runs, k) if which == "all" or p[0] == which]
        e = np.vstack([p[1] for p in paths if len(p[1])])
        s = np.vstack([p[2] for p in paths if len(p[2])])
        stored, other, _ = laws_at(db["energy_law"], l)
        err = np.abs(stored.eval(e)[1] - s).max(axis=1) / R
        row = [l, len(err), int((err <= THRESHOLD).sum()), float(err.max()), None, None]
        if other is not None:
            eo = np.abs(other.eval(e)[1] - s).max(axis=1) / R
            row[4], row[5] = int((eo <= THRESHOLD).sum()), float(eo.max())
        rows.append(tuple(row))
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("db", help="material database (HDF5) with /energy_law and /sweep input_json")
    ap.add_argument("--per-span", type=int, default=1,
                    help="loop lengths inside every span of the knots (default 1: midpoints)")
    ap.add_argument("--set", default="all",
                    help="paths to compare: all (default), paper, coverage or holdout")
    ap.add_argument("--work", help="directory for the sweep input and its database "
                    "(default: a new temporary directory, kept)")
    ap.add_argument("--knit-meso", default=os.path.join(os.path.dirname(os.path.abspath(
        __file__)), "..", "build", "bin", "knit-meso"))
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--between", help="reuse this database of cell runs between the knots "
                    "(written by an earlier run of this script) instead of running the cell")
    a = ap.parse_args(argv)
    import h5py
    db = open_database(a.db, "error")
    if "energy_law" not in db:
        raise SystemExit("error: %s: /energy_law: group missing (no energy law to check)" % a.db)
    if a.set not in ("all", "paper", "coverage", "holdout"):
        raise SystemExit("error: --set must be all, paper, coverage or holdout")
    out = a.between
    if out is None:
        stored = stored_sweep_input(db, a.db)
        knots = [float(x) for x in np.array(db["loop_lengths"])]
        ls = between_points(knots, a.per_span)
        out = run_sweep(a.knit_meso, sweep_input(stored, ls), a.work, "between", a.threads,
                        "the database's paths at %s mm" % ", ".join("%g" % x for x in ls))
    if not os.path.isfile(out):
        raise SystemExit("error: %s: no such file" % out)
    rows = compare(db, h5py.File(out, "r"), a.set)
    mode = laws_at(db["energy_law"], rows[0][0])[2] if rows else "?"
    other = {"energy": "parameters", "parameters": "energy"}.get(mode)
    print("%7s %7s  %-34s %s" % ("l mm", "states", "stored law (l_interpolation %s)" % mode,
                                "%s" % ("with l_interpolation %s" % other if other else "")))
    for l, n, w, big, wo, bo in rows:
        print("%7.3f %7d  %4d within 5 %%, largest %6.2f %%      %s" %
              (l, n, w, 100 * big, "%4d within 5 %%, largest %6.2f %%" % (wo, 100 * bo)
               if wo is not None else ""))
    n = sum(r[1] for r in rows)
    line = ("summary (%s paths): %d states between the knots; the stored law is within 5 %% of "
            "the range at %d (largest %.2f %%)" % (a.set, n, sum(r[2] for r in rows),
                                                   100 * max(r[3] for r in rows)))
    if other:
        line += "; with l_interpolation %s at %d (largest %.2f %%)" % (
            other, sum(r[4] for r in rows), 100 * max(r[5] for r in rows))
    print(line)
    print("cell runs: %s" % out)


if __name__ == "__main__":
    main()
