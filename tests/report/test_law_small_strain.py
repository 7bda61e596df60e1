#!/usr/bin/python3
"""scripts/law_small_strain.py (session 20): the energy law over the cell at small strains.

A hand-made database of one loop length (5 mm) whose law is S = 2 (E11, E22, 2 E12) (a network
with all parameters 0 and a floor of 2 MPa): a fit path whose small states carry the cell
stresses 0.01 and 0.04 MPa at E11 = 0.01 and 0.02 (ratios 2 and 1) and 9 MPa at E11 = 0.3
(not small), a pure-shear state at tensor E12 = 0.02 with S12 = 0.04 MPa (ratio 2; 1 if the
stored tensor shear were taken for engineering shear), an unloaded state (no ratio), and a
held-out path whose small state is far off (never counted). Also the cut --small, the sentence
the report prints, a database without a law and the command line's refusal of a bad --small.
Run by CTest (tests/CMakeLists.txt, label report) with Debian's /usr/bin/python3.
"""
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np

from checklist import Checklist  # tests/report/checklist.py, beside this file
from fixtures import (call_refuses, linear_network_law, raw_path,  # tests/report/fixtures.py
                      script_refuses)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(ROOT, "scripts", "law_small_strain.py")
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import law_small_strain as lss  # noqa: E402


def write_db(path, law=True):
    with h5py.File(path, "w") as f:
        f["loop_lengths"] = [5.0]
        if law:
            linear_network_law(f, 2.0)
        raw_path(f, "fit", "coverage", [[0.01, 0, 0], [0.02, 0, 0], [0.3, 0, 0], [0, 0, 0.02], [0, 0, 0]],
             [[0.01, 0, 0], [0.04, 0, 0], [9.0, 0, 0], [0, 0, 0.04], [0, 0, 0]])
        raw_path(f, "held", "holdout", [[0.01, 0, 0]], [[100.0, 0, 0]])


def main():
    c = Checklist()
    with tempfile.TemporaryDirectory(prefix="law_small_strain_test_") as tmp:
        db = os.path.join(tmp, "db.h5")
        write_db(db)
        rows = lss.small_strain_ratios(db)
        r = rows[0] if rows else {}
        c(len(rows) == 1 and r.get("n") == 3,
          "three small fit states with a cell stress (not the held-out one, not the unloaded "
          "one, not E11 = 0.3): %s" % rows)
        c(abs(r.get("median", 0) - 2.0) < 1e-12, "median ratio 2 (got %s)" % r.get("median"))
        c(abs(r.get("lo", 0) - 1.2) < 1e-12 and abs(r.get("hi", 0) - 2.0) < 1e-12,
          "10th / 90th percentiles of (2, 1, 2): 1.2 / 2 (got %s / %s)" % (r.get("lo"), r.get("hi")))
        c(abs(r.get("top", 0) - np.sqrt(2) * 0.04 / 9.0) < 1e-12,
          "largest small stress over the range 9 MPa: the shear state's tensor norm (got %s)"
          % r.get("top"))
        rows = lss.small_strain_ratios(db, 0.015)
        c(rows and rows[0]["n"] == 1 and abs(rows[0]["median"] - 2.0) < 1e-12,
          "--small 0.015 keeps E11 = 0.01 only: %s" % rows)
        text = lss.summary(lss.small_strain_ratios(db))
        c("5 mm: 2.00 (1.20-2.00, 3 states)" in text and "0.63 % of the stress range" in text,
          "the report's sentence: %s" % text)
        out = subprocess.run([sys.executable, SCRIPT, db], capture_output=True, text=True)
        c(out.returncode == 0 and "5 mm: 2.00" in out.stdout, "the script runs: %s"
          % (out.stdout + out.stderr)[-300:])
        script_refuses(c, SCRIPT, [db, "--small", "0"], "--small: must be a finite number > 0",
                       "--small 0 refused")
        script_refuses(c, SCRIPT, [db, "--small", "nan"], "--small: must be a finite number > 0",
                       "--small nan refused")
        # A file that is not HDF5: named, no traceback (scripts/cell_paths.py, open_database).
        notdb = os.path.join(tmp, "notes.h5")
        with open(notdb, "w") as fh:
            fh.write("not hdf5")
        out = subprocess.run([sys.executable, SCRIPT, notdb], capture_output=True, text=True)
        c(out.returncode != 0 and "notes.h5: not a readable HDF5 file" in out.stderr
          and "Traceback" not in out.stderr, "a non-HDF5 file refused by name: %s"
          % out.stderr.strip()[-300:])
        # A path without its set attribute: read as "paper" in a format-1 file (which never has
        # one), refused with its HDF5 path from format 2 on (scripts/cell_paths.py, path_set).
        with h5py.File(db, "a") as f:
            del f["loop_0/raw/held"].attrs["set"]
            f.attrs["format_version"] = 1
        rows = lss.small_strain_ratios(db)
        c(rows and rows[0]["n"] == 4,
          "format 1: the path without a set is read as a paper path (4 small states): %s" % rows)
        with h5py.File(db, "a") as f:
            f.attrs["format_version"] = 3
        call_refuses(c, lambda: lss.small_strain_ratios(db),
                     "/loop_0/raw/held: attribute set is missing",
                     "format 3: a path without a set is refused with its HDF5 path")
        write_db(db, law=False)
        c(lss.small_strain_ratios(db) == [], "no energy law: no rows")
        script_refuses(c, SCRIPT, [db], "no /energy_law", "no energy law: refused by the script")
    return c.exit_code()


if __name__ == "__main__":
    sys.exit(main())
