#!/usr/bin/python3
"""scripts/figures/energy_law.py (Fig. 6e, the energy law beside the cell's data) on a
hand-made database of one loop length whose law is S = 2 e (fixtures.py):

* it draws (exit 0, a PNG) from a format-3 database whose paths carry their set;
* a path without its set attribute in a format-3 file is refused, exit non-zero, naming the
  file and the HDF5 path (it used to be read as "paper": a held-out state drawn as fit data);
* a file that is missing or not HDF5 is refused by name, without a traceback (also by
  scripts/figures/surfaces.py, Fig. 6);
* a format-1 file (which never had the attribute) still draws;
* a database without /energy_law is refused by name, and with --absent-placeholder (the
  pipeline's call) gets a placeholder figure with exit 0;
* a law that cannot be evaluated as stored (a NaN in theta, h1 not matching theta's width, a
  negative floor) is refused by name, without a traceback, here and by law_held_out.py.
Run by CTest (tests/CMakeLists.txt, label report) with Debian's /usr/bin/python3.
"""
import os
import subprocess
import sys
import tempfile

import h5py

from checklist import Checklist  # tests/report/checklist.py, beside this file
from fixtures import linear_network_law, raw_path  # tests/report/fixtures.py

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(ROOT, "scripts", "figures", "energy_law.py")


def write_db(path, version, drop_set=False):
    with h5py.File(path, "w") as f:
        f.attrs["format_version"] = version
        f["loop_lengths"] = [5.0]
        law = linear_network_law(f, 2.0)
        law["box_min"], law["box_max"] = [-0.3, -0.3, -0.4], [0.6, 0.55, 0.4]
        raw_path(f, "fit", "coverage", [[0.1, 0, 0], [0.2, 0, 0]], [[0.2, 0, 0], [0.4, 0, 0]])
        held = raw_path(f, "held", "holdout", [[0, 0.1, 0]], [[0, 0.2, 0]])
        if drop_set:
            del held.attrs["set"]


def draw(db, png, *extra):
    return subprocess.run([sys.executable, SCRIPT, "--database", db, "--loop-length", "5",
                           "--out", png, *extra], capture_output=True, text=True)


