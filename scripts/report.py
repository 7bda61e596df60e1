#!/usr/bin/python3
"""Validation report of the reproduction (issues #8, #12): writes OUT/report.md.

Reads the pipeline's outputs (scripts/pipeline.mk): OUT/database.h5 and database.source/.time,
OUT/results/NAME/ (knit-macro output) and NAME.status, OUT/figures/*.png, and the sensitivity
table when it exists. `Data` loads curves and fields by case name; `checks(data)` turns them into
the list of verdicts with the pure functions of report_checks.py (each with its threshold and
our number); `Report.write` renders them. tests/report/test_report.py runs the same path on
synthetic result directories.

Usage: report.py --out-dir OUT --database OUT/database.h5 [--cells yes] [--sensitivity CSV]
                 [--cases-dir cases/paper]

Every case of --cases-dir counts: one without a status file or a result is "no result", not
left out of the count (session 30: deleting two status files gave "24 of 24 cases
completed"). A check FAILs when a run it reads has an exit code other than 0 while its summary
says "completed", knit-macro's "results are not trustworthy" (summary lines of failed material
evaluations or non-finite output fields, whether it completed or stopped), no status file, or
a field step whose load factor is not the CSV's (Data.run_defect).
Exit code 1, with the reason on stderr and report.md left as it was, when there is nothing to
judge: no case has a result.
"""
import argparse
import datetime
import glob
import json
import math
import os
import re
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "figures"))
from results import (Result, case_json_of, first_error_line, json_difference,  # noqa: E402
                     last_run_wrote, root_text_attribute)
from sensitivity import FIGURE as SENSITIVITY_FIGURE, read_table as read_sensitivity  # noqa: E402
from design import read_summary as read_design_summary  # noqa: E402

import report_checks as rc  # noqa: E402
from report_checks import Check, pct  # noqa: E402

SQ2 = math.sqrt(2.0)
L = 50.0  # patch size (mm)
# The paper's applied strain of every case (its statements are made there): a run that stops
# before it FAILs. 3.2.1 and 3.2.3 on the sqrt(2) u1 / L axis of the case files.
PAPER_STRAIN = {n: 0.30 for n in (
    "s312_uniform_45_course", "s312_uniform_45_wale", "s312_uniform_65_course",
    "s312_uniform_65_wale", "s313_discontinuous_course", "s313_discontinuous_wale",
    "s314_linear_course", "s314_linear_wale", "s315_diagonal_45deg_vertical")}
PAPER_STRAIN.update({f"conv7c_p{p}h{h}": 0.30 for p in (3, 5, 7) for h in (1, 4)})
PAPER_STRAIN.update({f"conv9e_p{p}h1": 0.30 for p in (3, 5, 7)})
# 3.2.1 mesh study: h = 1 is the paper's case, h = 2, 4 the same case refined.
MESH321 = {1: "s321_bilinear_diagonal", 2: "mesh321_p5h2", 4: "mesh321_p5h4"}
PAPER_STRAIN.update({n: SQ2 * 0.2 for n in MESH321.values()})
PAPER_STRAIN["s322_curved_horizontal"] = 0.40
# The refined meshes of 3.1.5 and 3.2.2 (h = 4; run beside their cases, judged by reach and
# monotonicity only).
PAPER_STRAIN["mesh315_p5h4"] = 0.30
PAPER_STRAIN["mesh322_p5h4"] = 0.40
PAPER_STRAIN["s323_hypar_tension"] = SQ2 * 0.15
PAPER_STRAIN["s323_hypar_compression"] = -SQ2 * 0.10
TENSILE = [n for n in PAPER_STRAIN if not n.startswith("s323")]
STIFFENING = ["s312_uniform_45_course", "s312_uniform_45_wale", "s312_uniform_65_course",
              "s312_uniform_65_wale", "s313_discontinuous_course", "s313_discontinuous_wale",
              "s314_linear_course", "s314_linear_wale", "s315_diagonal_45deg_vertical",
              "s322_curved_horizontal"]


def fmt(x, nd=3):
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "n/a"
    return f"{x:.{nd}f}"


def extrapolation(log_path):
    """From knit-macro's log: the knit material's end-of-run report, 'knit material: N
    evaluations; extrapolated:' followed by 'k x <kind>' lines (paper law), or 'knit material
    (energy law): N evaluations; K extrapolated (...)' (energy law: outside the data strain
    box; its next line 'at converged states: K of N ...' counts the converged states alone,
    appended to kinds). Returns (N, extrapolated, kinds, law): law "energy" or "paper", the
    law the run used."""
    if not os.path.exists(log_path):
        return None
    with open(log_path, errors="replace") as f:
        return extrapolation_of_lines(f)


def extrapolation_of_lines(lines):
    """extrapolation() of the report's lines (a log, summary.txt's "material report:" and the
    lines after it, or results.h5's material_report attribute); None without a report."""
    total, extra, kinds, inside, law = None, 0, [], False, "paper"
    for line in lines:
        line = line.rstrip()
        if line.startswith("material report: "):  # summary.txt's first line of it
            line = line[len("material report: "):]
        m = re.match(r"\s+at converged states: (\d+) of (\d+) evaluations extrapolated", line)
        if m and total is not None:  # the energy law's converged-state audit
            kinds.append(f"at converged states {100 * int(m.group(1)) / max(1, int(m.group(2))):.1f} %"
                         f" of {m.group(2)}")
            continue
        m = re.match(r"knit material(?: \(energy law\))?: (\d+) evaluations"
                     r"(?:; (\d+) extrapolated)?", line)
        if m:
            total, extra, kinds, inside = int(m.group(1)), 0, [], True
            law = "energy" if "(energy law)" in line else "paper"
            if m.group(2) is not None:  # the energy law reports its count on this line
                extra, inside = int(m.group(2)), False
            continue
        if inside:
            m = re.match(r"\s+(\d+) x (.*)", line)
            if m:
                extra += int(m.group(1))
                kinds.append(f"{m.group(1)} {m.group(2)}")
            else:
                inside = False
    return None if total is None else (total, extra, kinds, law)


def run_extrapolation(out, name):
    """(extrapolation, conflict) of case `name` under the pipeline's output `out`: the log's
    report (extrapolation()), and where its run's summary.txt or results.h5 (attribute
    material_report) also hold one, a conflict naming the first that counts other evaluations
    or extrapolations than the log (session 52's red team: the check read the log alone, and a
    summary.txt edited to 27 % extrapolated beside it passed). With a conflict the log's report
    is returned beside it (the review of session 52: returning None called the run one without
    a report); the law's row fails on any conflict."""
    ex = extrapolation(os.path.join(out, "logs", name + ".log"))
    run = os.path.join(out, "results", name)
    others = []
    summ = os.path.join(run, "summary.txt")
    if os.path.exists(summ):
        with open(summ, errors="replace") as f:
            lines = f.read().splitlines()
        start = next((i for i, l in enumerate(lines) if l.startswith("material report: ")), None)
        if start is not None:
            others.append(("summary.txt", extrapolation_of_lines(lines[start:])))
    h5 = os.path.join(run, "results.h5")
    if os.path.exists(h5):
        try:
            import h5py
            with h5py.File(h5, "r") as f:
                v = f.attrs.get("material_report")
            if v is not None:
                text = v.decode(errors="replace") if isinstance(v, bytes) else str(v)
                others.append(("results.h5 @material_report",
                               extrapolation_of_lines(text.splitlines())))
        except (OSError, ImportError) as e:
            return None, f"{h5} cannot be read ({e})"
    if ex is None:
        return None, None
    # knit-macro run writes the material's report into summary.txt and results.h5 of every
    # knit run (the second red team of session 52 deleted both and edited the log alone).
    if ex[3] in ("energy", "paper") and os.path.isdir(run):
        have = {where for where, _ in others}
        for where, what in (("summary.txt", os.path.join(run, "summary.txt")),
                            ("results.h5 @material_report", h5)):
            if os.path.exists(what) and where not in have:
                return ex, (f"{name}: its log reports {ex[1]} of {ex[0]} evaluations "
                            f"extrapolated, its {where} has no material report")
    for where, o in others:
        if o is not None and o[:2] != ex[:2]:
            return ex, (f"{name}: its log reports {ex[1]} of {ex[0]} evaluations "
                        f"extrapolated, its {where} {o[1]} of {o[0]}")
    return ex, None


def beside_bound(value, bound, nd=1):
    """`value` with `nd` decimals, or more where fewer would print the bound itself although
    the value is not it (session 42's red team: 2.0 % FAILed against <= 2 %)."""
    text = f"{value:.{nd}f}"
    while nd < 8 and value != bound and float(text) == bound:
        nd += 1
        text = f"{value:.{nd}f}"
    if value != bound and float(text) == bound:  # within round-off of it: every digit
        text = repr(float(value))
    return text


def verdict(ok):
    if ok is None:
        return "info"
    return "**pass**" if ok else "**FAIL**"


LAW_BOUND = 0.05  # issue 11: errors within 5 % of the stress range
EXTRAPOLATION_BOUND = 0.02  # issue 11: <= 2 % extrapolated material evaluations in every case


def held_out_runs(f):
    """(runs, planned) of the open database `f`: the held-out cell runs (raw paths of set
    "holdout" with at least one converged step) and the held-out states the sweep planned (every
    step of those paths, converged or not), over every loop length; (None, None) when the
    database holds no raw paths."""
    from cell_paths import path_set
    if "loop_lengths" not in f:
        return None, None
    runs, planned, seen = 0, 0, False
    for k in range(len(f["loop_lengths"])):
        raw = f.get(f"loop_{k}/raw")
        if raw is None:
            continue
        seen = True
        for g in raw.values():
            if path_set(f, g) == "holdout" and "status" in g:
                status = g["status"][()]
                runs += int(np.any(status == 0))
                planned += len(status)
    return (runs, planned) if seen else (None, None)


HELD_OUT_MIN_RUNS = 20  # issue 11: "at least 20 held-out cell runs"


