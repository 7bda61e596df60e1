#!/usr/bin/python3
"""scripts/path_consistency.py (issue 11): the cell's self-consistency across paths.

Two hand-made databases with two paths along the same strain ray, their states 0.002 apart:
one where the stress is the same function of the strain on both paths (no pair may be flagged),
one where the second path's S11 is 20 % of the range higher (its pairs must be flagged), plus
the script's own --self-check and its refusal of a file that is not a database. Run by CTest
(tests/CMakeLists.txt, label report) with Debian's /usr/bin/python3 (numpy, h5py).
"""
import os
import re
import subprocess
import sys
import tempfile

import h5py
import numpy as np

from checklist import Checklist  # tests/report/checklist.py, beside this file

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(ROOT, "scripts", "path_consistency.py")


def write_db(path, offset_s11):
    with h5py.File(path, "w") as f:
        f["loop_lengths"] = np.array([5.0])
        g = f.create_group("loop_0")
        g.attrs["loop_length"] = 5.0
        raw = g.create_group("raw")
        for i, (shift, ds) in enumerate([(0.0, 0.0), (0.002, offset_s11)]):
            t = np.linspace(0.05, 0.5, 10) + shift
            E = np.stack([t, 0.5 * t, 0.0 * t], 1)
            S = np.stack([10 * t + ds, 4 * t, 0.0 * t], 1)
            p = raw.create_group("path_%02d" % i)
            p["E"], p["S"], p["status"] = E, S, np.zeros(10, dtype=np.int32)
            p.attrs["set"] = "coverage"
            p.attrs["kind"] = "biaxial"


def run(*args):
    r = subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)
    return r.returncode, r.stdout + r.stderr


def flagged(out):
    m = re.search(r"(\d+) pairs, (\d+) differ by > 5 %", out)
    assert m, out
    return int(m.group(1)), int(m.group(2))


def main():
    check = Checklist()

    with tempfile.TemporaryDirectory() as d:
        same, shifted = os.path.join(d, "same.h5"), os.path.join(d, "shifted.h5")
        write_db(same, 0.0)
        write_db(shifted, 0.2 * 4.5)  # 0.9 MPa: 20 % of one path's S11 range, 17 % of both
        rc, out = run(same)
        pairs, over = flagged(out)
        check(rc == 0 and pairs >= 9 and over == 0,
              "one state function on both paths: %d pairs, %d flagged (0 expected)" % (pairs, over),
              out)
        rc, out = run(shifted)
        pairs, over = flagged(out)
        check(rc == 0 and over == pairs and pairs >= 9,
              "S11 20 %% of the range apart: %d of %d pairs flagged (all expected)" % (over, pairs),
              out)
        rc, out = run(same, "--self-check")
        check(rc == 0 and "now differ by > 5 %" in out, "--self-check detects its change", out)
        bad = os.path.join(d, "not.h5")
        with open(bad, "w") as f:
            f.write("not hdf5")
        rc, out = run(bad)
        check(rc == 2 and "not.h5" in out, "a file that is not a database: exit 2, named", out)
        # "nan" passed type=float and every comparison with it failed: "0 pairs", exit 0.
        for radius in ("nan", "0", "-1", "inf"):
            rc, out = run(same, "--radius", radius)
            check(rc == 2 and "--radius: must be a finite number > 0" in out,
                  "--radius %s refused (exit %d)" % (radius, rc), out)
    return check.exit_code()


if __name__ == "__main__":
    sys.exit(main())
