#!/usr/bin/python3
"""scripts/strain_box.py (issue 11): the visited strains judged against the database's own box.

A results directory with one case whose samples have E11 = 0.5 in half of them: inside the
default sweep's box (E11 up to 0.60, read from the database with --database), outside the API's
built-in box (0.45, used without --database or --box, and said so). Also: a database without
its sweep input and a file that is not HDF5 are refused with exit 2, naming the file and the
HDF5 path. Run by CTest (tests/CMakeLists.txt, label report) with Debian's /usr/bin/python3.
"""
import json
import os
import re
import subprocess
import sys
import tempfile

import h5py
import numpy as np

from checklist import Checklist  # tests/report/checklist.py, beside this file

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(ROOT, "scripts", "strain_box.py")


def run(*args):
    r = subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)
    return r.returncode, r.stdout + r.stderr


def inside_all(out):
    m = re.search(r"^ALL .* inside ([0-9.]+) %", out, re.M)
    assert m, out
    return float(m.group(1))


def main():
    check = Checklist()
    with tempfile.TemporaryDirectory() as d:
        case = os.path.join(d, "results", "case_a")
        os.makedirs(case)
        with h5py.File(os.path.join(case, "results.h5"), "w") as f:
            g = f.create_group("fields/step_0001")
            g["E_course"] = np.array([0.1, 0.2, 0.5, 0.5])
            g["E_wale"] = np.array([0.0, 0.1, 0.0, 0.1])
            g["E_course_wale"] = np.array([0.0, 0.05, 0.0, -0.05])
        db = os.path.join(d, "db.h5")
        box = {"E11": [-0.35, 0.60], "E22": [-0.30, 0.55], "E12_max": 0.40}
        with h5py.File(db, "w") as f:
            f.create_group("sweep").attrs["input_json"] = json.dumps({"load_paths": {"box": box}})
        res = os.path.join(d, "results")
        rc, out = run(res, "--database", db)
        check(rc == 0 and inside_all(out) == 100.0 and "E11 [-0.35, +0.60]" in out,
              "--database: the database's box (E11 up to 0.60), every sample inside", out)
        rc, out = run(res)
        check(rc == 0 and inside_all(out) == 50.0 and "built-in default" in out,
              "no box given: the built-in box (0.45), said so, half the samples inside", out)
        rc, out = run(res, "--box", "-0.35", "0.60", "-0.30", "0.55", "0.40")
        check(rc == 0 and inside_all(out) == 100.0, "--box as given", out)
        # A run the pipeline's status says was refused (exit 2) wrote nothing: its directory
        # is an earlier run's and is not counted (session 45's red team); exit 0 is.
        for code, counted in ((2, False), (0, True)):
            with open(case + ".status", "w") as f:
                json.dump({"case": "case_a", "exit_code": code}, f)
            rc, out = run(res, "--database", db)
            check((rc == 0 and "case_a" in out) if counted else (rc == 2 and "no results.h5" in out),
                  f"status exit {code}: {'counted' if counted else 'not counted'}", out)
        os.remove(case + ".status")
        # The completed output a stopped rerun replaced (knit-macro keeps it as
        # NAME.last-completed, session 46) is not one of the runs.
        kept = case + ".last-completed"
        os.makedirs(kept)
        with h5py.File(os.path.join(kept, "results.h5"), "w") as f:
            f.create_group("fields/step_0001")["E_course"] = np.array([0.9])
        os.rename(kept, kept + "-4242")  # and one beside a directory of that name
        os.makedirs(kept)
        with h5py.File(os.path.join(kept, "results.h5"), "w") as f:
            f.create_group("fields/step_0001")["E_course"] = np.array([0.9])
        rc, out = run(res, "--database", db)
        check(rc == 0 and "last-completed" not in out and inside_all(out) == 100.0,
              "NAME.last-completed and NAME.last-completed-PID are not counted", out)
        bare = os.path.join(d, "bare.h5")
        with h5py.File(bare, "w") as f:
            f.create_group("loop_0")
        rc, out = run(res, "--database", bare)
        check(rc == 2 and "bare.h5" in out and "/sweep" in out,
              "a database without its sweep input: exit 2, file and HDF5 path named", out)
        bad = os.path.join(d, "not.h5")
        with open(bad, "w") as f:
            f.write("not hdf5")
        rc, out = run(res, "--database", bad)
        check(rc == 2 and "not.h5" in out, "a file that is not HDF5: exit 2, named", out)
    return check.exit_code()


if __name__ == "__main__":
    sys.exit(main())