def law_checks(db_path, extrapolations, conflicts=()):
    """Issue 11's acceptance of the energy-based law, as checks that can fail: the fit's error
    per loop length against the cell data (RMS and maximum, % of that loop length's stress
    range), the held-out cell states (every one within 5 %), and the extrapolated material
    evaluations of every case (all evaluations, trial iterates included). Reads
    /energy_law/diagnostics of the database; `extrapolations` maps each case to
    extrapolation() of its knit-macro log (None: no material report), `conflicts` names the
    runs whose reports disagree (run_extrapolation()). Returns a list of
    (statement, threshold, measured, ok); one FAIL row when the database has no energy law
    (the paper's eq. 17 law or the synthetic stand-in: issue 11's law is not there to judge)."""
    rows = []
    try:
        import h5py
        with h5py.File(db_path, "r") as f:
            why = database_identity_defect(db_path)
            if why:
                return [("the material database", f"format {DATABASE_FORMAT!r} "
                         f"{'/'.join(map(str, DATABASE_VERSIONS))}, units {DATABASE_UNITS!r}",
                         why, False)]
            if "energy_law" not in f:
                # Issue 11's law is the default: its absence is not a pass by silence (session
                # 38's red team: /energy_law deleted, the whole table and its FAIL row went).
                used = sorted(n for n, ex in extrapolations.items() if ex is not None
                              and ex[3] == "energy")
                return [("the energy-based law (/energy_law)", "in the database",
                         "absent" + (f", although {len(used)} case log(s) report it "
                                     f"({', '.join(used[:3])}{' ...' if len(used) > 3 else ''}): "
                                     "the results are not of this database" if used else
                                     " (the database holds only the paper's law)"), False)]
            if "energy_law/diagnostics" not in f:  # an energy law without its record: no pass
                return [("the energy law's diagnostics (/energy_law/diagnostics)", "present",
                         "missing: the law's errors against the cell are not recorded", False)]
            d = f["energy_law/diagnostics"]
            db_loops = [float(x) for x in f["loop_lengths"][()]] if "loop_lengths" in f else None
            h_runs, h_planned = held_out_runs(f)
            loops = [float(x) for x in d["loop_length"][()]]
            rms = [float(x) for x in d["rms_relative"][()]]
            mx = [float(x) for x in d["max_relative"][()]]
            # The data's floor for any convex law (session 10; absent in older databases).
            mono = ([float(x) for x in d["monotonicity_bound"][()]]
                    if "monotonicity_bound" in d else None)
            a = d.attrs
            h_n = int(a.get("holdout_points", 0))
            h_in = int(a.get("holdout_within_5_percent", 0))
            h_max = float(a.get("holdout_max_relative", float("nan")))
            stored_points = ([int(x) for x in d["points"][()]] if "points" in d else None)
    except (OSError, KeyError, ValueError) as e:
        return [("the energy law's diagnostics (/energy_law/diagnostics)", "readable",
                 f"unreadable: {e}", False)]
    pct = lambda v: " / ".join(f"{100 * x:.1f}" for x in v) + " %"
    per_l = "l = " + " / ".join(f"{x:g}" for x in loops) + " mm: "
    # One finite error per loop length of the database (session 30: empty or shortened error
    # lists passed, all([]) being True).
    want = db_loops if db_loops is not None else loops
    whole = (len(want) > 0 and len(loops) == len(want) and np.allclose(loops, want, rtol=1e-6)
             and len(rms) == len(want) and len(mx) == len(want))
    short = "" if whole else (f" (errors for {len(rms)} / {len(mx)} loop lengths "
                              f"{', '.join(f'{x:g}' for x in loops)} mm; the database has "
                              f"{', '.join(f'{x:g}' for x in want)} mm)")
    # The stored errors against the law re-evaluated at its fit states (session 38's red team:
    # the law scaled by 1.15 kept the stored 4.5 % and PASS): the figures must agree to 1e-6 of
    # the range at every loop length. The fit states are the fit's own (cell_paths.fit_states
    # repeats its rule for a cell that gives way), so the stored count must equal the states
    # re-evaluated. Session 52's red team: a loop length whose counts differed was not compared
    # (its capped largest error passed), and a law that could not be re-evaluated (one NaN in
    # the cell data) left the stored figures to judge; both now fail. Only a whole record is
    # compared (the rows fail otherwise).
    fit_note, fit_agree = "", True
    try:
        import law_held_out
        refit = law_held_out.fit_errors(db_path) if whole else None
        if refit is None:
            pass
        elif not refit:
            fit_agree = False
            fit_note = "; the law re-evaluated has no fit states to compare"
        elif len(refit) != len(loops) or not np.allclose([x[0] for x in refit], loops,
                                                          rtol=1e-9):
            fit_agree = False
            fit_note = (f"; the law re-evaluated covers loop lengths "
                        f"{', '.join(f'{x[0]:g}' for x in refit)} mm")
        else:
            counts = []
            for i, (l, n, r_rms, r_max) in enumerate(refit):
                n0 = (stored_points[i] if stored_points and len(stored_points) == len(refit)
                      else None)
                if n != n0:
                    counts.append(f"{l:g} mm ({n0} stored, {n} by the fit's rule)")
                fit_agree = (fit_agree and n == n0 and abs(r_rms - rms[i]) <= 1e-6
                             and abs(r_max - mx[i]) <= 1e-6)
            if not fit_agree:
                fit_note = ("; the law re-evaluated at its fit states gives RMS "
                            + pct([x[2] for x in refit]) + ", largest "
                            + pct([x[3] for x in refit])
                            + ": the stored figures disagree with the stored law")
            if counts:
                fit_note += "; the fit states' counts differ: " + ", ".join(counts)
    except (OSError, KeyError, ValueError, ImportError) as e:
        fit_agree = False
        fit_note = f"; the stored law could not be re-evaluated, so it is not judged ({e})"
    rows.append(("fit data: RMS error per loop length, % of its stress range",
                 f"<= {100 * LAW_BOUND:g} %, every loop length", per_l + pct(rms) + short
                 + fit_note,
                 whole and fit_agree and all(math.isfinite(x) and x <= LAW_BOUND for x in rms)))
    floor = (f"; the data's own floor for a convex law (monotonicity bound): {pct(mono)}"
             if mono and len(mono) == len(mx) else "")
    rows.append(("fit data: largest error per loop length, % of its stress range",
                 f"<= {100 * LAW_BOUND:g} %, every loop length", per_l + pct(mx) + floor + short
                 + fit_note,
                 whole and fit_agree and all(math.isfinite(x) and x <= LAW_BOUND for x in mx)))
    held = (f"{h_in} of {h_n} (largest {beside_bound(100 * h_max, 100 * LAW_BOUND)} %)" if h_n
            else "none in the database")
    held += ("; runs not countable (no raw paths)" if h_runs is None else
             f" in {h_runs} held-out runs")
    # Every planned held-out state is judged: one where the cell did not converge is not a pass
    # (session 52's red team: the 11 misses marked unconverged, with the attributes made to
    # match, gave "349 of 349" and PASS).
    unjudged = (h_planned - h_n) if h_planned is not None else 0
    if unjudged > 0:
        held += (f"; {unjudged} of the {h_planned} planned held-out states not judged (the cell "
                 "did not converge there, or the record does not count them)")
    elif unjudged < 0:
        held += f"; the record counts more states than the {h_planned} planned"
    # The stored figures against the law re-evaluated at the same states (session 36's red
    # team: attributes set to 360 of 360 with h5py turned the verdict to PASS while the
    # re-evaluation beside it said 348): when the law can be re-evaluated, the two must agree.
    agree = True
    if h_n:
        try:
            import law_held_out
            states, within = law_held_out.held_out_misses(db_path)[:2]
            if (states, within) != (h_n, h_in):
                agree = False
                held += (f"; the law re-evaluated at the held-out states gives {within} of "
                         f"{states}: the stored figures disagree with the stored law")
        except (OSError, KeyError, ValueError, ImportError) as e:
            agree = False
            held += f"; the stored law could not be re-evaluated, so it is not judged ({e})"
    if h_n:
        held += held_out_reference_text(db_path)
    # Judged on the count, the runs and the largest error together (session 30: 1 of 1 state
    # passed "at least 20 runs", and 360 of 360 with a largest error of 50 % passed).
    rows.append(("held-out cell states (never fitted): every one within 5 % of the stress range",
                 f"all, largest <= {100 * LAW_BOUND:g} %, at least {HELD_OUT_MIN_RUNS} runs",
                 held, bool(h_n > 0 and h_in == h_n and math.isfinite(h_max)
                            and h_max <= LAW_BOUND and h_runs is not None
                            and h_runs >= HELD_OUT_MIN_RUNS and unjudged == 0 and agree)))
    worst, worst_case, missing = -1.0, None, []
    for n, ex in sorted(extrapolations.items()):
        if ex is None:
            missing.append(n)
            continue
        if ex[0] <= 0:  # a log that reports no evaluation judges nothing
            missing.append(n)
            continue
        frac = ex[1] / ex[0]
        if frac > worst:
            worst, worst_case = frac, n
    if worst_case is None:
        measured = "no case log with a material report"
    else:
        measured = (f"largest {beside_bound(100 * worst, 100 * EXTRAPOLATION_BOUND)} % "
                    f"({worst_case})")
        if missing:
            measured += (f"; no report (or 0 evaluations) in {len(missing)} log(s): "
                         f"{', '.join(missing[:3])}{' ...' if len(missing) > 3 else ''}")
    if conflicts:
        measured += "; reports that disagree: " + "; ".join(conflicts[:3]) + (
            " ..." if len(conflicts) > 3 else "")
    rows.append(("extrapolated material evaluations, every case (trial iterates included)",
                 f"<= {100 * EXTRAPOLATION_BOUND:g} %", measured,
                 worst_case is not None and not missing and not conflicts
                 and worst <= EXTRAPOLATION_BOUND))
    return rows


def held_out_reference(db_path):
    """What the sampling itself allows on the held-out criterion: over every loop length of the
    database, the held-out states that a free interpolant (each stress component its own
    tensor-product cubic spline, scripts/free_fit.py; no energy, no convexity) trained on the
    same fit paths predicts within LAW_BOUND of the loop length's stress range. Returns
    (within, states, largest error) or None when the database holds no raw held-out paths."""
    import h5py
    from cell_paths import fit_min_cos, fit_states, load_paths, stress_range
    from free_fit import free_fits
    within, states, worst = 0, 0, 0.0
    with h5py.File(db_path, "r") as f:
        if "loop_lengths" not in f:
            return None
        min_cos = fit_min_cos(f)
        for k in range(len(f["loop_lengths"])):
            if f"loop_{k}/raw" not in f:
                return None
            paths = fit_states(load_paths(f, k), min_cos)  # the fit's own states and range
            fit = [p for p in paths if p[0] != "holdout" and len(p[1])]
            held = [p for p in paths if p[0] == "holdout" and len(p[1])]
            if not fit or not held:
                continue
            te_s = np.concatenate([p[2] for p in held])
            interp = free_fits(np.concatenate([p[1] for p in fit]),
                               np.concatenate([p[2] for p in fit]),
                               np.concatenate([p[1] for p in held]))[1]
            err = np.abs(interp - te_s).max(axis=1) / stress_range(paths)
            if not np.all(np.isfinite(err)):
                raise ValueError(f"non-finite free-fit error at /loop_{k}")
            within += int(np.sum(err <= LAW_BOUND))
            states += len(err)
            worst = max(worst, float(err.max()))
    return (within, states, worst) if states else None


def held_out_reference_text(db_path):
    """held_out_reference() as the text printed beside the held-out verdict (not judged)."""
    try:
        ref = held_out_reference(db_path)
    except (OSError, KeyError, ValueError, np.linalg.LinAlgError) as e:
        return f"; the free-interpolant reference: not computed ({e})"
    if ref is None:
        return ""
    return (f"; a free interpolant trained on the same fit paths (no law, the sampling's own "
            f"reference): {ref[0]} of {ref[1]} (largest {100 * ref[2]:.1f} %)")


