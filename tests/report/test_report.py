#!/usr/bin/python3
"""Test of the validation report itself (issue #12): synthetic result directories with known
defects go through scripts/report.py's loading and checks, and each verdict is compared with
what the defect must cause.

A baseline of synthetic runs (every curve and field built so that each statement holds with a
margin) must pass every check; each variant injects one known defect (a load dip, an early
stop, a 3 % / 8 % convergence gap, a cut-back that shifts the rows, a constant zero alpha, a
non-uniform field, ...) and must fail exactly the checks that read it. Every check key fails in
at least one variant and passes in the baseline, so no check is vacuous.

Run: /usr/bin/python3 tests/report/test_report.py   (CTest: report_checks)
"""
import json
import math
import os
import shutil
import sys
import tempfile

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
sys.path.insert(0, os.path.join(ROOT, "scripts", "figures"))
import report  # noqa: E402
import report_checks as rc  # noqa: E402
from fixtures import linear_network_law, raw_path, write_tiny_png  # noqa: E402  (tests/report/fixtures.py)

L = 50.0
N = 11  # output grid n_u = n_v
SQ2 = math.sqrt(2.0)
SQUARE = {"degrees": [1, 1], "knots_u": [0, 0, 1, 1], "knots_v": [0, 0, 1, 1],
          "control_points": [[0, 0, 0], [L, 0, 0], [0, L, 0], [L, L, 0]], "thickness": 0.76}
CURVED = {"degrees": [3, 1], "knots_u": [0, 0, 0, 0, 1, 1, 1, 1], "knots_v": [0, 0, 1, 1],
          "control_points": [[x * L, y * L, 0.0] for x, y in zip(
              [-0.5, -1 / 6, 1 / 6, 0.5, -0.5, -1 / 6, 1 / 6, 0.5],
              [0.0, 0.0, -0.5, -0.5, 0.5, 0.5, 0.0, 0.0])],
          "weights": [1, 2, 2, 1, 1, 2, 2, 1], "thickness": 0.76}


# ---- synthetic runs --------------------------------------------------------------------------
def grid_X(geometry=SQUARE):
    _, X = rc.exact_alignment_angle(geometry, N, N)
    return X


def stiffening(k):
    return lambda e: k * (e + 20.0 * e ** 3)


def softening(k):
    return lambda e: k * (e - e ** 2)


def steps_to(target, n=20, cutback_at=None):
    """Strains of the converged steps: n equal steps to target; a cut-back halves step
    `cutback_at` (one extra row: the rows after it are shifted)."""
    e = list(np.linspace(0.0, target, n + 1)[1:])
    if cutback_at is not None:
        a = e[cutback_at - 1] if cutback_at > 0 else 0.0
        e.insert(cutback_at, 0.5 * (a + e[cutback_at]))
    return np.array(e)


class Run:
    """One synthetic case: its converged strains, a load function of strain, a function of
    strain giving the fields (dict of (N, N) arrays), the geometry and the exit code."""

    def __init__(self, target, load, fields=None, geometry=SQUARE, cutback_at=None):
        self.strain = steps_to(target, cutback_at=cutback_at)
        self.load = load
        self.fields = fields
        self.geometry = geometry
        self.exit_code = 0
        self.summary_status = "completed"  # summary.txt's status line
        self.summary_extra = ""            # further summary.txt lines (a failure's)
        self.status_file = True            # the pipeline's NAME.status is written
        self.last_fields_factor = 1.0      # load_factor stored with the last step's fields

    def stop_at(self, eps):
        """The run stops: only the steps with |strain| <= |eps| converged."""
        self.strain = self.strain[np.abs(self.strain) <= abs(eps) + 1e-12]
        self.exit_code = 1
        self.summary_status = "stopped"


def write_run(res_dir, name, run):
    import h5py
    d = os.path.join(res_dir, name)
    os.makedirs(d, exist_ok=True)
    loads = [run.load(e) for e in run.strain]
    with open(os.path.join(d, "load_strain.csv"), "w") as f:
        f.write("step,load_factor,applied_displacement_mm,strain,load_N,iterations\n")
        for k, (e, p) in enumerate(zip(run.strain, loads), 1):
            f.write(f"{k},{e / run.strain[-1] if len(run.strain) else 0:.12g},{e * L:.12g},"
                    f"{e:.15g},{p:.15g},3\n")
    with open(os.path.join(d, "case.json"), "w") as f:
        json.dump({"geometry": run.geometry, "output": {"grid": [N, N]}}, f)
    with open(os.path.join(d, "summary.txt"), "w") as f:
        f.write(f"status: {run.summary_status}\n{run.summary_extra}")
    if run.status_file:
        with open(os.path.join(res_dir, name + ".status"), "w") as f:
            json.dump({"case": name, "exit_code": run.exit_code, "seconds": 0.01}, f)
    if run.fields is None:
        return
    X = grid_X(run.geometry)
    with h5py.File(os.path.join(d, "results.h5"), "w") as h:
        for k, e in enumerate(run.strain, 1):
            g = h.create_group(f"fields/step_{k:04d}")
            g.attrs["load_factor"] = e / run.strain[-1] * (
                run.last_fields_factor if k == len(run.strain) else 1.0)
            u = np.zeros_like(X)
            u[..., 1] = e * X[..., 1]
            g["x"] = (X + u).reshape(-1, 3)
            g["displacement"] = u.reshape(-1, 3)
            for key, v in run.fields(e, X).items():
                g[key] = np.asarray(v, dtype=float).reshape(-1)


# ---- the baseline: every statement holds with a margin ----------------------------------------
def wale_e22(m20, m30, a):
    """E22 with its maximum m(eps) at the free edges' middle; `a` sets the non-uniformity."""
    def f(e, X):
        x, y = X[..., 0], X[..., 1]
        shape = 1.0 + a * ((x - 25.0) / 25.0) ** 2 * np.exp(-((y - 25.0) / 8.0) ** 2)
        c = np.interp(e, [0.0, 0.2, 0.3], [0.0, m20, m30]) / (1.0 + a)
        return {"E22": c * shape, "E11": -0.3 * c * shape, "E12": 0.0 * x}
    return f


def halves_e11(left, right):
    def f(e, X):
        x = X[..., 0]
        return {"E11": np.where(x < 25.0, left, right) * e / 0.3 + 0.0 * x}
    return f


def halves_e22(a_left, a_right):
    def f(e, X):
        x, y = X[..., 0], X[..., 1]
        a = np.where(x < 25.0, a_left, a_right)
        return {"E22": e * (1.0 + a * np.cos(2 * math.pi * y / L))}
    return f


def graded_e22(gradient, wiggle_bottom, wiggle_top):
    def f(e, X):
        x, y = X[..., 0], X[..., 1]
        s = y / L
        wig = wiggle_bottom * (1 - s) + wiggle_top * s
        return {"E22": e * (1.0 + gradient * s) * (1.0 + wig * np.cos(2 * math.pi * x / L))}
    return f


def diagonal_fields(asym11=0.0, asym12=0.0):
    def f(e, X):
        x, y = X[..., 0] / L, X[..., 1] / L
        g = lambda a, b: 0.1 + 0.05 * a + 0.03 * a * b + 0.02 * b ** 2  # noqa: E731
        return {"E11": e * (g(x, y) + asym11 * x), "E22": e * g(y, x),
                "E12": e * (0.03 * (x + y) + 0.01 * x * y + asym12 * x)}
    return f


def curved_fields(error):
    def f(e, X):
        return {"knitting_angle": EXACT_ALPHA + error(EXACT_ALPHA), "E22": 0.0 * EXACT_ALPHA + e}
    return f


EXACT_ALPHA = rc.exact_alignment_angle(CURVED, N, N)[0]


def hypar_fields(e, X):
    return {"E12": 0.01 * e + 0.0 * X[..., 0], "E22": 0.02 * e + 0.0 * X[..., 0],
            "kappa11": 0.001 * e + 0.0 * X[..., 0]}


def baseline():
    runs = {}
    for l, k in (("45", 20.0), ("65", 10.0)):
        runs[f"s312_uniform_{l}_course"] = Run(0.3, stiffening(k))
    runs["s312_uniform_45_wale"] = Run(0.3, stiffening(20.0), wale_e22(0.26, 0.38, 0.05))
    runs["s312_uniform_65_wale"] = Run(0.3, stiffening(10.0), wale_e22(0.25, 0.36, 0.30))
    runs["s313_discontinuous_course"] = Run(0.3, stiffening(12.0), halves_e11(0.12, 0.30))
    runs["s313_discontinuous_wale"] = Run(0.3, stiffening(12.0), halves_e22(0.3, 0.1))
    runs["s314_linear_course"] = Run(0.3, stiffening(12.0))
    runs["s314_linear_wale"] = Run(0.3, stiffening(12.0), graded_e22(0.5, 0.3, 0.05))
    runs["s315_diagonal_45deg_vertical"] = Run(0.3, stiffening(12.0))
    for p in (3, 5, 7):
        for h in (1, 4):
            runs[f"conv7c_p{p}h{h}"] = Run(0.3, stiffening(20.0))
        runs[f"conv9e_p{p}h1"] = Run(0.3, stiffening(12.0))
    for n in ("s321_bilinear_diagonal", "mesh321_p5h2", "mesh321_p5h4"):
        runs[n] = Run(SQ2 * 0.2, softening(30.0), diagonal_fields())
    runs["s322_curved_horizontal"] = Run(0.4, stiffening(8.0),
                                         curved_fields(lambda a: 0.02 * np.sin(3 * a)), CURVED)
    runs["mesh315_p5h4"] = Run(0.3, stiffening(12.0))
    runs["mesh322_p5h4"] = Run(0.4, stiffening(8.0))
    runs["s323_hypar_tension"] = Run(SQ2 * 0.15, lambda e: 5 * e, hypar_fields)
    runs["s323_hypar_compression"] = Run(-SQ2 * 0.10, lambda e: 5 * e, hypar_fields)
    return runs


# ---- variants: one known defect each, and the checks it must fail ------------------------------
def dip(run, at, frac):
    """Load drops to `frac` of its value from strain `at` on (17.1 -> 5.7 N at 21 % in #12)."""
    f = run.load
    run.load = lambda e: f(e) * (frac if e >= at - 1e-12 else 1.0)


def v_dip(r):
    dip(r["s312_uniform_65_wale"], 0.21, 1 / 3)


def v_early_stop_hypar(r):
    r["s323_hypar_tension"].stop_at(0.004)
    r["s323_hypar_compression"].stop_at(0.0)


def v_gap3(r):  # a known 3 % gap (PASS at 5 %), with a cut-back shifting the rows
    r["conv7c_p5h1"] = Run(0.3, lambda e: 1.03 * stiffening(20.0)(e), cutback_at=7)
    r["conv9e_p5h1"] = Run(0.3, lambda e: 0.97 * stiffening(12.0)(e), cutback_at=3)


def v_gap8(r):
    r["conv7c_p5h1"] = Run(0.3, lambda e: 1.08 * stiffening(20.0)(e))
    r["conv9e_p5h1"] = Run(0.3, lambda e: 0.92 * stiffening(12.0)(e))


def v_conv_stop(r):  # the reference stops at 24 %: the comparison cannot be made to 30 %
    r["conv7c_p7h4"].stop_at(0.24)


def v_not_much_stiffer(r):  # end loads 2 % apart (95.3 vs 93.4 N in #12)
    r["s312_uniform_45_course"].load = stiffening(10.2)
    r["s312_uniform_45_wale"].load = stiffening(10.2)


def v_linear(r):  # nearly linear course-wise curve (ratio 1.2 in #12)
    r["s312_uniform_45_course"].load = lambda e: 45.0 * (e + 0.3 * e ** 2)


def v_concave_middle(r):  # last/first ratio high but not convex (a soft middle third)
    r["s314_linear_course"].load = lambda e: 12.0 * np.interp(e, [0, 0.1, 0.2, 0.3],
                                                              [0, 0.1, 0.15, 0.5])


def v_e22_low(r):  # max E22 below the kinematic bound and the paper at both strains
    r["s312_uniform_45_wale"].fields = wale_e22(0.20, 0.30, 0.05)


def v_e22_center(r):  # maximum in the middle of the patch
    r["s312_uniform_65_wale"].fields = wale_e22(0.25, 0.36, -0.2)


def v_nonuniform_45(r):  # 4.5 mm less uniform than 6.5 mm along the central section
    r["s312_uniform_45_wale"].fields = wale_e22(0.26, 0.38, 0.30)
    r["s312_uniform_65_wale"].fields = wale_e22(0.25, 0.36, 0.05)


def v_right_not_higher(r):
    r["s313_discontinuous_course"].fields = halves_e11(0.12, 0.15)


def v_right_nonuniform(r):
    r["s313_discontinuous_wale"].fields = halves_e22(0.1, 0.3)


def v_top_equal(r):  # 0.334 vs 0.329 in #12: larger, but by 1.5 %
    r["s314_linear_wale"].fields = graded_e22(0.015, 0.3, 0.05)


def v_top_nonuniform(r):
    r["s314_linear_wale"].fields = graded_e22(0.5, 0.05, 0.3)


def v_mesh_stiffening(r):  # the finest mesh's curve stiffens
    r["mesh321_p5h4"].load = stiffening(30.0)


def v_mesh_gap(r):  # h = 4 differs from h = 2 by 10 % (still not stiffening)
    r["mesh321_p5h4"].load = lambda e: 1.1 * softening(30.0)(e)


