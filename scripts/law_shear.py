#!/usr/bin/python3
"""The energy law along the cell's pure-shear paths (session 55; not an acceptance check).

Like uniaxial tension (scripts/law_uniaxial.py), pure shear carries stresses far below the
stress range the acceptance measures errors against (issue 11: within 5 % of a range the jammed,
compressed corners set, 21-33 MPa), so a law can miss the cell's shear stiffness by half and
still pass. Session 55's red team found the default law's S12 along the paper's pure-shear path
(E11 = E22 = 0) at 2E12 = 0.174 to be 0.419 / 0.324 / 0.132 / 0.137 / 0.147 MPa at l = 4.5 /
5 / 5.5 / 6 / 6.5 mm, where the cell's falls with l (0.291 / 0.214 / 0.172 / 0.143 / 0.121):
the law's 5.5 mm knit is softer in shear than its 6.5 mm one. This script evaluates the law at
the states of the database's shear paths (kind "shear") and prints, per loop length, the law's
S12 over the cell's at the states whose S12 is at least MIN_SHARE of the path's largest, and
the order in l: at each shear strain that every loop length's path reaches (the same 2E12 to
1e-9), the pairs of neighbouring loop lengths whose cell stresses differ by more than
ORDER_MIN_GAP of the larger, and among them those where the law's S12 goes the other way:

    /usr/bin/python3 scripts/law_shear.py out/database.h5
    /usr/bin/python3 scripts/law_shear.py out/database.h5 --min-share 0.25

The law is re-evaluated by scripts/figures/energy_law.py, the cell states read by
scripts/cell_paths.py.
"""
import os
import sys

import h5py
import numpy as np

_here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(_here, "figures"))
sys.path.insert(0, _here)
from cell_paths import load_paths, share_script_main  # noqa: E402
from energy_law import load_law  # noqa: E402

MIN_SHARE = 0.1  # states with a cell S12 of at least this share of the path's largest
ORDER_MIN_GAP = 0.05  # neighbouring loop lengths whose cell S12 differ by less are not ordered
SAME_STRAIN = 1e-9  # 2E12 of two loop lengths' states this close: the same shear strain


def shear_states(db_path):
    """Per loop length: (l, e (n x 3, e3 = 2 E12), S (n x 3), S_law (n x 3), largest (n,: the
    largest cell |S12| of each state's path)) of its shear paths' converged states, in path
    order. Empty when the database has no energy law."""
    out = []
    with h5py.File(db_path, "r") as f:
        if "energy_law" not in f:
            return []
        for k, l in enumerate(np.asarray(f["loop_lengths"], dtype=float)):
            paths = [p for p in load_paths(f, k) if p[3] == "shear"]
            e = np.vstack([p[1] for p in paths]) if paths else np.zeros((0, 3))
            S = np.vstack([p[2] for p in paths]) if paths else np.zeros((0, 3))
            s_law = load_law(f["energy_law"], l).eval(e)[1] if len(e) else np.zeros((0, 3))
            # Each path's own largest |S12| for its cut (a path of negative shear: its
            # magnitudes; the review of session 55: such a path was dropped without a word).
            largest = np.concatenate([np.full(len(p[2]), np.abs(p[2][:, 2]).max(initial=0.0))
                                      for p in paths]) if paths else np.zeros(0)
            out.append((float(l), e, S, s_law, largest))
    return out


def shear_ratios(db_path, min_share=MIN_SHARE):
    """dict(rows=[per loop length: l, n (states kept), median, largest (of S12_law / S12_cell,
    the one farthest from 1), at (its 2E12)], order=dict(pairs (neighbouring loop lengths at a
    common shear strain whose states are kept at every loop length, their cell S12 differing by
    more than ORDER_MIN_GAP of the larger), reversed (of those,
    where the law's S12 goes the other way), example (the common strain with most reversals:
    g, l, cell, law))). None when the database has no energy law or no shear path."""
    states = shear_states(db_path)
    if not states or not any(len(s[1]) for s in states):
        return None
    rows = []
    for l, e, S, s_law, largest in states:
        keep = (largest > 0) & (np.abs(S[:, 2]) >= min_share * largest)
        row = {"l": l, "n": int(keep.sum())}
        if keep.any():
            ratio = s_law[keep, 2] / S[keep, 2]
            i = int(np.argmax(np.abs(ratio - 1.0)))
            row.update(median=float(np.median(ratio)), largest=float(ratio[i]),
                       at=float(e[keep][i, 2]))
        rows.append(row)
    # The order in l at the shear strains every loop length reaches.
    pairs = reversed_ = 0
    example = None
    base = states[0][1]
    for j, g in enumerate(base[:, 2] if len(base) else []):
        picks = []
        for l, e, S, s_law, largest in states:
            hit = np.flatnonzero(np.abs(e[:, 2] - g) <= SAME_STRAIN) if len(e) else []
            # The states the ratios keep, at every loop length.
            if len(hit) == 0 or not abs(S[hit[0], 2]) >= min_share * largest[hit[0]] > 0:
                break
            picks.append((l, S[hit[0], 2], s_law[hit[0], 2]))
        if len(picks) != len(states) or g == 0:
            continue
        n_rev = 0
        for (la, ca, wa), (lb, cb, wb) in zip(picks, picks[1:]):
            if abs(cb - ca) <= ORDER_MIN_GAP * max(abs(ca), abs(cb)):
                continue
            pairs += 1
            if (cb - ca) * (wb - wa) < 0:
                n_rev += 1
        reversed_ += n_rev
        if n_rev and (example is None or n_rev > example["n"]):
            example = {"n": n_rev, "g": float(g), "l": [p[0] for p in picks],
                       "cell": [float(p[1]) for p in picks], "law": [float(p[2]) for p in picks]}
    return {"rows": rows, "order": {"pairs": pairs, "reversed": reversed_, "example": example}}


def summary(result, min_share=MIN_SHARE):
    """One sentence for the report (empty without a result)."""
    if not result:
        return ""
    parts = []
    for r in result["rows"]:
        if r["n"]:
            parts.append(f"{r['l']:g} mm: {r['median']:.2f} (farthest from 1: {r['largest']:.2f} "
                         f"at 2E12 = {r['at']:.3f})")
        else:
            parts.append(f"{r['l']:g} mm: no state")
    o = result["order"]
    order = (f" Order in l: of {o['pairs']} pairs of neighbouring loop lengths at a shear strain "
             f"kept at every loop length whose cell S12 differ by more than "
             f"{100 * ORDER_MIN_GAP:g} %, the law reverses the cell's order at {o['reversed']}")
    x = o["example"]
    if x:
        def seq(v):
            return " / ".join(f"{s:.3f}" for s in v)
        order += (f" (most at 2E12 = {x['g']:.3f}: cell {seq(x['cell'])} MPa, law "
                  f"{seq(x['law'])} MPa at l = {' / '.join(f'{l:g}' for l in x['l'])} mm)")
    return (f"Pure shear (not judged; `scripts/law_shear.py`): at the states of the database's "
            f"pure-shear paths whose |S12| is at least {100 * min_share:g} % of the path's "
            f"largest, the law's S12 over the cell's is, median (farthest from 1): "
            f"{'; '.join(parts)}.{order}. The acceptance, relative to the range, does not see "
            f"this; cases with shear in the material frame (alpha not 0 or 90 deg, curved "
            f"patches) follow it.")


def main():
    share_script_main(__doc__, "law_shear", shear_ratios, summary, MIN_SHARE, "cell S12",
                      "no /energy_law or no shear path")


if __name__ == "__main__":
    main()