def beside_text(title, sentence, empty):
    """A sentence printed beside the law's checks, not judged: sentence() (a script's summary),
    "TITLE: not computed (why)." when it fails on the files, "TITLE: EMPTY." when it is empty."""
    try:
        text = sentence()
    except (OSError, KeyError, ValueError) as e:
        text = f"{title}: not computed ({e})."
    return (text or f"{title}: {empty}.") + "\n"


def near_visited_text(db_path, res_dir):
    """The law's errors at the cell states near the strains the runs visit
    (scripts/law_near_visited.py)."""
    import law_near_visited as m
    return beside_text("Where the runs go", lambda: m.summary(m.near_errors(db_path, res_dir)),
                       "no run wrote material-frame strains")


def held_out_text(db_path):
    """Which held-out cell states the law misses (scripts/law_held_out.py)."""
    import law_held_out as m
    return beside_text("Where the held-out states miss",
                       lambda: m.summary(m.held_out_misses(db_path)),
                       "the database has no energy law or no held-out path")


def uniaxial_text(db_path):
    """The law along the cell's uniaxial-stress paths (scripts/law_uniaxial.py)."""
    import law_uniaxial as m
    return beside_text("Uniaxial tension", lambda: m.summary(m.uniaxial_ratios(db_path)),
                       "the database has no energy law")


def shear_text(db_path):
    """The law along the cell's pure-shear paths (scripts/law_shear.py)."""
    import law_shear as m
    return beside_text("Pure shear", lambda: m.summary(m.shear_ratios(db_path)),
                       "the database has no energy law or no shear path")


def small_strain_text(db_path):
    """The law over the cell at small strains (scripts/law_small_strain.py)."""
    import law_small_strain as m
    return beside_text("Small strains", lambda: m.summary(m.small_strain_ratios(db_path)),
                       "the database has no energy law")


class Data:
    """The pipeline's results, loaded on demand: curves and fields by case name."""

    def __init__(self, res_dir, db_date=None, cases_src=None, db_defect=None):
        self.res_dir = res_dir
        self.db_date = db_date  # the database's date_utc: results of another one are stale
        self.db_defect = db_defect  # database_identity_defect(): knit runs are no data then
        self.cases_src = cases_src  # the checkout's cases (--cases-dir): the pipeline copies them
        self.cache = {}
        self.read = set()      # names read since the last take_read() (checks() attributes them)
        self.read_fields = set()  # ... of those, the names whose fields were read
        self.field_bad = {}    # name -> why its fields could not be read (checks reading them)
        self.defects = {}      # name -> run_defect(name), computed once

    def r(self, name):
        self.read.add(name)
        if name not in self.cache:
            self.cache[name] = Result(self.res_dir, name)
        return self.cache[name]

    def take_read(self):
        """(runs read, runs whose fields were read) since the last call."""
        names, self.read = self.read, set()
        fields, self.read_fields = self.read_fields, set()
        return names, fields

    def run_defect(self, name):
        """Why a run's results are no data to judge although it may have reached its strain,
        or None: no status file (exit code unknown), an exit code other than 0 that is not
        an early stop (summary "stopped": the stop is judged by the checks themselves),
        summary lines of failed material evaluations or non-finite output fields (knit-macro's
        own "results are not trustworthy", whether the run completed or stopped: the count of
        failed evaluations is the whole run's), a field step whose stored load factor is
        not the CSV's, or results computed with another database (results.h5's
        material_database_date_utc is not the database's date_utc; since session 38). Computed once per run, before any check reads its fields, so that every
        check of the run is judged alike. Session 30: every check passed with exit code 1 in
        every status file."""
        if name not in self.defects:
            self.defects[name] = self._run_defect(name)
        return self.defects[name]

    def _run_defect(self, name):
        # Not through r(): that would count the run as read by the next check.
        r = self.cache[name] if name in self.cache else Result(self.res_dir, name)
        if r.problem:
            return r.problem
        if not r.ok:
            return None  # no result: every check that needs it says so
        if not r.status:
            return "no status file (its exit code is unknown)"
        lines = r.summary().splitlines()
        stopped = "status: stopped" in lines
        bad = [l for l in lines if l.startswith(("material failures:", "output failure:"))]
        if bad:
            return bad[0]
        ex = r.status.get("exit_code")
        if ex != 0 and not stopped:
            return f"exit code {ex} although its summary says it completed"
        if ex == 0 and stopped:
            return "exit code 0 although its summary says it stopped"
        # Results of another database (session 38's red team: results older than the database
        # were judged as its own): knit-macro run records the date_utc of the database it read.
        knit = r.case.get("material", {}).get("type") == "knit"
        if knit and self.db_defect:
            return f"the material database is not one this report can judge: {self.db_defect}"
        # The run's own units where results.h5 states them (knit-macro run always does; session
        # 52's red team: results.h5 @units "m, kN, GPa" passed).
        units = root_text_attribute(os.path.join(r.dir, "results.h5"), "units")
        if units is not None and units != RESULT_UNITS:
            return (f"its results.h5 states units {units!r}, not {RESULT_UNITS!r} (the report "
                    "reads mm, N and MPa)")
        if r.database_date() is not None or (self.db_date == UNDATED and knit):
            why = stale_against(r.database_date(), self.db_date, "the run", "rerun the case")
            if why:
                return why
        # Results that do not say which database they read (no material_database_date_utc:
        # written before session 38, or changed since) are not judged as this database's
        # (session 42's red team: with the attribute deleted, a stale run passed).
        if self.db_date is not None and r.database_date() is None and knit:
            return ("its results.h5 does not say which database it read (no "
                    "material_database_date_utc: written before session 38, changed since, or "
                    "no results.h5, which the report needs for a knit run: rerun the case with "
                    "/output/hdf5 true, the default)")
        # The case the run was computed from against the pipeline's copy of it (session 50's
        # red team): OUT/cases/NAME.json beside OUT/results (OUT/cases_paper_law beside
        # OUT/results_paper_law).
        base = os.path.basename(os.path.normpath(self.res_dir))
        if base.startswith("results"):
            cases = os.path.join(os.path.dirname(os.path.normpath(self.res_dir)),
                                 "cases" + base[len("results"):])
            why = r.case_defect(os.path.join(cases, name + ".json"))
            if why:
                return why
            if base == "results" and self.cases_src:
                why = copy_defect(os.path.join(cases, name + ".json"),
                                  os.path.join(self.cases_src, name + ".json"))
                if why:
                    return why
        # The run's own outputs against each other (session 42's red team: a doubled strain
        # column, another step's fields, a summary of fewer steps than the CSV).
        why = r.consistency_defect()
        if why:
            return why
        for s in r.steps():  # step_0010's fields copied into step_0020 were judged at 30 %
            lf, csv_lf = r.load_factor_of_step(s), r.csv_load_factor(s)
            if lf is not None and csv_lf is not None and abs(lf - csv_lf) > 1e-9 * max(1.0, abs(csv_lf)):
                return (f"its fields of step {s} carry load factor {lf:g}, load_strain.csv "
                        f"{csv_lf:g} for that step")
        return None

    def curve(self, name):
        """(strain, load) with (0, 0) first, or None without a converged step."""
        r = self.r(name)
        if not r.ok or len(r.strain()) < 2:
            return None
        return r.strain(), r.load()

    def fields_at(self, name, eps):
        """Fields at applied strain eps, linear between the two output steps around it; None
        when the run has no output step at or beyond eps (it stopped before)."""
        r = self.r(name)
        self.read_fields.add(name)
        if not r.ok:
            return None
        have = sorted((r.strain_of_step(s), s) for s in r.steps())
        have = [(e, s) for e, s in have if math.isfinite(e)]
        if not have:
            return None
        tol = rc.TOL_REACH * abs(eps)
        exact = [s for e, s in have if abs(e - eps) <= tol]
        below = [(e, s) for e, s in have if e < eps]
        above = [(e, s) for e, s in have if e > eps]
        if not exact and (not below or not above):
            return None
        try:
            if exact:
                return self.step_fields(r, exact[0])
            (ea, sa), (eb, sb) = below[-1], above[0]
            fa, fb = self.step_fields(r, sa), self.step_fields(r, sb)
        except (OSError, KeyError, ValueError) as e:  # a missing VTU, a grid that is not one
            self.field_bad[name] = f"its fields cannot be read ({e})"
            return None
        return {key: rc.interpolate_fields(ea, fa[key], eb, fb[key], eps)
                for key in fa if key in fb and np.shape(fa[key]) == np.shape(fb[key])}

    def step_fields(self, r, step):
        """r.fields(step) of a run, counted as its fields read (a check reading them FAILs
        if they cannot be read: field_bad)."""
        self.read_fields.add(r.name)
        return r.fields(step)

    def case(self, name):
        return self.r(name).case


def copy_defect(copy_file, src_file):
    """Why the pipeline's copy of a case (OUT/cases/NAME.json) is not the checkout's case file
    with the database the pipeline set (resolve_case.py: /material/database), or None; None
    without the checkout's file. Session 52's red team: a paper-law run and its case, copied
    into OUT/results and OUT/cases, agreed with each other and were judged as the default law's
    run; its second red team deleted the copy instead, which turned this and case_defect off:
    a copy missing from the pipeline's OUT/cases beside a checkout case is a defect (an output
    without OUT/cases at all, a hand-made one, is not judged by it)."""
    if not os.path.exists(src_file):
        return None
    if not os.path.exists(copy_file) and os.path.isdir(os.path.dirname(copy_file)):
        return (f"the pipeline's copy of its case, {copy_file}, is missing, so its results "
                "cannot be tied to the checkout's case (rerun the pipeline)")
    if not os.path.exists(copy_file):
        return None
    try:
        with open(copy_file) as f:
            copy = json.load(f)
        with open(src_file) as f:
            want = json.load(f)
    except (OSError, ValueError) as e:
        return f"its case cannot be compared with the checkout's ({e})"
    mc, mw = copy.get("material"), want.get("material")
    if isinstance(mc, dict) and isinstance(mw, dict) and "database" in mc:
        mw["database"] = mc["database"]
    ptr = json_difference(want, copy)
    if ptr is None:
        return None
    return (f"its case {copy_file} is not the checkout's {src_file}: they differ at {ptr or '/'} "
            "(only /material/database is the pipeline's to set; rerun the pipeline)")


def _field(f, key):
    return None if f is None else f.get(key)


