#!/usr/bin/python3
"""scripts/law_uniaxial.py (session 39): the energy law along the cell's uniaxial-stress paths.

A hand-made database of one loop length (5 mm) whose law is S = 2 (E11, E22, 2 E12) (a network
with all parameters 0 and a floor of 2 MPa). A uniaxial wale path (axis 1) whose cell carries
S22 = 0.4, 1.0 and 4.0 MPa at E22 = 0.1, 0.25, 0.5 with E11 = -0.05, -0.1, -0.2 and S11 = 0:
the law's axial stress is 0.2, 0.5, 1.0 MPa, so the ratios are 0.5, 0.5, 0.25 and the lateral
shares |2 E11| / S22 0.25, 0.2, 0.1; the first state (0.4 MPa, 10 % of the path's largest
4.0) is kept at the default share and dropped at 0.2. A second wale path of small stresses is
cut by its own largest, not by the first path's. A biaxial path and a held-out uniaxial
course path with the same stresses must not count as the wale's. Also the sentence, a database
without a law and the command line's refusal of a bad --min-share.

The law's own uniaxial response (session 40): with S = 2 e the lateral stress vanishes at a
lateral strain of 0, so the own ratios are the ratios above. A coupled law S = Q e, Q = L L^T =
[[2, 1, 0], [1, 2, 0], [0, 0, 0]], contracts to E11 = -E22 / 2 and carries S22 = 1.5 E22 there:
own ratios 0.15 / 0.4, 0.375 / 1, 0.75 / 4 = 0.375, 0.375, 0.1875 (at the cell's states the
law gives 0.375, 0.4, 0.2). With Q = [[1, 2, 0], [2, 5, 0], [0, 0, 0]] the zero lies
at E11 = -2 E22, outside the bracket (E > -0.5) for E22 = 0.4: that state is counted missing.
Run by CTest (tests/CMakeLists.txt, label report) with Debian's /usr/bin/python3.
"""
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np

from checklist import Checklist  # tests/report/checklist.py, beside this file
from fixtures import linear_network_law, raw_path, script_refuses  # tests/report/fixtures.py

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(ROOT, "scripts", "law_uniaxial.py")
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import law_uniaxial as lu  # noqa: E402

E = [[-0.05, 0.1, 0], [-0.1, 0.25, 0], [-0.2, 0.5, 0]]
S = [[0, 0.4, 0], [0, 1.0, 0], [0, 4.0, 0]]


def uniaxial_path(*args, axis):
    """raw_path(*args) marked as a uniaxial-stress path along `axis` (0 course, 1 wale)."""
    g = raw_path(*args)
    g.attrs["kind"], g.attrs["axis"] = "uniaxial", axis
    return g


def coupled_db(path, L, E_path, S_path):
    """One loop length, the law S = L L^T e (floor 0), one uniaxial wale path."""
    with h5py.File(path, "w") as f:
        f["loop_lengths"] = [5.0]
        law = linear_network_law(f, 0.0)
        theta = np.zeros((1, 20))
        theta[0, 11:] = np.array(L, float).ravel()  # the last 9 parameters: L, row by row
        del law["theta"]
        law["theta"] = theta
        uniaxial_path(f, "path_0", "coverage", E_path, S_path, axis=1)


def write_db(path, law=True):
    with h5py.File(path, "w") as f:
        f["loop_lengths"] = [5.0]
        if law:
            linear_network_law(f, 2.0)
        uniaxial_path(f, "path_0", "coverage", E, S, axis=1)
        raw_path(f, "path_1", "coverage", E, [[9, 9, 0]] * 3)  # biaxial-like: not counted
        # A second uniaxial wale path of small stresses, cut by its own largest (0.4 MPa), not
        # by path_0's 4 MPa: its states of 0.05 and 0.4 MPa are kept (0.02 is below 10 %), with
        # ratios 0.1 / 0.05 = 2 and 0.2 / 0.4 = 0.5 and lateral shares 0.04 / 0.05 = 0.8, 0.25.
        uniaxial_path(f, "path_3", "coverage", [[-0.01, 0.02, 0], [-0.02, 0.05, 0], [-0.05, 0.1, 0]],
                      [[0, 0.02, 0], [0, 0.05, 0], [0, 0.4, 0]], axis=1)
        uniaxial_path(f, "path_2", "holdout", [[0.3, 0, 0]], [[0.1, 0, 0]], axis=0)


