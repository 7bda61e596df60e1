#!/usr/bin/python3
"""Calibration of the unit cell against the paper's observations (issue #12 items 3-4).

For each open mesoscale choice (contact allowance g0, normal penalty k_N, friction mu, loop
shape gamma/w, yarn diameter d) varied one at a time over a physically plausible range (the
others at their defaults; ranges and sources in docs/unit-cell.md, "Calibration"), runs the
cell's uniaxial-stress paths along the course and the wale at l = 4.5 and 6.5 mm
(`knit-meso path --uniaxial AXIS E`) and records cell-level observables:

  S_<dir>_<l>@E<e>       S_aa [MPa] at E_aa = e (0.1, 0.2, 0.3, 0.4); dir = course | wale,
                         l = 45 | 65
  ratio_<dir>@E<e>       S(4.5) / S(6.5) at E_aa = e  (the paper: 4.5 mm "much stiffer")
  min_ratio_<dir>        the smallest of S(4.5)/S(6.5) on E_aa = 0.05, 0.075, ..., 0.40 (the
                         paper's local E22 reach ~37 %)
  stiffening_<dir>_<l>   secant stiffness at 0.3 over that at 0.1 (> 1: a stiffening curve)
  lateral_<dir>_<l>      the lateral Green-Lagrange strain at E_aa = 0.3 (contraction < 0)
  E_at_<S>MPa_<dir>_<l>  the strain E_aa at which S_aa first reaches S = 0.5 MPa
  extensibility_<l>      E_at_0.5MPa course / wale: single jersey stretches about twice as far
                         widthwise (course) as lengthwise (wale) (textile handbooks, docs)
  reached_<dir>_<l>      the largest E_aa reached (a path that stops early is recorded here and
                         its missing observables are left out, never invented; each such path is
                         named by a warning on stderr and counted at the end)
  refused_<dir>_<l>      1: knit-meso refused the cell as input (exit 2, e.g. gamma/w = 0.10 at
                         l = 6.5 mm does not interlock); the path has no other observable

Output: the sensitivity table (CSV, parameter,value,observable,result; format:
scripts/figures/sensitivity.py), read by the pipeline (SENSITIVITY, scripts/pipeline.mk).
The observable names group as <panel>@<line> (or <panel>_<line>) for the figure.

  /usr/bin/python3 scripts/calibrate.py --bin build/bin/knit-meso \\
      --out cases/calibration/sensitivity.csv [--only g0,gamma] [--steps 12] [--work DIR]
  /usr/bin/python3 scripts/calibrate.py --bin ... --point gamma_over_w=0.25,g0=0.1  (one
      parameter set, observables printed: for trying a rule before adopting it)
  /usr/bin/python3 scripts/calibrate.py --summarize TABLE.csv  (the docs' markdown table)

--only takes the parameter names (g0, gamma_over_w, k_N, mu, d) or the table's (g0, gamma,
normal_stiffness, friction, diameter); other names are refused. With --only, the other
parameters' rows of an existing --out table are kept (merged), if that table was made with
the same steps and base; an --out that is not such a table (header parameter,value,
observable,result) is never overwritten. The study exits 1 and writes nothing when no path
gave an observable beyond reached_* and refused_* (every path stopped at once or refused).

Runs one knit-meso process at a time (the machine is shared); every path is cached in WORK by
the binary's sha256 and its parameters, so a rerun only computes what is new. A path counts as
cached only when its knit-meso run ended (exit 0, or 1: stopped early, its converged steps
kept): it runs into WORK/.../NAME.part and is renamed when done. A path knit-meso refuses is
not cached (asked again on a rerun: 0.06 s). The key is the parameters and the steps; E_END
and the cell's fixed settings (cell_config) are constants of this script.
"""
import argparse
import collections
import csv
import hashlib
import json
import math
import os
import shutil
import subprocess
import sys
import time

LOOPS = (4.5, 6.5)
DIRS = (("course", 0), ("wale", 1))
E_END = 0.4            # end Green-Lagrange strain of the uniaxial paths
E_OBS = (0.1, 0.2, 0.3, 0.4)
S_EXT = 0.5            # stress level of the extensibility observable [MPa]
E_GRID = [0.05 + 0.025 * k for k in range(15)]  # 0.05 ... 0.40: the "over the range" ratio