def checks(d):
    """Every check of the report on the loaded data `d` (a Data): a list of Check. A check
    FAILs when a run it read (the runs read since the previous check, plus `runs`) has a
    run_defect, named in its measured text."""
    out = []
    d.take_read()

    def add(c, runs=()):
        """runs: the runs `c` judges that were read for an earlier check (data reused)."""
        names, fields = d.take_read()
        names |= set(runs)
        bad = [(n, d.run_defect(n) or (d.field_bad.get(n) if n in fields | set(runs) else None))
               for n in sorted(names)]
        bad = [(n, why) for n, why in bad if why]
        if bad and c.ok is not None:
            c.ok = False
            c.measured += "; but " + "; ".join(f"{n}: {why}" for n, why in bad)
        out.append(c)
    # -- every run: reaches the paper's strain; tensile curves monotone ---------------------------
    for n, target in PAPER_STRAIN.items():
        add(rc.check_reaches(f"reach:{n}", "runs", n, d.curve(n), target))
    for n in TENSILE:
        add(rc.check_monotone(f"monotone:{n}", "runs", n, d.curve(n)))

    # -- 3.1.2 ------------------------------------------------------------------------------------
    S = "3.1.2"
    for l, paper in (("45", 0.37), ("65", 0.32)):
        name = f"s312_uniform_{l}_wale"
        maxima = {}
        for at in (0.2, 0.3):
            e22 = _field(d.fields_at(name, at), "E22")
            maxima[at] = None if e22 is None else float(np.max(e22))
            add(rc.check_e22_bound(f"e22bound:{l}:{at:g}", S, name, e22, at))
        add(rc.check_e22_value(f"e22value:{l}", S, name, maxima, paper), runs=[name])
        f = d.fields_at(name, 0.3)
        add(rc.check_max_location(f"e22where:{l}", S, name, _field(f, "E22"), _field(f, "X"), L,
                                  0.3))
    for dirn in ("course", "wale"):
        a, b = f"s312_uniform_45_{dirn}", f"s312_uniform_65_{dirn}"
        add(rc.check_much_stiffer(f"stiffer:{dirn}", S, f"4.5 mm much stiffer than 6.5 mm "
                                  f"({dirn}-wise), over the whole curve", d.curve(a), d.curve(b),
                                  0.30, ("4.5 mm", "6.5 mm")))
    st = ("wale-wise at 30 %: E22 along the central section (y = L/2) more uniform for 4.5 mm "
          "than for 6.5 mm")
    f45 = d.fields_at("s312_uniform_45_wale", 0.3)
    f65 = d.fields_at("s312_uniform_65_wale", 0.3)
    add(field_check("uniform312", S, st, "4.5 mm more uniform", UNIFORM,
                    None if f45 is None or f65 is None else (f45, f65),
                    lambda f: rc.check_more_uniform("uniform312", S, st, central_row(f[0], "E22"),
                                                    central_row(f[1], "E22"),
                                                    ("4.5 mm", "6.5 mm"))))
    add(rc.check_convergence("conv7c", S, "Fig. 7c: p = 5, h = 1 within engineering accuracy of "
                             "p = 7, h = 4", d.curve("conv7c_p5h1"), d.curve("conv7c_p7h4"), 0.30,
                             ("conv7c_p5h1", "conv7c_p7h4")))
    for n in STIFFENING:
        sec = "3.2.2" if n.startswith("s322") else "3.1." + n[3]
        add(rc.check_stiffening(f"stiffening:{n}", sec, n, d.curve(n), PAPER_STRAIN[n]))

    # -- 3.1.3 ------------------------------------------------------------------------------------
    S = "3.1.3"
    st = "course-wise at 30 %: E11 much higher in the right (6.5 mm) half"
    add(field_check("e11right313", S, st, "right much higher",
                    f"mean ratio >= {rc.FACTOR_MUCH_LARGER:g}",
                    d.fields_at("s313_discontinuous_course", 0.3),
                    lambda f: rc.check_larger("e11right313", S, st, *halves(f, "E11")[::-1],
                                              ("right", "left"), rc.FACTOR_MUCH_LARGER)))
    st = "wale-wise at 30 %: E22 more uniform in the right (6.5 mm) half"
    add(field_check("uniform313", S, st, "right more uniform", UNIFORM,
                    d.fields_at("s313_discontinuous_wale", 0.3),
                    lambda f: rc.check_more_uniform("uniform313", S, st, *halves(f, "E22")[::-1],
                                                    ("right", "left"))))
    add(rc.check_convergence("conv9e", S, "Fig. 9e: p = 5 sufficiently converged (vs p = 7, "
                             "h = 1)", d.curve("conv9e_p5h1"), d.curve("conv9e_p7h1"), 0.30,
                             ("conv9e_p5h1", "conv9e_p7h1")))

    # -- 3.1.4 ------------------------------------------------------------------------------------
    S = "3.1.4"
    f = d.fields_at("s314_linear_wale", 0.3)
    st = "wale-wise at 30 %: larger E22 in the top (6.5 mm) third than in the bottom third"
    add(field_check("larger314", S, st, "top larger", f"mean ratio >= {rc.FACTOR_LARGER:g}", f,
                    lambda f: rc.check_larger("larger314", S, st, *thirds_y(f, "E22")[::-1],
                                              ("top", "bottom"), rc.FACTOR_LARGER)))
    st = "wale-wise at 30 %: more uniform E22 in the top third than in the bottom third"
    add(field_check("uniform314", S, st, "top more uniform", UNIFORM, f,
                    lambda f: rc.check_more_uniform("uniform314", S, st, *thirds_y(f, "E22")[::-1],
                                                    ("top", "bottom"))), runs=["s314_linear_wale"])

    # -- 3.2.1: mesh study h = 1, 2, 4 --------------------------------------------------------------
    S = "3.2.1"
    target = PAPER_STRAIN[MESH321[1]]
    subs = [rc.check_stiffening(f"notstiff321:h{h}", S, n, d.curve(n), target, stiffening=False)
            for h, n in MESH321.items()]
    add(Check("notstiff321", S, "diagonal test: load-strain curve NOT stiffening, on every mesh "
              "(p = 5; h = 1, 2, 4)", "not stiffening", subs[0].threshold,
              "; ".join(f"h = {h}: {'pass' if c.ok else 'FAIL'} ({c.measured})"
                        for h, c in zip(MESH321, subs)), all(c.ok for c in subs)))
    sym = []
    for h, n in MESH321.items():
        f = d.fields_at(n, target)
        if f is None or any(k not in f for k in ("E11", "E22", "E12")):
            sym.append((h, None, None))
        else:
            dev = rc.mirror_deviation(f["E11"], f["E22"], f["E12"])
            if all(math.isfinite(x) for x in dev):
                sym.append((h,) + dev)
            else:  # the reason, printed and failed
                why = "strain field: " + rc.field_defect(f["E11"], f["E22"], f["E12"])
                sym.append((h, why, why))
    for key, idx, st in (("mirror321", 1, "E11(x, y) = E22(y, x) (the paper's 'anti-symmetric'), "
                          "every mesh: max|E11 - E22^T| / max|E|"),
                         ("sym321", 2, "E12 symmetric about the diagonal, every mesh: "
                          "max|E12 - E12^T| / max|E12|")):
        got = "; ".join(f"h = {s[0]}: " + ("no field at the paper's strain" if s[idx] is None
                                          else s[idx] if isinstance(s[idx], str)
                                          else f"{s[idx]:.2e}") for s in sym)
        add(Check(key, S, st, "symmetric", f"<= {rc.TOL_SYMMETRY:g} on every mesh", got,
                  all(isinstance(s[idx], float) and s[idx] <= rc.TOL_SYMMETRY for s in sym)),
            runs=MESH321.values())
    add(rc.check_convergence("mesh321", S, "diagonal test: the load-strain curve converges under "
                             "h-refinement (h = 2 vs h = 4; the corner conditions act on a 5 mm "
                             "pad, see docs/reproduction.md)", d.curve(MESH321[2]), d.curve(MESH321[4]),
                             target, (MESH321[2], MESH321[4])))

    # -- 3.2.2 ------------------------------------------------------------------------------------
    S = "3.2.2"
    n = "s322_curved_horizontal"
    r = d.r(n)
    alpha, exact = None, None
    if r.ok and r.steps() and "geometry" in d.case(n):
        try:
            fl = d.step_fields(r, r.steps()[-1])
        except (OSError, KeyError, ValueError) as e:
            d.field_bad[n] = f"its fields cannot be read ({e})"
            fl = {}
        alpha = fl.get("knitting_angle")
        if alpha is not None:
            exact, _ = rc.exact_alignment_angle(d.case(n)["geometry"], alpha.shape[1],
                                                alpha.shape[0])
    add(rc.check_alpha("alpha322", S, alpha, exact))

    # -- 3.2.3: listed with numbers (the paper gives none), reach judged above -----------------------
    for n in ("s323_hypar_tension", "s323_hypar_compression"):
        r = d.r(n)
        try:
            f = d.step_fields(r, r.steps()[-1]) if r.ok and r.steps() else None
        except (OSError, KeyError, ValueError) as e:
            d.field_bad[n] = f"its fields cannot be read ({e})"
            f = None
        if f is not None and "E12" in f and "E22" in f:
            kap = max(float(np.max(np.abs(f[k]))) for k in ("kappa11", "kappa22", "kappa12")
                      if k in f) if any(k in f for k in ("kappa11", "kappa22", "kappa12")) else 0.0
            got = (f"at {pct(r.strain_of_step(r.steps()[-1]))}: max |E12| "
                   f"{np.max(np.abs(f['E12'])):.3f}, max |E22| {np.max(np.abs(f['E22'])):.3f}, "
                   f"max |kappa| {kap:.4f} 1/mm")
        else:
            got = "no result"
        add(Check(f"info:{n}", "3.2.3", f"{n}: bending-dominated, low mid-surface E12 and E22",
                  "low (no number)", "none (the paper gives no number)", got, None))
    return out


UNIFORM = f"CV ratio <= {rc.FACTOR_MORE_UNIFORM:g}"


def field_check(key, section, statement, paper, threshold, fields, judge):
    """judge(fields) -> Check; a FAIL when the run has no field at the strain (it stopped)."""
    have = fields is not None and all(
        "X" in f for f in (fields if isinstance(fields, tuple) else (fields,)))
    if not have:
        return rc.missing(key, section, statement, paper, threshold,
                          "no field at 30 % (the run stopped before, or wrote no fields)")
    return judge(fields)


def central_row(f, key):
    """The field along the central section: the grid row nearest to mid-height."""
    y = f["X"][:, :, 1]
    ymid = 0.5 * (float(np.min(y)) + float(np.max(y)))
    j = int(np.argmin(np.abs(y[:, 0] - ymid)))
    return f[key][j, :]


def halves(f, key):
    """(left, right) samples: reference x below / above the middle (the middle column out)."""
    x = f["X"][:, :, 0]
    xm = 0.5 * (float(np.min(x)) + float(np.max(x)))
    eps = 1e-9 * (float(np.max(x)) - float(np.min(x)))
    return f[key][x < xm - eps], f[key][x > xm + eps]


def thirds_y(f, key):
    """(bottom third, top third) samples by reference y."""
    y = f["X"][:, :, 1]
    y0, y1 = float(np.min(y)), float(np.max(y))
    h = (y1 - y0) / 3.0
    return f[key][y <= y0 + h + 1e-9], f[key][y >= y1 - h - 1e-9]


CASES_DIR = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "cases",
                         "paper")


def case_names(cases_dir, res_dir):
    """The cases the report accounts for: every case file of `cases_dir` (the pipeline's
    CASEDIR) and every status file of `res_dir`."""
    names = {os.path.basename(p)[:-5] for p in glob.glob(os.path.join(cases_dir, "*.json"))}
    names |= {os.path.basename(p)[:-7] for p in glob.glob(os.path.join(res_dir, "*.status"))}
    return sorted(names)


