#!/usr/bin/python3
"""The energy law's errors where the macroscale runs go (issue 11; not an acceptance check).

The law's acceptance judges its error over the whole strain box: every fit state and every
held-out state within 5 % of the loop length's stress range. Most of the box is never reached
by the paper's cases (docs/unit-cell.md, "Strain box"). This script restricts both sets to the
cell states that lie within RADIUS (Euclidean in (E11, E22, E12), tensor shear; W is even in
E12, so a visited state counts with either sign of E12) of a strain state that some run
visits, and prints the law's error there, in the same units as the acceptance (% of the stress
range; errors are the largest stress component's).

    /usr/bin/python3 scripts/law_near_visited.py out/database.h5 out/results
    /usr/bin/python3 scripts/law_near_visited.py out/database.h5 out/results --radius 0.1

The visited states are those of scripts/strain_box.py (fields/step_NNNN of every results.h5);
the law is re-evaluated by scripts/figures/energy_law.py, the cell states read by
scripts/cell_paths.py.
"""
import argparse
import os
import sys

import h5py
import numpy as np

_here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(_here, "figures"))
sys.path.insert(0, _here)
from cell_paths import (fit_min_cos, fit_states, load_paths, open_database,  # noqa: E402
                        positive_number, stress_range)
from energy_law import load_law  # noqa: E402
from strain_box import current_results, read_case  # noqa: E402

RADIUS = 0.05
BOUND = 0.05  # issue 11: within 5 % of the stress range


def visited_strains(results_dir):
    """(E11, E22, E12) of every output sample of every results.h5 under results_dir, with its
    mirror image E12 -> -E12, finite ones only, rounded to 1e-4 and deduplicated."""
    parts = [read_case(p) for p in current_results(results_dir)]
    V = np.vstack(parts) if parts else np.zeros((0, 3))
    V = V[np.all(np.isfinite(V), axis=1)]
    V = np.vstack([V, V * [1.0, 1.0, -1.0]])
    return np.unique(np.round(V, 4), axis=0)


class NearIndex:
    """Which query points lie within `radius` of a set of points: a hash of cubes of edge
    `radius`, so each query looks at the 27 cubes around it only."""

    def __init__(self, points, radius):
        self.r = radius
        self.cells = {}
        keys = np.floor(points / radius).astype(np.int64)
        order = np.lexsort(keys.T)
        keys, points = keys[order], points[order]
        if len(points):
            cut = np.flatnonzero(np.any(np.diff(keys, axis=0) != 0, axis=1)) + 1
            for k, block in zip(np.split(keys, cut), np.split(points, cut)):
                self.cells[tuple(k[0])] = block

    def near(self, q):
        """Boolean mask over the rows of q (n x 3)."""
        out = np.zeros(len(q), dtype=bool)
        for n, x in enumerate(q):
            c = np.floor(x / self.r).astype(np.int64)
            for d in np.ndindex(3, 3, 3):
                block = self.cells.get((c[0] + d[0] - 1, c[1] + d[1] - 1, c[2] + d[2] - 1))
                if block is not None and np.min(np.sum((block - x) ** 2, axis=1)) <= self.r ** 2:
                    out[n] = True
                    break
        return out


def near_errors(db_path, results_dir, radius=RADIUS):
    """Per loop length: dict(l, fit_n, fit_near, fit_max (over the near fit states, nan if
    none), hold_n, hold_near, hold_in (near held-out states within BOUND), hold_max). Empty
    when the database has no energy law or no run visited any state."""
    V = visited_strains(results_dir)
    if not len(V):
        return []
    index = NearIndex(V, radius)
    rows = []
    with h5py.File(db_path, "r") as f:
        if "energy_law" not in f:
            return []
        for k, l in enumerate(np.asarray(f["loop_lengths"], dtype=float)):
            paths = fit_states(load_paths(f, k), fit_min_cos(f))  # the fit's states and range
            R = stress_range(paths)
            law = load_law(f["energy_law"], l)
            row = {"l": float(l)}
            for which, held in (("fit", False), ("hold", True)):
                sel = [p for p in paths if (p[0] == "holdout") == held]
                e = np.vstack([p[1] for p in sel]) if sel else np.zeros((0, 3))
                S = np.vstack([p[2] for p in sel]) if sel else np.zeros((0, 3))
                err = (np.abs(law.eval(e)[1] - S).max(axis=1) / R) if len(e) else np.zeros(0)
                tensor = e * [1.0, 1.0, 0.5]  # e3 = 2 E12 -> E12
                near = index.near(tensor) if len(e) else np.zeros(0, dtype=bool)
                row[which + "_n"] = int(len(e))
                row[which + "_near"] = int(near.sum())
                row[which + "_max"] = float(err[near].max()) if near.any() else float("nan")
                if held:
                    row["hold_in"] = int((err[near] <= BOUND).sum())
            rows.append(row)
    return rows


def summary(rows, radius=RADIUS):
    """One sentence for the report (empty without rows)."""
    if not rows:
        return ""
    pct = lambda v: " / ".join("-" if not np.isfinite(x) else f"{100 * x:.1f}" for x in v)
    ls = " / ".join(f"{r['l']:g}" for r in rows)
    fit_near = ", ".join(str(r["fit_near"]) for r in rows)
    hold_near = sum(r["hold_near"] for r in rows)
    hold_in = sum(r["hold_in"] for r in rows)
    hold_max = max((r["hold_max"] for r in rows if np.isfinite(r["hold_max"])), default=float("nan"))
    return (f"Where the runs go (not judged; `scripts/law_near_visited.py`): of the cell states "
            f"within {radius:g} of a strain state that a run visits, the fit data's largest "
            f"error is {pct([r['fit_max'] for r in rows])} % of the stress range (l = {ls} mm; "
            f"{fit_near} of {rows[0]['fit_n']} fit states), and {hold_in} of {hold_near} "
            f"held-out states are within {100 * BOUND:g} % (largest "
            f"{'-' if not np.isfinite(hold_max) else f'{100 * hold_max:.1f}'} %).")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("database", help="material database (HDF5) with /energy_law")
    ap.add_argument("results", help="directory searched recursively for results.h5")
    ap.add_argument("--radius", type=positive_number, default=RADIUS,
                    help=f"distance to a visited state, tensor strain (default {RADIUS})")
    a = ap.parse_args()
    open_database(a.database, "law_near_visited").close()
    rows = near_errors(a.database, a.results, a.radius)
    if not rows:
        sys.exit(f"law_near_visited: nothing to compare ({a.database}: no /energy_law, or no "
                 f"results.h5 with material-frame strains under {a.results})")
    for r in rows:
        print(f"l = {r['l']:g} mm: fit states near a visited state {r['fit_near']} of "
              f"{r['fit_n']}, largest error {100 * r['fit_max']:.1f} %; held out near "
              f"{r['hold_near']} of {r['hold_n']}, within {100 * BOUND:g} %: {r['hold_in']}, "
              f"largest {100 * r['hold_max']:.1f} %")
    print(summary(rows, a.radius))


if __name__ == "__main__":
    main()
