#!/usr/bin/python3
"""scripts/law_shear.py (session 55): the energy law along the cell's pure-shear paths.

A hand-made database of two loop lengths, 4.5 and 6.5 mm, whose law is S12 = a(l)^2 2E12 (a
network with all parameters 0 but the last of its 3 x 3 factor L, a(4.5) = 1 and a(6.5) = 2,
theta linear in l; floor 0). The cell's pure-shear path reaches 2E12 = 0.1, 0.2, 0.4 with S12 =
0.01, 0.3, 0.8 MPa at 4.5 mm and 0.1, 0.2, 0.4 at 6.5 mm: at 4.5 mm the first state (below 10 %
of 0.8) is dropped, the ratios are 0.2 / 0.3 and 0.4 / 0.8 (median 0.583, farthest 0.5 at
0.4); at 6.5 mm 4 throughout. The order in l is judged at 0.2 and 0.4 (0.1 is dropped at 4.5
mm): the cell's S12 falls with l and the law's rises, 2 reversals of 2 pairs; with a(4.5) = 2
and a(6.5) = 1 none. A biaxial path with the same strains does not count. Also the sentence, a
database without a law and the command line's refusal of a bad --min-share.
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
SCRIPT = os.path.join(ROOT, "scripts", "law_shear.py")
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import law_shear as ls  # noqa: E402

G = [0.1, 0.2, 0.4]
CELL = {0: [0.01, 0.3, 0.8], 1: [0.1, 0.2, 0.4]}


def write_db(path, a=(1.0, 2.0), law=True, sign=1.0):
    """Loop lengths 4.5 and 6.5 mm, the law S12 = a(l)^2 2E12, a shear path per loop length
    (sign -1: its mirror image, negative shear)."""
    with h5py.File(path, "w") as f:
        f["loop_lengths"] = [4.5, 6.5]
        if law:
            g = linear_network_law(f, 0.0)
            del g["l_knots"], g["theta"]
            g["l_knots"] = [4.5, 6.5]
            theta = np.zeros((2, 20))
            theta[:, 19] = a  # L[2][2]: S12 = L22^2 e3
            g["theta"] = theta
        for loop in (0, 1):
            E = [[0, 0, sign * x / 2] for x in G]
            S = [[0, 0, sign * s] for s in CELL[loop]]
            raw_path(f, "path_0", "paper", E, S, loop=loop).attrs["kind"] = "shear"
            raw_path(f, "path_1", "coverage", E, [[0, 0, 9]] * 3, loop=loop)  # not shear


def main():
    c = Checklist()
    with tempfile.TemporaryDirectory(prefix="law_shear_test_") as tmp:
        db = os.path.join(tmp, "db.h5")
        write_db(db)
        r = ls.shear_ratios(db)
        rows = r["rows"] if r else []
        c(len(rows) == 2 and rows[0]["n"] == 2 and rows[1]["n"] == 3,
          "4.5 mm: 2 states (0.01 of 0.8 dropped); 6.5 mm: 3: %s" % rows)
        c(rows and abs(rows[0]["median"] - (0.2 / 0.3 + 0.5) / 2) < 1e-12
          and abs(rows[0]["largest"] - 0.5) < 1e-12 and abs(rows[0]["at"] - 0.4) < 1e-12,
          "4.5 mm: median of 0.667 and 0.5, farthest 0.5 at 2E12 = 0.4: %s" % rows)
        c(len(rows) == 2 and abs(rows[1]["median"] - 4.0) < 1e-12,
          "6.5 mm: the law 4 times the cell: %s" % rows)
        o = r["order"] if r else {}
        c(o.get("pairs") == 2 and o.get("reversed") == 2,
          "the law rises with l where the cell falls, at 2E12 = 0.2 and 0.4: %s" % o)
        x = o.get("example") or {}
        c(abs(x.get("g", 0) - 0.2) < 1e-12 and np.allclose(x.get("cell", []), [0.3, 0.2])
          and np.allclose(x.get("law", []), [0.2, 0.8]),
          "the example: 2E12 = 0.2, cell 0.3 / 0.2, law 0.2 / 0.8: %s" % x)
        text = ls.summary(r)
        c("4.5 mm: 0.58 (farthest from 1: 0.50 at 2E12 = 0.400)" in text
          and "the law reverses the cell's order at 2 (most at 2E12 = 0.200: cell 0.300 / 0.200 "
          "MPa, law 0.200 / 0.800 MPa at l = 4.5 / 6.5 mm)" in text,
          "the sentence: %s" % text)
        kept = os.path.join(tmp, "kept.h5")
        write_db(kept, a=(2.0, 1.0))
        o = ls.shear_ratios(kept)["order"]
        c(o["pairs"] == 2 and o["reversed"] == 0 and o["example"] is None,
          "a law that falls with l like the cell reverses nothing: %s" % o)
        c("reverses the cell's order at 0." in ls.summary(ls.shear_ratios(kept)),
          "and the sentence says 0")
        o = ls.shear_ratios(db, 0.5)
        c(o["rows"][0]["n"] == 1 and o["order"]["pairs"] == 1,
          "--min-share 0.5 keeps only 0.8 of 0.8 at 4.5 mm, and one common strain: %s" % o)
        # A path of negative shear counts by its magnitudes (the review of session 55: it was
        # dropped): the mirror image of db's path gives db's ratios and order.
        mirrored = os.path.join(tmp, "mirrored.h5")
        write_db(mirrored, sign=-1.0)
        m = ls.shear_ratios(mirrored)
        c(m is not None and [(x["n"], round(x["median"], 12)) for x in m["rows"]]
          == [(x["n"], round(x["median"], 12)) for x in r["rows"]]
          and m["order"]["reversed"] == 2,
          "negative shear: the same states, ratios and reversals: %s" % m)
        bare = os.path.join(tmp, "bare.h5")
        write_db(bare, law=False)
        c(ls.shear_ratios(bare) is None, "no law: nothing")
        out = subprocess.run([sys.executable, SCRIPT, db], capture_output=True, text=True)
        c(out.returncode == 0 and "Pure shear" in out.stdout, "the command line prints it")
        script_refuses(c, SCRIPT, [db, "--min-share", "-1"], "--min-share", "a negative share")
        script_refuses(c, SCRIPT, [bare], "no /energy_law", "a database without a law")
    return c.exit_code()


if __name__ == "__main__":
    sys.exit(main())