# The cell defaults (schemas/cell.schema.json) and the plausible ranges (docs/unit-cell.md,
# "Calibration", where each range has its source).
DEFAULTS = {"g0": 0.14, "k_N": 1000.0, "mu": 0.15, "gamma_over_w": 0.225, "d": 0.38}
RANGES = {
    "g0": [0.06, 0.10, 0.14, 0.18, 0.22],
    "gamma_over_w": [0.10, 0.15, 0.175, 0.198413, 0.225, 0.25, 0.275, 0.30],
    "k_N": [250.0, 500.0, 1000.0, 2000.0, 4000.0],
    "mu": [0.05, 0.10, 0.15, 0.22, 0.30],
    "d": [0.29, 0.33, 0.38, 0.42],
}
# Parameter names in the table (the figure puts g0 and gamma first).
TABLE_NAME = {"g0": "g0", "gamma_over_w": "gamma", "k_N": "normal_stiffness", "mu": "friction",
              "d": "diameter"}
HEADER = "parameter,value,observable,result"
PROG = "calibrate.py"
# Observables that say what happened to a path rather than measure it: a study whose rows are
# all of these measured nothing.
STATUS_PREFIXES = ("reached_", "refused_")

# A path's outcome: its converged steps (E_aa, S_aa, E_lateral), step 0 included ([] when no
# load step converged; None when refused), whether it reached lambda = 1, and knit-meso's
# message when it refused the cell (exit 2).
Path = collections.namedtuple("Path", "curve completed refused")


def die(msg, code=2):
    """One line on stderr and the exit code (2: bad command line or input, as knit-meso)."""
    print(f"{PROG}: error: {msg}", file=sys.stderr)
    sys.exit(code)


def warn(msg):
    print(f"{PROG}: warning: {msg}", file=sys.stderr)


def cell_config(p):
    """The cell parameter file (schemas/cell.schema.json) of a parameter set."""
    # max_overlap 1 (the overlap bound off, the side check of the pass-through guard kept): the
    # soft penalties of the sensitivity study sink deeper than the default 0.8 d in
    # equilibrium (k_N = 250 MPa: 0.775 d on the (0.4, 0.4) path at 4.5 mm; docs/unit-cell.md).
    return {"yarn": {"d": p["d"]}, "loop": {"gamma_over_w": p["gamma_over_w"]},
            "contact": {"allowance": p["g0"], "penalty": p["k_N"], "mu": p["mu"],
                        "max_overlap": 1.0}}


def key(p):
    return "_".join(f"{k}{p[k]:.6g}" for k in sorted(p))


