#!/usr/bin/python3
"""The report's verdict on twin experiments (scripts/report.py, twin_verdict; session 37): a
design with a twin recovers it when its status is converged and every variable ends within
TWIN_TOLERANCE of its bound interval of the twin's value, recomputed from the summary's
variable lines; a design off by more, one that did not converge, one whose twin line disagrees
with its variable line and one whose lines cannot be read do not; a design without a twin has
no verdict. The design table and the summary's count say so. Run by CTest (label report).
"""
import os
import sys
import tempfile

from checklist import Checklist  # tests/report/checklist.py, beside this file

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
sys.path.insert(0, os.path.join(ROOT, "scripts", "figures"))
import report  # noqa: E402

# summary.txt of knit-macro design with a twin (the lines the verdict reads).
SUMMARY = """status: {status}
J_initial: 122.66
J_final: 2.97785e-23
variable l: 5.5 -> {end} in [4.5, 6.5] mm
twin target load_at_20: 48.0437
twin l: 6 (recovered {got}, off by 0 % of the bounds)
final run: completed
"""


def write_design(out, name, text, exit_code=0, twin=None):
    os.makedirs(os.path.join(out, "design", name), exist_ok=True)
    with open(os.path.join(out, "design", name + ".status"), "w") as f:
        f.write('{"design": "%s", "exit_code": %d, "seconds": 0.1}\n' % (name, exit_code))
    if twin is not None:
        write_input(out, name, twin)
    with open(os.path.join(out, "design", name, "summary.txt"), "w") as f:
        f.write(text)


def write_input(out, name, twin):
    os.makedirs(os.path.join(out, "design", "inputs"), exist_ok=True)
    with open(os.path.join(out, "design", "inputs", name + ".json"), "w") as f:
        f.write('{"case": "c.json", "variables": [], "objectives": [], "twin": %s}\n' % twin)