# The date of a database file that does not say when it was written (no date_utc attribute:
# every database knit-meso writes has one; session 51's red team: with it deleted, every stale
# check was off and runs of another database passed).
UNDATED = ""


def database_date(db_path):
    """The database file's date_utc attribute (when it was written); UNDATED for an HDF5 file
    that opens without it (or with an empty one); None without a database, or where it cannot
    be read (missing, not HDF5, no h5py: the report says so elsewhere)."""
    if not db_path:
        return None
    date = root_text_attribute(db_path, "date_utc")
    if date is not None:
        return date
    try:
        import h5py
        with h5py.File(db_path, "r"):
            return UNDATED
    except (OSError, ValueError, ImportError):
        return None


DATABASE_FORMAT = "knitscale-material-database"  # common/src/material_database_io.cpp
DATABASE_VERSIONS = (1, 2, 3)                    # the formats knit-macro reads
DATABASE_UNITS = "length mm, force N, stress MPa"
RESULT_UNITS = "mm, N, MPa"                      # knit-macro run's results.h5 @units


def database_identity_defect(db_path):
    """Why the database file is not a knitscale material database in mm, N and MPa, by its
    root attributes format, format_version and units, each judged where present (knit-macro
    refuses a database without a format; the report's own hand-made test databases have none),
    or None (also when it cannot be read: the report says so elsewhere). Session 52's red team:
    units "length m, force kN, stress GPa", format "not-a-knitscale-db" and format_version 99
    changed no verdict."""
    if not db_path:
        return None
    got = {k: root_text_attribute(db_path, k) for k in ("format", "format_version", "units")}
    if got["format"] not in (None, DATABASE_FORMAT):
        return f"its format is {got['format']!r}, not {DATABASE_FORMAT!r}"
    if got["format_version"] not in {None} | {str(v) for v in DATABASE_VERSIONS}:
        return f"its format_version is {got['format_version']}, not one of {DATABASE_VERSIONS}"
    if got["units"] not in (None, DATABASE_UNITS):
        return f"its units are {got['units']!r}, not {DATABASE_UNITS!r}"
    return None


def is_run_check(c):
    """Whether a check row judges the run itself rather than a statement of the paper: the
    "runs" rows (reaches the paper's strain, monotone curve) and the kinematic bound on max E22
    (met by any run that holds its boundary conditions)."""
    return c.key.startswith(("reach:", "monotone:", "e22bound:"))


def completed_runs(names, data):
    """The runs of `names` that completed and have no defect (Data.run_defect): what the
    summary counts as completed."""
    return [n for n in names if data.r(n).completed and not data.run_defect(n)]


class Report:
    def __init__(self, out_dir, sensitivity=None, cases_dir=CASES_DIR, database=None):
        self.out = out_dir
        self.res_dir = os.path.join(out_dir, "results")
        self.data = Data(self.res_dir, database_date(database), cases_dir,
                         database_identity_defect(database))
        self.sensitivity = sensitivity
        self.names = case_names(cases_dir, self.res_dir)
        self.rows = []
        # The figures the pipeline draws (--expect-figures): a missing one is named (session
        # 38's red team: a deleted figure dropped its section without a word).
        self.expected_figures = []

    def r(self, name):
        return self.data.r(name)

    def checks(self):
        self.rows = checks(self.data)
        # A case the report has no strain for is judged by nothing: that is a FAIL of its own.
        for n in self.names:
            if n not in PAPER_STRAIN:
                self.rows.append(rc.missing(f"reach:{n}", "runs", f"{n} runs to the paper's "
                                            "strain", "?", "a paper strain in report.py's "
                                            "PAPER_STRAIN", "no paper strain known for this "
                                            "case: no check reads it"))
        return self.rows

    # -- output ------------------------------------------------------------------------------------
    def strict_problems(self):
        """What `--strict` fails on, after write(): "2 checks of the runs themselves fail",
        ...; empty when every run check passes, every case completed, every twin experiment was
        recovered and every figure was drawn."""
        return [f"{n} {what}" for what, n in getattr(self, "strict_counts", {}).items() if n]

    def write(self, db_path, cells):
        src_file = os.path.join(self.out, "database.source")
        source = open(src_file).read().split() if os.path.exists(src_file) else []
        mode = source[0] if source else "?"
        tfile = os.path.join(self.out, "database.time")
        db_seconds = database_seconds(tfile)
        generator, loops = "?", []
        try:
            import h5py
            with h5py.File(db_path, "r") as f:
                g = f.attrs.get("generator", b"?")
                generator = g.decode() if isinstance(g, bytes) else str(g)
                loops = [float(x) for x in f["loop_lengths"]]
        except Exception as e:  # the report still says what it could not read
            generator = f"unreadable ({e})"
        # knit-meso synth's "synth" and a sweep with the synthetic runner's "sweep (synthetic
        # runner)" (session 50: the second was reported as the mesoscale sweep).
        synthetic = mode == "synth" or generator == "synth" or "synthetic" in generator
        try:
            rev = subprocess.run(["git", "-C", os.path.dirname(os.path.abspath(__file__)),
                                  "rev-parse", "--short", "HEAD"], capture_output=True,
                                 text=True).stdout.strip()
        except OSError:
            rev = "?"
        names = self.names
        L = []
        L.append("# Reproduction report: multiscale simulation of graded knitted textiles\n")
        L.append(f"Generated {datetime.datetime.utcnow().strftime('%Y-%m-%d %H:%M UTC')} by "
                 f"`scripts/report.py` (git {rev}); regenerate with `scripts/run.sh` "
                 "(see docs/reproduction.md).\n")
        npass = sum(1 for c in self.rows if c.ok is True)
        nfail = sum(1 for c in self.rows if c.ok is False)
        ninfo = sum(1 for c in self.rows if c.ok is None)
        # The summary counts the paper's statements apart from the checks of the runs
        # themselves (session 50's red team: "73 of 82 checks of the paper's statements" held
        # 50 rows of reach and monotone curves and 4 of the kinematic bound on max E22, which a
        # run that holds its boundary conditions meets by kinematics alone).
        run_rows = [c for c in self.rows if is_run_check(c)]
        rpass = sum(1 for c in run_rows if c.ok is True)
        rfail = sum(1 for c in run_rows if c.ok is False)
        # A completed run with a defect (Data.run_defect: stale, inconsistent, not trustworthy)
        # is not counted as completed (session 42's red team: "26 of 26 cases completed" beside
        # a run whose every check FAILed for its defect).
        ndone = len(completed_runs(names, self.data))
        # Each log is read once: for the law's check and for the runs table below.
        read = {n: run_extrapolation(self.out, n) for n in names}
        extrapolations = {n: r[0] for n, r in read.items()}
        conflicts = [r[1] for r in read.values() if r[1]]
        law = law_checks(db_path, extrapolations, conflicts)
        law_pass = sum(1 for r in law if r[3])
        law_text = (f"; material law: {law_pass} of {len(law)} checks pass" if law else "")
        law_text += laws_used_text(extrapolations)
        twins_ok, twins = twin_counts(self.out)
        if twins:
            law_text += f"; inverse design: {twins_ok} of {twins} twin experiments recovered"
        n_failed_figs = sum(1 for p in glob.glob(os.path.join(self.out, "figures", "*.png"))
                            if figure_failed(p))
        if n_failed_figs:
            law_text += f"; {n_failed_figs} figure script(s) FAILED (placeholders)"
        missing_figs = [n for n in self.expected_figures
                        if not os.path.exists(os.path.join(self.out, "figures", n))]
        if missing_figs:
            law_text += f"; {len(missing_figs)} figure(s) MISSING"
        damaged_figs = [os.path.basename(p)[:-4]
                        for p in sorted(glob.glob(os.path.join(self.out, "figures", "*.png")))
                        if not figure_failed(p) and figure_damage(p)]
        if damaged_figs:
            law_text += (f"; {len(damaged_figs)} figure(s) DAMAGED (not complete PNG images: "
                         f"{', '.join(damaged_figs)})")
        spass, sfail = npass - rpass, nfail - rfail
        # What --strict judges (strict_problems): the runs, not the paper's statements nor the
        # law's checks, which measure the method against the paper and may fail on a sound run.
        self.strict_counts = {
            "checks of the runs themselves fail": rfail,
            "cases did not complete": len(names) - ndone,
            "twin experiments not recovered": twins - twins_ok,
            "figure scripts failed (placeholders)": n_failed_figs,
            "figures missing": len(missing_figs),
            "figures damaged (not complete PNG images)": len(damaged_figs),
        }
        L.append(f"**Summary:** {spass} of {spass + sfail} checks of the paper's statements pass, "
                 f"{sfail} fail, and {ninfo} more are listed with our numbers only (the paper "
                 "giving none); "
                 f"{rpass} of {rpass + rfail} checks of the runs themselves pass (each case "
                 "reaches the paper's strain with a monotone load-strain curve; max E22 above "
                 "the kinematic bound); "
                 f"{ndone} of {len(names)} cases completed; material database: "
                 f"{'SYNTHETIC stand-in' if synthetic else 'mesoscale sweep'}"
                 f"{law_text}.\n")
        L.append("## Material database\n")
        if synthetic:
            L.append("> **The SYNTHETIC stand-in database was used** (the law of `knit-meso synth`: a known "
                     "orthotropic stiffening law, S1 = k(0.5 E1 + 0.1 E2 + 8 E1^3), S2 = k(0.1 E1 "
                     "+ E2 + 12 E2^3), S12 = k(0.3 E12 + 4 E12^3), k = (4.5/l)^2 MPa; not a knit). "
                     + (f"It was written by a sweep with the synthetic runner (generator "
                        f"`{generator}`: the sweep input's \"runner\": \"synthetic\"). "
                        if "synthetic" in generator else
                        "Reason: this build has no `knit-meso sweep` (the mesoscale sweep had not "
                        "landed) or DB_SOURCE=synth was asked for. ") +
                     "Every number below that depends "
                     "on the material (strain maxima, loads) is therefore NOT a reproduction of "
                     "the paper's values; the structural statements (symmetry, convergence, "
                     "alpha range, stiffening of the law) still test the chain.\n")
        else:
            L.append(f"The database was computed by the mesoscale sweep "
                     f"({sweep_command(source)}): homogenized unit cells, fitted response "
                     f"surfaces.\n")
        L.append(f"- file: `{db_path}`; generator attribute: `{generator}`; loop lengths: "
                 f"{', '.join(f'{x:g}' for x in loops)} mm")
        L.append(database_time_line(db_seconds, loops) + "\n")
        if law:
            L.append("## Material law (issue 11's acceptance)\n")
            L.append("The energy-based law's fit against the cell data and the held-out cell runs "
                     "(the database's /energy_law/diagnostics; docs/database.md), and how often "
                     "the cases evaluated it outside its data (logs/NAME.log).\n")
            L.append("| check | threshold | ours | verdict |")
            L.append("|---|---|---|---|")
            for statement, threshold, measured, ok in law:
                L.append(f"| {md(statement)} | {md(threshold)} | {md(measured)} | {verdict(ok)} |")
            L.append("")
            L.append(held_out_text(db_path))
            L.append(near_visited_text(db_path, os.path.join(self.out, "results")))
            L.append(small_strain_text(db_path))
            L.append(uniaxial_text(db_path))
            L.append(shear_text(db_path))
        L.append("## Statements of the paper against our numbers\n")
        L.append("Each check is a function of the loaded results (scripts/report_checks.py; "
                 "thresholds and their reasons in docs/reproduction.md). Curves are compared at "
                 "equal strain (interpolated on a common grid), a run that stops before the "
                 "paper's strain fails every check that needs it, and a verdict is printed "
                 "beside its threshold and the measured number.\n")
        L.append("| Sect. | statement | paper | threshold | ours | verdict |")
        L.append("|---|---|---|---|---|---|")
        for c in self.rows:
            L.append(f"| {c.section} | {md(c.statement)} | {md(c.paper)} | {md(c.threshold)} | "
                     f"{md(c.measured)} | {verdict(c.ok)} |")
        L.append(f"\n{npass} pass, {nfail} fail, {ninfo} listed without a verdict. The paper's "
                 "load-strain curves are compared with experiments we do not have, so the load "
                 "values themselves have no pass/fail.\n")
        L.extend(self.sensitivity_section())
        L.append("## Runs and run times\n")
        L.append("Paper: one macroscale simulation with 15-20 load steps took ~15 min (MATLAB, "
                 "i7-5930K).\n")
        L.append("The last column counts the material evaluations outside the fitted data (the "
                 "knit material's end-of-run report in logs/NAME.log; issue 11's bound: <= 2 % "
                 "in every case): all evaluations, Newton's rejected trial iterates included, and "
                 "in brackets the converged states alone (one extra residual pass per step).\n")
        L.append("| case | status | converged steps | final strain | final load [N] | wall [s] | "
                 "extrapolated |")
        L.append("|---|---|---|---|---|---|---|")
        total = 0.0
        for n in names:
            r = self.r(n)
            ex = r.status.get("exit_code", "?")
            stopped = "status: stopped" in r.summary().splitlines()
            defect = None if r.problem else self.data.run_defect(n)
            st = (f"not taken: {md(r.problem)}" if r.problem
                  else f"completed, but {md(defect)}" if r.completed and defect
                  else "completed" if r.completed else
                  ("no status file" if r.ok else "no result (no status file)") if not r.status
                  else f"stopped (exit {ex})" if r.ok and stopped
                  else f"ended in error (exit {ex})" if r.ok
                  # (session 38's red team: a deleted result of exit 0 read "failed (exit 0)")
                  else f"result missing (its status says exit {ex})" if ex == 0
                  else f"failed (exit {ex})")
            steps = len(r.csv.get("step", [])) if r.ok else 0
            fe = r.strain()[-1] if r.ok and steps else float("nan")
            fl = r.load()[-1] if r.ok and steps else float("nan")
            total += r.seconds if math.isfinite(r.seconds) else 0.0
            ex = extrapolations[n]
            exs = "n/a" if ex is None else (f"{100 * ex[1] / max(1, ex[0]):.1f} % of {ex[0]}"
                                           + (f" ({'; '.join(ex[2])})" if ex[2] else ""))
            L.append(f"| {n} | {st} | {steps} | {fmt(100 * fe, 1)} % | {fmt(fl, 3)} | "
                     f"{fmt(r.seconds, 2)} | {exs} |")
        L.append(f"\nAll {len(names)} macroscale cases together: **{total:.1f} s** of wall time "
                 "(sum over the runs; target <= 30 s), against ~15 min each in the paper.\n")
        failed = [n for n in names if not self.r(n).completed]
        for n in failed:
            lines = self.r(n).summary().splitlines()
            msg = [l for l in lines if l.startswith("message:")]
            summ = (msg[0] if msg else "; ".join(lines[:3])) or "no output"
            L.append(f"- `{n}`: {summ} (log: logs/{n}.log)")
        if failed:
            L.append("")
        L.extend(run_warnings(names, self.r))
        L.extend(design_section(self.out))
        L.extend(knitmap_section(self.out))
        L.append("## Figures\n")
        figs = sorted(glob.glob(os.path.join(self.out, "figures", "*.png")))
        if cells != "yes":
            L.append("Fig. 5 (unit cells) is missing: this build has no `knit-meso cell`.\n")
        # Every placeholder is listed here, the design and sensitivity ones (shown in their own
        # sections) too, so that the list matches the summary's count.
        failed_figs = [os.path.basename(p)[:-4] for p in figs if figure_failed(p)]
        for p in figs:
            base = os.path.basename(p)
            if base == SENSITIVITY_FIGURE or base.startswith(("design_", "knitmap_")):
                continue  # shown in its own section
            L.append(f"### {base[:-4]}\n")
            if figure_failed(p):  # session 38's red team: embedded as if drawn
                L.append(f"**The figure script failed**: this is its placeholder (log: "
                         f"logs/figures/{base[:-4]}.log).\n")
            elif note := damage_note(p):
                L.append(note)
            L.append(f"![{base}](figures/{base})\n")
        if failed_figs:
            at = next(i for i, l in enumerate(L) if l.startswith("## Figures"))
            L.insert(at + 1, f"**{len(failed_figs)} figure script(s) failed** (placeholders "
                             f"below): {', '.join(failed_figs)}.\n")
        if missing_figs:
            at = next(i for i, l in enumerate(L) if l.startswith("## Figures"))
            L.insert(at + 1, f"**{len(missing_figs)} figure(s) missing** (drawn by the pipeline, "
                             f"not in figures/): {', '.join(n[:-4] for n in missing_figs)}.\n")
        with open(os.path.join(self.out, "report.md.tmp"), "w") as f:
            f.write("\n".join(L) + "\n")
        os.replace(os.path.join(self.out, "report.md.tmp"), os.path.join(self.out, "report.md"))
        print(f"report: {npass} pass, {nfail} fail")

    def sensitivity_section(self):
        """Observables against the open mesoscale parameters (g0, gamma, ...): the table
        written by the calibration study (format: scripts/figures/sensitivity.py)."""
        L = ["## Sensitivity of the observables to the unit-cell parameters\n"]
        path = self.sensitivity
        if not path or not os.path.exists(path):
            L.append(f"Not yet measured: no sensitivity table (`{path or 'none given'}`; CSV "
                     "with columns parameter, value, observable, result; docs/reproduction.md)."
                     "\n")
            return L
        try:
            rows = read_sensitivity(path)
        except ValueError as e:
            L.append(f"The sensitivity table `{path}` is unreadable: {e}\n")
            return L
        params = sorted({r[0] for r in rows})
        obs = sorted({r[2] for r in rows})
        L.append(f"Table `{path}`: {len(rows)} results, parameters {', '.join(params)}; "
                 f"observables {', '.join(obs)}.\n")
        head = sorted(o for o in obs if o.startswith("min_ratio"))
        if head:
            L.append("Headline (the paper's \"4.5 mm much stiffer than 6.5 mm\", cell level: "
                     "the smallest S(4.5)/S(6.5) over the strain range; scripts/calibrate.py):\n")
            L.append("| parameter | value | " + " | ".join(head) + " |")
            L.append("|---|---|" + "---|" * len(head))
            res = {(r[0], r[1], r[2]): r[3] for r in rows}
            for p, v in sorted({(r[0], r[1]) for r in rows}):
                cells = [fmt(res[(p, v, o)]) if (p, v, o) in res else "–" for o in head]
                L.append(f"| {md(p)} | {v:g} | " + " | ".join(cells) + " |")
            L.append("")
        fig = os.path.join(self.out, "figures", SENSITIVITY_FIGURE)
        if os.path.exists(fig):
            L.append(f"![{SENSITIVITY_FIGURE}](figures/{SENSITIVITY_FIGURE})\n")
        else:
            L.append("(the figure was not drawn: see logs/figures/sensitivity.log)\n")
        return L