class Runner:
    """Runs knit-meso paths, caches them by the binary's identity and the parameters, and keeps
    the count of the paths that stopped early or were refused."""

    def __init__(self, binary, work, steps):
        self.binary, self.steps = binary, steps
        self.sha = binary_sha(binary)
        # A cache per binary (the audit of session 56: a filled WORK of another binary, or of
        # none, was reused).
        self.work = os.path.join(work, "knit-meso-" + self.sha[:16])
        self.paths = 0
        self.stopped = []   # (label, loop, axis, reached)
        self.refused = []   # (label, loop, axis, message)

    def run_path(self, p, loop, axis, label):
        """-> Path of the uniaxial path along axis at loop length `loop` of parameter set p;
        label names the parameter set in the messages."""
        self.paths += 1
        d = os.path.join(self.work, f"{key(p)}_l{loop}_a{axis}_n{self.steps}")
        csv_path = os.path.join(d, "path.csv")
        marker = os.path.join(d, "calibrate.json")
        where = f"{label}, l = {loop:g} mm, axis {axis} ({DIRS[axis][0]})"
        if not os.path.exists(marker):
            # Into NAME.part, renamed when knit-meso has ended: a crashed run leaves no cached
            # path (the audit: a partial path.csv was reused on the next run).
            os.makedirs(self.work, exist_ok=True)
            part = d + ".part"
            shutil.rmtree(part, ignore_errors=True)
            cfg = d + ".json"
            with open(cfg, "w") as f:
                json.dump(cell_config(p), f)
            cmd = [self.binary, "path", "--loop-length", str(loop), "--uniaxial", str(axis),
                   str(E_END), "--steps", str(self.steps), "--no-vtp", "--config", cfg,
                   "--out", part]
            t0 = time.time()
            r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            lines = (r.stdout + r.stderr).strip().splitlines() or ["?"]
            print(f"  l={loop} axis={axis} {key(p)}: exit {r.returncode}, "
                  f"{time.time() - t0:.1f} s  {lines[-1][:90]}", file=sys.stderr)
            errors = [x for x in r.stderr.splitlines() if "error" in x] or \
                r.stderr.strip().splitlines() or ["(no message)"]
            if r.returncode == 2:
                # Refused as input (knit::kExitBadInput): recorded, the study goes on.
                shutil.rmtree(part, ignore_errors=True)
                msg = " ".join(x.strip() for x in errors)
                print(f"{PROG}: refused: {where}: knit-meso exit 2: {msg}", file=sys.stderr)
                self.refused.append((label, loop, axis, msg))
                return Path(None, False, msg)
            stopped_at_start = (r.returncode == 1 and not os.path.exists(
                os.path.join(part, "path.csv")) and "no load step converged" in r.stderr)
            if r.returncode not in (0, 1) or not (
                    os.path.exists(os.path.join(part, "path.csv")) or stopped_at_start):
                shutil.rmtree(part, ignore_errors=True)
                tail = "\n".join((r.stdout + r.stderr).strip().splitlines()[-10:])
                die(f"knit-meso failed on {where} (exit {r.returncode}; {' '.join(cmd)}):\n"
                    f"{tail}\nnothing written", 1)
            os.makedirs(part, exist_ok=True)
            with open(os.path.join(part, "calibrate.json"), "w") as f:
                json.dump({"exit": r.returncode, "binary": self.binary,
                           "binary_sha256": self.sha, "command": cmd}, f)
            shutil.rmtree(d, ignore_errors=True)  # an earlier, unfinished cache entry
            os.rename(part, d)
        curve, completed = [], False
        if os.path.exists(csv_path):
            e, s, lat = ("E11", "S11_MPa", "E22") if axis == 0 else ("E22", "S22_MPa", "E11")
            with open(csv_path) as f:
                rows = list(csv.DictReader(f))
            curve = [(float(row[e]), float(row[s]), float(row[lat])) for row in rows]
            completed = bool(rows) and float(rows[-1]["lambda"]) >= 1 - 1e-9
        if not completed:
            reached = max((c[0] for c in curve), default=0.0)
            warn(f"{where}: the path stopped at E = {reached:.4g} before {E_END:g}; its "
                 "observables beyond it are left out")
            self.stopped.append((label, loop, axis, reached))
        return Path(curve, completed, None)

    def measure(self, p, label):
        return observables({(dname, loop): self.run_path(p, loop, axis, label)
                            for dname, axis in DIRS for loop in LOOPS})

    def summary(self):
        """The closing count (stderr)."""
        print(f"{PROG}: {self.paths} paths: {len(self.stopped)} stopped before E = {E_END:g}, "
              f"{len(self.refused)} refused by knit-meso", file=sys.stderr)


def interp(curve, e, col):
    """Linear interpolation of column col (1 = S, 2 = lateral E) at E_aa = e; None beyond the
    reached strain."""
    for (e0, *v0), (e1, *v1) in zip(curve, curve[1:]):
        if e0 <= e <= e1 and e1 > e0:
            t = (e - e0) / (e1 - e0)
            return v0[col - 1] + t * (v1[col - 1] - v0[col - 1])
    return None


def strain_at_stress(curve, s):
    """The first E_aa at which S_aa reaches s (linear between steps); None if never."""
    for (e0, s0, _), (e1, s1, _) in zip(curve, curve[1:]):
        if s0 < s <= s1:
            return e0 + (s - s0) / (s1 - s0) * (e1 - e0)
    return None