def main():
    c = Checklist()
    tol = 2.0 * report.TWIN_TOLERANCE  # the bound interval is 2 mm
    cases = {
        "recovered": (dict(status="converged", end="6", got="6"), True),
        "just inside": (dict(status="converged", end=repr(6 - 0.9 * tol),
                             got=repr(6 - 0.9 * tol)), True),
        "off by more than the tolerance": (dict(status="converged", end=repr(6 - 1.1 * tol),
                                                got=repr(6 - 1.1 * tol)), False),
        "recovered but not converged": (dict(status="target not met", end="6", got="6"), False),
        "twin line disagrees with the variable line": (dict(status="converged", end="6",
                                                            got="5.9"), False),
        "unreadable numbers": (dict(status="converged", end="nan", got="nan"), False),
    }
    for what, (fields, expect) in cases.items():
        summ = {}
        for line in SUMMARY.format(**fields).splitlines():
            k, _, v = line.partition(":")
            summ.setdefault(k.strip(), v.strip())
        got = report.twin_verdict(summ)
        c(got is not None and got[0] is expect, "%s: %s" % (what, "recovered" if expect else
                                                          "not recovered"), repr(got))
    c(report.twin_verdict({"status": "converged", "variable l": "5.5 -> 6 in [4.5, 6.5]"}) is None,
      "a design without a twin has no verdict")
    with tempfile.TemporaryDirectory(prefix="design_twin_test_") as out:
        write_design(out, "good", SUMMARY.format(status="converged", end="6", got="6"))
        write_design(out, "bad", SUMMARY.format(status="converged", end="5.9", got="5.9"))
        write_design(out, "plain", "status: converged\nvariable l: 5.5 -> 6 in [4.5, 6.5]\n")
        c(report.twin_counts(out) == (1, 2), "the count: 1 of 2 twin experiments recovered",
          repr(report.twin_counts(out)))
        table = "\n".join(report.design_section(out))
        c("| good |" in table and "**pass**: l 6 (twin 6" in table, "the table: good passes", table)
        c("**FAIL**: l 5.9 (twin 6, off by 5 %" in table, "the table: bad fails with its distance",
          table)
        c("| plain |" in table and table.split("| plain |")[1].split("\n")[0].rstrip().endswith(
            "| - |"), "the table: no twin, no verdict", table)
    # Session 38's red team: the verdict came from the summaries alone.
    recovered = SUMMARY.format(status="converged", end="6", got="6")
    with tempfile.TemporaryDirectory(prefix="design_twin_test_") as out:
        write_design(out, "good", recovered, twin='{"l": 6.0}')
        c(report.twin_counts(out) == (1, 1), "declared and recovered: 1 of 1",
          repr(report.twin_counts(out)))
        write_input(out, "gone", '{"l": 6.0}')  # declared, its output deleted
        c(report.twin_counts(out) == (1, 2), "a declared twin without output counts, not "
          "recovered: 1 of 2", repr(report.twin_counts(out)))
        table = "\n".join(report.design_section(out))
        c("| gone |" in table and "declared (twin 6.0) but not in the summary (no output)"
          in table, "the table names the declared twin without output", table)
        write_design(out, "failed", recovered, exit_code=1, twin='{"l": 6.0}')
        c(report.twin_counts(out) == (1, 3), "exit code 1: not recovered",
          repr(report.twin_counts(out)))
        write_design(out, "stale", recovered, twin='{"l": 5.0}')
        c(report.twin_counts(out) == (1, 4), "a summary of another twin (stale): not recovered",
          repr(report.twin_counts(out)))
        table = "\n".join(report.design_section(out))
        c("the input's twin is 5.0, not 6 (a stale summary)" in table and "exit 1" in table,
          "the table says why", table)
        # Exit 2 wrote nothing: the summary left in design/refused is an earlier run's, not
        # shown as this one's (session 45); the log's error line says why.
        write_design(out, "refused", recovered, exit_code=2, twin='{"l": 6.0}')
        os.makedirs(os.path.join(out, "logs"), exist_ok=True)
        with open(os.path.join(out, "logs", "design_refused.log"), "w") as f:
            f.write("knit-macro design: error: c.json: /material/stitch_value: 6.5 mm is "
                    "outside the database's 4.5-4.5 mm\n")
        row = "\n".join(report.design_section(out)).split("| refused |")[1].split("\n")[0]
        c("no output (exit 2): knit-macro design: error: c.json: /material/stitch_value" in row
          and "122.66" not in row and "converged" not in row,
          "exit 2: no output, the log's error, not the earlier summary", row)
    # Session 42's red team: with $(OUT)/design deleted (its inputs too) the twin verdict
    # dropped out of the summary without a FAIL. An expected design (--expect-designs) takes its
    # twin from --designs-dir.
    with tempfile.TemporaryDirectory(prefix="design_twin_test_") as out:
        src = os.path.join(out, "src")
        os.makedirs(src)
        with open(os.path.join(src, "wanted.json"), "w") as f:
            f.write('{"twin": {"l": 6.0}}')
        c(report.twin_counts(out) == (0, 0), "nothing expected, nothing there: 0 of 0",
          repr(report.twin_counts(out)))
        report.EXPECTED_DESIGNS, report.DESIGNS_DIR = ["wanted"], src
        try:
            c(report.twin_counts(out) == (0, 1), "an expected twin without any output: 0 of 1",
              repr(report.twin_counts(out)))
            table = "\n".join(report.design_section(out))
            c("| wanted |" in table and "no status file" in table
              and "declared (twin 6.0) but not in the summary (no output)" in table,
              "the table names the expected design without output", table)
        finally:
            report.EXPECTED_DESIGNS, report.DESIGNS_DIR = [], None
    # Session 50's red team: with the database rebuilt (another date_utc), the twin of a
    # design whose final run read the former database still counted as recovered, and the
    # knitting maps were shown as the new database's.
    import h5py
    with tempfile.TemporaryDirectory(prefix="design_twin_test_") as out:
        write_design(out, "twin", SUMMARY.format(status="converged", end="6", got="6"),
                     twin='{"l": 6.0}')
        os.makedirs(os.path.join(out, "design", "twin", "run"))
        with h5py.File(os.path.join(out, "design", "twin", "run", "results.h5"), "w") as h:
            h.attrs["material_database_date_utc"] = "2026-12-01T10:00:00Z"
        os.makedirs(os.path.join(out, "knitmap", "m"))
        with open(os.path.join(out, "knitmap", "m", "summary.txt"), "w") as f:
            f.write("database_date_utc: 2026-12-01T10:00:00Z\nstitches: 10\nneedles: 5\n")
        try:
            for date, recovered in (("2026-12-01T10:00:00Z", 1), ("2026-12-05T12:00:00Z", 0)):
                report.DATABASE_DATE = date
                c(report.twin_counts(out) == (recovered, 1),
                  f"database of {date}: {recovered} of 1 recovered", repr(report.twin_counts(out)))
                stale = "stale: its final run was computed with the database written" in \
                    "\n".join(report.design_section(out))
                c(stale == (recovered == 0), f"database of {date}: the design table says stale "
                  f"{recovered == 0}", "\n".join(report.design_section(out)))
                maps = "\n".join(report.knitmap_section(out))
                c(("stale: the map was computed" in maps) == (recovered == 0),
                  f"database of {date}: the map stale {recovered == 0}", maps)
        finally:
            report.DATABASE_DATE = None
    # Session 52's red team: l = 5.0 written into the design's case.json, run/case.json and
    # history.csv beside a summary ending l at 6 still recovered the twin. The designed case's
    # field values at each variable's indices must be the summary's end values, and the final
    # run's results.h5 /case_json the designed case.
    import json
    with tempfile.TemporaryDirectory(prefix="design_twin_test_") as out:
        write_design(out, "twin", SUMMARY.format(status="converged", end="6", got="6"),
                     twin='{"l": 6.0}')
        with open(os.path.join(out, "design", "inputs", "twin.json"), "w") as f:
            json.dump({"case": "c.json", "twin": {"l": 6.0}, "objectives": [],
                       "variables": [{"name": "l", "field": "stitch_value",
                                      "indices": [0, 2]}]}, f)
        os.makedirs(os.path.join(out, "design", "twin", "run"))

        def designed(values, run_values=None):
            case = {"material": {"type": "knit", "stitch_value": {"values": values}}}
            with open(os.path.join(out, "design", "twin", "case.json"), "w") as f:
                json.dump(case, f)
            run = {"material": {"type": "knit", "stitch_value": {"values": run_values or values}}}
            with h5py.File(os.path.join(out, "design", "twin", "run", "results.h5"), "w") as h:
                h["case_json"] = json.dumps(run)

        for what, values, run_values, recovered, needle in [
                ("the case of the summary", [6.000000000004, 5.5, 6.0], None, 1, None),
                ("l = 5.0 in the case", [5.0, 5.5, 5.0], None, 0,
                 "its case.json has stitch_value value 5.0 at index 0 where its summary.txt "
                 "ends variable l at 6"),
                ("a tied index off", [6.0, 5.5, 5.0], None, 0, "value 5.0 at index 2"),
                ("a final run of another case", [6.0, 5.5, 6.0], [5.0, 5.5, 5.0], 0,
                 "its final run (run/results.h5 /case_json) differs from its case.json at "
                 "/material/stitch_value/values/0")]:
            designed(values, run_values)
            c(report.twin_counts(out) == (recovered, 1), f"{what}: {recovered} of 1 recovered",
              repr(report.twin_counts(out)))
            why = report.design_output_defect(out, "twin")
            c((why is None) == (needle is None) and (needle is None or needle in why),
              f"{what}: the design's defect", repr(why))
        # The second red team of session 52: /case_json not JSON, or "indices": 0, raised.
        designed([6.0, 5.5, 6.0])
        with h5py.File(os.path.join(out, "design", "twin", "run", "results.h5"), "w") as h:
            h["case_json"] = "{not json"
        why = report.design_output_defect(out, "twin")
        c(why is not None and "/case_json is not JSON" in why, "a /case_json that is not JSON",
          repr(why))
        with open(os.path.join(out, "design", "inputs", "twin.json"), "w") as f:
            json.dump({"case": "c.json", "twin": {"l": 6.0}, "objectives": [],
                       "variables": [{"name": "l", "field": "stitch_value", "indices": 0}]}, f)
        designed([5.0, 5.5, 6.0])
        why = report.design_output_defect(out, "twin")
        c(why is not None and "value 5.0 at index 0" in why, "indices given as a number",
          repr(why))
    return c.exit_code()


if __name__ == "__main__":
    sys.exit(main())