def main():
    c = Checklist()
    with tempfile.TemporaryDirectory(prefix="energy_law_figure_test_") as tmp:
        db, png = os.path.join(tmp, "db.h5"), os.path.join(tmp, "fig.png")
        write_db(db, 3)
        r = draw(db, png)
        c(r.returncode == 0 and os.path.getsize(png) > 0,
          "format 3 with every set: drawn (exit %d, %s)" % (r.returncode, r.stderr.strip()[-300:]))
        c("note:" not in r.stderr, "its own loop length: no note (%s)" % r.stderr.strip()[-200:])
        os.remove(png)
        # A loop length the database does not have (session 48's walkthrough: the nearest was
        # drawn without a word): drawn, with a note that names both.
        r = draw(db, png, "--loop-length", "5.6")
        c(r.returncode == 0 and "energy_law.py: note: the database has no loop length 5.6 mm "
          "(it has 5 mm); the figure shows the nearest, 5 mm" in r.stderr,
          "another loop length: drawn with a note (exit %d, %s)"
          % (r.returncode, r.stderr.strip()[-300:]))
        os.remove(png)
        write_db(db, 3, drop_set=True)
        r = draw(db, png)
        c(r.returncode != 0 and not os.path.exists(png),
          "format 3, /loop_0/raw/held without set: refused, nothing drawn (exit %d)" % r.returncode)
        c("db.h5" in r.stderr and "/loop_0/raw/held: attribute set is missing" in r.stderr,
          "the message names the file and the HDF5 path: %s" % r.stderr.strip()[-300:])
        # A file that is not HDF5 (and one that is not there): named, no traceback, for this
        # figure and Fig. 6 (scripts/figures/surfaces.py), which share the command line.
        notdb = os.path.join(tmp, "notes.h5")
        with open(notdb, "w") as fh:
            fh.write("not hdf5")
        for script in (SCRIPT, os.path.join(ROOT, "scripts", "figures", "surfaces.py")):
            for path, what in ((notdb, "notes.h5: not a readable HDF5 file"),
                               (os.path.join(tmp, "missing.h5"), "missing.h5: no such file")):
                r = subprocess.run([sys.executable, script, "--database", path, "--out", png],
                                   capture_output=True, text=True)
                c(r.returncode != 0 and what in r.stderr and "Traceback" not in r.stderr,
                  "%s, %s: refused by name (exit %d): %s" % (os.path.basename(script), what,
                                                            r.returncode, r.stderr.strip()[-200:]))
        # A law that cannot be evaluated as stored (session 47's red team: a NaN in theta drew
        # a blank figure with exit 0; law_small_strain.py printed "nan" with exit 0): refused
        # by name, without a traceback, by the figure and by law_held_out.py (the shared reader,
        # load_law).
        held_out = os.path.join(ROOT, "scripts", "law_held_out.py")
        for what, damage, message in (
                ("a NaN in theta", lambda f: f["energy_law/theta"].__setitem__((0, 0), float("nan")),
                 "/energy_law/theta: expected finite real numbers in 2-D"),
                ("h1 not matching theta", lambda f: f["energy_law"].attrs.__setitem__("h1", 11),
                 "/energy_law/theta: shape"),
                ("a negative floor", lambda f: f["energy_law"].attrs.__setitem__("floor", -1.0),
                 "/energy_law: attribute floor must be finite and >= 0"),
                ("an empty floor", lambda f: f["energy_law"].attrs.__setitem__(
                    "floor", h5py.Empty("f8")), "/energy_law: attribute floor must be one number"),
                ("no h1", lambda f: f["energy_law"].attrs.__delitem__("h1"),
                 "/energy_law: attribute h1 must be one number")):
            write_db(db, 3)
            with h5py.File(db, "a") as f:
                damage(f)
            for cmd in ([sys.executable, SCRIPT, "--database", db, "--loop-length", "5", "--out",
                         png], [sys.executable, held_out, db]):
                r = subprocess.run(cmd, capture_output=True, text=True)
                c(r.returncode != 0 and db + ": " + message in r.stderr
                  and "Traceback" not in r.stderr and not os.path.exists(png),
                  "%s, %s: refused by name, no figure (exit %d): %s"
                  % (os.path.basename(cmd[1]), what, r.returncode, r.stderr.strip()[-300:]))
        write_db(db, 1, drop_set=True)
        r = draw(db, png)
        c(r.returncode == 0 and os.path.exists(png),
          "format 1 without set (its paths are the paper's): drawn (exit %d, %s)"
          % (r.returncode, r.stderr.strip()[-300:]))
        # A database without the energy law (a sweep input with "energy_fit": false): an error
        # by itself; with --absent-placeholder (the pipeline) a placeholder with exit 0 and a
        # normal date, which the report does not count as a failed figure (session 46: it did).
        os.remove(png)
        write_db(db, 3)
        with h5py.File(db, "a") as f:
            del f["energy_law"]
        r = draw(db, png)
        c(r.returncode != 0 and "/energy_law: group missing" in r.stderr
          and not os.path.exists(png),
          "no /energy_law: refused by name, nothing drawn (exit %d): %s"
          % (r.returncode, r.stderr.strip()[-200:]))
        r = draw(db, png, "--absent-placeholder")
        c(r.returncode == 0 and os.path.exists(png) and os.path.getmtime(png) > 86400,
          "no /energy_law with --absent-placeholder: a placeholder, exit 0 (exit %d, %s)"
          % (r.returncode, r.stderr.strip()[-300:]))
    return c.exit_code()


if __name__ == "__main__":
    sys.exit(main())