def v_asym(r):
    r["mesh321_p5h2"].fields = diagonal_fields(asym11=0.01)


def v_asym12(r):
    r["s321_bilinear_diagonal"].fields = diagonal_fields(asym12=0.01)


def v_alpha_zero(r):
    r["s322_curved_horizontal"].fields = curved_fields(lambda a: -a)


def v_alpha_off(r):  # 5 degrees off everywhere
    r["s322_curved_horizontal"].fields = curved_fields(lambda a: math.radians(5) + 0 * a)


def v_all_stop(r):  # every run stops at half its strain
    for run in r.values():
        run.stop_at(0.5 * run.strain[-1])


# -- garbage that passed before session 30 (a helper's mutation audit of the report) --------------
def v_nan_soft(r):  # the 6.5 mm course loads NaN: "much stiffer" passed as ratio infinity
    r["s312_uniform_65_course"].load = lambda e: float("nan")


def v_zero_soft(r):  # ... and zero: the same
    r["s312_uniform_65_course"].load = lambda e: 0.0


def v_swapped_strain(r):  # two rows' strains swapped, loads in place: passed "monotone"
    s = r["s312_uniform_45_course"].strain
    s[5], s[15] = s[15], s[5]


def v_zero_e22_65(r):  # zero E22 made 4.5 mm "more uniform" (CV inf <= 0.9 inf)
    r["s312_uniform_65_wale"].fields = lambda e, X: {"E22": np.zeros(X.shape[:2])}


def v_zero_e22_314(r):  # zero E22 made the top "larger" (0 >= 1.1 x 0)
    r["s314_linear_wale"].fields = lambda e, X: {"E22": np.zeros(X.shape[:2])}


