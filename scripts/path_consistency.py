#!/usr/bin/python3
"""Is the unit cell's stress a function of its strain? (issue 11, "Fit quality")

Any law S(E) — hyperelastic or not — can match two cell states at (nearly) the same strain only
as well as the cell itself agrees with itself there. The cell is frictional (mu = 0.15), so its
stress could depend on the path that led to a strain. This script measures how much, from the
data the database already holds: for each loop length it takes every converged state of every
raw path (fitted and held-out), finds the pairs of states of DIFFERENT paths whose strains
e = (E11, E22, 2 E12) lie within `--radius` of each other (Euclidean), and prints how far their
stresses differ: max over (S11, S22, S12) of |S_a - S_b|, in % of the loop length's stress range
(largest max - min of a component over its fit data, as in docs/database.md). The threshold
printed is the fit criterion's 5 %. The difference includes what the strain offset |e_a - e_b|
itself causes (at most the largest tangent times the radius), so it is an upper bound of the
path dependence at that radius.

`--self-check` makes the check fail on purpose: it adds 10 % of the range to S11 of one path of
a copy of the data and requires that pairs with that path now differ by more than 5 %.

Usage: /usr/bin/python3 scripts/path_consistency.py DATABASE.h5 [--radius 0.01]
       /usr/bin/python3 scripts/path_consistency.py DATABASE.h5 --self-check
Needs python3-numpy and python3-h5py. Exit status 0 (the figures are a measurement, not a
verdict), 2 for an unreadable database, 1 when the self-check does not detect its change.
"""
import argparse
import sys

import numpy as np

try:
    import h5py
except ImportError:
    sys.exit("path_consistency.py: needs python3-h5py (run it with /usr/bin/python3)")

from cell_paths import load_paths, positive_number, stress_range  # scripts/cell_paths.py


def read_loop(f, loop):
    """Converged states of /loop_<loop>/raw (cell_paths.load_paths), fitted and held out:
    e (n x 3), S (n x 3), path index, and the loop length's stress range."""
    paths = load_paths(f, loop)
    E = np.concatenate([p[1] for p in paths])
    S = np.concatenate([p[2] for p in paths])
    pid = np.concatenate([np.full(len(p[1]), i) for i, p in enumerate(paths)])
    return E, S, pid, stress_range(paths)


def pairs(E, S, pid, rng, radius):
    """(difference / rng, |e_a - e_b|, a, b) of every cross-path pair within radius."""
    out = []
    for a in range(len(E)):
        d = np.linalg.norm(E[a + 1:] - E[a], axis=1)
        for off in np.nonzero((d < radius) & (pid[a + 1:] != pid[a]))[0]:
            b = a + 1 + off
            out.append((float(np.abs(S[a] - S[b]).max()) / rng, float(d[off]), a, b))
    out.sort(reverse=True)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("database")
    ap.add_argument("--radius", type=positive_number, default=0.01)
    ap.add_argument("--self-check", action="store_true")
    a = ap.parse_args()
    try:
        f = h5py.File(a.database, "r")
        ls = [float(x) for x in f["loop_lengths"][()]]
        data = [read_loop(f, k) for k in range(len(ls))]
    except (OSError, KeyError, ValueError) as e:
        print(f"path_consistency.py: {a.database}: {e}", file=sys.stderr)
        return 2
    if not data:
        print(f"path_consistency.py: {a.database}: no loop lengths", file=sys.stderr)
        return 2
    if a.self_check:
        E, S, pid, rng = data[0]
        before = pairs(E, S, pid, rng, a.radius)
        if not before:
            print("self-check: no pair within the radius to perturb", file=sys.stderr)
            return 1
        victim = pid[before[0][2]]
        S = S.copy()
        S[pid == victim, 0] += 0.10 * rng
        after = pairs(E, S, pid, rng, a.radius)
        hit = [p for p in after if victim in (pid[p[2]], pid[p[3]]) and p[0] > 0.05]
        print(f"self-check (loop_0): +10 % of the range on S11 of path {victim}: "
              f"{len(hit)} of its pairs now differ by > 5 % (largest before "
              f"{100 * before[0][0]:.1f} %)")
        return 0 if hit else 1
    print(f"{a.database}: pairs of states of different paths with |e_a - e_b| < {a.radius} "
          f"(e = (E11, E22, 2E12)); their largest stress difference, % of the stress range "
          f"(criterion of the fit: 5 %)")
    for k, (E, S, pid, rng) in enumerate(data):
        out = pairs(E, S, pid, rng, a.radius)
        over = sum(1 for p in out if p[0] > 0.05)
        largest = f"{100 * out[0][0]:.1f} %" if out else "-"
        print(f"  loop_{k} (l = {ls[k]:g} mm): range {rng:.3g} MPa, {len(out)} pairs, "
              f"{over} differ by > 5 %, largest {largest}")
        for diff, dist, i, j in out[:2]:
            print(f"      {100 * diff:.1f} % at e = {np.round(E[i], 3)} (|de| {dist:.4f}): "
                  f"path {pid[i]} S = {np.round(S[i], 3)}, path {pid[j]} S = {np.round(S[j], 3)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
