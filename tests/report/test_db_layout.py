#!/usr/bin/python3
"""The material database against schemas/database.layout.json, both ways (scripts/db_layout.py,
session 37): databases written by knit-meso synth, by a reduced knit-meso sweep and by knit-meso
fit hold every group, dataset and attribute the layout requires and nothing it does not
describe; their root attribute `input` names what they were made from; an undocumented dataset
or attribute added with h5py, and a required attribute removed, are each reported by HDF5 path
with exit 1. Run by CTest (tests/CMakeLists.txt, label report) with /usr/bin/python3;
KNIT_BIN_DIR names the directory of knit-meso.
"""
import os
import shutil
import subprocess
import sys
import tempfile

import h5py

from checklist import Checklist  # tests/report/checklist.py, beside this file

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CHECK = os.path.join(ROOT, "scripts", "db_layout.py")
BIN = os.environ.get("KNIT_BIN_DIR", os.path.join(ROOT, "build", "bin"))
REDUCED = os.path.join(ROOT, "cases", "sweep", "reduced.json")


def layout(db):
    return subprocess.run([sys.executable, CHECK, db], capture_output=True, text=True)


def meso(*args, cwd):
    return subprocess.run([os.path.join(BIN, "knit-meso")] + list(args), cwd=cwd,
                          capture_output=True, text=True)


def main():
    c = Checklist()
    with tempfile.TemporaryDirectory(prefix="db_layout_test_") as tmp:
        made = {
            "synth": meso("synth", "-o", "synth.h5", cwd=tmp),
            "sweep": meso("sweep", REDUCED, "-o", "sweep.h5", "--no-progress", cwd=tmp),
        }
        for name, r in made.items():
            c(r.returncode == 0, "knit-meso %s wrote its database" % name, r.stderr[-500:])
        made["fit"] = meso("fit", "sweep.h5", "-o", "fit.h5", cwd=tmp)
        c(made["fit"].returncode == 0, "knit-meso fit wrote its database", made["fit"].stderr[-500:])
        for name in ("synth", "sweep", "fit"):
            db = os.path.join(tmp, name + ".h5")
            r = layout(db)
            c(r.returncode == 0, "%s database: as the layout describes" % name, r.stdout + r.stderr)
        with h5py.File(os.path.join(tmp, "sweep.h5"), "r") as f:
            c(f.attrs["input"] == REDUCED, "the sweep's database names its input",
              repr(f.attrs["input"]))
        with h5py.File(os.path.join(tmp, "fit.h5"), "r") as f:
            c(f.attrs["input"] == "sweep.h5", "the fit's database names the database it read",
              repr(f.attrs["input"]))
        # Damaged copies: each difference reported by its HDF5 path, exit 1.
        damages = {
            "an undocumented dataset": (lambda f: f.create_dataset("energy_law/extra", data=[1.0]),
                                        "/energy_law/extra (dataset)"),
            "an undocumented root attribute": (lambda f: f.attrs.create("mood", "good"),
                                               "/@mood (attribute)"),
            "an undocumented group": (lambda f: f.create_group("loop_0/notes"),
                                      "/loop_0/notes (group)"),
            "a required attribute removed": (lambda f: f["loop_0"].attrs.__delitem__("wale_width"),
                                             "/loop_0@wale_width (attribute)"),
        }
        for what, (damage, path) in damages.items():
            copy = os.path.join(tmp, "damaged.h5")
            shutil.copy(os.path.join(tmp, "synth.h5"), copy)
            with h5py.File(copy, "r+") as f:
                damage(f)
            r = layout(copy)
            c(r.returncode == 1 and path in r.stdout, "%s: exit 1 naming %s" % (what, path),
              "exit %d: %s" % (r.returncode, r.stdout + r.stderr))
        r = layout(os.path.join(tmp, "missing.h5"))
        c(r.returncode == 2 and "missing.h5" in r.stderr, "a file that cannot be read: exit 2",
          "exit %d: %s" % (r.returncode, r.stderr))
    return c.exit_code()


if __name__ == "__main__":
    sys.exit(main())