def observables(paths):
    """paths[(dir, loop)] (Path) -> {observable: value} (missing ones left out; a refused path
    gives refused_<dir>_<l> = 1 and nothing else)."""
    out = {}
    curves = {}
    for dname, _ in DIRS:
        for loop in LOOPS:
            path = paths[(dname, loop)]
            tag = f"{dname}_{int(round(loop * 10))}"
            if path.refused is not None:
                out[f"refused_{tag}"] = 1.0
                continue
            c = curves[(dname, loop)] = path.curve
            out[f"reached_{tag}"] = max((e for e, _, _ in c), default=0.0)
            for e in E_OBS:
                s = interp(c, e, 1)
                if s is not None:
                    out[f"S_{tag}@E{e:g}"] = s
            s1, s3 = interp(c, 0.1, 1), interp(c, 0.3, 1)
            if s1 is not None and s3 is not None and s1 > 0:
                out[f"stiffening_{tag}"] = (s3 / 0.3) / (s1 / 0.1)
            lat = interp(c, 0.3, 2)
            if lat is not None:
                out[f"lateral_{tag}"] = lat
            ext = strain_at_stress(c, S_EXT)
            if ext is not None:
                out[f"E_at_{S_EXT:g}MPa_{tag}"] = ext
        c45, c65 = curves.get((dname, 4.5)), curves.get((dname, 6.5))
        if c45 is None or c65 is None:
            continue
        ratios = []
        for e in E_GRID:
            s45, s65 = interp(c45, e, 1), interp(c65, e, 1)
            if s45 is None or s65 is None or s65 <= 0:
                ratios = None
                break
            ratios.append(s45 / s65)
            if any(abs(e - x) < 1e-9 for x in E_OBS):
                out[f"ratio_{dname}@E{e:g}"] = s45 / s65
        if ratios:
            out[f"min_ratio_{dname}"] = min(ratios)
    for loop in LOOPS:
        tag = int(round(loop * 10))
        ec = out.get(f"E_at_{S_EXT:g}MPa_course_{tag}")
        ew = out.get(f"E_at_{S_EXT:g}MPa_wale_{tag}")
        if ec is not None and ew is not None and ew > 0:
            out[f"extensibility_{tag}"] = ec / ew
    return out


def measured(obs):
    """Whether observables hold anything beyond the paths' status (reached_*, refused_*)."""
    return any(not o.startswith(STATUS_PREFIXES) for o in obs)


SUMMARY = ["ratio_wale@E0.2", "ratio_wale@E0.3", "ratio_wale@E0.4", "min_ratio_wale",
           "min_ratio_course", "S_wale_45@E0.2", "S_wale_65@E0.2", "S_course_45@E0.2",
           "stiffening_wale_45", "stiffening_course_45", "lateral_wale_45", "extensibility_45"]


def summarize(path):
    """A markdown table of the headline observables of a sensitivity table (docs), and a line
    per parameter value whose paths knit-meso refused."""
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "figures"))
    from sensitivity import read_table
    try:
        rows = read_table(path)
    except (OSError, ValueError) as e:
        die(f"--summarize: {e}")
    res = {(p, v, o): r for p, v, o, r in rows}
    order = list(TABLE_NAME.values())
    points = sorted({(p, v) for p, v, _, _ in rows},
                    key=lambda t: (order.index(t[0]) if t[0] in order else len(order), t[0],
                                   t[1]))
    short = [o.replace("ratio_", "r_").replace("stiffening_", "stf_").replace("lateral_", "lat_")
             .replace("extensibility_", "ext_")
             for o in SUMMARY]
    print("| parameter | value | " + " | ".join(short) + " |")
    print("|---|---|" + "---|" * len(SUMMARY))
    for p, v in points:
        cells = [f"{res[(p, v, o)]:.3g}" if (p, v, o) in res else "–" for o in SUMMARY]
        print(f"| {p} | {v:g} | " + " | ".join(cells) + " |")
    for p, v in points:
        refused = sorted(o[len("refused_"):] for (q, w, o) in res
                         if (q, w) == (p, v) and o.startswith("refused_"))
        if refused:
            print(f"\nrefused by knit-meso: {p} = {v:g}: {', '.join(refused)}")


