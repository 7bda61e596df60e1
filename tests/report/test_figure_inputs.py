#!/usr/bin/python3
"""The figure scripts a user runs on a directory (scripts/figures/knitmap.py, design.py,
cells.py, sensitivity.py) refuse a missing or damaged input with one line naming the file and a
non-zero exit, without a Python traceback (scripts/figures/figure_inputs.py; session 22: they
ended in FileNotFoundError and JSONDecodeError tracebacks), and draw nothing.
Run by CTest (tests/CMakeLists.txt, label report) with Debian's /usr/bin/python3.
"""
import os
import subprocess
import sys
import tempfile

from checklist import Checklist  # tests/report/checklist.py, beside this file

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
FIG = os.path.join(ROOT, "scripts", "figures")


def run(script, *args):
    return subprocess.run([sys.executable, os.path.join(FIG, script)] + list(args),
                          capture_output=True, text=True, env=dict(os.environ, MPLBACKEND="Agg"))


def main():
    c = Checklist()
    with tempfile.TemporaryDirectory(prefix="figure_inputs_test_") as tmp:
        missing = os.path.join(tmp, "missing")
        damaged = os.path.join(tmp, "damaged")
        os.makedirs(damaged)
        with open(os.path.join(damaged, "history.csv"), "w") as f:
            f.write("iteration,J\n0,1\n1,0.5\n")
        for name in ("case.json", "cell.json"):
            with open(os.path.join(damaged, name), "w") as f:
                f.write("{\n")
        png = os.path.join(tmp, "x.png")
        table = os.path.join(tmp, "table.csv")
        with open(table, "w") as f:
            f.write("p,v\n")
        jobs = [
            (("knitmap.py", missing, "--out", png), os.path.join(missing, "knitmap.csv")),
            (("design.py", missing, "--out", png), os.path.join(missing, "history.csv")),
            (("design.py", damaged, "--out", png),
             os.path.join(damaged, "case.json") + ": not valid JSON (line 2"),
            (("cells.py", "--out", png, missing), os.path.join(missing, "cell.json")),
            (("cells.py", "--out", png, damaged),
             os.path.join(damaged, "cell.json") + ": not valid JSON (line 2"),
            (("sensitivity.py", "--out", png, table), table + ":1: header must be"),
        ]
        for args, expect in jobs:
            r = run(*args)
            what = " ".join(os.path.relpath(a, tmp) if a.startswith(tmp) else a for a in args)
            c(r.returncode != 0 and not os.path.exists(png),
              f"{what}: refused (exit {r.returncode}), nothing drawn", r.stderr[-500:])
            c(expect in r.stderr and "Traceback" not in r.stderr,
              f"{what}: one line naming the file, no traceback", r.stderr[-500:])
        # A run that wrote nothing (the pipeline's status file, session 45): its directory may
        # hold an earlier run's map or design, which is not drawn as this run's; the figure is
        # a placeholder saying so with its log's error line, exit 0 (not a failed figure).
        stale = os.path.join(tmp, "stale")
        os.makedirs(stale)
        with open(os.path.join(stale, "knitmap.csv"), "w") as f:
            f.write("course,needle,x_mm,y_mm,l_mm\n1,1,0,0,5.0\n1,2,1,0,5.5\n")
        with open(os.path.join(stale, "summary.txt"), "w") as f:
            f.write("stitches: 2\nyarn_length_mm: 10.5\n")
        os.makedirs(os.path.join(tmp, "knitmap"))
        os.makedirs(os.path.join(tmp, "design"))
        os.makedirs(os.path.join(tmp, "logs"))
        with open(os.path.join(tmp, "logs", "knitmap_stale.log"), "w") as f:
            f.write("knit-macro knitmap: error: c.json: 6.5 mm is outside the database's\n")
        status = os.path.join(tmp, "knitmap", "stale.status")
        dstatus = os.path.join(tmp, "design", "d.status")
        for st_path, st, script, d, want_placeholder, what in (
                (status, '{"knitmap": "stale", "exit_code": 2}', "knitmap.py", stale, True,
                 "knitmap.py, exit 2"),
                (status, '{"knitmap": "stale", "exit_code": 0, "wrote": false}', "knitmap.py",
                 stale, True, "knitmap.py, exit 0 but wrote false"),
                (dstatus, '{"design": "d", "exit_code": 1, "wrote": false}', "design.py",
                 damaged, True, "design.py, exit 1 that wrote nothing"),
                (dstatus, '{"design": "d", "exit_code": 2}', "design.py", damaged, True,
                 "design.py, exit 2"),
                (status, '{"knitmap": "stale", "exit_code": 0, "wrote": true}', "knitmap.py",
                 stale, False, "knitmap.py, a run that wrote its map")):
            with open(st_path, "w") as f:
                f.write(st + "\n")
            if os.path.exists(png):
                os.remove(png)
            r = run(script, d, "--status", st_path, "--out", png)
            said = "wrote nothing: drew a placeholder" in r.stdout
            c(r.returncode == 0 and os.path.exists(png) and said == want_placeholder
              and "Traceback" not in r.stderr,
              f"{what}: {'a placeholder' if want_placeholder else 'drawn'}, exit 0",
              r.stdout[-300:] + r.stderr[-300:])
    sys.path.insert(0, FIG)
    from results import last_run_wrote  # noqa: E402
    for st, want in (({}, True), ({"exit_code": 0}, True), ({"exit_code": 1}, True),
                     ({"exit_code": 2}, False), ({"exit_code": 1, "wrote": False}, False),
                     ({"exit_code": 2, "wrote": True}, True)):
        c(last_run_wrote(st) is want, f"last_run_wrote({st}) is {want}")
    # A mesh study's legend names each mesh and its corner condition (session 26: the h = 1
    # curve of Sect. 3.2.1's study read "diagonal (load along the diagonal)").
    sys.path.insert(0, FIG)
    import plots  # noqa: E402
    point = {"refinement": {"degree": 5, "elements": [1, 1]},
             "boundary_conditions": [{"all": True, "fix": ["z"]}, {"corner": "u0v0", "fix": ["x"]}]}
    pad = {"refinement": {"degree": 5, "elements": [4, 4]},
           "boundary_conditions": [{"corner": "u1v1", "fix": ["x"], "radius": 5.0}]}
    edges = {"refinement": {"degree": 3, "elements": [4, 2]},
             "boundary_conditions": [{"edge": "v0", "fix": ["x"]}]}
    for case, want in ((point, "p = 5, h = 1 (corner point)"), (pad, "p = 5, h = 4 (5 mm pad)"),
                       (edges, "p = 3, h = 4x2"), ({}, None)):
        got = plots.mesh_label(case)
        c(got == want, f"mesh_label: {want!r}", repr(got))
    c(plots.label_of("s321_bilinear_diagonal", point, study=True) == "p = 5, h = 1 (corner point)"
      and plots.label_of("s321_bilinear_diagonal", point) == plots.LABELS["s321_bilinear_diagonal"],
      "label_of: by mesh in a study only")
    # The load-strain figures mark the runs whose law departs from the cell in uniaxial
    # tension (session 41): knit-macro's warning line in summary.txt, not another warning.
    # fig07e labels each run by the law its summary says it evaluated (session 45's red team:
    # with a database without the energy law, the default runs were labelled "energy law").
    c(plots.law_of_run("material report: knit material (energy law): 10 evaluations; 0 "
                       "extrapolated\n", "paper's law") == "energy law"
      and plots.law_of_run("status: completed\nmaterial report: knit material: 10 evaluations; "
                           "extrapolated:\n", "energy law") == "paper's law"
      and plots.law_of_run("status: completed\n", "energy law") == "energy law",
      "law_of_run: the summary's material report, else the expected law")
    c(plots.uniaxial_warned("status: completed\nwarning: where the fabric is stretched "
                            "uniaxially along the wale (E_wale, the material frame's E22), ...\n")
      and not plots.uniaxial_warned("status: completed\nwarning: load drop: ...\n")
      and not plots.uniaxial_warned(""), "uniaxial_warned: knit-macro's uniaxial line only")
    # plots.py: a results directory or a case the pipeline never made is a command-line
    # mistake (exit 2, named), not a failed run drawn as a placeholder with exit 0 (session 36).
    with tempfile.TemporaryDirectory(prefix="plots_args_test_") as tmp:
        res = os.path.join(tmp, "results")
        os.makedirs(os.path.join(res, "made"))
        png = os.path.join(tmp, "x.png")
        for args, needle in (
                (("--results", os.path.join(tmp, "nope"), "load", "--out", png, "made"),
                 "--results: " + os.path.join(tmp, "nope") + " is not a directory"),
                (("--results", res, "load", "--out", png, "made", "mdae"),
                 "mdae: no status file and no output in " + res),
                (("--results", res, "deformed", "--case", "mdae", "--field", "E22", "--out", png),
                 "mdae: no status file and no output")):
            r = run("plots.py", *args)
            c(r.returncode == 2 and needle in r.stderr and "Traceback" not in r.stderr
              and not os.path.exists(png), "plots.py %s: exit 2, named" % args[2], r.stderr)
        r = run("plots.py", "--results", res, "load", "--out", png, "made")
        c(r.returncode == 0 and os.path.exists(png),
          "plots.py on a made case without a curve draws its placeholder", r.stderr)
        # The two laws side by side (fig07e, session 43): both directories must hold the case.
        os.remove(png)
        paper = os.path.join(tmp, "paper")
        for args, needle in (
                (("--results", res, "laws", "--paper-results", os.path.join(tmp, "nope"),
                  "--out", png, "made"), "--paper-results: " + os.path.join(tmp, "nope")),
                (("--results", res, "laws", "--paper-results", res, "--out", png, "mdae"),
                 "mdae: no status file and no output in " + res)):
            r = run("plots.py", *args)
            c(r.returncode == 2 and needle in r.stderr and not os.path.exists(png),
              "plots.py laws %s: exit 2, named" % args[4][len(tmp):], r.stderr)
        for d in (res, paper):
            os.makedirs(os.path.join(d, "made"), exist_ok=True)
            with open(os.path.join(d, "made", "load_strain.csv"), "w") as f:
                f.write("step,load_factor,applied_displacement_mm,strain,load_N,iterations,"
                        "residual,seconds,negative_pivots,determinant_sign\n"
                        "1,0.5,1,0.1,2,3,0,0,-1,1\n2,1,2,0.2,3,3,0,0,-1,-1\n")
        r = run("plots.py", "--results", res, "laws", "--paper-results", paper, "--out", png,
                "made")
        c(r.returncode == 0 and os.path.exists(png), "plots.py laws draws both runs", r.stderr)
        # A paper-law run without a curve is named below the axis (session 43's review: the
        # figure drew the energy curve alone beside a note promising the dashed one).
        notes = []
        saved = plots.finish_load_figure
        plots.finish_load_figure = lambda fig, ax, a, drawn, size, note: notes.append(note)
        try:
            os.remove(os.path.join(paper, "made", "load_strain.csv"))  # no curve, status kept
            with open(os.path.join(paper, "made.status"), "w") as f:
                f.write('{"case": "made", "exit_code": 1, "seconds": 0.1}')

            class Args:
                results, paper_results, cases, out, title = res, paper, ["made"], png, "t"
            plots.cmd_laws(Args())
        finally:
            plots.finish_load_figure = saved
        c(len(notes) == 1 and "no curve" in notes[0] and "made (paper's law)" in notes[0]
          and "made (energy law)" not in notes[0], "plots.py laws names a missing paper-law curve",
          repr(notes))
    c(list(plots.negative_determinant(plots.np.array([1, -1, 0, -1]))) ==
      [False, False, True, False, True] and not plots.negative_determinant(None).any(),
      "negative_determinant: the steps with det K < 0, after the origin")
    # Figures are written through a temporary and a rename (figure_inputs.save_figure, session
    # 36): a drawing killed or failing half-way leaves no PNG that make takes as complete.
    sys.path.insert(0, FIG)
    import re
    from figure_inputs import save_figure

    class Failing:
        def savefig(self, path, **kw):
            with open(path, "w") as f:
                f.write("half a PNG")
            raise RuntimeError("killed while drawing")

    with tempfile.TemporaryDirectory(prefix="figure_save_test_") as tmp:
        out = os.path.join(tmp, "fig.png")
        try:
            save_figure(Failing(), out)
        except RuntimeError:
            pass
        c(not os.path.exists(out), "a drawing that fails half-way leaves no figure at its name")
    # Every figure script saves through a temporary: no savefig straight to its output.
    direct = []
    for name in sorted(os.listdir(FIG)):
        if name.endswith(".py") and name != "figure_inputs.py":
            with open(os.path.join(FIG, name)) as f:
                for m in re.finditer(r"\.savefig\(\s*([A-Za-z_.]+)", f.read()):
                    if m.group(1) != "tmp":
                        direct.append(f"{name}: savefig({m.group(1)}")
    c(not direct, "no figure script saves straight to its output: %s" % direct)
    # design.py labels a designed angle field in its own unit (session 39: degrees said rad).
    sys.path.insert(0, FIG)
    import design  # noqa: E402
    import math
    spec = {"degrees": [0, 0], "knots_u": [0, 1], "knots_v": [0, 1], "values": [30],
            "unit": "deg"}
    scale = design.field_grid(spec, n=3)[4]
    c(design.field_unit("knitting_angle", scale) == "deg", "an angle field in deg is labelled deg")
    spec["unit"] = "rad"
    c(design.field_unit("knitting_angle", design.field_grid(spec, n=3)[4]) == "rad",
      "an angle field in rad is labelled rad")
    c(design.field_unit("stitch_value", 1.0) == "mm", "the stitch value is labelled mm")
    c(abs(scale - math.pi / 180) < 1e-15, "field_grid's scale of a deg field is pi / 180")
    # design.py draws displacement objectives from summary.txt's 'reached' lines (session 40).
    summ = {"reached pull": "5.11828 21.6887 N (target 10 100; at strain 0.1 0.2)",
            "reached center_ux": "4.17938 mm (target 4; at strain 0.2)", "reached bad": "x mm"}
    c(design.reached_values(summ, "pull") == ([5.11828, 21.6887], "N"),
      "two values and the unit N: %s" % (design.reached_values(summ, "pull"),))
    c(design.reached_values(summ, "center_ux") == ([4.17938], "mm"),
      "one value in mm: %s" % (design.reached_values(summ, "center_ux"),))
    c(design.reached_values(summ, "bad") is None and design.reached_values(summ, "none") is None,
      "a line without numbers and a missing line give None")
    # A field uniform to round-off is drawn in one colour around its value (session 40).
    import numpy as np
    lo, hi, uniform = design.colour_limits(np.array([[5.982232096, 5.982232096 + 1e-11]]))
    c(uniform and abs(lo - (5.982232096 - 0.01 * 5.982232096)) < 1e-9 and lo < 5.98 < 6.0 < hi,
      "l = 5.98 +- 1e-11: uniform, scale 5.98 +- 1 %%: %s" % ((lo, hi, uniform),))
    lo, hi, uniform = design.colour_limits(np.array([[4.5, 6.5]]))
    c(not uniform and (lo, hi) == (4.5, 6.5), "a graded field keeps its range: %s" % ((lo, hi),))
    lo, hi, uniform = design.colour_limits(np.zeros((2, 2)))
    c(uniform and (lo, hi) == (-0.01, 0.01), "alpha = 0: +-0.01 around 0: %s" % ((lo, hi),))
    return c.exit_code()


if __name__ == "__main__":
    sys.exit(main())
