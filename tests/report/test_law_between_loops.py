#!/usr/bin/python3
"""scripts/law_between_loops.py (issue 11): the energy law against cell runs between its knots.

The loop lengths inside the spans, and the sweep input (the stored one at those loop lengths,
no fit); then the comparison on a hand-made database: two knots (5 and 6 mm) whose fit data
span a stress range of 10 and 20 MPa, a network law of two quadratic networks stored with
l_interpolation "energy", and "cell runs" at 5.5 mm whose stresses are the stored law's own
except one state 1.6 MPa off in S11 (10.7 % of the interpolated range 15): 4 of 5 states within
5 %, the largest 10.7 %, and the other interpolation (theta) evaluated beside it. Also the
whole script with --between, and its refusal of a run outside the database's range. Run by
CTest (tests/CMakeLists.txt, label report) with Debian's /usr/bin/python3 (numpy, h5py).
"""
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np

from checklist import Checklist  # tests/report/checklist.py, beside this file

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(ROOT, "scripts", "law_between_loops.py")
sys.path.insert(0, os.path.join(ROOT, "scripts"))
sys.path.insert(0, os.path.join(ROOT, "scripts", "figures"))
import law_between_loops as lb  # noqa: E402
from energy_law import load_law  # noqa: E402

LA = np.array([[1.2, 0.0, 0.0], [0.3, 0.9, 0.0], [0.0, 0.0, 0.8]])
LB = np.array([[0.5, 0.0, 0.0], [-0.4, 1.5, 0.0], [0.2, 0.0, 0.3]])


def raw_path(g, name, E, S, s="coverage"):
    """A converged raw path: E with tensor E12 in column 3, as the sweep writes it."""
    p = g.create_group(name)
    p["E"], p["S"], p["status"] = E, S, np.zeros(len(E), dtype=np.int32)
    p.attrs["set"], p.attrs["kind"], p.attrs["axis"] = s, "gradient", 0


def write_db(path):
    with h5py.File(path, "w") as f:
        f["loop_lengths"] = [5.0, 6.0]
        for k, top in enumerate((10.0, 20.0)):  # stress ranges 10 and 20 MPa
            raw = f.create_group("loop_%d/raw" % k)
            E = np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0]])
            raw_path(raw, "path_00", E, np.array([[0.0, 0.0, 0.0], [top, 0.0, 0.0]]))
            # held out: not part of the range
            raw_path(raw, "path_01", E, np.array([[0.0, 0.0, 0.0], [99.0, 0.0, 0.0]]), "holdout")
        law = f.create_group("energy_law")
        law.attrs["family"], law.attrs["l_interpolation"] = "network", "energy"
        law.attrs["h1"], law.attrs["h2"], law.attrs["floor"] = 1, 1, 0.02
        theta = np.zeros((2, 20))
        theta[0, 11:], theta[1, 11:] = LA.ravel(), LB.ravel()
        law["l_knots"] = [5.0, 6.0]
        law["theta"] = theta


def write_runs(path, db):
    """Cell runs at 5.5 mm: the stored law's stresses, one state 1.6 MPa off in S11."""
    e = np.array([[0.05, -0.02, 0.06], [0.2, 0.1, -0.3], [-0.25, 0.3, 0.4], [0.1, 0.1, 0.1],
                  [0.3, -0.2, 0.2]])
    with h5py.File(db, "r") as f:
        S = load_law(f["energy_law"], 5.5).eval(e)[1]
    S[2, 0] += 1.6
    E = e.copy()
    E[:, 2] *= 0.5
    with h5py.File(path, "w") as f:
        f["loop_lengths"] = [5.5]
        raw = f.create_group("loop_0/raw")
        raw_path(raw, "path_00", E[:3], S[:3], "paper")
        raw_path(raw, "path_01", E[3:], S[3:], "holdout")


def main():
    c = Checklist()
    c(lb.between_points([4.5, 5.5, 6.5], 1) == [5.0, 6.0], "midpoints of two spans")
    c(lb.between_points([4.5, 5.5], 3) == [4.75, 5.0, 5.25], "three points in a span")
    try:
        lb.between_points([4.5, 5.5], 0)
        c(False, "per_span 0 refused")
    except ValueError:
        c(True, "per_span 0 refused")
    stored = {"loop_lengths": [4.5, 6.5], "cell": {"elements": 24}, "fit": {"degree_1": 3},
              "energy_fit": {"family": "network"}, "load_paths": {"preset": "default"}}
    s = lb.sweep_input(stored, [5.5])
    c(s["loop_lengths"] == [5.5] and s["fit"] is False and s["energy_fit"] is False,
            "the sweep input: the new loop lengths, no fit")
    c(s["cell"] == stored["cell"] and s["load_paths"] == stored["load_paths"],
            "the sweep input keeps the database's cell and paths")
    c(stored["loop_lengths"] == [4.5, 6.5], "the stored input is not modified")

    with tempfile.TemporaryDirectory(prefix="law_between_loops_test_") as tmp:
        return file_checks(c, tmp)


def file_checks(c, tmp):
    """The checks on files (a database and cell runs in `tmp`, removed afterwards)."""
    db, runs = os.path.join(tmp, "db.h5"), os.path.join(tmp, "runs.h5")
    write_db(db)
    write_runs(runs, db)
    with h5py.File(db, "r") as f, h5py.File(runs, "r") as r:
        rows = lb.compare(f, r)
        held = lb.compare(f, r, "holdout")
    l, n, w, big, wo, bo = rows[0]
    c(len(rows) == 1 and l == 5.5 and n == 5, "one loop length, five states: %s" % rows)
    c(w == 4, "four states within 5 %% (got %d)" % w)
    c(abs(big - 1.6 / 15.0) < 1e-9, "largest 10.67 %% of the interpolated range 15 "
            "(got %.4f %%)" % (100 * big))
    c(wo is not None and bo > 0.0 and bo != big,
            "the other interpolation is evaluated beside it (largest %s)" % bo)
    c(held[0][1] == 2 and held[0][2] == 2, "--set holdout: its two states, both within")

    out = subprocess.run([sys.executable, SCRIPT, db, "--between", runs], capture_output=True,
                         text=True)
    c(out.returncode == 0, "the script runs with --between: %s" % out.stderr[-300:])
    c("within 5 % of the range at 4 (largest 10.67 %)" in out.stdout,
            "the summary line: %s" % out.stdout.strip().splitlines()[-2:])
    c("with l_interpolation parameters at" in out.stdout, "the other mode is printed")
    with h5py.File(runs, "a") as f:
        del f["loop_lengths"]
        f["loop_lengths"] = [6.5]
    out = subprocess.run([sys.executable, SCRIPT, db, "--between", runs], capture_output=True,
                         text=True)
    c(out.returncode != 0 and "outside the database's range" in out.stderr,
            "a run outside the range is refused: %s" % out.stderr.strip()[-200:])
    return c.exit_code()


if __name__ == "__main__":
    sys.exit(main())