# A twin experiment (knit-macro design's "twin", docs/design.md) recovers its twin when every
# variable ends within this fraction of its bound interval of the twin's value: 0.5 %, 0.01 mm
# of a stitch value's 4.5-6.5 mm (the shipped example lands within 1e-13; a design stopped
# by the function tolerance 1e-6 of J within about 0.1 %).
TWIN_TOLERANCE = 0.005


# The designs the pipeline runs and where their files come from (--expect-designs,
# --designs-dir): an expected design whose outputs and inputs are gone is still accounted for
# (session 42's red team: with $(OUT)/design deleted the twin verdict dropped out of the
# summary without a FAIL). Set by main(); empty in the tests that build their own outputs.
EXPECTED_DESIGNS = []
DESIGNS_DIR = None
# The database's date_utc, set by main() (None in the tests that build their own outputs): a
# design or knitting map computed with another database is stale (session 50's red team: with
# the database rebuilt, the twin still counted as recovered and the maps were shown as its own).
DATABASE_DATE = None


def stale_against(used, current, what, rerun="rerun it"):
    """Why an output computed with the database of date `used` (None: it does not say) is not
    the database of date `current`, or None (`current` unknown, or the same date). The one
    rule for case runs (Data.run_defect), designs and knitting maps (session 51's review).
    An UNDATED database tells no output apart from one of another database."""
    if current is None:
        return None
    if current == UNDATED:
        return (f"the database does not say when it was written (no date_utc attribute), so "
                f"{what} cannot be told apart from one computed with another database (use a "
                f"database knit-meso wrote, then {rerun})")
    if used is None:
        return (f"{what} does not say which database it read (written before it recorded the "
                f"date; {rerun})")
    if used != current:
        return (f"stale: {what} was computed with the database written {used}; the database "
                f"is of {current} ({rerun})")
    return None


def stale_output(used, what):
    """stale_against() the pipeline's database (DATABASE_DATE)."""
    return stale_against(used, DATABASE_DATE, what)


def design_stale(out, name):
    """stale_output() of design NAME's final run (design/NAME/run/results.h5's
    material_database_date_utc), or design_output_defect(); None when the design wrote no
    run."""
    h5 = os.path.join(out, "design", name, "run", "results.h5")
    if not os.path.exists(h5):
        return None
    return (stale_output(root_text_attribute(h5, "material_database_date_utc"), "its final run")
            or design_output_defect(out, name))


