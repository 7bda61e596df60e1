#!/usr/bin/python3
"""scripts/cell_uniqueness.py (issue 11): is the cell's end stress a function of the strain?

The twins' deformation gradients end at the same strain (an identity, on random gradients);
then the whole script on a hand-made database of two held-out gradient paths of 6 steps, with
a stand-in for knit-meso that writes the twins' database from the sweep input it is given: the
cell's stress is S = 10 E at every step of every path, except that the lower-triangular twin
of the first held-out path (steps factor 2) ends 2 MPa higher in S11 (20 % of the range 10),
and the same-path twin of the second held-out path with 3 times the steps is 1 MPa higher in
S11 halfway (10 %). Those two states must be flagged (spreads 20 % and 10 %), the second
path's end state not (0 %), and the law (S = 10 E, exact) must be within 5 % at every state.
With `--steps-factor 4` the halfway state is one state (its perturbed twin is not run). Also
the refusal of a bad factor and of a database without /sweep input_json. Run by CTest
(tests/CMakeLists.txt, label report) with Debian's /usr/bin/python3 (numpy, h5py).
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
SCRIPT = os.path.join(ROOT, "scripts", "cell_uniqueness.py")
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import cell_uniqueness as cu  # noqa: E402

# The stand-in for knit-meso: `FAKE sweep INPUT -o OUT ...` writes OUT with one raw path per
# item of the input's extra list (after the preset's one path), S = 10 E at each of its steps
# (F = I + t H, t = k / steps), except the end of item 2 (the first path's lower-triangular
# twin with the first factor): S11 + 2; and with the default factors 2, 3, 4 the halfway state
# of item 12 (the second path's same-path twin with factor 3; 9 twins per path): S11 + 1.
FAKE = r'''#!/usr/bin/python3
import json, sys
import h5py, numpy as np
args = sys.argv[1:]
assert args[0] == "sweep", args
inp = json.load(open(args[1]))
assert inp["fit"] is False and inp["cell"] == {"elements": 24}, inp
out = args[args.index("-o") + 1]
with h5py.File(out, "w") as f:
    f["loop_lengths"] = np.array(inp["loop_lengths"], dtype=float)
    for k, l in enumerate(inp["loop_lengths"]):
        raw = f.create_group("loop_%d/raw" % k)
        p = raw.create_group("path_00")
        p["E"], p["S"], p["status"] = np.zeros((1, 3)), np.zeros((1, 3)), np.zeros(1, np.int32)
        for i, x in enumerate(inp["load_paths"]["extra"]):
            n = x["steps"]
            E = np.zeros((n, 3))
            for k in range(n):
                F = np.eye(2) + (k + 1) / n * np.array(x["H"])
                G = 0.5 * (F.T @ F - np.eye(2))
                E[k] = [G[0, 0], G[1, 1], G[0, 1]]
            S = 10.0 * E * np.array([1.0, 1.0, 2.0])
            if i == 2:
                S[-1, 0] += 2.0
            if i == 12:
                S[n // 2 - 1, 0] += 1.0
            p = raw.create_group("path_%02d" % (i + 1))
            p["E"], p["S"], p["status"] = E, S, np.zeros(n, np.int32)
'''


def write_db(path, with_input=True):
    """Two held-out gradient paths and one fitted path (the stress range: 10 MPa). No law is
    stored (the script then prints no law errors); compare() is given one below."""
    Hs = [np.array([[0.1, 0.3], [0.0, 0.05]]), np.array([[0.2, -0.1], [0.0, 0.1]])]
    with h5py.File(path, "w") as f:
        f["loop_lengths"] = np.array([5.0])
        raw = f.create_group("loop_0/raw")
        p = raw.create_group("path_00")
        t = np.linspace(0.0, 1.0, 5)[:, None]
        p["E"] = t * np.array([[1.0, 0.5, 0.0]])
        p["S"] = 10.0 * p["E"][:]
        p["status"] = np.zeros(5, np.int32)
        p.attrs["set"], p.attrs["kind"] = "coverage", "biaxial"
        p.attrs["target"], p.attrs["steps"] = np.array([1.0, 0.5]), 5
        for i, H in enumerate(Hs):
            E = np.zeros((6, 3))
            for k in range(6):
                G = cu.green((k + 1) / 6 * H)
                E[k] = [G[0, 0], G[1, 1], G[0, 1]]
            p = raw.create_group("path_%02d" % (i + 1))
            p["E"], p["S"] = E, 10.0 * E * np.array([1.0, 1.0, 2.0])
            p["status"] = np.zeros(6, np.int32)
            p.attrs["set"], p.attrs["kind"] = "holdout", "gradient"
            p.attrs["H"], p.attrs["steps"] = H.reshape(-1), 6
        if with_input:
            s = f.create_group("sweep")
            s.attrs["input_json"] = json.dumps({"loop_lengths": [5.0], "cell": {"elements": 24},
                                                "runner": "cell"})


class LinearLaw:
    def eval(self, e):
        return None, 10.0 * np.asarray(e)


def main():
    check = Checklist()

    rng = np.random.default_rng(3)
    worst = 0.0
    for _ in range(200):
        H = rng.uniform(-0.4, 0.6, (2, 2))
        if np.linalg.det(np.eye(2) + H) < 0.2:
            continue
        U, L = cu.twin_gradients(H)
        worst = max(worst, np.abs(cu.green(U) - cu.green(H)).max(),
                    np.abs(cu.green(L) - cu.green(H)).max(), abs(U[0, 1] - U[1, 0]),
                    abs(L[0, 1]))
    check(worst < 1e-12, "twins end at the same strain; U symmetric, L lower triangular "
          "(largest deviation %.1e)" % worst)

    with tempfile.TemporaryDirectory() as d:
        db, fake = os.path.join(d, "db.h5"), os.path.join(d, "fake-meso")
        write_db(db)
        with open(fake, "w") as fh:
            fh.write(FAKE)
        os.chmod(fake, 0o755)
        r = subprocess.run([sys.executable, SCRIPT, db, "--knit-meso", fake, "--work",
                            os.path.join(d, "w")], capture_output=True, text=True)
        out = r.stdout + r.stderr
        check(r.returncode == 0, "the script runs with the stand-in (exit %d)" % r.returncode, out)
        m = re.search(r"path_01 .* ([0-9.]+)% \* ", out)
        check(m is not None and abs(float(m.group(1)) - 20.0) < 0.05,
              "the first path's end state is flagged with a spread of 20 %", out)
        m = re.search(r"path_02 .* ([0-9.]+)%   ", out)
        check(m is not None and float(m.group(1)) == 0.0,
              "the second path's end state is one state of the cell (0 %)", out)
        check("2 end states; 0 with a twin that did not converge; 1 are one state" in out,
              "the summary counts 1 of 2", out)
        m = re.search(r"path_02 +3 .* ([0-9.]+)% \* ", out)
        check(m is not None and abs(float(m.group(1)) - 10.0) < 0.05,
              "the second path's halfway state is flagged with a spread of 10 %", out)
        check("12 converged states; 0 with a twin that did not converge there; 10 are one "
              "state" in out, "the summary along the paths counts 10 of 12", out)

        # The law's errors, through compare() with a law given directly.
        paths = cu.selected_paths(h5py.File(db, "r"), "holdout")
        _, counts = cu.twin_extras(paths, [2, 3, 4])
        rows, along, summary = cu.compare(
            h5py.File(db, "r"), h5py.File(os.path.join(d, "w", "twins.h5"), "r"), paths,
            counts, lambda l: LinearLaw(), factors=[2, 3, 4])
        errs = [r[4] for r in rows]
        check(np.allclose(errs[0], [0.0, 0.0, 0.0, 0.2] + [0.0] * 6) and
              np.allclose(errs[1], 0.0),
              "the law's errors against the original and the twins (0 and 20 %)", str(errs))
        check(summary["unique"] == 1 and summary["law_within"] == 1 and
              summary["law_within_all"] == 2, "law within 5 % at the one state", str(summary))
        check(len(along) == 12 and summary["along_unique"] == 10 and
              summary["along_law_within"] == 10 and summary["along_law_within_all"] == 12,
              "along the paths: 10 states of the cell, the law within 5 % at all 12",
              str(summary))

        # One factor: the halfway perturbation is not run, that state is one state.
        r = subprocess.run([sys.executable, SCRIPT, db, "--knit-meso", fake, "--work",
                            os.path.join(d, "w4"), "--steps-factor", "4"],
                           capture_output=True, text=True)
        out = r.stdout + r.stderr
        check(r.returncode == 0 and "12 converged states; 0 with a twin that did not converge "
              "there; 11 are one state" in out, "--steps-factor 4: 11 of 12", out)
        r = subprocess.run([sys.executable, SCRIPT, db, "--knit-meso", fake, "--steps-factor",
                            "2,0"], capture_output=True, text=True)
        check(r.returncode != 0 and "--steps-factor" in r.stderr,
              "a factor below 1 is refused", r.stdout + r.stderr)

        write_db(db, with_input=False)
        r = subprocess.run([sys.executable, SCRIPT, db, "--knit-meso", fake],
                           capture_output=True, text=True)
        check(r.returncode != 0 and "/sweep has no attribute input_json" in r.stderr,
              "a database without the sweep input is refused", r.stdout + r.stderr)

    return check.exit_code()


if __name__ == "__main__":
    sys.exit(main())