def v_nan_e22(r):  # one NaN sample at a free edge's middle moved the argmax there
    f = r["s312_uniform_45_wale"].fields

    def g(e, X):
        out = f(e, X)
        out["E22"] = np.array(out["E22"], dtype=float)
        out["E22"][N // 2, 0] = float("nan")
        return out
    r["s312_uniform_45_wale"].fields = g


def v_zero_321(r):  # zero strains were symmetric (0 / 1e-300)
    for n in ("s321_bilinear_diagonal", "mesh321_p5h2", "mesh321_p5h4"):
        r[n].fields = lambda e, X: {k: np.zeros(X.shape[:2]) for k in ("E11", "E22", "E12")}


def v_exit1_completed(r):  # exit 1 although it completed (failed material evaluations)
    r["s312_uniform_45_course"].exit_code = 1
    r["s312_uniform_45_course"].summary_extra = ("material failures: completed with 3 failed "
                                                 "material evaluations; results are not "
                                                 "trustworthy\n")


def v_no_status(r):  # the status file is missing: exit code unknown
    r["s312_uniform_45_course"].status_file = False


def v_stale_fields(r):  # the fields at 30 % carry the load factor of 15 %
    r["s313_discontinuous_course"].last_fields_factor = 0.5


def v_exit1_314(r):  # exit 1 after completing, on a run two field checks share (review)
    r["s314_linear_wale"].exit_code = 1


def v_material_failure_stopped(r):  # failed evaluations of the step that stopped the run
    r["s312_uniform_45_course"].stop_at(0.2)
    r["s312_uniform_45_course"].summary_extra = ("material failures: stopped with 2 failed "
                                                 "material evaluations; results are not "
                                                 "trustworthy\n")


def v_case_missing(r):  # a case of cases/paper has no result at all
    del r["mesh322_p5h4"]


S45C = "s312_uniform_45_course"
S65C = "s312_uniform_65_course"
CURVE_45C = {f"reach:{S45C}", f"monotone:{S45C}", f"stiffening:{S45C}", "stiffer:course"}
CURVE_65C = {f"reach:{S65C}", f"monotone:{S65C}", f"stiffening:{S65C}", "stiffer:course"}
E22_65 = {"uniform312", "e22bound:65:0.2", "e22bound:65:0.3", "e22value:65", "e22where:65"}


def v_all_dip(r):  # every curve drops to half at 2/3 of its strain
    for run in r.values():
        dip(run, 2 * run.strain[-1] / 3, 0.5)


MONO = [f"monotone:{n}" for n in report.TENSILE]
REACH = [f"reach:{n}" for n in report.PAPER_STRAIN]
VARIANTS = {
    # name: (mutation, checks that must fail, exact: no other check may fail)
    "dip 17.1 -> 5.7 N at 21 %": (v_dip, {"monotone:s312_uniform_65_wale",
                                          "stiffening:s312_uniform_65_wale"}, True),
    "hyperbolic paraboloids stop at 0.4 % and 0 %": (
        v_early_stop_hypar, {"reach:s323_hypar_tension", "reach:s323_hypar_compression"}, True),
    "3 % convergence gap with cut-backs": (v_gap3, set(), True),
    "8 % convergence gap": (v_gap8, {"conv7c", "conv9e"}, True),
    "convergence reference stops at 24 %": (
        v_conv_stop, {"conv7c", "reach:conv7c_p7h4"}, True),
    "4.5 mm stiffer by 2 % only": (v_not_much_stiffer, {"stiffer:course", "stiffer:wale"}, True),
    "nearly linear curve": (v_linear, {"stiffening:s312_uniform_45_course"}, True),
    "soft middle third": (v_concave_middle, {"stiffening:s314_linear_course"}, True),
    "max E22 too low": (v_e22_low, {"e22bound:45:0.2", "e22bound:45:0.3", "e22value:45"}, True),
    "max E22 in the middle": (v_e22_center, {"e22where:65"}, True),
    "4.5 mm less uniform": (v_nonuniform_45, {"uniform312"}, True),
    "E11 right not much higher": (v_right_not_higher, {"e11right313"}, True),
    "E22 right half less uniform": (v_right_nonuniform, {"uniform313"}, True),
    "top strains 1.5 % larger": (v_top_equal, {"larger314"}, True),
    "top strains less uniform": (v_top_nonuniform, {"uniform314"}, True),
    "finest mesh stiffening": (v_mesh_stiffening, {"notstiff321", "mesh321"}, True),
    "10 % mesh gap": (v_mesh_gap, {"mesh321"}, True),
    "E11/E22 not mirrored": (v_asym, {"mirror321"}, True),
    "E12 not symmetric": (v_asym12, {"sym321"}, True),
    "constant zero alpha": (v_alpha_zero, {"alpha322"}, True),
    "alpha 5 deg off": (v_alpha_off, {"alpha322"}, True),
    "every run stops at half": (v_all_stop, set(REACH), False),
    "6.5 mm course loads NaN": (v_nan_soft, CURVE_65C, True),
    "6.5 mm course loads zero": (v_zero_soft, CURVE_65C, True),
    "two strains swapped": (v_swapped_strain, CURVE_45C, True),
    "zero E22, 6.5 mm wale": (v_zero_e22_65, E22_65, True),
    "zero E22, 3.1.4 wale": (v_zero_e22_314, {"larger314", "uniform314"}, True),
    "one NaN E22 sample at an edge": (v_nan_e22, {"e22where:45", "e22bound:45:0.3",
                                                  "e22value:45", "uniform312"}, False),
    "zero strain fields in 3.2.1": (v_zero_321, {"mirror321", "sym321"}, True),
    "exit 1 after completing": (v_exit1_completed, CURVE_45C, True),
    "no status file": (v_no_status, CURVE_45C, True),
    "fields of 15 % stored as 30 %": (v_stale_fields, {"e11right313", "reach:s313_discontinuous_course", "monotone:s313_discontinuous_course", "stiffening:s313_discontinuous_course"}, True),
    "exit 1 after completing, 3.1.4 wale": (v_exit1_314, {
        "reach:s314_linear_wale", "monotone:s314_linear_wale", "stiffening:s314_linear_wale",
        "larger314", "uniform314"}, True),
    # knit-macro's "not trustworthy" counts the whole run's evaluations: every check FAILs
    "a stop with failed evaluations": (v_material_failure_stopped, CURVE_45C, True),
    "a case without a result": (v_case_missing, {"reach:mesh322_p5h4",
                                                 "monotone:mesh322_p5h4"}, True),
    "every curve drops at 2/3": (v_all_dip, set(MONO), False),
}


def verdicts(runs, tmp):
    res = os.path.join(tmp, "results")
    shutil.rmtree(res, ignore_errors=True)
    os.makedirs(res)
    for name, run in runs.items():
        write_run(res, name, run)
    rep = report.Report(tmp)
    return rep, {c.key: c for c in rep.checks()}


def law_check_failures(tmp):
    """report.law_checks on a synthetic database and logs: all four checks pass on the
    baseline, each variant fails exactly its own check, a database without an energy law gives
    no rows."""
    import h5py
    out = []
    db = os.path.join(tmp, "law.h5")
    logs = os.path.join(tmp, "law_logs")
    os.makedirs(logs, exist_ok=True)

    def write(rms=(0.02, 0.03), mx=(0.04, 0.045), h=(24, 24, 0.04), extra=(10, 20), energy=True,
              mono=None, runs=12, diagnostics=True, evaluations=1000, points=(1, 1),
              unconverged="paper"):
        with h5py.File(db, "w") as f:
            f["loop_lengths"] = [4.5, 6.5]
            f.attrs["format_version"] = 3
            for k in range(2):  # `runs` held-out paths per loop length (one converged step),
                for q in range(runs + 3):  # one not converged (`unconverged`), two fit paths
                    g = f.create_group(f"loop_{k}/raw/path_{q:02d}")
                    g.attrs["set"] = ("holdout" if q < runs else unconverged if q == runs
                                      else "paper")
                    g["status"] = [0 if q < runs else 2]
                    g["E"] = np.zeros((1, 3))
                    g["S"] = np.zeros((1, 3))
            if energy and not diagnostics:
                f.create_group("energy_law")
            if energy and diagnostics:
                d = f.create_group("energy_law/diagnostics")
                d["loop_length"] = [4.5, 6.5]
                d["rms_relative"] = list(rms)
                d["max_relative"] = list(mx)
                d["points"] = list(points)
                if mono is not None:
                    d["monotonicity_bound"] = list(mono)
                d.attrs["holdout_points"] = h[0]
                d.attrs["holdout_within_5_percent"] = h[1]
                d.attrs["holdout_max_relative"] = h[2]
        for name, k in zip(("a", "b"), extra):
            path = os.path.join(logs, name + ".log")
            if k is None:
                if os.path.exists(path):
                    os.remove(path)
                continue
            with open(path, "w") as f:
                f.write("step    1  load factor 1\n"
                        f"knit material (energy law): {evaluations} evaluations; {k} extrapolated "
                        f"({k / 10} %, outside the data strain box ...)\n"
                        "  at converged states: 0 of 100 evaluations extrapolated (0 %)\n")

    def extrapolations():  # as Report.write reads them
        return {n: report.extrapolation(os.path.join(logs, n + ".log")) for n in ("a", "b")}

    def verdicts():
        return [r[3] for r in report.law_checks(db, extrapolations())]

    # The hand-made database has no law to re-evaluate; since session 52 a law that cannot be
    # re-evaluated fails, so the re-evaluations stand in here, agreeing with the stored figures
    # (held_out_agreement_failures and the block below test the disagreements).
    import law_held_out
    real_fit, real_held = law_held_out.fit_errors, law_held_out.held_out_misses

    def agreeing_fit(db_path):
        with h5py.File(db_path, "r") as f:
            d = f["energy_law/diagnostics"]
            return [(float(l), int(n), float(r), float(m)) for l, n, r, m in
                    zip(d["loop_length"][()], d["points"][()], d["rms_relative"][()],
                        d["max_relative"][()])]

    def agreeing_held(db_path):
        with h5py.File(db_path, "r") as f:
            a = f["energy_law/diagnostics"].attrs
            n, w = int(a["holdout_points"]), int(a["holdout_within_5_percent"])
        return n, w, [], (n, w)
    law_held_out.fit_errors, law_held_out.held_out_misses = agreeing_fit, agreeing_held
    try:
        return law_check_variants(out, write, db, extrapolations, verdicts, law_held_out,
                                  agreeing_fit)
    finally:
        law_held_out.fit_errors, law_held_out.held_out_misses = real_fit, real_held


def law_check_variants(out, write, db, extrapolations, verdicts, law_held_out, agreeing_fit):
    """law_check_failures' variants, with the re-evaluations standing in."""
    write()
    # Reports of a run that disagree (report.run_extrapolation, session 52) fail the row.
    rows = report.law_checks(db, extrapolations(), ["b: its log reports 20 of 1000 ..."])
    if rows[3][3] is not False or "reports that disagree: b: its log" not in rows[3][2] or \
            "no report" in rows[3][2]:
        out.append(f"law checks: a conflict of reports does not fail the row: {rows[3]}")
    if verdicts() != [True, True, True, True]:
        out.append(f"law checks: the baseline gives {verdicts()}")
    variants = [("rms 6 %", dict(rms=(0.02, 0.06)), 0),
                ("largest error 5.5 %", dict(mx=(0.055, 0.045)), 1),
                ("one held-out state at 5.2 %", dict(h=(24, 23, 0.052)), 2),
                ("no held-out states", dict(h=(0, 0, float("nan"))), 2),
                ("a case with 2.1 % extrapolated", dict(extra=(10, 21)), 3),
                ("a case without its material report", dict(extra=(10, None)), 3),
                # session 30: each of these passed
                ("held-out states in 2 x 9 runs only", dict(runs=9), 2),
                ("every held-out state 'within' but the largest at 50 %", dict(h=(24, 24, 0.5)),
                 2),
                ("errors for one loop length of two", dict(rms=(0.02,), mx=(0.04,)), None),
                ("a log of 0 evaluations", dict(evaluations=0, extra=(0, 0)), 3),
                # Session 52's red team: the misses marked unconverged, the attributes made to
                # match: "349 of 349" passed. A planned held-out state not judged fails.
                ("a held-out state not converged", dict(unconverged="holdout"), 2)]
    for name, kw, k in variants:
        write(**kw)
        want = [True] * 4
        if k is None:  # both fit rows
            want[0] = want[1] = False
        else:
            want[k] = False
        if verdicts() != want:
            out.append(f"law checks, {name}: {verdicts()} instead of {want}")
    # The data's floor for a convex law is printed beside the largest error, not judged.
    write(mx=(0.055, 0.045), mono=(0.016, 0.035))
    row = report.law_checks(db, extrapolations())[1]
    if "monotonicity bound): 1.6 / 3.5 %" not in row[2] or row[3] is not False:
        out.append(f"law checks: the monotonicity bound is not printed as given: {row}")
    write()
    if "monotonicity" in report.law_checks(db, extrapolations())[1][2]:
        out.append("law checks: a monotonicity bound printed for a database without one")
    # Session 38's red team: /energy_law deleted, the table and its FAIL row went. Now one FAIL
    # row, naming the logs that report the energy law (the results are not of this database).
    write(energy=False)
    rows = report.law_checks(db, extrapolations())
    if (len(rows) != 1 or rows[0][3] is not False or "absent, although 2 case log(s)" not in
            rows[0][2]):
        out.append(f"law checks: a database without an energy law gives {rows}")
    # The stored fit errors against the law re-evaluated at its fit states (session 38's red
    # team: the law scaled by 1.15 kept its stored 4.5 % and PASS): agreeing figures pass,
    # disagreeing ones (larger or smaller) fail both fit rows; so does a loop length whose
    # stored count is not the re-evaluated one (session 52's red team: such a loop length was
    # not compared, and its capped largest error passed), and a law that cannot be
    # re-evaluated (one NaN in the cell data left the stored figures to judge).
    try:
        for name, refit, want, points in [
                ("the same figures", [(4.5, 1, 0.02, 0.04), (6.5, 1, 0.03, 0.045)], True, (1, 1)),
                ("a law 129 % off", [(4.5, 1, 0.6, 1.29), (6.5, 1, 0.7, 2.53)], False, (1, 1)),
                ("a smaller re-evaluated error", [(4.5, 1, 0.01, 0.03), (6.5, 1, 0.02, 0.04)],
                 False, (1, 1)),
                ("a loop length missing", [(4.5, 1, 0.02, 0.04)], False, (1, 1)),
                ("another count of fit states", [(4.5, 2, 0.02, 0.04), (6.5, 1, 0.03, 0.045)],
                 False, (1, 1))]:
            law_held_out.fit_errors = lambda db_path, r=refit: r
            write(points=points)
            rows = report.law_checks(db, extrapolations())
            got = [rows[0][3], rows[1][3]]
            if got != [want, want]:
                out.append(f"law checks, re-evaluated fit errors, {name}: {got}: {rows[:2]}")
            if name == "another count of fit states" and \
                    "4.5 mm (1 stored, 2 by the fit's rule)" not in rows[1][2]:
                out.append(f"law checks: the loop length of another count is not named: "
                           f"{rows[1][2]}")

        def unreadable(db_path):
            raise ValueError("/loop_0: the law's error at its fit states is not finite")
        law_held_out.fit_errors = unreadable
        write()
        rows = report.law_checks(db, extrapolations())
        if [rows[0][3], rows[1][3]] != [False, False] or "could not be re-evaluated" not in \
                rows[1][2]:
            out.append(f"law checks: a law that cannot be re-evaluated passes: {rows[:2]}")
        # A record shorter than the loop lengths fails without a traceback (the review).
        law_held_out.fit_errors = lambda db_path: [(4.5, 1, 0.02, 0.04), (6.5, 1, 0.03, 0.045)]
        write(rms=(0.02,), mx=(0.04,))
        rows = report.law_checks(db, extrapolations())
        if rows[0][3] is not False or rows[1][3] is not False:
            out.append(f"law checks: a short record passes: {rows[:2]}")
    finally:
        law_held_out.fit_errors = agreeing_fit
    write(diagnostics=False)  # session 30: the whole table vanished, no FAIL
    rows = report.law_checks(db, extrapolations())
    if len(rows) != 1 or rows[0][3] is not False:
        out.append(f"law checks: an energy law without diagnostics gives {rows}")
    return out


def held_out_reference_failures(tmp):
    """report.held_out_reference on a hand-made database whose cell stress is a smooth function
    of the strain (S = C e + quadratic terms): the free interpolant trained on the fit paths
    predicts every held-out state; with one held-out path's S11 raised by 20 % of the stress
    range it misses exactly that path's states; the text beside the verdict prints the count;
    a database without raw paths gives no reference."""
    import h5py
    out = []
    db = os.path.join(tmp, "ref.h5")
    rng = np.random.default_rng(3)
    C = np.array([[4.0, 1.0, 0.0], [1.0, 2.0, 0.0], [0.0, 0.0, 1.0]])

    def stress(e):  # e = (E11, E22, 2 E12)
        return e @ C + np.stack([e[:, 0] ** 2, e[:, 1] ** 2, e[:, 0] * e[:, 2]], 1)

    ends = rng.uniform(-1, 1, (60, 3)) * [0.3, 0.3, 0.5]
    held_ends = rng.uniform(-1, 1, (5, 3)) * [0.2, 0.2, 0.3]

    def write(bump):
        with h5py.File(db, "w") as f:
            f["loop_lengths"] = [5.0]
            g = f.create_group("loop_0/raw")
            for i, (end, kind) in enumerate([(x, "coverage") for x in ends] +
                                            [(x, "holdout") for x in held_ends]):
                e = np.outer(np.linspace(1 / 6, 1, 6), end)
                S = stress(e)
                if kind == "holdout" and i == len(ends) and bump:
                    S[:, 0] += bump
                E = e.copy()
                E[:, 2] *= 0.5  # stored as E12 (load_paths doubles it)
                p = g.create_group("path_%02d" % i)
                p["E"], p["S"], p["status"] = E, S, np.zeros(6, dtype=int)
                p.attrs["set"], p.attrs["kind"] = kind, "gradient"
        with h5py.File(db, "r") as f:
            from cell_paths import load_paths, stress_range
            return stress_range(load_paths(f, 0))

    R = write(0.0)
    ref = report.held_out_reference(db)
    if ref is None or ref[:2] != (30, 30):
        out.append(f"held-out reference, smooth data: {ref} instead of 30 of 30 within 5 %")
    write(0.2 * R)
    ref = report.held_out_reference(db)
    if ref is None or ref[:2] != (24, 30) or not 0.15 < ref[2] < 0.25:
        out.append(f"held-out reference, one path bumped by 20 % of the range: {ref} instead of "
                   "24 of 30 within 5 % and a largest error near 20 %")
    if "a free interpolant trained on the same fit paths" not in report.held_out_reference_text(db):
        out.append("held-out reference: the text beside the verdict does not print it")
    with h5py.File(db, "w") as f:
        f["loop_lengths"] = [5.0]
    if report.held_out_reference(db) is not None:
        out.append("held-out reference: a database without raw paths gives one")
    return out


def near_visited_failures(tmp):
    """scripts/law_near_visited.py on a hand-made database whose law is S = 0 (a network with
    all parameters 0 and no floor), so a state's error is |S_cell| / range: which states count
    as near a visited strain (radius, the mirror in E12, tensor shear), and the numbers the
    report prints."""
    import h5py
    import law_near_visited as lnv
    out = []
    db = os.path.join(tmp, "near.h5")
    res = os.path.join(tmp, "near_results")
    os.makedirs(os.path.join(res, "case"), exist_ok=True)
    with h5py.File(os.path.join(res, "case", "results.h5"), "w") as f:
        g = f.create_group("fields/step_0001")
        g["E_course"], g["E_wale"], g["E_course_wale"] = [0.1, 0.3], [0.0, 0.3], [0.0, -0.05]
    with h5py.File(db, "w") as f:
        f["loop_lengths"] = [5.0]
        linear_network_law(f, 0.0)

        def path(name, set_, E, S):
            raw_path(f, name, set_, E, S)
        # Stored E is tensor shear. Range of the fit data: S11 from 0.5 to 10 -> 9.5 MPa.
        path("fit", "coverage", [[0.1, 0.0, 0.0], [0.6, 0.0, 0.0], [0.3, 0.3, 0.049]],
             [[0.5, 0.0, 0.0], [10.0, 0.0, 0.0], [0.5, 0.76, 0.0]])
        path("held", "holdout", [[0.13, 0.0, 0.0], [0.3, 0.3, 0.05], [-0.3, 0.0, 0.0]],
             [[0.2, 0.0, 0.0], [0.0, 0.95, 0.0], [3.0, 0.0, 0.0]])
    rows = lnv.near_errors(db, res, 0.05)
    want = dict(fit_n=3, fit_near=2, hold_n=3, hold_near=2, hold_in=1)
    got = {k: rows[0][k] for k in want} if rows else None
    if got != want:
        out.append(f"near visited: {got} instead of {want}")
    # The near fit states' largest error: (0.3, 0.3, 0.049) is 0.001 in E12 from the mirror
    # image (0.3, 0.3, 0.05) of the visited (0.3, 0.3, -0.05): 0.76 / 9.5 = 8 %.
    if not rows or abs(rows[0]["fit_max"] - 0.08) > 1e-12:
        out.append(f"near visited: fit_max {rows[0]['fit_max'] if rows else None}, want 0.08")
    if not rows or abs(rows[0]["hold_max"] - 0.1) > 1e-12:
        out.append(f"near visited: hold_max {rows[0]['hold_max'] if rows else None}, want 0.1")
    text = lnv.summary(rows)
    if "8.0 %" not in text or "1 of 2 held-out states" not in text:
        out.append(f"near visited: the report's sentence misses its numbers: {text}")
    # A smaller radius leaves the held-out state at 0.03 out.
    rows = lnv.near_errors(db, res, 0.02)
    if not rows or rows[0]["hold_near"] != 1:
        out.append(f"near visited, radius 0.02: {rows[0]['hold_near'] if rows else None} "
                   "held-out states near, want 1")
    return out


def unknown_value_failures(db, attr, value, label):
    """Sets /energy_law's attribute `attr` of the file `db` to an unknown `value`: the Python
    evaluator must refuse it, naming the attribute and /energy_law."""
    import h5py
    from energy_law import load_law
    with h5py.File(db, "a") as f:
        f["energy_law"].attrs[attr] = value
    with h5py.File(db, "r") as f:
        try:
            load_law(f["energy_law"], 5.3)
        except ValueError as err:
            if attr not in str(err) or "/energy_law" not in str(err):
                return [f"{label}: the refusal does not name the attribute: {err}"]
            return []
    return [f"{label}: an unknown {attr} {value!r} was read"]


def outer_exp_failures(tmp):
    """scripts/figures/energy_law.py's NetworkLaw with the exponential outer function (session
    15) on a hand-made law whose network is its quadratic part alone, N = 1/2 e^T L L^T e: then
    W = c g(N) - c g(0) + floor/2 |e|^2 is Fung's law in closed form, g = exp below the cap and
    exp(cap) (1 + d + d^2 / 2) beyond (both pieces sampled); S against central differences of W;
    an unknown outer function is refused."""
    import h5py
    from energy_law import load_law
    out = []
    db = os.path.join(tmp, "outer.h5")
    c, cap, floor = 1.7, 0.03, 0.02
    L = np.array([[1.2, 0.0, 0.0], [0.3, 0.9, 0.0], [0.0, 0.0, 0.8]])
    theta = np.zeros((1, 20))
    theta[0, 11:] = L.ravel()
    with h5py.File(db, "w") as f:
        law = f.create_group("energy_law")
        law.attrs["family"] = "network"
        law.attrs["h1"], law.attrs["h2"], law.attrs["floor"] = 1, 1, floor
        law.attrs["outer"], law.attrs["outer_scale"], law.attrs["outer_cap"] = "exp", c, cap
        law["l_knots"] = [5.0]
        law["theta"] = theta
    Q = L @ L.T
    e = np.array([[0.05, -0.02, 0.03], [0.2, 0.1, -0.15], [-0.25, 0.3, 0.2], [0.0, 0.0, 0.0]])

    def g(n):
        d = np.maximum(n - cap, 0.0)
        return np.exp(np.minimum(n, cap)) * (1.0 + d + 0.5 * d * d)
    n = 0.5 * np.einsum("ki,ij,kj->k", e, Q, e)
    want = c * (g(n) - 1.0) + 0.5 * floor * np.sum(e * e, axis=1)
    with h5py.File(db, "r") as f:
        law = load_law(f["energy_law"], 5.0)
        W, S = law.eval(e)
        h = 1e-6
        Sfd = np.stack([(law.eval(e + h * np.eye(3)[j])[0] - law.eval(e - h * np.eye(3)[j])[0])
                        / (2 * h) for j in range(3)], axis=-1)
    if not (n[1:3] > cap).all() or not (n[0] < cap):
        out.append(f"outer exp: the samples do not straddle the cap: N = {n}")
    if np.abs(W - want).max() > 1e-12:
        out.append(f"outer exp: W {W} instead of Fung's {want}")
    if np.abs(S - Sfd).max() > 1e-7 * (1 + np.abs(S).max()):
        out.append(f"outer exp: S {S.tolist()} is not dW/de {Sfd.tolist()}")
    return out + unknown_value_failures(db, "outer", "log", "outer exp")


def l_interpolation_failures(tmp):
    """scripts/figures/energy_law.py's interpolation in l (attribute l_interpolation, session
    16) on a hand-made law of two knots whose networks are their quadratic parts alone,
    N_j = 1/2 e^T L_j L_j^T e: "energy" gives W = (1 - t) N_a + t N_b + floor/2 |e|^2 between
    them, "parameters" (and a file without the attribute) the quadratic of the interpolated L,
    at a knot both give that knot's law; an unknown value is refused."""
    import h5py
    from energy_law import load_law
    out = []
    db = os.path.join(tmp, "l_interpolation.h5")
    floor = 0.02
    La = np.array([[1.2, 0.0, 0.0], [0.3, 0.9, 0.0], [0.0, 0.0, 0.8]])
    Lb = np.array([[0.5, 0.0, 0.0], [-0.4, 1.5, 0.0], [0.2, 0.0, 0.3]])
    theta = np.zeros((2, 20))
    theta[0, 11:], theta[1, 11:] = La.ravel(), Lb.ravel()
    e = np.array([[0.05, -0.02, 0.03], [0.2, 0.1, -0.15], [-0.25, 0.3, 0.2]])

    def quad(L):  # the mirror average 1/2 (N(e) + N(M e)), M = diag(1, 1, -1), plus the floor
        m = e * np.array([1.0, 1.0, -1.0])
        Q = L @ L.T
        return (0.25 * (np.einsum("ki,ij,kj->k", e, Q, e) + np.einsum("ki,ij,kj->k", m, Q, m))
                + 0.5 * floor * np.sum(e * e, axis=1))

    t = 0.3
    want = {"energy": (1 - t) * quad(La) + t * quad(Lb),
            "parameters": quad((1 - t) * La + t * Lb), None: quad((1 - t) * La + t * Lb)}
    for mode, w in want.items():
        with h5py.File(db, "w") as f:
            law = f.create_group("energy_law")
            law.attrs["family"] = "network"
            law.attrs["h1"], law.attrs["h2"], law.attrs["floor"] = 1, 1, floor
            if mode is not None:
                law.attrs["l_interpolation"] = mode
            law["l_knots"] = [5.0, 6.0]
            law["theta"] = theta
        with h5py.File(db, "r") as f:
            W = load_law(f["energy_law"], 5.0 + t).eval(e)[0]
            Wk = load_law(f["energy_law"], 6.0).eval(e)[0]
        if np.abs(W - w).max() > 1e-12:
            out.append(f"l_interpolation {mode}: W {W} at t = 0.3, want {w}")
        if np.abs(Wk - quad(Lb)).max() > 1e-12:
            out.append(f"l_interpolation {mode}: W {Wk} at the knot 6.0, want {quad(Lb)}")
    if np.abs(want["energy"] - want["parameters"]).max() < 1e-3:
        out.append("l_interpolation: the two modes agree on this law; the check cannot tell them")
    return out + unknown_value_failures(db, "l_interpolation", "spline", "l_interpolation")


def unusable_result_failures(tmp):
    """A case's result that cannot be taken is named and not judged as completed (session 36's
    red team): a truncated status file and a non-numeric CSV ended in tracebacks naming no
    file; results/NAME copied from another case were judged as NAME's; an empty CSV counted
    as a completed case."""
    sys.path.insert(0, os.path.join(ROOT, "scripts", "figures"))
    from results import Result
    out = []
    res = os.path.join(tmp, "unusable")

    def fresh(name):
        shutil.rmtree(res, ignore_errors=True)
        d = os.path.join(res, name)
        os.makedirs(d)
        with open(os.path.join(d, "load_strain.csv"), "w") as f:
            f.write("step,strain,load_N\n1,0.1,2.0\n2,0.2,5.0\n")
        with open(os.path.join(d, ".knitscale-output"), "w") as f:
            f.write(f"knitscale output: knit-macro run\n{{}}\nfor: {name}\nfile: load_strain.csv\n")
        with open(os.path.join(res, name + ".status"), "w") as f:
            json.dump({"case": name, "exit_code": 0, "seconds": 0.1}, f)
        return d

    fresh("a")
    r = Result(res, "a")
    if not r.completed or r.problem:
        out.append(f"unusable results: a good result is not completed ({r.problem})")
    with open(os.path.join(res, "a", "load_strain.csv"), "w") as f:  # its own CSV line: taken
        f.write("# knit-macro results of /x/cases/a.json (knitscale 0.1.0, git 0)\n"
                "step,strain,load_N\n1,0.1,2.0\n")
    r = Result(res, "a")
    if not r.completed or r.problem:
        out.append(f"unusable results: a CSV naming its own case is not taken ({r.problem})")
    variants = {
        "a truncated status file": (lambda d: open(os.path.join(res, "a.status"), "w").write(
            '{"case": "a", "exit_co'), "a.status is unreadable"),
        "a non-numeric CSV value": (lambda d: open(os.path.join(d, "load_strain.csv"), "w").write(
            "step,strain,load_N\n1,0.1,abc\n"), "load_strain.csv is unreadable"),
        "an empty CSV": (lambda d: open(os.path.join(d, "load_strain.csv"), "w").close(),
                         "load_strain.csv is unreadable (no rows)"),
        "another case's output": (lambda d: open(os.path.join(d, ".knitscale-output"), "w").write(
            "knitscale output: knit-macro run\n{}\nfor: b\n"),
            "holds the output written for b, not for a"),
        # session 38's red team: another case's CSV copied in was judged as this case's
        "another case's CSV": (lambda d: open(os.path.join(d, "load_strain.csv"), "w").write(
            "# knit-macro results of /x/cases/b.json (knitscale 0.1.0, git 0)\n"
            "step,strain,load_N\n1,0.1,2.0\n"), "holds the results of b.json, not of a.json"),
        # session 55's red team: a truncated case.json ended the report in a traceback
        "a truncated case.json": (lambda d: open(os.path.join(d, "case.json"), "w").write(
            '{"output": {"gri'), "case.json is unreadable"),
        "a case.json that is no object": (lambda d: open(os.path.join(d, "case.json"), "w").write(
            "[0]"), "case.json is unreadable (not a JSON object)"),
        "a case.json whose grid is not two integers": (
            lambda d: open(os.path.join(d, "case.json"), "w").write('{"output": {"grid": 7}}'),
            "/output/grid is not two integers"),
        # the review of session 55: a list as /output, a string or booleans as the grid
        "a case.json whose output is a list": (
            lambda d: open(os.path.join(d, "case.json"), "w").write('{"output": [1]}'),
            "/output is not a JSON object"),
        "a case.json whose grid is a string": (
            lambda d: open(os.path.join(d, "case.json"), "w").write('{"output": {"grid": "21"}}'),
            "/output/grid is not two integers"),
        "a case.json whose grid is booleans": (
            lambda d: open(os.path.join(d, "case.json"), "w").write(
                '{"output": {"grid": [true, true]}}'), "/output/grid is not two integers"),
    }
    # Results of another database (session 38's red team): results.h5 names the date_utc of
    # the database the run read; another date than the database's is a defect of the run.
    import h5py
    fresh("a")
    with h5py.File(os.path.join(res, "a", "results.h5"), "w") as h:
        h.attrs["material_database_date_utc"] = "2026-12-01T10:00:00Z"
    with open(os.path.join(res, "a", "summary.txt"), "w") as f:
        f.write("status: completed\n")
    same = report.Data(res, "2026-12-01T10:00:00Z").run_defect("a")
    other = report.Data(res, "2026-12-05T12:00:00Z").run_defect("a")
    unknown = report.Data(res, None).run_defect("a")
    if same is not None or unknown is not None or other is None or "stale" not in other:
        out.append(f"stale results: same date {same!r}, another {other!r}, no date {unknown!r}")
    # A database without its date_utc (session 51's red team: every stale check was off).
    undated = report.Data(res, report.UNDATED).run_defect("a")
    if undated is None or "does not say when it was written" not in undated:
        out.append(f"stale results: a database without date_utc: {undated!r}")
    # UNDATED only for a file that opens without the attribute (the review of session 51: a
    # missing file was named "no date_utc attribute"); None where it cannot be read.
    no_date = os.path.join(res, "no_date.h5")
    with h5py.File(no_date, "w") as h:
        h.attrs["generator"] = "sweep"
    got = (report.database_date(no_date), report.database_date(os.path.join(res, "none.h5")),
           report.database_date(os.path.join(res, "a", "summary.txt")))
    if got != (report.UNDATED, None, None):
        out.append(f"database_date of a file without date_utc, a missing one, a text file: {got!r}")
    # The case the run was computed from (session 50's red team: another case's results.h5
    # copied in turned two FAILs into passes): results.h5's /case_json against the pipeline's
    # copy OUT/cases/NAME.json beside OUT/results.
    out_dir = os.path.join(tmp, "case_identity")
    results, cases = os.path.join(out_dir, "results"), os.path.join(out_dir, "cases")
    case = {"material": {"type": "knit", "stitch_value": 4.5}, "loads": [1.5]}
    for held, defect in ((case, None), (case | {"material": {"type": "knit", "stitch_value": 6.5}},
                                        "/material/stitch_value")):
        shutil.rmtree(out_dir, ignore_errors=True)
        os.makedirs(os.path.join(results, "a"))
        os.makedirs(cases)
        with open(os.path.join(cases, "a.json"), "w") as f:
            json.dump(case, f)
        with open(os.path.join(results, "a", "load_strain.csv"), "w") as f:
            f.write("step,strain,load_N\n1,0.1,2.0\n2,0.2,5.0\n")
        with open(os.path.join(results, "a.status"), "w") as f:
            json.dump({"case": "a", "exit_code": 0, "seconds": 0.1}, f)
        with open(os.path.join(results, "a", "summary.txt"), "w") as f:
            f.write("status: completed\n")
        with h5py.File(os.path.join(results, "a", "results.h5"), "w") as h:
            h.create_dataset("case_json", data=[json.dumps(held)], dtype=h5py.string_dtype())
        got = report.Data(results, None).run_defect("a")
        if defect is None and got is not None and "another case" in got:
            out.append(f"case identity: the pipeline's own case was taken for another ({got})")
        if defect is not None and (got is None or "computed from another case" not in got
                                   or defect not in got):
            out.append(f"case identity: results of another case were not refused ({got!r})")
    for what, (damage, needle) in variants.items():
        damage(fresh("a"))
        try:
            r = Result(res, "a")
        except Exception as e:  # noqa: BLE001 (the point: no exception at all)
            out.append(f"unusable results, {what}: {type(e).__name__}: {e}")
            continue
        if r.completed or r.ok or needle not in r.problem:
            out.append(f"unusable results, {what}: completed={r.completed}, problem "
                       f"{r.problem!r}")
    # The last run refused (exit 2: it wrote nothing): results/a is an earlier run's, not
    # taken (session 45's red team: a switched sweep input's refused runs were judged, drawn
    # and counted on the former database's results). Exit 1 (stopped early) wrote its steps.
    # Since the review of session 45 the status says whether the run wrote ("wrote"): exit 1
    # with nothing written (no load step converged) is not taken either.
    for code, taken, wrote in ((2, False, None), (3, False, None), (1, True, None),
                               (1, False, False), (0, True, True)):
        fresh("a")
        with open(os.path.join(res, "a.status"), "w") as f:
            json.dump({"case": "a", "exit_code": code, "seconds": 0.1}
                      | ({} if wrote is None else {"wrote": wrote}), f)
        r = Result(res, "a")
        if r.ok is not taken or (not taken and "earlier run's output" not in r.problem):
            out.append(f"refused last run, exit {code}: ok={r.ok}, problem {r.problem!r}")
    # ... and its log's error line, where the pipeline keeps it (OUT/logs/NAME.log beside
    # OUT/results; paper_law_NAME.log for results_paper_law).
    for sub, log in (("results", "a.log"), ("results_paper_law", "paper_law_a.log")):
        base = os.path.join(tmp, "pipeline_out_" + sub)
        d = os.path.join(base, sub)
        os.makedirs(os.path.join(d, "a"), exist_ok=True)
        os.makedirs(os.path.join(base, "logs"), exist_ok=True)
        with open(os.path.join(d, "a.status"), "w") as f:
            json.dump({"case": "a", "exit_code": 2, "wrote": False}, f)
        with open(os.path.join(base, "logs", log), "w") as f:
            f.write("knit-macro run: error: a.json: /material: 6.5 mm is outside\n")
        r = Result(d, "a")
        if "(knit-macro run: error: a.json: /material: 6.5 mm is outside)" not in r.problem:
            out.append(f"refused last run in {sub}: its log's error not quoted: {r.problem!r}")
    return out


def held_out_agreement_failures(tmp):
    """The held-out verdict against the stored law re-evaluated (session 36's red team: the
    diagnostics' attributes set to all within with h5py turned it to PASS while the sentence
    below it said otherwise). A law S = 2 e, 24 held-out runs (12 per loop length's record, one
    loop length) on the law; the stored figures say so (PASS); the same law with its stored
    count raised above the re-evaluation, or one state moved off the law with the stored count
    left at all within (FAIL, the disagreement said)."""
    import h5py
    out = []
    db = os.path.join(tmp, "agree.h5")

    def write(within=24, off=0.0):
        with h5py.File(db, "w") as f:
            f["loop_lengths"] = [5.0]
            law = linear_network_law(f, 2.0)
            d = law.create_group("diagnostics")
            d["loop_length"], d["rms_relative"], d["max_relative"] = [5.0], [0.01], [0.02]
            d.attrs["holdout_points"], d.attrs["holdout_within_5_percent"] = 24, within
            d.attrs["holdout_max_relative"] = 0.0
            raw_path(f, "path_00", "coverage", [[0, 0, 0], [5.0, 0, 0]], [[0, 0, 0], [10.0, 0, 0]])
            for q in range(24):
                e = 0.01 * (q + 1)
                raw_path(f, f"path_{q + 1:02d}", "holdout", [[e, 0, 0]],
                         [[2 * e + (off if q == 0 else 0.0), 0, 0]])

    def row():
        return report.law_checks(db, {})[2]

    write()
    if row()[3] is not True or "disagree" in row()[2]:
        out.append(f"held-out agreement: the law and its figures agree, got {row()}")
    write(within=24, off=1.0)  # one state 10 % of the range off; stored: all within
    r = row()
    if r[3] is not False or "gives 23 of 24: the stored figures disagree" not in r[2]:
        out.append(f"held-out agreement: stored 24 of 24, the law 23 of 24, got {r}")
    # Session 52's red team: one NaN in a held-out state stopped the re-evaluation, and the
    # stored figures (set to all within) passed. A law that cannot be re-evaluated fails.
    write()
    with h5py.File(db, "r+") as f:
        f["loop_0/raw/path_05/S"][0, 0] = float("nan")
    r = row()
    if r[3] is not False or "could not be re-evaluated" not in r[2]:
        out.append(f"held-out agreement: a NaN held-out state, stored all within, got {r}")
    return out


def run_extrapolation_failures(tmp):
    """report.run_extrapolation: the log's report, checked against the run's summary.txt and
    results.h5 @material_report (session 52's red team: summary.txt edited to 27 % extrapolated
    beside a log of 0 % passed). Agreeing reports give the log's; one that counts otherwise is a
    conflict beside the log's report, and the law's extrapolation row FAILs naming it."""
    import h5py
    out = []
    o = os.path.join(tmp, "extra_out")
    shutil.rmtree(o, ignore_errors=True)
    os.makedirs(os.path.join(o, "logs"))
    os.makedirs(os.path.join(o, "results", "a"))
    report_text = ("knit material (energy law): 1000 evaluations; 10 extrapolated (1 %, outside "
                   "the data strain box ...)\n  at converged states: 0 of 100 evaluations "
                   "extrapolated (0 %)\n")
    with open(os.path.join(o, "logs", "a.log"), "w") as f:
        f.write("step    1  load factor 1\n" + report_text)

    def summary(text):
        with open(os.path.join(o, "results", "a", "summary.txt"), "w") as f:
            f.write("status: completed\nmaterial report: " + text + "converged steps: 1\n")

    def h5(text):
        with h5py.File(os.path.join(o, "results", "a", "results.h5"), "w") as f:
            f.attrs["material_report"] = text

    ex, why = report.run_extrapolation(o, "a")
    if ex is None or ex[:2] != (1000, 10) or why is not None:
        out.append(f"run_extrapolation: the log alone: {ex}, {why}")
    summary(report_text)
    h5(report_text)
    ex, why = report.run_extrapolation(o, "a")
    if ex is None or ex[:2] != (1000, 10) or why is not None:
        out.append(f"run_extrapolation: three agreeing reports: {ex}, {why}")
    # The second red team of session 52 deleted the run's reports and edited the log alone.
    with open(os.path.join(o, "results", "a", "summary.txt"), "w") as f:
        f.write("status: completed\nconverged steps: 1\n")
    ex, why = report.run_extrapolation(o, "a")
    if why is None or "its summary.txt has no material report" not in why:
        out.append(f"run_extrapolation: a summary.txt without the report: {ex}, {why}")
    summary(report_text)
    for what, edit in (("summary.txt", summary), ("results.h5 @material_report", h5)):
        edit(report_text.replace("10 extrapolated (1 %", "300 extrapolated (30 %"))
        ex, why = report.run_extrapolation(o, "a")
        if ex is None or ex[:2] != (1000, 10) or why is None or \
                f"its {what} 300 of 1000" not in why:
            out.append(f"run_extrapolation: {what} of 30 %: {ex}, {why}")
        edit(report_text)
    return out


def consistency_failures(tmp):
    """A run's outputs that disagree with each other are a defect of the run (session 42's red
    team: a doubled strain column was judged at 60 %, step 10's fields copied into step 20 with
    its load factor left were judged at 30 %, a summary of 12 steps beside 20 CSV rows passed,
    and results.h5 without the database's date passed as this database's)."""
    import h5py
    sys.path.insert(0, os.path.join(ROOT, "scripts", "figures"))
    from results import Result
    out = []
    res = os.path.join(tmp, "consistency")

    def fresh(strain_scale=1.0, steps_line=2, last_lf="1", field_scale=1.0, date=True,
              corner=False, d1="1", strain1=None, rows=True, bcs=None, geometry=None):
        shutil.rmtree(res, ignore_errors=True)
        d = os.path.join(res, "a")
        os.makedirs(d)
        with open(os.path.join(d, "load_strain.csv"), "w") as f:  # 2 mm over L = 20 mm at lf 1
            f.write("step,load_factor,applied_displacement_mm,strain,load_N\n")
            if rows:
                e1 = 0.05 * strain_scale if strain1 is None else strain1
                f.write(f"1,0.5,{d1},{e1},2.0\n2,1,2,{0.1 * strain_scale},5.0\n")
        with open(os.path.join(d, "case.json"), "w") as f:
            json.dump({"material": {"type": "knit"}, "output": {"grid": [3, 3],
                       "applied_displacement": {"corner" if corner else "edge":
                                                "u1v1" if corner else "v1",
                                                "component": "y", "gauge_length": 20}},
                       **({} if bcs is None else {"boundary_conditions": bcs}),
                       **({} if geometry is None else {"geometry": geometry})}, f)
        with open(os.path.join(d, "summary.txt"), "w") as f:
            f.write(f"status: completed\nconverged steps: {steps_line}\n"
                    f"last load factor: {last_lf}\n")
        with open(os.path.join(res, "a.status"), "w") as f:
            json.dump({"case": "a", "exit_code": 0, "seconds": 0.1}, f)
        with h5py.File(os.path.join(d, "results.h5"), "w") as h:
            if date:
                h.attrs["material_database_date_utc"] = "2026-12-01T10:00:00Z"
            g = h.create_group("fields/step_0002")
            g.attrs["grid_u"], g.attrs["grid_v"], g.attrs["load_factor"] = 3, 3, 1.0
            u = np.zeros((3, 3, 3))
            u[:, :, 1] = np.linspace(0.0, 2.0, 3)[:, None] * field_scale  # v1 (last row): 2 mm
            g["displacement"] = u.reshape(-1, 3)
            g["x"] = u.reshape(-1, 3)
            if geometry is not None:  # as knit-macro writes them: X the patch, x = X + u
                X = QUARTER_X.reshape(-1, 3)
                g["X"], g["x"][...] = X, X + u.reshape(-1, 3)
                g = h.create_group("fields/step_0001")
                g.attrs["grid_u"], g.attrs["grid_v"], g.attrs["load_factor"] = 3, 3, 0.5
                g["X"], g["x"] = X, X + 0.5 * u.reshape(-1, 3)
                g["displacement"] = 0.5 * u.reshape(-1, 3)
        return Result(res, "a")

    # The case's patch for the reference grid's checks: a quarter cylinder of radius 20 mm
    # (rational quadratic in u, weights 1, 1/sqrt(2), 1) and height 10 mm (linear in v), whose
    # 3 x 3 grid samples are known: angles 0, 45 and 90 degrees at z = 0, 5, 10.
    from results import nurbs_on_grid
    c = 1 / SQ2
    QUARTER = {"degrees": [2, 1], "knots_u": [0, 0, 0, 1, 1, 1], "knots_v": [0, 0, 1, 1],
               "control_points": [[20, 0, 0], [20, 20, 0], [0, 20, 0],
                                  [20, 0, 10], [20, 20, 10], [0, 20, 10]],
               "weights": [1, c, 1, 1, c, 1], "thickness": 0.76}
    QUARTER_X = np.array([[[20 * math.cos(a), 20 * math.sin(a), z]
                           for a in (0.0, math.pi / 4, math.pi / 2)] for z in (0.0, 5.0, 10.0)])
    # The evaluator itself (Cox-de Boor with weights): the bilinear square is its grid, the
    # quarter circle's samples lie on the circle (its midpoint at 45 degrees).
    S = nurbs_on_grid(SQUARE, 5, 3)
    sq = np.stack(np.meshgrid(np.linspace(0, L, 5), np.linspace(0, L, 3)) + [np.zeros((3, 5))],
                  -1)
    if S is None or np.max(np.abs(S - sq)) > 1e-12:
        out.append(f"nurbs_on_grid: the bilinear square is not its grid: {S}")
    S = nurbs_on_grid(QUARTER, 9, 3)
    if S is None or np.max(np.abs(np.hypot(S[..., 0], S[..., 1]) - 20.0)) > 1e-12 \
            or np.max(np.abs(S[:, ::4] - QUARTER_X)) > 1e-12:
        out.append(f"nurbs_on_grid: the quarter circle is off its circle: {S}")

    if fresh(corner=True).consistency_defect() is not None:
        out.append("consistency: a consistent corner-loaded run has a defect")
    if fresh().consistency_defect() is not None:
        out.append(f"consistency: a consistent run has a defect: {fresh().consistency_defect()!r}")
    for what, kw, needle in [
            ("a doubled strain column", dict(strain_scale=2.0),
             "strain 0.1 is not the applied displacement 1 mm over the gauge length 20 mm"),
            ("a summary of fewer steps", dict(steps_line=1),
             "summary.txt says 1 converged steps, load_strain.csv has 2 rows"),
            ("a summary of another last load factor", dict(last_lf="0.6"),
             "summary.txt says last load factor 0.6"),
            ("fields of half the load", dict(field_scale=0.5),
             "the displacement of v1 along y is up to 1 mm off the applied displacement 2 mm"),
            # the review of session 42: corners, proportionality, NaN and an empty CSV
            ("a corner's fields of half the load", dict(field_scale=0.5, corner=True),
             "the displacement of u1v1 along y is up to 1 mm off the applied displacement 2 mm"),
            ("a displacement not proportional to the load factor", dict(d1="1.5", strain1=0.075),
             "applied displacement 1.5 mm at load factor 0.5 is not proportional"),
            ("a NaN strain", dict(strain1=float("nan")), "holds a non-finite"),
            ("a summary of steps beside an empty CSV", dict(rows=False),
             "summary.txt says 2 converged steps, load_strain.csv has 0 rows")]:
        why = fresh(**kw).consistency_defect()
        if why is None or needle not in why:
            out.append(f"consistency, {what}: {why!r}")
    fresh(date=False)
    why = report.Data(res, "2026-12-01T10:00:00Z").run_defect("a")
    if why is None or "does not say which database it read" not in why:
        out.append(f"consistency, results without the database's date: {why!r}")
    if report.Data(res, None).run_defect("a") is not None:  # no database date to compare with
        out.append("consistency: a run without a date is a defect without a database date")
    fresh()
    why = report.Data(res, "2026-12-01T10:00:00Z").run_defect("a")
    if why is not None:
        out.append(f"consistency: a consistent run with its database's date: {why!r}")
    # The summary's count of completed cases leaves a defective run out ("26 of 26 cases
    # completed" beside a run whose every check FAILed).
    if report.completed_runs(["a"], report.Data(res, "2026-12-01T10:00:00Z")) != ["a"]:
        out.append("consistency: a consistent run is not counted as completed")
    fresh(strain_scale=2.0)
    if report.completed_runs(["a"], report.Data(res, "2026-12-01T10:00:00Z")) != []:
        out.append("consistency: a defective run is counted as completed")
    # Session 50's red team: summary.txt deleted and the CSV cut to half its rows counted as
    # completed; results.h5's /steps holds the run's converged steps.
    r = fresh()
    os.remove(os.path.join(res, "a", "summary.txt"))
    why = r.consistency_defect()
    if why is None or "its summary.txt is missing" not in why:
        out.append(f"consistency, no summary.txt: {why!r}")
    for steps, defect in (([0.5, 1.0], False), ([0.5, 1.0, 1.5], True), ([0.25, 1.0], True)):
        r = fresh()
        with h5py.File(os.path.join(res, "a", "results.h5"), "a") as h:
            h["steps/load_factor"] = np.asarray(steps)
        why = r.consistency_defect()
        if (why is not None) != defect or (defect and "results.h5 /steps holds" not in why):
            out.append(f"consistency, results.h5 /steps {steps} beside the CSV's [0.5, 1]: {why!r}")
    # Session 52's red team: the CSV's load column halved passed "much stiffer"; results.h5's
    # /steps holds the loads, strains and displacements too. The CSV's (2, 5 N; 0.05, 0.1; 1,
    # 2 mm) pass, and each of them changed in one row is named.
    for what, loads, strain, disp, needle in [
            ("the CSV's own figures", [2.0, 5.0], [0.05, 0.1], [1.0, 2.0], None),
            ("a load halved", [2.0, 10.0], [0.05, 0.1], [1.0, 2.0],
             "column load_N row 2 is not results.h5 /steps/reactions/load (5 against 10)"),
            ("another strain", [2.0, 5.0], [0.05, 0.12], [1.0, 2.0],
             "column strain row 2 is not results.h5 /steps/strain"),
            ("another displacement", [2.0, 5.0], [0.05, 0.1], [1.2, 2.0],
             "column applied_displacement_mm row 1 is not results.h5 /steps/applied_displacement"),
            ("one load more", [2.0, 5.0, 6.0], [0.05, 0.1], [1.0, 2.0],
             "column load_N row 3 is not results.h5 /steps/reactions/load (2 rows against 3)")]:
        r = fresh()
        with h5py.File(os.path.join(res, "a", "results.h5"), "a") as h:
            h["steps/load_factor"] = np.asarray([0.5, 1.0])
            h["steps/reactions/load"] = np.asarray(loads)
            h["steps/strain"] = np.asarray(strain)
            h["steps/applied_displacement"] = np.asarray(disp)
        why = r.consistency_defect()
        if (why is None) != (needle is None) or (needle and needle not in why):
            out.append(f"consistency, results.h5 /steps with {what}: {why!r}")
    # Session 52's red team: E22 scaled by 0.8 in results.h5, the displacements left, passed.
    # The interior's membrane strains must be those of the stored deformation: a 21 x 21 grid of
    # a 20 x 10 mm patch stretched by 1.1 along y and 0.95 along x and sheared by 0.05 (E11 =
    # (0.95^2 - 1)/2, E22 = (1.1^2 + 0.05^2 - 1)/2, E12 = 0.95 * 0.05 / 2), once as is, once with
    # E22 scaled by 0.8, once with one edge sample changed (judged since session 53: the
    # red team's raised edge sample moved "max E22 at central boundaries").
    for what, scale, edge, needle in [("the strains of its deformation", 1.0, False, None),
                                      ("E22 scaled by 0.8", 0.8, False, "E22 at X = ("),
                                      ("an edge sample changed", 1.0, True, "E22 at X = (0, 0, 0)")]:
        r = fresh()
        nu = nv = 21
        u, v = np.meshgrid(np.linspace(0, 20, nu), np.linspace(0, 10, nv))
        X = np.stack([u, v, 0 * u], -1)
        x = np.stack([0.95 * u + 0.05 * v, 1.1 * v, 0 * u], -1)
        E11, E22, E12 = (0.95 ** 2 - 1) / 2, (1.1 ** 2 + 0.05 ** 2 - 1) / 2, 0.95 * 0.05 / 2
        with h5py.File(os.path.join(res, "a", "results.h5"), "a") as h:
            g = h.create_group("fields/step_0001")
            g.attrs["grid_u"], g.attrs["grid_v"], g.attrs["load_factor"] = nu, nv, 0.5
            g["x"], g["displacement"] = x.reshape(-1, 3), (x - X).reshape(-1, 3)
            g["E11"], g["E12"] = np.full(nu * nv, E11), np.full(nu * nv, E12)
            e22 = np.full(nu * nv, E22 * scale)
            if edge:
                e22[0] = 0.5
            g["E22"] = e22
        why = r._strain_field_defect()
        if (why is None) != (needle is None) or (needle and needle not in why):
            out.append(f"consistency, strain fields with {what}: {why!r}")
    # Session 53: the edges are judged with one-sided differences of orders 4 and 3; a smooth
    # deformation that is not affine (cubic in u, quadratic in v) with its exact strains
    # passes, edges included (its largest strain about 0.5), and the same with one sample of the
    # edge row v = 10 raised by 0.02 (the bound there about 0.005) does not.
    for what, raise_edge, needle in [("a cubic deformation's exact strains", False, None),
                                     ("an edge sample of it raised by 0.02", True,
                                      "E11 at X = (10, 10, 0)")]:
        r = fresh()
        n = 21
        u, v = np.meshgrid(np.linspace(0, 20, n), np.linspace(0, 10, n))
        X = np.stack([u, v, 0 * u], -1)
        x = np.stack([u + u ** 3 / 4000.0, v + u * v ** 2 / 1000.0, 0 * u], -1)
        xu, xv = 1 + 3 * u ** 2 / 4000.0, 0 * u  # dx/du, dx/dv
        yu, yv = v ** 2 / 1000.0, 1 + 2 * u * v / 1000.0  # dy/du, dy/dv
        e11 = 0.5 * (xu ** 2 + yu ** 2 - 1)
        e22 = 0.5 * (xv ** 2 + yv ** 2 - 1)
        e12 = 0.5 * (xu * xv + yu * yv)
        if raise_edge:
            e11[-1, n // 2] += 0.02
        with h5py.File(os.path.join(res, "a", "results.h5"), "a") as h:
            g = h.create_group("fields/step_0001")
            g.attrs["grid_u"], g.attrs["grid_v"], g.attrs["load_factor"] = n, n, 0.5
            g["x"], g["displacement"] = x.reshape(-1, 3), (x - X).reshape(-1, 3)
            g["E11"], g["E22"], g["E12"] = e11.ravel(), e22.ravel(), e12.ravel()
        why = r._strain_field_defect()
        if (why is None) != (needle is None) or (needle and needle not in why):
            out.append(f"consistency, strain fields with {what}: {why!r}")
    # The second red team of session 52: an outlier of 50 at a corner sample (where the bound
    # took its scale) hid E22 x 1.25 in the top rows; without grid_u the check was off. Both
    # are named now; a 9 x 9 grid (coarser than STRAIN_FIELD_MIN_GRID) is not judged.
    for what, outlier, drop_grid, n, needle in [
            ("an outlier beside E22 x 1.25 on top", True, False, 21, "E22 at X = ("),
            ("no grid attributes (the case's /output/grid [3, 3] is not this grid)", False,
             True, 21, "cannot be checked against its deformation"),
            ("a 9 x 9 grid with E22 x 1.25 on top", False, False, 9, None)]:
        r = fresh()
        u, v = np.meshgrid(np.linspace(0, 20, n), np.linspace(0, 10, n))
        X = np.stack([u, v, 0 * u], -1)
        x = np.stack([0.95 * u + 0.05 * v, 1.1 * v, 0 * u], -1)
        e22 = np.full((n, n), (1.1 ** 2 + 0.05 ** 2 - 1) / 2)
        e22[n // 2:] *= 1.25
        e12 = np.full((n, n), 0.95 * 0.05 / 2)
        if outlier:
            e12[0, 0] = 50.0
        with h5py.File(os.path.join(res, "a", "results.h5"), "a") as h:
            g = h.create_group("fields/step_0001")
            if not drop_grid:
                g.attrs["grid_u"], g.attrs["grid_v"] = n, n
            g.attrs["load_factor"] = 0.5
            g["x"], g["displacement"] = x.reshape(-1, 3), (x - X).reshape(-1, 3)
            g["E11"], g["E22"], g["E12"] = (np.full(n * n, (0.95 ** 2 - 1) / 2), e22.ravel(),
                                            e12.ravel())
        why = r._strain_field_defect()
        if (why is None) != (needle is None) or (needle and needle not in why):
            out.append(f"consistency, strain fields with {what}: {why!r}")
    # Session 55's red team: the held edge v0 of s312_uniform_45_wale slipped along y by 30 % of
    # the applied displacement in results.h5 (x and the strain fields changed to match) and
    # every run check passed. The fixture's field (u_y 0, 1, 2 mm on the rows v0, middle, v1;
    # u_x = u_z = 0) keeps the wale test's conditions; each change of a held or prescribed
    # component is named with its target and component, and a change below the tolerance
    # (1e-6 x max(1, 2 mm)) or of a free component is not a defect.
    wale = [{"all": True, "fix": ["z"]}, {"edge": "v0", "fix": ["x", "y"]},
            {"edge": "v1", "fix": ["x"], "prescribe": {"y": 2.0}}]
    corner = [{"point": [0, 0], "fix": ["x", "y", "z"]}, {"corner": "u1v1", "radius": 5.0,
                                                          "prescribe": {"x": 0.5, "y": 2.0}}]
    sym = [{"edge": "u0", "symmetry": "x", "clamp": True}]
    v0, mid, u0 = (0, slice(None)), (1, 1), (slice(None), 0)
    for what, bcs, moves, needle in [
            ("the wale test's conditions kept", wale, [], None),
            ("v0 slipped along y by 30 % of the applied 2 mm", wale, [(v0, 1, 0.6)],
             "step_0002: the displacement of v0 along y is up to 0.6 mm off 0 mm at which "
             "/boundary_conditions/1 holds it"),
            ("v0 slipped along x", wale, [(v0, 0, -0.01)],
             "the displacement of v0 along x is up to 0.01 mm off 0 mm"),
            ("v0 slipped by 1e-9 mm (round-off)", wale, [(v0, 1, 1e-9)], None),
            ("the middle sample lifted out of the plane", wale, [(mid, 2, 0.1)],
             "the displacement of every sample along z is up to 0.1 mm off 0 mm at which "
             "/boundary_conditions/0 holds it"),
            ("the middle sample moved along x (free there)", wale, [(mid, 0, 0.1)], None),
            ("a corner pad's prescribed x kept", corner, [((-1, -1), 0, 0.5)], None),
            ("a corner pad's prescribed x missed", corner, [((-1, -1), 0, 0.7)],
             "the displacement of u1v1 along x is up to 0.2 mm off the 0.5 mm "
             "/boundary_conditions/1 prescribes at load factor 1"),
            ("the corner point [0, 0] moved", corner, [((-1, -1), 0, 0.5), ((0, 0), 2, 0.05)],
             "the displacement of u0v0 along z is up to 0.05 mm off 0 mm"),
            ("a symmetry plane's edge moved along its normal", sym, [(u0, 0, 0.3)],
             "the displacement of u0 along x is up to 0.3 mm off 0 mm")]:
        r = fresh(bcs=bcs)
        with h5py.File(os.path.join(res, "a", "results.h5"), "a") as h:
            g = h["fields/step_0002"]
            u = np.asarray(g["displacement"]).reshape(3, 3, 3)
            for where, comp, by in moves:
                u[where + (comp,)] += by
            g["displacement"][...] = u.reshape(-1, 3)
            g["x"][...] = u.reshape(-1, 3)  # X = 0 here: x moves with it
        why = r.consistency_defect()
        if (why is None) != (needle is None) or (needle and needle not in why):
            out.append(f"consistency, boundary conditions with {what}: {why!r}")
    # ... and such a run is no data to the report (Data.run_defect).
    fresh(bcs=wale)
    with h5py.File(os.path.join(res, "a", "results.h5"), "a") as h:
        g = h["fields/step_0002"]
        u = np.asarray(g["displacement"]).reshape(3, 3, 3)
        u[0, :, 1] += 0.6
        g["displacement"][...] = u.reshape(-1, 3)
    why = report.Data(res, "2026-12-01T10:00:00Z").run_defect("a")
    if why is None or "off 0 mm at which /boundary_conditions/1 holds it" not in why:
        out.append(f"consistency, a slipped held edge through run_defect: {why!r}")
    # Session 55: nothing checked x = X + displacement or X itself; x (and the strain fields
    # that the strain check derives from x and X) moved with the displacement left would pass
    # the boundary-condition check, which reads the displacement. Outputs as knit-macro writes
    # them (X the case's patch, the same at both steps, x = X + displacement) pass, also moved
    # by round-off; x moved alone, X moved at one step, X off the case's patch at every step
    # and, without a stored X, x moved alone at one or at every step are named.
    mid = 4  # the middle sample (theta1, theta2) = (1/2, 1/2)

    def move(h, steps, names, by=0.3, comp=0):
        for st in steps:
            g = h[f"fields/step_{st:04d}"]
            for n in names:
                v = np.asarray(g[n])
                v[mid, comp] += by
                g[n][...] = v

    def drop_X(h):
        for st in (1, 2):
            del h[f"fields/step_{st:04d}/X"]

    def short_X(h):  # step 1's X of 4 samples beside x and displacement of 9
        del h["fields/step_0001/X"]
        h["fields/step_0001/X"] = np.zeros((4, 3))
    at_mid = "at (theta1, theta2) = (1/2, 1/2)"
    for what, change, needle in [
            ("as written", lambda h: None, None),
            ("x moved by round-off", lambda h: move(h, (2,), ["x"], by=1e-9), None),
            ("x and X moved by round-off", lambda h: move(h, (1, 2), ["x", "X"], by=1e-9), None),
            ("x moved, the displacement left", lambda h: move(h, (2,), ["x"]),
             f"results.h5 step_0002: x - X is 0.3 mm off its displacement {at_mid}"),
            ("x and X moved at one step", lambda h: move(h, (2,), ["x", "X"]),
             f"results.h5 step_0002: its reference grid (X) is 0.3 mm off step_0001's {at_mid}"),
            ("x and X moved at every step", lambda h: move(h, (1, 2), ["x", "X"], comp=2),
             "results.h5 step_0001: its reference grid (X) is 0.3 mm off the case's /geometry "
             f"(its NURBS patch) {at_mid}"),
            ("no X, x moved at one step", lambda h: (drop_X(h), move(h, (2,), ["x"])),
             "results.h5 step_0002: its reference grid (x - displacement) is 0.3 mm off "
             f"step_0001's {at_mid}"),
            ("no X, x moved at every step", lambda h: (drop_X(h), move(h, (1, 2), ["x"])),
             "results.h5 step_0001: its reference grid (x - displacement) is 0.3 mm off the "
             "case's /geometry"),
            ("X of another grid", short_X,
             "results.h5 step_0001: its reference grid cannot be checked (ValueError: x 9, X 4, "
             "displacement 9 samples on a 3 x 3 grid)")]:
        r = fresh(geometry=QUARTER)
        with h5py.File(os.path.join(res, "a", "results.h5"), "a") as h:
            change(h)
        why = r.consistency_defect()
        if (why is None) != (needle is None) or (needle and needle not in why):
            out.append(f"consistency, reference grid with {what}: {why!r}")
    # Fine grids are compared with the patch on a sub-grid that keeps both ends (the review of
    # session 55: the pure-Python evaluator would take a minute at 1001 x 1001): the strides,
    # and at most 2 samples per direction (the corners) the middle sample moved at every step
    # is not seen by the patch comparison, a corner is, named at its place in the full grid.
    import results
    strides = [results.grid_stride(n) for n in (41, 101, 102, 201, 1001)]
    if strides != [1, 1, 101, 2, 10]:
        out.append(f"grid_stride of 41, 101, 102, 201, 1001: {strides}")
    kept = results.NURBS_CHECK_SAMPLES
    try:
        results.NURBS_CHECK_SAMPLES = 2
        for sample, needle in ((mid, None), (8, "(its NURBS patch) at (theta1, theta2) = (2/2, 2/2)")):
            r = fresh(geometry=QUARTER)
            with h5py.File(os.path.join(res, "a", "results.h5"), "a") as h:
                for st in (1, 2):
                    g = h[f"fields/step_{st:04d}"]
                    for n in ("x", "X"):
                        v = np.asarray(g[n])
                        v[sample, 2] += 0.3
                        g[n][...] = v
            why = r.consistency_defect()
            if (why is None) != (needle is None) or (needle and needle not in why):
                out.append(f"consistency, the patch on a 2 x 2 sub-grid, sample {sample} moved: "
                           f"{why!r}")
    finally:
        results.NURBS_CHECK_SAMPLES = kept
    # ... another patch in the case (radius 20.3 mm), and a moved x through run_defect.
    fresh(geometry=dict(QUARTER, control_points=[[p * 1.015 for p in q[:2]] + [q[2]]
                                                 for q in QUARTER["control_points"]]))
    why = report.Data(res, "2026-12-01T10:00:00Z").run_defect("a")
    if why is None or "its reference grid (X) is 0.3 mm off the case's /geometry" not in why:
        out.append(f"consistency, X off another case's patch through run_defect: {why!r}")
    fresh(geometry=QUARTER)
    why = report.Data(res, "2026-12-01T10:00:00Z").run_defect("a")
    if why is not None:
        out.append(f"consistency: an untouched run with its patch through run_defect: {why!r}")
    with h5py.File(os.path.join(res, "a", "results.h5"), "a") as h:
        move(h, (2,), ["x"])
    why = report.Data(res, "2026-12-01T10:00:00Z").run_defect("a")
    if why is None or "x - X is 0.3 mm off its displacement" not in why:
        out.append(f"consistency, x moved alone through run_defect: {why!r}")
    # Session 52's red team: results.h5 @units "m, kN, GPa", and a database whose units, format
    # or format_version are not ours, changed no verdict. A run states mm, N, MPa or is no data;
    # a database that states other units, format or version makes every knit run no data and
    # the law's table one FAIL row.
    r = fresh()
    date = "2026-12-01T10:00:00Z"
    with h5py.File(os.path.join(res, "a", "results.h5"), "a") as h:
        h.attrs["units"] = "mm, N, MPa"
    why = report.Data(res, date).run_defect("a")
    if why is not None:
        out.append(f"consistency: a run in mm, N, MPa has a defect: {why!r}")
    with h5py.File(os.path.join(res, "a", "results.h5"), "a") as h:
        h.attrs["units"] = "m, kN, GPa"
    why = report.Data(res, date).run_defect("a")
    if why is None or "states units 'm, kN, GPa'" not in why:
        out.append(f"consistency: a run in m, kN, GPa: {why!r}")
    fresh()
    dbf = os.path.join(tmp, "identity.h5")
    for attr, value, needle in [(None, None, None),
                                ("units", "length m, force kN, stress GPa", "its units are"),
                                ("format", "not-a-knitscale-db", "its format is"),
                                ("format_version", 99, "its format_version is 99")]:
        with h5py.File(dbf, "w") as f:
            f.attrs["format"] = report.DATABASE_FORMAT
            f.attrs["format_version"] = 3
            f.attrs["units"] = report.DATABASE_UNITS
            if attr:
                f.attrs[attr] = value
        why = report.database_identity_defect(dbf)
        if (why is None) != (needle is None) or (needle and needle not in why):
            out.append(f"database identity, {attr} = {value!r}: {why!r}")
        rd = report.Data(res, date, None, why).run_defect("a")
        if (rd is None) != (needle is None):
            out.append(f"database identity, {attr} = {value!r}: the knit run's defect {rd!r}")
        rows = report.law_checks(dbf, {})
        if needle and (len(rows) != 1 or rows[0][3] is not False or needle not in rows[0][2]):
            out.append(f"database identity, {attr} = {value!r}: the law's rows {rows}")
    # Session 52's red team: a paper-law run and its case copied into OUT/results and OUT/cases
    # were judged as the default law's. The pipeline's copy must be the checkout's case with
    # only /material/database set.
    src = os.path.join(tmp, "consistency_src")
    os.makedirs(src, exist_ok=True)
    copy = os.path.join(tmp, "consistency_copy.json")
    case = {"material": {"type": "knit", "database": "../database.h5", "stitch_value": 5.0}}
    with open(os.path.join(src, "a.json"), "w") as f:
        json.dump(case, f)
    for what, change, needle in [
            ("another database path", {"database": "elsewhere.h5"}, None),
            ("the paper's law", {"law": "paper"}, "they differ at /material/law"),
            ("another stitch value", {"stitch_value": 5.5}, "they differ at /material/stitch_value")]:
        with open(copy, "w") as f:
            json.dump({"material": dict(case["material"], **change)}, f)
        why = report.copy_defect(copy, os.path.join(src, "a.json"))
        if (why is None) != (needle is None) or (needle and needle not in why):
            out.append(f"consistency, the pipeline's copy with {what}: {why!r}")
    # The second red team of session 52 deleted the copy: missing from a directory of copies it
    # is a defect; an output without such a directory is not judged by it.
    os.remove(copy)
    why = report.copy_defect(copy, os.path.join(src, "a.json"))
    if why is None or "is missing" not in why:
        out.append(f"consistency, the pipeline's copy deleted: {why!r}")
    if report.copy_defect(os.path.join(tmp, "no_such_dir", "a.json"),
                          os.path.join(src, "a.json")) is not None:
        out.append("consistency: an output without copies is judged by copy_defect")
    # ... through Data.run_defect: OUT/cases/a.json beside OUT/results, cases_src the checkout.
    out_dir = os.path.join(tmp, "consistency_out")
    shutil.rmtree(out_dir, ignore_errors=True)
    r = fresh()
    with h5py.File(os.path.join(res, "a", "results.h5"), "a") as h:
        h["case_json"] = json.dumps(r.case)
    shutil.copytree(res, os.path.join(out_dir, "results"))
    os.makedirs(os.path.join(out_dir, "cases"))
    with open(os.path.join(out_dir, "cases", "a.json"), "w") as f:
        json.dump(r.case, f)  # the run's own case: case_defect agrees
    with open(os.path.join(src, "a.json"), "w") as f:
        json.dump(r.case, f)
    date = "2026-12-01T10:00:00Z"
    why = report.Data(os.path.join(out_dir, "results"), date, src).run_defect("a")
    if why is not None:
        out.append(f"consistency: a run whose case is the checkout's has a defect: {why!r}")
    with open(os.path.join(src, "a.json"), "w") as f:
        json.dump(dict(r.case, material={"type": "knit", "law": "energy"}), f)
    why = report.Data(os.path.join(out_dir, "results"), date, src).run_defect("a")
    if why is None or "is not the checkout's" not in why:
        out.append(f"consistency: a run whose case is not the checkout's: {why!r}")
    return out


def main():
    failures = []
    tmp = tempfile.mkdtemp(prefix="knit_report_test_")
    try:
        # -- baseline: every check passes, each with its threshold and number printed ----------
        rep, base = verdicts(baseline(), tmp)
        judged = {k for k, c in base.items() if c.ok is not None}
        for k, c in base.items():
            if not c.threshold or not c.measured:
                failures.append(f"baseline: {k} prints no threshold or number")
            if c.ok is False:
                failures.append(f"baseline: {k} fails: {c.measured} ({c.threshold})")
        expected_keys = set(REACH) | set(MONO) | {
            "e22bound:45:0.2", "e22bound:45:0.3", "e22bound:65:0.2", "e22bound:65:0.3",
            "e22value:45", "e22value:65", "e22where:45", "e22where:65", "stiffer:course",
            "stiffer:wale", "uniform312", "conv7c", "e11right313", "uniform313", "conv9e",
            "larger314", "uniform314", "notstiff321", "mirror321", "sym321", "mesh321",
            "alpha322"} | {f"stiffening:{n}" for n in report.STIFFENING}
        if judged != expected_keys:
            failures.append(f"check keys changed: missing {sorted(expected_keys - judged)}, "
                            f"new {sorted(judged - expected_keys)} (give them a failing variant)")
        # the report renders, and its summary counts what the table shows
        rep.write(os.path.join(tmp, "no-database.h5"), "")
        text = open(os.path.join(tmp, "report.md")).read()
        # the paper's statements apart from the runs' own checks (session 50's red team)
        runs = {k for k in judged if k.startswith(("reach:", "monotone:", "e22bound:"))}
        n_paper, n_runs = len(judged) - len(runs), len(runs)
        summary = (f"**Summary:** {n_paper} of {n_paper} checks of the paper's statements pass, "
                   f"0 fail")
        if summary not in text or f"; {n_runs} of {n_runs} checks of the runs themselves pass" \
                not in text:
            failures.append(f"summary line: '{summary}' (and {n_runs} run checks) not in the "
                            "report")
        # --strict judges the runs (session 54): nothing to say on the baseline.
        if rep.strict_problems():
            failures.append(f"--strict on the baseline: {rep.strict_problems()}")
        if "Not yet measured" not in text:
            failures.append("no sensitivity table: the report must say 'Not yet measured'")
        # A figure script that failed leaves a placeholder dated 1970 (batch.py): the report
        # says so in its summary and above the figure (session 38's red team: embedded as if
        # drawn); a drawn figure gets no such note.
        figs = os.path.join(tmp, "figures")
        os.makedirs(figs, exist_ok=True)
        for name, failed in (("fig_drawn", False), ("fig_failed", True)):
            write_tiny_png(os.path.join(figs, name + ".png"))
            if failed:
                os.utime(os.path.join(figs, name + ".png"), (0, 0))
        rep.write(os.path.join(tmp, "no-database.h5"), "")
        text = open(os.path.join(tmp, "report.md")).read()
        if ("1 figure script(s) FAILED (placeholders)" not in text
                or "**1 figure script(s) failed** (placeholders below): fig_failed." not in text
                or text.count("**The figure script failed**") != 1):
            failures.append("a failed figure's placeholder is not named in the report")
        if rep.strict_problems() != ["1 figure scripts failed (placeholders)"]:
            failures.append(f"--strict with a failed figure: {rep.strict_problems()}")
        # A figure file that is not a complete PNG image is named, above it and in the summary,
        # and --strict fails on it (session 55's red team: empty, text and cut-short files were
        # embedded as drawn, exit 0); a complete one (fig_drawn) is not.
        drawn = os.path.join(figs, "fig_drawn.png")
        whole = open(drawn, "rb").read()
        for content, why in ((b"", "an empty file"), (b"not an image", "not a PNG image"),
                             (whole[:-12], "a PNG cut short (no end chunk)"),
                             (whole[:8] + whole[8:12] + b"IHDR" + bytes(8) + whole[24:],
                              "a PNG without an image header")):
            with open(drawn, "wb") as f:
                f.write(content)
            rep.write(os.path.join(tmp, "no-database.h5"), "")
            text = open(os.path.join(tmp, "report.md")).read()
            if ("1 figure(s) DAMAGED (not complete PNG images: fig_drawn)" not in text
                    or f"**The figure file is damaged**: {why}; draw it again." not in text
                    or "1 figures damaged (not complete PNG images)" not in rep.strict_problems()):
                failures.append(f"a damaged figure ({why}) is not named: "
                                f"{rep.strict_problems()}")
        write_tiny_png(drawn)
        # ... and a failing check of a run is one (a row's verdict turned, then restored).
        row = next(c for c in rep.rows if report.is_run_check(c) and c.ok is True)
        row.ok = False
        rep.write(os.path.join(tmp, "no-database.h5"), "")
        if "1 checks of the runs themselves fail" not in rep.strict_problems():
            failures.append(f"--strict with a failing run check: {rep.strict_problems()}")
        row.ok = True
        # A figure the pipeline draws that is not there is named (session 38's red team: its
        # section vanished without a word).
        rep.expected_figures = ["fig_drawn.png", "fig_failed.png", "fig_gone.png"]
        rep.write(os.path.join(tmp, "no-database.h5"), "")
        text = open(os.path.join(tmp, "report.md")).read()
        if ("1 figure(s) MISSING" not in text
                or "**1 figure(s) missing** (drawn by the pipeline, not in figures/): fig_gone."
                not in text):
            failures.append("a missing figure is not named in the report")
        rep.expected_figures = []
        shutil.rmtree(figs)
        # A result deleted after a run of exit 0 is "result missing", not "failed (exit 0)"
        # (session 38's red team).
        victim = sorted(n for n in rep.names if rep.r(n).completed)[0]
        shutil.rmtree(os.path.join(tmp, "results", victim))
        rep2 = report.Report(tmp)
        rep2.checks()
        rep2.write(os.path.join(tmp, "no-database.h5"), "")
        text = open(os.path.join(tmp, "report.md")).read()
        if f"| {victim} | result missing (its status says exit 0) |" not in text:
            failures.append(f"a deleted result of exit 0 is not 'result missing' ({victim})")
        # -- variants: the known defect fails exactly the checks that read it ------------------
        failed_somewhere = set()
        for name, (mutate, must_fail, exact) in VARIANTS.items():
            runs = baseline()
            mutate(runs)
            rep, got = verdicts(runs, tmp)
            failed = {k for k, c in got.items() if c.ok is False}
            failed_somewhere |= failed
            if not must_fail <= failed:
                for k in sorted(must_fail - failed):
                    failures.append(f"{name}: {k} should FAIL, got " + (
                        f"pass: {got[k].measured}" if k in got else "no such check"))
            if exact and failed != must_fail:
                for k in sorted(failed - must_fail):
                    failures.append(f"{name}: {k} should pass, got FAIL: {got[k].measured}")
            if name == "3 % convergence gap with cut-backs":
                m = got["conv7c"].measured
                if not m.startswith("3.00 %"):
                    failures.append(f"{name}: conv7c measured {m}, expected 3.00 %")
            if name == "every run stops at half":
                text_ok = all("stopped at" in got[k].measured for k in
                              ("conv7c", "stiffer:wale", "mesh321"))
                if not text_ok:
                    failures.append(f"{name}: an early stop is not named in the verdict")
        never = judged - failed_somewhere
        if never:
            failures.append(f"checks no variant makes FAIL (vacuous?): {sorted(never)}")
        # -- the sensitivity table: read, drawn, reported -----------------------------------------
        table = os.path.join(tmp, "sensitivity.csv")
        with open(table, "w") as f:
            f.write("# synthetic\nparameter,value,observable,result\n")
            for g0 in (0.01, 0.02, 0.04):
                f.write(f"g0,{g0},max_E22_45_wale_30,{0.3 + g0}\n")
                f.write(f"g0,{g0},F45_over_F65_wale_30,{2 - g0}\n")
                f.write(f"g0,{g0},min_ratio_wale,{0.9 + g0}\n")
            for gam in (0.2, 0.25, 0.3):
                f.write(f"gamma,{gam},max_E22_45_wale_30,{0.35 + gam / 10}\n")
        from sensitivity import draw, read_table
        rows = read_table(table)
        if len(rows) != 12 or rows[0] != ("g0", 0.01, "max_E22_45_wale_30", 0.31):
            failures.append(f"sensitivity table read as {rows[:2]}")
        draw(rows, os.path.join(tmp, "figures", "sensitivity.png"))
        rep = report.Report(tmp, table)
        rep.checks()
        rep.write(os.path.join(tmp, "no-database.h5"), "")
        text = open(os.path.join(tmp, "report.md")).read()
        if "figures/sensitivity.png" not in text or "Not yet measured" in text:
            failures.append("a sensitivity table exists but the report does not show its figure")
        if "| g0 | 0.04 | 0.940 |" not in text:
            failures.append("the sensitivity section lacks the headline table (min_ratio_*)")
        with open(table, "w") as f:
            f.write("parameter,value,result\n")
        try:
            read_table(table)
            failures.append("a table with a wrong header was accepted")
        except ValueError:
            pass
        # -- the material law's checks (issue 11): each one made to fail ------------------------
        failures.extend(law_check_failures(tmp))
        failures.extend(near_visited_failures(tmp))
        failures.extend(outer_exp_failures(tmp))
        failures.extend(l_interpolation_failures(tmp))
        failures.extend(held_out_reference_failures(tmp))
        failures.extend(held_out_agreement_failures(tmp))
        failures.extend(unusable_result_failures(tmp))
        failures.extend(consistency_failures(tmp))
        failures.extend(run_extrapolation_failures(tmp))
        # -- the pure functions on arrays ---------------------------------------------------------
        e = np.array([0.0, 0.1, 0.15, 0.2, 0.3])
        if rc.largest_drop((e, np.array([0, 1, 2, 1.5, 3.0])))[0] != 0.5:
            failures.append("largest_drop")
        if not rc.reaches((np.array([0, -0.1, -0.1414213562]), np.zeros(3)), -SQ2 * 0.1):
            failures.append("reaches: compression to -14.1 % not recognised")
        if abs(rc.stretch_bound(0.3) - 0.345) > 1e-12 or abs(rc.stretch_bound(0.2) - 0.22) > 1e-12:
            failures.append("kinematic bound")
        # The runs' warnings (session 41): every `warning:` line of a summary, under its name.
        runs = {"a": "status: completed\nwarning: in uniaxial tension along the wale\n"
                     "warning: load drop: x | y\n", "b": "status: completed\n"}

        class _Summary:
            def __init__(self, text):
                self.text = text

            def summary(self):
                return self.text
        text = "\n".join(report.run_warnings(sorted(runs), lambda n: _Summary(runs[n])))
        if ("- `a`: in uniaxial tension along the wale" not in text
                or "- `a`: load drop: x \\| y" not in text or "`b`" in text):
            failures.append("run warnings: " + text[-300:])
        text = "\n".join(report.run_warnings(["b"], lambda n: _Summary(runs[n])))
        if "No run warned" not in text:
            failures.append("run warnings without any: " + text)
        # The knitting maps' section (session 39): totals and every warning of each summary.
        km = os.path.join(tmp, "km_out")
        text = "\n".join(report.knitmap_section(km))
        if "No knitting map was made" not in text:
            failures.append("knitmap section without maps: " + text[:200])
        os.makedirs(os.path.join(km, "knitmap", "patch"))
        with open(os.path.join(km, "knitmap", "patch", "summary.txt"), "w") as f:
            f.write("# provenance: {}\nstitches: 1547\nyarn_length_mm: 8306.5\nneedles: 40\n"
                    "courses: 41\nloop_length_min_mm: 4.5177\nloop_length_max_mm: 6.4432\n"
                    "warning: first one\nwarning: second one\n")
        text = "\n".join(report.knitmap_section(km))
        if "| patch | 1547 | 40 | 41 | 8.31 | 4.52-6.44 | first one; second one |" not in text:
            failures.append("knitmap section row: " + text[-300:])
        # A run that failed (its status file, session 45): said so with the log's error line,
        # and the earlier run's summary.txt left in knitmap/patch is not shown as its result.
        # A failed run without any map is listed too.
        os.makedirs(os.path.join(km, "logs"))
        with open(os.path.join(km, "knitmap", "patch.status"), "w") as f:
            f.write('{"knitmap": "patch", "exit_code": 2}\n')
        with open(os.path.join(km, "knitmap", "other.status"), "w") as f:
            f.write('{"knitmap": "other", "exit_code": 1}\n')
        with open(os.path.join(km, "logs", "knitmap_patch.log"), "w") as f:
            f.write("knit-macro knitmap: error: p.json: /material/stitch_value/values/2: 6.5 mm "
                    "is outside the database's 4.5-4.5 mm\n")
        text = "\n".join(report.knitmap_section(km))
        if ("| patch | - | - | - | - | - | **failed**: exit 2: knit-macro knitmap: error: p.json: "
                "/material/stitch_value/values/2: 6.5 mm is outside" not in text
                or "1547" in text or "| other | - | - | - | - | - | **failed**: exit 1 |" not in text):
            failures.append("knitmap section, failed runs: " + text[-600:])
        with open(os.path.join(km, "knitmap", "patch.status"), "w") as f:
            f.write('{"knitmap": "patch", "exit_code": 0}\n')
        text = "\n".join(report.knitmap_section(km))
        if "| patch | 1547 | 40 | 41 |" not in text:
            failures.append("knitmap section, a run that exited with 0: " + text[-300:])
        # The sweep input the database was made from, as the pipeline recorded it (session 45:
        # the report named cases/sweep/default.json whatever SWEEP_INPUT was).
        root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
        for words, want in (
                (["sweep", os.path.join(root, "cases", "sweep", "reduced.json")],
                 "`knit-meso sweep cases/sweep/reduced.json`"),
                (["sweep", "/elsewhere/my sweep.json"], "`knit-meso sweep /elsewhere/my sweep.json`"),
                (["sweep"], "not recorded"), ([], "not recorded"),
                (["sweep", os.path.join(root, "cases", "sweep", "reduced.json"), "sha256:ab",
                  "cell:sha256:cd"], "`knit-meso sweep cases/sweep/reduced.json`")):
            got = report.sweep_command(words)
            if want not in got:
                failures.append(f"sweep_command({words}) = {got!r}, wanted {want!r}")
        # The summary names the law the cases evaluated unless it is the energy law alone
        # (session 45's red team: with "energy_fit": false it never said so).
        for ex, want in (({"a": (10, 0, [], "energy"), "b": None}, ""),
                         ({"a": (10, 0, [], "paper")}, "; the cases evaluated the paper's law "
                                                       "(eq. 17), by their logs"),
                         ({"a": (10, 0, [], "energy"), "b": (5, 0, [], "paper")},
                          "the energy law and the paper's law (eq. 17)")):
            got = report.laws_used_text(ex)
            if (want == "" and got != "") or want not in got:
                failures.append(f"laws_used_text({ex}) = {got!r}")
        # No case with a result: not run, or run and refused (session 45's red team: "run the
        # cases first" when every case had run and been refused by the database).
        nr = os.path.join(tmp, "no_result")
        os.makedirs(os.path.join(nr, "results"))
        os.makedirs(os.path.join(nr, "logs"))
        why = report.no_result_reason(os.path.join(nr, "results"), ["a", "b"])
        if "run the cases first" not in why:
            failures.append("no_result_reason without status files: " + why)
        for n, code in (("a", 2), ("b", 0)):
            with open(os.path.join(nr, "results", n + ".status"), "w") as f:
                json.dump({"case": n, "exit_code": code}, f)
        with open(os.path.join(nr, "logs", "a.log"), "w") as f:
            f.write("knit-macro run: error: a.json: /material/stitch_value: 6.5 mm is outside "
                    "the database's 5-6 mm\n")
        why = report.no_result_reason(os.path.join(nr, "results"), ["a", "b"])
        if ("2 of 2 cases ran, 1 of them refused" not in why
                or "first: a: knit-macro run: error: a.json" not in why):
            failures.append("no_result_reason with a refused case: " + why)
        # A value beside its bound prints the digits that tell it from the bound (session 42's
        # red team: "largest 2.0 %" FAILed against "<= 2 %").
        for v, b, want in ((2.0004, 2.0, "2.0004"), (1.9996, 2.0, "1.9996"), (2.0, 2.0, "2.0"),
                           (11.7, 5.0, "11.7"), (5.000000000000001, 5.0, "5.000000000000001")):
            if report.beside_bound(v, b) != want:
                failures.append(f"beside_bound({v}, {b}) = {report.beside_bound(v, b)!r}")
        # The database's build time: the paper's ~30 min only beside loop lengths read.
        line = report.database_time_line(None, [])
        if "30 min" in line or "missing or unreadable" not in line:
            failures.append(f"database time without a database: {line!r}")
        line = report.database_time_line(91.0, [4.5, 5.0, 5.5, 6.0, 6.5])
        if "~150 min for 5 loop lengths" not in line or "91" not in line:
            failures.append(f"database time of five loop lengths: {line!r}")
        if "for 1 loop length," not in report.database_time_line(3.0, [4.5]):
            failures.append("database time of one loop length: not singular")
        # $(OUT)/database.time truncated or not a record: no time, no traceback (session 55's
        # red team: a JSONDecodeError ended the report, none written).
        tfile = os.path.join(tmp, "database.time.test")
        for content, want in (('{"seconds": 91.5}', 91.5), ('{"seco', None), ("[0]", None),
                              ('{"seconds": "x"}', None)):
            with open(tfile, "w") as f:
                f.write(content)
            if report.database_seconds(tfile) != want:
                failures.append(f"database_seconds of {content!r}: "
                                f"{report.database_seconds(tfile)!r}, not {want!r}")
        if report.database_seconds(os.path.join(tmp, "none.time")) is not None:
            failures.append("database_seconds of a missing file")
        # A design's status file that is not a JSON object (session 55's red team: "[0]" ended
        # the report in an AttributeError): read as unreadable.
        dd = os.path.join(tmp, "design_status_test")
        os.makedirs(os.path.join(dd, "design"))
        with open(os.path.join(dd, "design", "ex.status"), "w") as f:
            f.write("[0]")
        try:
            lines = "\n".join(report.design_section(dd))
            if "? (status file unreadable)" not in lines:
                failures.append(f"a design status of [0]: {lines[-300:]!r}")
        except Exception as e:  # noqa: BLE001 (the point: no exception at all)
            failures.append(f"a design status of [0]: {type(e).__name__}: {e}")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    for f in failures:
        print("FAIL:", f)
    print(f"report test: {len(VARIANTS)} variants, {len(failures)} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