def parse_point(text, option):
    """k=v,... over the defaults; a bad item exits 2 naming `option`."""
    p = dict(DEFAULTS)
    for item in filter(None, text.split(",")):
        k, eq, v = item.partition("=")
        k = k.strip()
        if not eq:
            die(f"{option}: '{item}' is not NAME=VALUE (e.g. {option} g0=0.1)")
        if k not in p:
            die(f"{option}: unknown parameter {k} (known: {', '.join(p)})")
        try:
            p[k] = float(v)
        except ValueError:
            die(f"{option}: {k}: '{v}' is not a number")
        if not math.isfinite(p[k]):
            die(f"{option}: {k}: {v} is not finite")
    return p


def parse_only(text):
    """--only: -> the parameter names (RANGES order); unknown names exit 2 naming the allowed."""
    by_name = {n: n for n in RANGES}
    by_name.update({t: n for n, t in TABLE_NAME.items()})
    names = [x.strip() for x in text.split(",") if x.strip()]
    if not text:
        return list(RANGES)
    unknown = [x for x in names if x not in by_name]
    if unknown or not names:
        die(f"--only: unknown parameter {', '.join(unknown) or repr(text)} (allowed: "
            f"{', '.join(RANGES)}, or the table's names {', '.join(TABLE_NAME.values())})")
    wanted = {by_name[x] for x in names}
    return [n for n in RANGES if n in wanted]


def read_own_table(path):
    """-> (settings comment lines, rows as (parameter, value text, observable, result text)) of
    an existing table of ours; None when `path` is not one (no header parameter,value,
    observable,result before its first data line)."""
    comments, rows, header = [], [], False
    try:
        with open(path, encoding="utf-8") as f:
            for line in f:
                line = line.strip()
                if not line:
                    continue
                if line.startswith("#"):
                    comments.append(line)
                    continue
                if not header:
                    if line.replace(" ", "") != HEADER:
                        return None
                    header = True
                    continue
                cells = [c.strip() for c in line.split(",")]
                if len(cells) != 4:
                    return None
                rows.append(tuple(cells))
    except (OSError, UnicodeDecodeError):
        return None
    return (comments, rows) if header else None