def design_output_defect(out, name):
    """Why design NAME's outputs disagree with each other, or None: each variable's end value
    in summary.txt ('variable NAME: START -> END in [LO, HI]') must be the designed case's
    (design/NAME/case.json) field value at the variable's indices (design/inputs/NAME.json), to
    the summary's six digits, and the final run's results.h5 /case_json must be that case
    (session 52's red team: l = 5.0 written into case.json, run/case.json and history.csv beside
    a summary of l = 6 still "recovered" the twin)."""
    d = os.path.join(out, "design", name)
    try:
        with open(os.path.join(out, "design", "inputs", name + ".json")) as f:
            variables = json.load(f).get("variables", [])
        with open(os.path.join(d, "case.json")) as f:
            case = json.load(f)
    except (OSError, ValueError, AttributeError):
        return None  # no input or no case: the design's own row says what is missing
    summ = read_design_summary(os.path.join(d, "summary.txt"))
    material = case.get("material", {}) if isinstance(case, dict) else {}
    for v in variables if isinstance(variables, list) else []:
        if not isinstance(v, dict) or "name" not in v or "field" not in v:
            continue
        m = re.match(r"^\S+ -> (\S+) in \[(\S+), (\S+)\]", summ.get("variable " + v["name"], ""))
        field = material.get(v["field"])
        values = field.get("values") if isinstance(field, dict) else [field]
        if not m or not isinstance(values, list):
            continue
        try:
            end, lo, hi = (float(x) for x in m.groups())
        except ValueError:
            continue
        indices = v.get("indices", [0])
        for i in indices if isinstance(indices, list) else [indices]:
            got = values[i] if isinstance(i, int) and 0 <= i < len(values) else None
            if not isinstance(got, (int, float)) or not abs(got - end) <= 1e-5 * max(
                    abs(end), hi - lo):
                return (f"its case.json has {v['field']} value {got} at index {i} where its "
                        f"summary.txt ends variable {v['name']} at {end:g}: the outputs are "
                        "not of one design")
    try:
        held = case_json_of(os.path.join(d, "run", "results.h5"))
    except (ValueError, ImportError) as e:
        return f"its final run's results.h5 /case_json is not JSON, or cannot be read ({e})"
    if held is not None:
        ptr = json_difference(case, held)
        if ptr is not None:
            return (f"its final run (run/results.h5 /case_json) differs from its case.json at "
                    f"{ptr or '/'}")
    return None


def declared_twins(out):
    """{design: {variable: value}} of the design inputs of the run ($(OUT)/design/inputs/*.json
    with a "twin"): what each design was asked to recover, independent of its outputs; for an
    expected design (EXPECTED_DESIGNS), its file in DESIGNS_DIR too, whose twin counts unless
    the run's own input declares one."""
    twins = {}
    paths = [os.path.join(DESIGNS_DIR, n + ".json") for n in EXPECTED_DESIGNS] if DESIGNS_DIR \
        else []
    paths += sorted(glob.glob(os.path.join(out, "design", "inputs", "*.json")))
    for p in paths:  # the run's own inputs last: they win
        if not os.path.exists(p):
            continue
        try:
            with open(p) as f:
                j = json.load(f)
        except (OSError, ValueError):
            continue
        if isinstance(j, dict) and isinstance(j.get("twin"), dict):
            twins[os.path.basename(p)[:-5]] = j["twin"]
    return twins


def design_exit_code(out, name):
    """The exit code in $(OUT)/design/NAME.status, or None (missing or unreadable)."""
    try:
        with open(os.path.join(out, "design", name + ".status")) as f:
            return json.load(f).get("exit_code")
    except (OSError, ValueError, AttributeError):
        return None


def twin_verdict(summ, declared=None, exit_code=0):
    """(ok, text) of a design's twin lines in summary.txt ({key: value}, design.read_summary),
    or None for a design without a twin: 'twin NAME: V (recovered X, off by P % of the
    bounds)'. A twin line that cannot be read, or a design whose status is not converged, does
    not recover. `declared`: the twin of the design's input ({variable: value}); then a design
    with no twin line (no output), another twin value (a stale summary) or a twin variable
    missing does not recover either (session 38's red team: a deleted design output dropped
    out of the count, and a summary of another twin passed). `exit_code`: the design's, from
    its status file (None: unknown); anything but 0 does not recover."""
    rows = [(k[len("twin "):], v) for k, v in summ.items()
            if k.startswith("twin ") and not k.startswith("twin target ")]
    if not rows and not declared:
        return None
    parts, ok = [], summ.get("status") == "converged" and exit_code == 0
    if declared:
        written = {n for n, _ in rows}
        for name in sorted(set(declared) - written):
            parts.append(f"{name}: declared (twin {declared[name]}) but not in the summary "
                         f"({'no output' if not summ else 'no twin line'})")
            ok = False
    number = r"(\S+)"
    for name, value in rows:
        # The distance is recomputed from the twin and the variable's own line ('variable
        # NAME: START -> END in [LO, HI] UNIT', the unit since session 39), not taken from the
        # summary's "off by".
        m = re.match(r"^%s \(recovered %s, off by \S+ %% of the bounds\)$" % (number, number),
                     value)
        v = re.match(r"^\S+ -> %s in \[%s, %s\](?: (?:mm|deg|rad))?$" % (number, number, number),
                     summ.get("variable " + name, ""))
        try:
            twin, got = (float(x) for x in m.groups()) if m else (None, None)
            end, lo, hi = (float(x) for x in v.groups()) if v else (None, None, None)
        except ValueError:
            twin = end = None
        if (twin is None or end is None or
                not all(math.isfinite(x) for x in (twin, got, end, lo, hi)) or not hi > lo
                or got != end):
            parts.append(f"{name}: unreadable ({value}; variable line: "
                         f"{summ.get('variable ' + name, 'missing')})")
            ok = False
            continue
        off = 100 * abs(end - twin) / (hi - lo)
        ok = ok and off <= 100 * TWIN_TOLERANCE
        parts.append(f"{name} {end:.6g} (twin {twin:g}, off by {off:.2g} % of [{lo:g}, {hi:g}])")
        if declared is not None:
            want = declared.get(name)
            # (the summary prints the twin with 6 significant digits: equal to 1e-6 relative)
            if not isinstance(want, (int, float)) or abs(float(want) - twin) > 1e-6 * max(
                    1.0, abs(twin)):
                ok = False
                parts.append(f"{name}: the input's twin is {want}, not {twin:g} (a stale summary)")
    if summ.get("status") != "converged":
        parts.append(f"status {summ.get('status', 'missing')}")
    if exit_code != 0:
        parts.append(f"exit {exit_code if exit_code is not None else 'unknown'}")
    return ok, "; ".join(parts)


def run_warnings(names, result):
    """The `warning:` lines of each run's summary.txt (knit-macro's: the law's own uniaxial
    response against the cell's, extrapolation, load drops, the solver's fallback), one item
    each, under the runs' table (session 41: the uniaxial one was in the logs only)."""
    rows = []
    for n in names:
        for line in result(n).summary().splitlines():
            if line.startswith("warning:"):
                rows.append(f"- `{n}`: {md(line[len('warning:'):].strip())}")
    if not rows:
        return ["No run warned (`warning:` lines of summary.txt).\n"]
    return (["Warnings of the runs (the `warning:` lines of their summary.txt, not judged; "
             "docs/case-format.md):\n"] + rows + [""])


def design_section(out):
    """Inverse design (issue 13, docs/design.md): each example's status, objective before and
    after and its figure, from $(OUT)/design/NAME.status and NAME/summary.txt."""
    L = ["## Inverse design (knit-macro design)\n"]
    twins = declared_twins(out)
    names = sorted({os.path.basename(p)[:-7]
                    for p in glob.glob(os.path.join(out, "design", "*.status"))} | set(twins)
                   | set(EXPECTED_DESIGNS))
    if not names:
        L.append("No design example was run (`make -f scripts/pipeline.mk designs`).\n")
        return L
    L.append("The examples of cases/design (docs/design.md): `knit-macro design` with the "
             "pipeline's database; J is the weighted least-squares objective.\n")
    L.append(f"A twin experiment (`twin` in the design file) takes its targets from the case run "
             f"at the twin's values and must recover them: every variable within "
             f"{100 * TWIN_TOLERANCE:g} % of its bound interval, with the status converged.\n")
    L.append("| example | status | J before | J after | iterations | evaluations | wall [s] | "
             "twin recovered |")
    L.append("|---|---|---|---|---|---|---|---|")
    for n in names:
        try:
            with open(os.path.join(out, "design", n + ".status")) as f:
                st = json.load(f)
            if not isinstance(st, dict):  # session 55's red team: "[0]" ended in a traceback
                st = None
        except (OSError, ValueError):
            st = None  # unreadable
        missing = not os.path.exists(os.path.join(out, "design", n + ".status"))
        exit_code = ("? (no status file)" if missing else "? (status file unreadable)"
                     if st is None else st.get("exit_code", "?"))
        # Exit 2 or more wrote nothing: a summary.txt in design/NAME is an earlier run's
        # (session 45: it was shown as this run's, with "(exit 2)" beside it).
        wrote = st is None or last_run_wrote(st)
        summ = (read_design_summary(os.path.join(out, "design", n, "summary.txt")) if wrote
                else {})
        status = summ.get("status", f"no output (exit {exit_code})")
        if not wrote:
            why = first_error_line(os.path.join(out, "logs", f"design_{n}.log"))
            status += f": {why}" if why else ""
        if "status" in summ and exit_code != 0:  # the summary alone is not the verdict
            status += f" (exit {exit_code})"
        stale = design_stale(out, n) if wrote else None
        if stale:
            status += f"; **{stale}**"
        L.append(f"| {n} | {md(status)} | {md(summ.get('J_initial', '-'))} | "
                 f"{md(summ.get('J_final', '-'))} | {summ.get('iterations', '-')} | "
                 f"{summ.get('evaluations', '-')} | "
                 f"{fmt((st or {}).get('seconds', float('nan')), 1)} | "
                 f"{md(twin_cell(summ, twins.get(n), None if st is None else exit_code, stale))} |")
    return L + section_figures(out, [f"design_{n}.png" for n in names])


def section_figures(out, names):
    """A section's figures that exist in OUT/figures, each under its own heading, after an
    empty line that ends the section's table."""
    L = [""]
    for fig in names:
        path = os.path.join(out, "figures", fig)
        if os.path.exists(path):
            L.append(f"### {fig[:-4]}\n")
            note = damage_note(path)
            if note:
                L.append(note)
            L.append(f"![{fig}](figures/{fig})\n")
    return L


