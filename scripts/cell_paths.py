"""The unit cell's raw load paths in a material database (/loop_<k>/raw), for the analysis
scripts (fit_bounds.py, path_consistency.py): numpy and h5py only."""
import argparse
import math
import os

import numpy as np


def open_database(path, prog):
    """The HDF5 file at `path`, opened for reading, or SystemExit naming it: missing, or not an
    HDF5 file (the scripts ended in an OSError traceback there before session 21)."""
    import h5py
    if not os.path.isfile(path):
        raise SystemExit(f"{prog}: {path}: no such file")
    try:
        return h5py.File(path, "r")
    except OSError as err:
        raise SystemExit(f"{prog}: {path}: not a readable HDF5 file ({err})")


def positive_number(text):
    """An argparse type: a finite number > 0. With type=float, "nan" passed every check and
    every comparison with it was false (path_consistency.py --radius nan: "0 pairs", exit 0)."""
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}")
    if not (math.isfinite(v) and v > 0):
        raise argparse.ArgumentTypeError(f"must be a finite number > 0, got {text}")
    return v


def share_script_main(doc, prog, compute, summary, default_share, kept, missing):
    """The command line of the law-along-the-cell's-paths scripts (law_uniaxial.py,
    law_shear.py): DATABASE and --min-share (default `default_share`, the smallest `kept` cell
    stress, as a share of the path's largest); prints summary(compute(db, share), share), or
    exits naming the database with `missing` when compute() finds nothing."""
    ap = argparse.ArgumentParser(description=doc.split("\n")[0])
    ap.add_argument("database", help="material database (HDF5) with /energy_law")
    ap.add_argument("--min-share", type=positive_number, default=default_share,
                    help=f"smallest {kept} kept, as a share of the path's largest "
                         f"(default {default_share})")
    a = ap.parse_args()
    open_database(a.database, prog).close()
    result = compute(a.database, a.min_share)
    if not result:
        raise SystemExit(f"{prog}: {a.database}: {missing}")
    print(summary(result, a.min_share))


def attr_text(v):
    """An HDF5 string attribute as str (h5py gives bytes or str, depending on how it was
    written)."""
    return v.decode() if isinstance(v, bytes) else str(v)


def path_set(f, g):
    """The set ("paper", "coverage", "holdout") of the raw path group `g` of the open database
    `f`: its attribute set. A format-1 file has none (its paths are the paper's); from format 2
    on a missing one is a damaged file, refused with its HDF5 path (as knit-meso's reader does:
    read as "paper", a coverage path would join the fan and a held-out path the fit data)."""
    s = g.attrs.get("set")
    if s is None:
        version = int(f.attrs.get("format_version", 1))
        if version >= 2:
            raise ValueError("%s: %s: attribute set is missing (format %d writes it on every "
                             "path)" % (f.filename, g.name, version))
        return "paper"
    return attr_text(s)


def load_paths(f, loop):
    """[(set, e (n x 3, e3 = 2 E12), S (n x 3), kind, axis)] of the converged steps of
    /loop_<loop>/raw, in the order of the path names."""
    g = f["loop_%d/raw" % loop]
    out = []
    for name in sorted(g):
        ok = g[name]["status"][:] == 0
        e = g[name]["E"][:][ok].copy()
        e[:, 2] *= 2.0
        kind = attr_text(g[name].attrs.get("kind", "biaxial"))
        out.append((path_set(f, g[name]), e, g[name]["S"][:][ok], kind,
                    int(g[name].attrs.get("axis", 0))))
    return out


def fit_min_cos(f):
    """The energy fit's stable_min_cos, from /energy_law/diagnostics@options_json of the open
    database `f`; -2 (no cut) where the record or the key is absent: a fit from before the
    option (session 14) cut nothing (the review of session 52)."""
    import json
    d = f.get("energy_law/diagnostics")
    if d is None or "options_json" not in d.attrs:
        return -2.0
    return float(json.loads(attr_text(d.attrs["options_json"])).get("stable_min_cos", -2.0))


def fit_states(paths, min_cos=0.0):
    """`paths` (load_paths) with each fitted path cut where knit-meso fit leaves it out: from
    the first converged state where the cell gives way, cos(dS, de) < min_cos (de and dS from
    the previous converged state, the first from the stress-free reference; the rule of
    fit_energy.cpp's collect, off for min_cos < -1). Held-out paths are kept whole. The report
    re-evaluates the law at exactly the fit's states (session 52's red team: a loop length
    whose stored count differed was not compared, and a capped largest error passed)."""
    out = []
    for p in paths:
        s, e, S = p[0], p[1], p[2]
        n = len(e)
        if s != "holdout" and min_cos >= -1.0:
            prev_e, prev_S = np.zeros(3), np.zeros(3)
            for i in range(len(e)):
                de, dS = e[i] - prev_e, S[i] - prev_S
                norm = np.linalg.norm(de) * np.linalg.norm(dS)
                if norm > 0 and de @ dS < min_cos * norm:
                    n = i
                    break
                prev_e, prev_S = e[i], S[i]
        out.append((s, e[:n], S[:n]) + tuple(p[3:]))
    return out


def stress_range(paths):
    """The loop length's stress range of docs/database.md: the largest max - min of a stress
    component over its fit data (every path but the held-out ones)."""
    s = np.concatenate([p[2] for p in paths if p[0] != "holdout"])
    return max(s[:, c].max() - s[:, c].min() for c in range(3))


def stored_sweep_input(db, path):
    """The sweep input stored in an open database (/sweep attribute input_json), as a dict;
    exits with an error naming the file and the HDF5 path when it is missing."""
    import json
    if "sweep" not in db or "input_json" not in db["sweep"].attrs:
        raise SystemExit("error: %s: /sweep has no attribute input_json (not a sweep's "
                         "database)" % path)
    v = db["sweep"].attrs["input_json"]
    return json.loads(v.decode() if isinstance(v, bytes) else str(v))


def run_sweep(knit_meso, sweep, work, name, threads, what):
    """Writes `sweep` (a dict) to WORK/NAME.json (WORK: a new kept temporary directory when
    None), runs `knit-meso sweep` on it into WORK/NAME.h5 and returns that path; `what` says
    what is run, in the line printed before. The sweep's output (its progress lines and its
    closing summary) goes to stderr, the caller's stdout staying the script's own report
    (session 58: a twin sweep of 545 cases ran eight minutes without a word)."""
    import json
    import os
    import subprocess
    import sys
    import tempfile
    work = work or tempfile.mkdtemp(prefix=name + "_")
    os.makedirs(work, exist_ok=True)
    inp, out = os.path.join(work, name + ".json"), os.path.join(work, name + ".h5")
    with open(inp, "w") as fh:
        json.dump(sweep, fh, indent=1)
    print("running %s: %s sweep %s -o %s" % (what, knit_meso, inp, out), flush=True)
    subprocess.run([knit_meso, "sweep", inp, "-o", out, "--threads", str(threads), "--force",
                    "--plain"], check=True, stdout=sys.stderr)
    return out