def binary_sha(binary):
    """sha256 of the knit-meso binary's bytes (hex): which build made a path or a table."""
    with open(binary, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def settings_lines(steps, base, sha):
    """The comment lines of a table: what made it (compared when merging), the knit-meso build
    by its sha256 (the review of session 56: --only merged rows of two builds silently)."""
    return ["# Sensitivity of the unit cell's observables (scripts/calibrate.py, issue 12);",
            f"# uniaxial-stress paths to E = {E_END} in {steps} steps, l = 4.5 and 6.5 mm;",
            "# one parameter varied at a time, the others at "
            + " ".join(f"{k}={base[k]:.6g}" for k in sorted(base)),
            f"# knit-meso sha256 {sha[:16]}"]


def check_out(out, merging, steps, base, sha):
    """Before any run: --out must be a new file or a table of ours (never overwrite anything
    else); with --only (merging) -> the existing table's rows to keep, else []."""
    if os.path.isdir(out):
        die(f"--out: {out} is a directory; name the table file")
    if not os.path.exists(out):
        return []
    own = read_own_table(out)
    if own is None:
        die(f"--out: {out} exists and is not a sensitivity table (no header {HEADER}): "
            "not overwritten; name a new file or remove it")
    if not merging:
        return []
    comments, rows = own
    mine = settings_lines(steps, base, sha)[1:3]
    theirs = [c for c in comments if c.startswith(("# uniaxial-stress", "# one parameter"))]
    if theirs and theirs != mine:
        die(f"--out: {out} was made with other settings ({' '.join(theirs)}) than this run "
            f"({' '.join(mine)}): its rows cannot be merged with --only; name another --out")
    build = settings_lines(steps, base, sha)[3]
    made_by = [c for c in comments if c.startswith("# knit-meso sha256 ")]
    if made_by != [build]:
        said = made_by[0][len("# knit-meso "):] if made_by else "no recorded build"
        die(f"--out: {out} was made by another knit-meso ({said}) than this run's "
            f"({build[len('# knit-meso '):]}): --only would mix the rows of two builds; run the "
            "whole study without --only (about 2 minutes), or name another --out")
    return rows


def write_table(out, rows, steps, base, sha):
    """rows (parameter, value text, observable, result text) -> out, atomically."""
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    tmp = out + ".tmp"
    try:
        with open(tmp, "w") as f:
            f.write("\n".join(settings_lines(steps, base, sha)) + "\n")
            f.write(HEADER + "\n")
            for r in rows:
                f.write(",".join(r) + "\n")
        os.replace(tmp, out)
    except OSError as e:
        if os.path.exists(tmp):
            os.remove(tmp)
        die(f"--out: {out}: {e}", 1)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default="build/bin/knit-meso")
    ap.add_argument("--out", default="cases/calibration/sensitivity.csv")
    ap.add_argument("--work", default="/tmp/knit_calibration")
    ap.add_argument("--steps", type=int, default=12, help="steps of each uniaxial path")
    ap.add_argument("--only", default="",
                    help="comma-separated subset of " + ",".join(RANGES) + " (or the table's "
                    "names " + ",".join(TABLE_NAME.values()) + "); the other parameters' rows "
                    "of an existing --out are kept")
    ap.add_argument("--point", default=None,
                    help="one parameter set k=v,... over the defaults: print its observables")
    ap.add_argument("--base", default="",
                    help="k=v,... replacing defaults for the one-at-a-time study")
    ap.add_argument("--summarize", default=None,
                    help="print a markdown table of the headline observables of a table")
    a = ap.parse_args()
    if a.summarize:
        summarize(a.summarize)
        return 0
    if a.steps < 1:
        die(f"--steps: must be at least 1, got {a.steps}")
    # Everything the command line says is checked before the first run.
    point = parse_point(a.point, "--point") if a.point is not None else None
    base = parse_point(a.base, "--base")
    names = parse_only(a.only)
    binary = shutil.which(a.bin)
    if binary is None:
        die(f"--bin: {a.bin} is not an executable file (build knit-meso, or name it)")
    if point is not None:
        runner = Runner(binary, a.work, a.steps)
        obs = runner.measure(point, "--point " + a.point)
        runner.summary()
        for k in sorted(obs):
            print(f"{k:28s} {obs[k]:.4f}")
        if not measured(obs):
            die("no path gave an observable beyond reached_* / refused_*", 1)
        return 0
    kept = check_out(a.out, bool(a.only), a.steps, base, binary_sha(binary))
    runner = Runner(binary, a.work, a.steps)
    new = {}
    any_measured = False
    for n in names:
        rows = new[TABLE_NAME[n]] = []
        for v in RANGES[n]:
            p = dict(base)
            p[n] = v
            print(f"{n} = {v}", file=sys.stderr)
            obs = runner.measure(p, f"{n} = {v:g}")
            any_measured = any_measured or measured(obs)
            for o, r in sorted(obs.items()):
                rows.append((TABLE_NAME[n], f"{v:.6g}", o, f"{r:.6g}"))
    runner.summary()
    if not any_measured:
        die(f"no path gave an observable beyond reached_* / refused_* (every path stopped at "
            f"once or was refused): nothing written to {a.out}", 1)
    # --only: the other parameters' rows of the existing table, in the table's order.
    old = collections.OrderedDict()
    for r in kept:
        if r[0] not in new:
            old.setdefault(r[0], []).append(r)
    if old:
        print(f"kept from {a.out}: {sum(len(x) for x in old.values())} rows of "
              f"{', '.join(old)} (not rerun: --only {a.only})")
    order = list(TABLE_NAME.values())
    groups = sorted(list(new.items()) + list(old.items()),
                    key=lambda t: order.index(t[0]) if t[0] in order else len(order))
    rows = [r for _, g in groups for r in g]
    write_table(a.out, rows, a.steps, base, runner.sha)
    print(f"{len(rows)} results -> {a.out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
