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
                         its missing observables are left out, never invented)

Output: the sensitivity table (CSV, parameter,value,observable,result; format:
scripts/figures/sensitivity.py), read by the pipeline (SENSITIVITY, scripts/pipeline.mk).
The observable names group as <panel>@<line> (or <panel>_<line>) for the figure.

  /usr/bin/python3 scripts/calibrate.py --bin build/bin/knit-meso \\
      --out cases/calibration/sensitivity.csv [--only g0,gamma] [--steps 12] [--work DIR]
  /usr/bin/python3 scripts/calibrate.py --bin ... --point gamma_over_w=0.25,g0=0.1  (one
      parameter set, observables printed: for trying a rule before adopting it)

Runs one knit-meso process at a time (the machine is shared); every path is cached in WORK by
its parameters, so a rerun only computes what is new.
"""
import argparse
import csv
import json
import os
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


def run_path(binary, work, p, loop, axis, steps):
    """-> list of (E_aa, S_aa, E_lateral) of the converged steps (step 0 included)."""
    d = os.path.join(work, f"{key(p)}_l{loop}_a{axis}_n{steps}")
    csv_path = os.path.join(d, "path.csv")
    if not os.path.exists(csv_path):
        os.makedirs(work, exist_ok=True)
        cfg = d + ".json"
        with open(cfg, "w") as f:
            json.dump(cell_config(p), f)
        cmd = [binary, "path", "--loop-length", str(loop), "--uniaxial", str(axis), str(E_END),
               "--steps", str(steps), "--no-vtp", "--config", cfg, "--out", d]
        t0 = time.time()
        r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        last = (r.stdout.strip().splitlines() or ["?"])[-1]
        print(f"  l={loop} axis={axis} {key(p)}: exit {r.returncode}, {time.time() - t0:.1f} s"
              f"  {last[:90]}", file=sys.stderr)
        if r.returncode not in (0, 1) or not os.path.exists(csv_path):
            raise RuntimeError(f"knit-meso failed ({' '.join(cmd)}):\n{r.stdout}")
    e, s, lat = ("E11", "S11_MPa", "E22") if axis == 0 else ("E22", "S22_MPa", "E11")
    with open(csv_path) as f:
        return [(float(row[e]), float(row[s]), float(row[lat])) for row in csv.DictReader(f)]


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


def observables(curves):
    """curves[(dir, loop)] -> {observable: value} (missing ones left out)."""
    out = {}
    for dname, _ in DIRS:
        for loop in LOOPS:
            c = curves[(dname, loop)]
            tag = f"{dname}_{int(round(loop * 10))}"
            out[f"reached_{tag}"] = max(e for e, _, _ in c)
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
        c45, c65 = curves[(dname, 4.5)], curves[(dname, 6.5)]
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


def measure(binary, work, p, steps):
    curves = {}
    for dname, axis in DIRS:
        for loop in LOOPS:
            curves[(dname, loop)] = run_path(binary, work, p, loop, axis, steps)
    return observables(curves)


SUMMARY = ["ratio_wale@E0.2", "ratio_wale@E0.3", "ratio_wale@E0.4", "min_ratio_wale",
           "min_ratio_course", "S_wale_45@E0.2", "S_wale_65@E0.2", "S_course_45@E0.2",
           "stiffening_wale_45", "stiffening_course_45", "lateral_wale_45", "extensibility_45"]


def summarize(path):
    """A markdown table of the headline observables of a sensitivity table (docs)."""
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "figures"))
    from sensitivity import read_table
    rows = read_table(path)
    res = {(p, v, o): r for p, v, o, r in rows}
    points = sorted({(p, v) for p, v, _, _ in rows}, key=lambda t: (list(TABLE_NAME.values())
                                                                   .index(t[0]), t[1]))
    short = [o.replace("ratio_", "r_").replace("stiffening_", "stf_").replace("lateral_", "lat_")
             .replace("extensibility_", "ext_")
             for o in SUMMARY]
    print("| parameter | value | " + " | ".join(short) + " |")
    print("|---|---|" + "---|" * len(SUMMARY))
    for p, v in points:
        cells = [f"{res[(p, v, o)]:.3g}" if (p, v, o) in res else "–" for o in SUMMARY]
        print(f"| {p} | {v:g} | " + " | ".join(cells) + " |")


def parse_point(text):
    p = dict(DEFAULTS)
    for item in filter(None, text.split(",")):
        k, v = item.split("=")
        if k not in p:
            raise SystemExit(f"--point: unknown parameter {k} (known: {', '.join(p)})")
        p[k] = float(v)
    return p


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default="build/bin/knit-meso")
    ap.add_argument("--out", default="cases/calibration/sensitivity.csv")
    ap.add_argument("--work", default="/tmp/knit_calibration")
    ap.add_argument("--steps", type=int, default=12, help="steps of each uniaxial path")
    ap.add_argument("--only", default="", help="comma-separated subset of " + ",".join(RANGES))
    ap.add_argument("--point", default=None,
                    help="one parameter set k=v,... over the defaults: print its observables")
    ap.add_argument("--base", default="",
                    help="k=v,... replacing defaults for the one-at-a-time study")
    ap.add_argument("--summarize", default=None,
                    help="print a markdown table of the headline observables of a table")
    a = ap.parse_args()
    if a.summarize:
        summarize(a.summarize)
        return
    if a.point is not None:
        obs = measure(a.bin, a.work, parse_point(a.point), a.steps)
        for k in sorted(obs):
            print(f"{k:28s} {obs[k]:.4f}")
        return
    base = parse_point(a.base)
    names = [n for n in RANGES if not a.only or n in a.only.split(",")]
    rows = []
    for n in names:
        for v in RANGES[n]:
            p = dict(base)
            p[n] = v
            print(f"{n} = {v}", file=sys.stderr)
            for o, r in sorted(measure(a.bin, a.work, p, a.steps).items()):
                rows.append((TABLE_NAME[n], v, o, r))
    os.makedirs(os.path.dirname(os.path.abspath(a.out)), exist_ok=True)
    tmp = a.out + ".tmp"
    with open(tmp, "w") as f:
        f.write("# Sensitivity of the unit cell's observables (scripts/calibrate.py, issue 12);\n")
        f.write(f"# uniaxial-stress paths to E = {E_END} in {a.steps} steps, l = 4.5 and 6.5 mm;\n")
        f.write("# one parameter varied at a time, the others at "
                + " ".join(f"{k}={base[k]:.6g}" for k in sorted(base)) + "\n")
        f.write("parameter,value,observable,result\n")
        for r in rows:
            f.write(f"{r[0]},{r[1]:.6g},{r[2]},{r[3]:.6g}\n")
    os.replace(tmp, a.out)
    print(f"{len(rows)} results -> {a.out}", file=sys.stderr)


if __name__ == "__main__":
    main()