def main():
    c = Checklist()
    with tempfile.TemporaryDirectory(prefix="law_uniaxial_test_") as tmp:
        db = os.path.join(tmp, "db.h5")
        write_db(db)
        rows = lu.uniaxial_ratios(db)
        wale = [r for r in rows if r["axis"] == "wale"]
        r = wale[0] if wale else {}
        c(r.get("n") == 5, "the wale states, each path cut at 10 %% of its own largest: 3 + 2 "
          "(with path_0's largest for both: 3): %s" % rows)
        c(abs(r.get("median", 0) - 0.5) < 1e-12, "median of 0.5, 0.5, 0.25, 2, 0.5: 0.5 (got %s)"
          % r.get("median"))
        c(abs(r.get("largest", 0) - 2.0) < 1e-12 and abs(r.get("at", 0) - 0.05) < 1e-12,
          "farthest from 1: 2 at E22 = 0.05 (got %s at %s)" % (r.get("largest"), r.get("at")))
        c(abs(r.get("lateral", 0) - 0.8) < 1e-12,
          "largest lateral share |2 E11| / S22 = 0.8 (got %s)" % r.get("lateral"))
        course = [r for r in rows if r["axis"] == "course"]
        c(len(course) == 1 and abs(course[0]["median"] - 6.0) < 1e-12,
          "the course path (held out, still the cell's uniaxial states): ratio 0.6 / 0.1 = 6: %s"
          % course)
        c(abs(r.get("own_median", 0) - 0.5) < 1e-12 and abs(r.get("own_largest", 0) - 2.0) < 1e-12
          and abs(r.get("own_lateral", 1)) < 1e-12 and r.get("own_missing") == 0,
          "S = 2 e: the law's own uniaxial states have lateral strain 0 and the same ratios: %s" % r)
        coupled = os.path.join(tmp, "coupled.h5")
        s2 = 0.5 ** 0.5
        coupled_db(coupled, [[2 ** 0.5, 0, 0], [s2, 1.5 ** 0.5, 0], [0, 0, 0]], E, S)
        r = lu.uniaxial_ratios(coupled)
        r = r[0] if r else {}
        c(abs(r.get("own_median", 0) - 0.375) < 1e-9 and abs(r.get("own_largest", 0) - 0.1875)
          < 1e-9 and abs(r.get("own_at", 0) - 0.5) < 1e-12
          and abs(r.get("own_lateral", 0) + 0.25) < 1e-9 and abs(r.get("cell_lateral", 0) + 0.2)
          < 1e-12, "coupled law: own ratios 0.375, 0.375, 0.1875, farthest at E22 = 0.5 with "
          "E11 = -0.25 (cell -0.2): %s" % r)
        c(abs(r.get("largest", 0) - 0.2) < 1e-9 and abs(r.get("lateral", 0) - 0.05) < 1e-9,
          "coupled law at the cell's states (not its own): S22 = E11 + 2 E22 = 0.15, 0.4, 0.8 "
          "over 0.4, 1, 4, farthest 0.2; S11 = 2 E11 + E22 = 0, 0.05, 0.1, largest share 0.05: %s"
          % r)
        steep = os.path.join(tmp, "steep.h5")
        coupled_db(steep, [[1, 0, 0], [2, 1, 0], [0, 0, 0]],
                   [[-0.2, 0.1, 0], [-0.4, 0.2, 0], [-0.6, 0.4, 0]], S)
        r = lu.uniaxial_ratios(steep)
        r = r[0] if r else {}
        c(r.get("own_missing") == 1 and abs(r.get("own_median", 0) - 0.225) < 1e-9,
          "E11 = -2 E22 leaves the bracket at E22 = 0.4: 1 missing, median of 0.25 and 0.2: %s" % r)
        c("1 without a zero" in lu.summary([r]), "the sentence says so: %s" % lu.summary([r]))
        # A law whose stress is not finite on the bisection's way (its first midpoint, lateral
        # strain 0.5): that state is missing, not taken for a stress <= 0 (the session's review).
        class Holed:
            def eval(self, e):
                S = 2.0 * np.asarray(e, float)
                S[np.abs(e[..., 0] - 0.5) < 0.05] = np.nan
                return None, S
        lat, ax = lu.own_uniaxial(Holed(), [0.1, 0.2], 1)
        c(np.isnan(lat).all() and np.isnan(ax).all(),
          "a non-finite stress at a midpoint makes the state missing: %s, %s" % (lat, ax))
        class Whole:
            def eval(self, e):
                return None, 2.0 * np.asarray(e, float)
        lat, ax = lu.own_uniaxial(Whole(), [0.1, 0.2], 1)
        c(np.allclose(lat, 0.0, atol=1e-15) and np.allclose(ax, [0.2, 0.4]),
          "the same law without the hole: lateral 0, axial 2 E22: %s, %s" % (lat, ax))
        rows = lu.uniaxial_ratios(db, 0.2)
        wale = [r for r in rows if r["axis"] == "wale"]
        c(wale and wale[0]["n"] == 3 and abs(wale[0]["lateral"] - 0.25) < 1e-12,
          "--min-share 0.2 drops 0.4 of 4 MPa and 0.05 of 0.4 MPa: %s" % rows)
        text = lu.summary(lu.uniaxial_ratios(db))
        c("5 mm wale: 0.50 (farthest from 1: 2.00 at E = 0.050; lateral 80 %)" in text,
          "the sentence gives the wale row: %s" % text)
        bare = os.path.join(tmp, "bare.h5")
        write_db(bare, law=False)
        c(lu.uniaxial_ratios(bare) == [], "no law: no rows")
        out = subprocess.run([sys.executable, SCRIPT, db], capture_output=True, text=True)
        c(out.returncode == 0 and "Uniaxial tension" in out.stdout, "the command line prints it")
        script_refuses(c, SCRIPT, [db, "--min-share", "-1"], "--min-share", "a negative share")
        script_refuses(c, SCRIPT, [bare], "no /energy_law", "a database without a law")
    return c.exit_code()


if __name__ == "__main__":
    sys.exit(main())