def knitmap_section(out):
    """The knitting maps (docs/design.md, "The knitting map"; session 39: drawn by the main job,
    before only by `make ... knitmaps`): per planar paper case, the totals of its summary.txt
    ($(OUT)/knitmap/NAME/) and its figure; warnings named."""
    L = ["## Knitting maps (knit-macro knitmap)\n"]
    # Since session 45 the pipeline records each run's exit code in knitmap/NAME.status: a run
    # that failed is said so, and an earlier run's summary.txt left in knitmap/NAME is not shown
    # as its result.
    names = sorted({os.path.basename(os.path.dirname(p))
                    for p in glob.glob(os.path.join(out, "knitmap", "*", "summary.txt"))}
                   | {os.path.basename(p)[:-len(".status")]
                      for p in glob.glob(os.path.join(out, "knitmap", "*.status"))})
    if not names:
        L.append("No knitting map was made (`make -f scripts/pipeline.mk knitmaps`).\n")
        return L
    L.append("Course by course and needle by needle, the loop length of each stitch of the "
             "planar paper cases (`knit-macro knitmap` with the pipeline's database; "
             "knitmap.csv and courses.csv in knitmap/NAME/).\n")
    L.append("| case | stitches | needles | courses | yarn [m] | l [mm] | warnings |")
    L.append("|---|---|---|---|---|---|---|")
    for n in names:
        failed = knitmap_failure(out, n)
        if failed:
            L.append(f"| {n} | - | - | - | - | - | **failed**: {md(failed)} |")
            continue
        summ = read_design_summary(os.path.join(out, "knitmap", n, "summary.txt"))
        stale = stale_output(summ.get("database_date_utc"), "the map")
        if stale:
            L.append(f"| {n} | - | - | - | - | - | **{md(stale)}** |")
            continue
        try:
            yarn = f"{float(summ.get('yarn_length_mm', 'nan')) / 1000:.2f}"
            lo, hi = (float(summ.get(k, "nan")) for k in ("loop_length_min_mm",
                                                           "loop_length_max_mm"))
            lrange = f"{lo:.2f}-{hi:.2f}"
        except ValueError:
            yarn, lrange = "?", "?"
        try:  # every warning line (read_design_summary keeps the first of a key)
            with open(os.path.join(out, "knitmap", n, "summary.txt")) as f:
                warnings = [line[len("warning:"):].strip() for line in f
                            if line.startswith("warning:")]
        except OSError:
            warnings = []
        L.append(f"| {n} | {summ.get('stitches', '?')} | {summ.get('needles', '?')} | "
                 f"{summ.get('courses', '?')} | {yarn} | {lrange} | "
                 f"{md('; '.join(warnings)) if warnings else '-'} |")
    return L + section_figures(out, [f"knitmap_{n}.png" for n in names])


def laws_used_text(extrapolations):
    """'; the cases evaluated ...' for the summary line when the cases' logs (extrapolation()
    per case) show a law other than the energy law alone, else "" (session 45's red team: with
    "energy_fit": false every case ran on the paper's eq. 17 surfaces, and the report never
    said so)."""
    used = sorted({ex[3] for ex in extrapolations.values() if ex is not None})
    if not used or used == ["energy"]:
        return ""
    names = {"paper": "the paper's law (eq. 17)", "energy": "the energy law"}
    return ("; the cases evaluated " + " and ".join(names.get(u, u) for u in used) +
            ", by their logs")


def no_result_reason(res_dir, names):
    """Why no case has a result: the cases were not run, or (session 45's red team) they ran
    and were refused, e.g. by a database whose loop lengths cover none of them: then how many
    and the first refusal's error line from its log (OUT/logs/NAME.log)."""
    codes = {}
    for n in names:
        try:
            with open(os.path.join(res_dir, n + ".status")) as f:
                codes[n] = json.load(f).get("exit_code")
        except (OSError, ValueError, AttributeError):
            pass
    if not codes:
        return "run the cases first (make -f scripts/pipeline.mk cases)"
    refused = [n for n in names if codes.get(n) not in (None, 0, 1)]
    why = ""
    for n in refused:
        why = first_error_line(os.path.join(os.path.dirname(res_dir), "logs", n + ".log"))
        if why:
            why = f" (first: {n}: {why})"
            break
    return (f"{len(codes)} of {len(names)} cases ran, {len(refused)} of them refused with exit "
            f"2 or more{why}: fix what the logs say (e.g. a database whose loop lengths do not "
            f"cover the cases) and run them again")


def sweep_command(source):
    """The sweep that made the database, from database.source's words (mode, sweep input):
    the input as the pipeline was given it (SWEEP_INPUT), relative to the checkout when inside
    it. Session 45: the report named cases/sweep/default.json whatever the input was."""
    if len(source) < 2 or source[0] != "sweep":
        return "its sweep input is not recorded in database.source"
    # (the words after the path are the inputs' digests, scripts/figures/input_digest.py)
    path = " ".join(w for w in source[1:] if not w.startswith(("sha256:", "cell:", "unreadable")))
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    rel = os.path.relpath(path, root) if os.path.isabs(path) else path
    return f"`knit-meso sweep {rel if not rel.startswith('..') else path}`"


def knitmap_failure(out, name):
    """Why the pipeline's knitmap run of `name` failed, or "" if it did not (or was made
    before status files existed, session 45): its exit code and the first error line of
    logs/knitmap_NAME.log."""
    path = os.path.join(out, "knitmap", name + ".status")
    if not os.path.exists(path):
        return ""
    try:
        with open(path) as f:
            code = json.load(f).get("exit_code", "?")
    except (OSError, ValueError):
        return f"its status file {path} is unreadable"
    if code == 0:
        return ""
    why = f"exit {code}"
    first = first_error_line(os.path.join(out, "logs", f"knitmap_{name}.log"))
    return why + (f": {first}" if first else "")


def twin_cell(summ, declared=None, exit_code=0, stale=None):
    """The design table's twin column: '-' without a twin, else the verdict and the numbers;
    a stale design (design_stale) does not recover."""
    t = twin_verdict(summ, declared, exit_code)
    if t is None:
        return "-"
    return f"{verdict(t[0] and not stale)}: {t[1]}" + (f"; {stale}" if stale else "")


def database_seconds(tfile):
    """The database's build time from $(OUT)/database.time ({"seconds": ...}), or None when
    the file is missing or is not such a record (session 55's red team: a truncated file ended
    the report in a JSONDecodeError traceback, no report written)."""
    try:
        with open(tfile) as f:
            v = json.load(f).get("seconds")
        return float(v) if isinstance(v, (int, float)) else None
    except (OSError, ValueError, AttributeError):
        return None


def database_time_line(db_seconds, loops):
    """The database section's line on its build time: the paper's ~30 min per loop length
    only beside a database whose loop lengths were read (session 38's red team: with
    database.h5 missing it said "~30 min for 1 loop lengths")."""
    if not loops:
        return (f"- time to build it: {fmt(db_seconds, 1)} s (no loop lengths read: the "
                "database is missing or unreadable, see above)")
    n = len(loops)
    return (f"- time to build it: {fmt(db_seconds, 1)} s (paper: ~30 min per loop length, "
            f"i.e. ~{30 * n} min for {n} loop length{'s' if n != 1 else ''}, on 6 cores)")


def twin_counts(out):
    """(recovered, twins) over the designs of $(OUT)/design that have a twin."""
    twins = declared_twins(out)
    names = ({os.path.basename(p)[:-7] for p in glob.glob(os.path.join(out, "design", "*.status"))}
             | set(twins) | set(EXPECTED_DESIGNS))
    got = [(twin_verdict(read_design_summary(os.path.join(out, "design", n, "summary.txt")),
                         twins.get(n), design_exit_code(out, n)), design_stale(out, n))
           for n in sorted(names)]
    got = [(t, stale) for t, stale in got if t is not None]
    return sum(1 for (ok, _), stale in got if ok and not stale), len(got)


PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
PNG_END = b"\x00\x00\x00\x00IEND\xaeB`\x82"  # the IEND chunk: length 0, type, CRC


def figure_damage(path):
    """Why a figure file is not a complete PNG image, or None: its signature, a first IHDR
    chunk of a positive size and the IEND chunk at its end (not a decode). Session 55's red
    team: an empty file, a text file and a PNG cut to 200 bytes were embedded as drawn, and
    --strict exited 0."""
    try:
        with open(path, "rb") as f:
            head = f.read(24)
            size = f.seek(0, os.SEEK_END)
            f.seek(max(0, size - len(PNG_END)))
            tail = f.read()
    except OSError as e:
        return f"unreadable ({e.strerror})"
    if size == 0:
        return "an empty file"
    if head[:8] != PNG_SIGNATURE:
        return "not a PNG image"
    if len(head) < 24 or head[12:16] != b"IHDR" or min(int.from_bytes(head[16:20], "big"),
                                                       int.from_bytes(head[20:24], "big")) == 0:
        return "a PNG without an image header"
    if tail != PNG_END:
        return "a PNG cut short (no end chunk)"
    return None


def damage_note(path):
    """The line put above a damaged figure (figure_damage), or None."""
    why = figure_damage(path)
    return f"**The figure file is damaged**: {why}; draw it again.\n" if why else None


def figure_failed(path):
    """Whether a figure is the placeholder of a figure script that failed: scripts/figures/
    batch.py dates those 1970 (mtime 0) so that the next run draws them again."""
    try:
        return os.path.getmtime(path) < 86400
    except OSError:
        return False


def md(text):
    """A table cell: pipes escaped."""
    return str(text).replace("|", "\\|")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out-dir", required=True)
    ap.add_argument("--database", required=True)
    ap.add_argument("--cells", default="")
    ap.add_argument("--sensitivity", default="",
                    help="sensitivity table (CSV: parameter,value,observable,result)")
    ap.add_argument("--expect-figures", default="",
                    help="the figures the pipeline draws (file names, blank-separated): a "
                         "missing one is named in the report")
    ap.add_argument("--cases-dir", default=CASES_DIR,
                    help="the case files the pipeline runs (default: the checkout's cases/paper)")
    ap.add_argument("--expect-designs", default="",
                    help="the design examples the pipeline runs (names, blank-separated): one "
                         "without outputs is listed, and its twin, if its file declares one, "
                         "FAILs")
    ap.add_argument("--designs-dir", default=os.path.join(os.path.dirname(CASES_DIR), "design"),
                    help="where the expected designs' files are when $(OUT)/design/inputs lacks "
                         "them (default: the checkout's cases/design)")
    ap.add_argument("--strict", action="store_true",
                    help="exit 3 (after writing report.md) when a check of the runs themselves "
                         "fails, a case did not complete, a twin experiment was not recovered "
                         "or a figure failed, is missing or is damaged; the paper's statements "
                         "and the law's checks are reported, not judged here")
    a = ap.parse_args()
    global EXPECTED_DESIGNS, DESIGNS_DIR, DATABASE_DATE
    EXPECTED_DESIGNS, DESIGNS_DIR = a.expect_designs.split(), a.designs_dir
    if not glob.glob(os.path.join(a.cases_dir, "*.json")):
        print(f"report: error: --cases-dir {a.cases_dir}: holds no case file (*.json)",
              file=sys.stderr)
        sys.exit(2)
    rep = Report(a.out_dir, a.sensitivity, a.cases_dir, a.database)
    DATABASE_DATE = rep.data.db_date  # read once, by Report
    rep.expected_figures = a.expect_figures.split()
    if not any(rep.r(n).ok for n in rep.names):
        # Nothing to judge: a report of 0 passes would read as a result (session 30: exit 0).
        print(f"report: error: {rep.res_dir}: no case of {a.cases_dir} has a result "
              f"(load_strain.csv); {no_result_reason(rep.res_dir, rep.names)}; report.md is "
              "left as it was", file=sys.stderr)
        sys.exit(1)
    rep.checks()
    rep.write(a.database, a.cells)
    if a.strict and rep.strict_problems():
        print(f"report: --strict: {'; '.join(rep.strict_problems())} (written: "
              f"{os.path.join(rep.out, 'report.md')})", file=sys.stderr)
        sys.exit(3)


if __name__ == "__main__":
    main()
