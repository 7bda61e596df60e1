#!/usr/bin/python3
"""Material-frame strains that the macroscale cases visit, against the database's strain box.

Reads fields/step_NNNN/{E_course, E_wale, E_course_wale} (mid-surface Green-Lagrange strains in
the material frame, tensor shear E12; written by knit-macro for `knit` materials, see
docs/case-format.md) of every results.h5 under a results directory (the pipeline writes
out/results/<case>/results.h5, scripts/pipeline.mk), and prints per case and overall the
visited box (min/max of E11 = E_course, E22 = E_wale, |E12|), the 1/99 % quantiles and the
fraction of samples inside the database box (docs/unit-cell.md, "Strain box").

    /usr/bin/python3 scripts/strain_box.py out/results --database out/database.h5
    /usr/bin/python3 scripts/strain_box.py out/results --box -0.35 0.60 -0.30 0.55 0.40

The box is the one the database was swept with (`--database`: load_paths.box of the sweep input
stored in /sweep's attribute input_json), or `--box`; without either, the API's built-in
StrainBox (E11 up to 0.45, not the default sweep's 0.60), and the first line says so.
"""
import argparse
import glob
import json
import os
import re
import sys

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cell_paths import stored_sweep_input  # noqa: E402
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "figures"))
from results import last_run_wrote  # noqa: E402

# The default box of knit/material/load_paths.hpp (StrainBox): E11, E22 ranges and |E12| bound.
DEFAULT_BOX = (-0.35, 0.45, -0.30, 0.55, 0.40)


def current_results(results_dir):
    """Every results.h5 under results_dir, but those the pipeline's status file beside their
    run's directory (NAME.status beside NAME/) says the last run did not write
    (results.last_run_wrote: a refused run, or one that converged no step, wrote nothing, so
    NAME/ is an earlier run's; session 45's red team: a sweep input switched in the same OUT
    left the former database's runs, which were counted as this one's), knit-macro's
    partial directories (NAME.partial-PID) and the completed outputs that stopped reruns
    replaced (NAME.last-completed)."""
    out = []
    for p in sorted(glob.glob(os.path.join(results_dir, "**", "results.h5"), recursive=True)):
        run = os.path.dirname(p)
        if ".partial-" in os.path.basename(run) or re.search(r"\.last-completed(-\d+)?$", run):
            # a run being written, or one killed while it was (knit-macro's partials); and the
            # completed output a stopped rerun replaced (NAME.last-completed, session 46)
            continue
        try:
            with open(run + ".status") as f:
                status = json.load(f)
        except (OSError, ValueError):
            status = {}  # no pipeline status (a run of one's own): taken
        if isinstance(status, dict) and not last_run_wrote(status):
            continue
        out.append(p)
    return out


def read_case(path):
    """All (E11, E22, E12) samples of every output step of one results.h5, shape (n, 3)."""
    rows = []
    with h5py.File(path, "r") as f:
        if "fields" not in f:
            return np.zeros((0, 3))
        for name in sorted(f["fields"]):
            g = f["fields"][name]
            if not all(k in g for k in ("E_course", "E_wale", "E_course_wale")):
                continue
            rows.append(np.column_stack([np.asarray(g["E_course"]), np.asarray(g["E_wale"]),
                                         np.asarray(g["E_course_wale"])]))
    return np.vstack(rows) if rows else np.zeros((0, 3))


class BadInput(Exception):
    """Bad input: printed with the file and the path inside it, exit code 2."""


def database_box(path):
    """(E11_min, E11_max, E22_min, E22_max, E12_max) of the sweep input stored in a database;
    a clear error naming the file and the HDF5 path or JSON key where it is missing."""
    try:
        f = h5py.File(path, "r")
    except OSError as e:
        raise BadInput("%s: not a readable HDF5 file (%s)" % (path, e))
    with f:
        try:
            stored = stored_sweep_input(f, path)
        except SystemExit as e:
            raise BadInput("%s; give the box with --box" % str(e).replace("error: ", "", 1))
        except ValueError as e:
            raise BadInput("%s: /sweep input_json: not JSON (%s)" % (path, e))
    try:
        b = stored["load_paths"]["box"]
        box = (b["E11"][0], b["E11"][1], b["E22"][0], b["E22"][1], b["E12_max"])
        box = tuple(float(v) for v in box)
    except (KeyError, IndexError, TypeError, ValueError) as e:
        raise BadInput("%s: /sweep input_json: /load_paths/box missing or malformed (%s); give "
                       "the box with --box" % (path, e))
    if not all(np.isfinite(box)) or not (box[0] < box[1] and box[2] < box[3] and box[4] > 0):
        raise BadInput("%s: /sweep input_json: /load_paths/box is not a box: %s" % (path, box))
    return box


def inside(E, box):
    e11lo, e11hi, e22lo, e22hi, e12 = box
    return ((E[:, 0] >= e11lo) & (E[:, 0] <= e11hi) & (E[:, 1] >= e22lo) & (E[:, 1] <= e22hi) &
            (np.abs(E[:, 2]) <= e12))


def line(name, E, box):
    q = np.quantile(E, [0.01, 0.99], axis=0)
    return ("%-34s %7d  E11 [%+.3f, %+.3f] (1-99%%: %+.3f, %+.3f)  E22 [%+.3f, %+.3f] "
            "(%+.3f, %+.3f)  |E12| <= %.3f (99%%: %.3f)  inside %.2f %%" %
            (name, len(E), E[:, 0].min(), E[:, 0].max(), q[0, 0], q[1, 0], E[:, 1].min(),
             E[:, 1].max(), q[0, 1], q[1, 1], np.abs(E[:, 2]).max(),
             np.quantile(np.abs(E[:, 2]), 0.99), 100.0 * inside(E, box).mean()))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("results", help="directory searched recursively for results.h5")
    src = ap.add_mutually_exclusive_group()
    src.add_argument("--database", help="material database (.h5): use the box it was swept with")
    src.add_argument("--box", nargs=5, type=float,
                     metavar=("E11_MIN", "E11_MAX", "E22_MIN", "E22_MAX", "E12_MAX"))
    a = ap.parse_args()
    origin = "given"
    if a.database:
        try:
            a.box, origin = database_box(a.database), "of " + a.database
        except BadInput as e:
            print("error: %s" % e, file=sys.stderr)
            return 2
    elif a.box is None:
        a.box, origin = DEFAULT_BOX, "the API's built-in default (no --database or --box)"
    files = current_results(a.results)
    if not files:
        print("no results.h5 under %s" % a.results, file=sys.stderr)
        return 2
    print("box (%s): E11 [%+.2f, %+.2f], E22 [%+.2f, %+.2f], |E12| <= %.2f" %
          ((origin,) + tuple(a.box)))
    allE = []
    for p in files:
        E = read_case(p)
        if len(E) == 0:
            print("%-34s no material-frame strain fields (not a knit material?)" %
                  os.path.basename(os.path.dirname(p)))
            continue
        allE.append(E)
        print(line(os.path.basename(os.path.dirname(p)), E, a.box))
    if not allE:
        return 1
    print(line("ALL", np.vstack(allE), a.box))
    return 0


if __name__ == "__main__":
    sys.exit(main())
