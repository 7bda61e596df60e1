#!/usr/bin/python3
"""scripts/run.sh, scripts/pipeline.mk and resolve_case.py against session 36's red team: what
the pipeline writes stays inside its own output, and what it judges is its own.

* Output paths make cannot carry are refused before anything is written: a space in OUT split
  it into two words (`make clean` removed "DIR/my", a user's directory, and "out/..." of the
  caller's directory), a $ was expanded by make (every output went elsewhere, exit 0).
* `make clean` keeps a user's files in figures/ and results/, and refuses another program's
  output (knit-macro run writes the same marker file); run.sh names a dangling symbolic link.
* resolve_case.py names the database relative to the resolved case, so a moved or copied
  output runs against its own database.
* A case whose results were removed is run again (this part needs the built executables:
  KNIT_BUILD, set by CTest; a synthetic database and one case keep it to seconds).
Run by CTest (tests/CMakeLists.txt, label report) with Debian's /usr/bin/python3.
"""
import json
import os
import shutil
import signal
import subprocess
import tempfile

from checklist import Checklist  # tests/report/checklist.py, beside this file

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def run_sh(out):
    """run.sh with KNIT_OUT=out: (exit code, output). Expected to refuse at once; if it goes
    on (a regression), its whole process group (builds, the pipeline) is killed after 60 s."""
    env = dict(os.environ, KNIT_OUT=out)
    p = subprocess.Popen(["bash", os.path.join(ROOT, "scripts", "run.sh")], env=env,
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                         start_new_session=True)
    try:
        text = p.communicate(timeout=60)[0]
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        p.communicate()
        return -1, "run.sh did not refuse: it ran on for 60 s (killed)"
    return p.returncode, text


def make_clean(out, cwd):
    r = subprocess.run(["make", "-f", os.path.join(ROOT, "scripts", "pipeline.mk"),
                        "ROOT=" + ROOT, "BUILD=" + os.path.join(cwd, "nobuild"), "OUT=" + out,
                        "clean"], cwd=cwd, capture_output=True, text=True, timeout=60)
    return r.returncode, r.stdout + r.stderr


def main():
    check = Checklist()
    with tempfile.TemporaryDirectory() as d:
        mine = os.path.join(d, "my")
        os.makedirs(mine)
        thesis = os.path.join(mine, "thesis.txt")
        with open(thesis, "w") as f:
            f.write("precious")
        # The caller's own out/ (the relative word "out/..." of a split path).
        os.makedirs(os.path.join(d, "out"))
        callers = os.path.join(d, "out", "database.h5")
        with open(callers, "w") as f:
            f.write("the caller's")
        for bad, char in ((mine + " out", " "), (os.path.join(d, "res$x"), "$"),
                          (os.path.join(d, "a;b"), ";"), (os.path.join(d, "a#b"), "#"),
                          (os.path.join(d, "a,b"), ","), (os.path.join(d, "a:b"), ":")):
            rc, out = run_sh(bad)
            check(rc == 2 and ("holds the character '%s'" % char) in out
                  and not os.path.exists(bad),
                  "run.sh refuses KNIT_OUT=%r (exit %d), nothing created" % (bad, rc), out)
        check(not os.path.exists(os.path.join(d, "res")), "a $ did not redirect to DIR/res")
        # The makefile's clean with a spaced OUT (the marker made as run.sh made it before).
        spaced = mine + " out"
        os.makedirs(spaced)
        with open(os.path.join(spaced, ".knitscale-output"), "w") as f:
            f.write("knitscale output: the reproduction pipeline (scripts/run.sh)\n")
        rc, out = make_clean(spaced, d)
        check(rc != 0 and "holds a space" in out, "make clean refuses OUT with a space", out)
        check(os.path.exists(thesis) and open(callers).read() == "the caller's",
              "the user's directory and the caller's out/ are kept")
        # A plain OUT: clean removes the pipeline's files only inside it.
        plain = os.path.join(d, "plain")
        os.makedirs(os.path.join(plain, "figures"))
        with open(os.path.join(plain, ".knitscale-output"), "w") as f:
            f.write("knitscale output: the reproduction pipeline (scripts/run.sh)\n")
        # (and an interrupted sweep's checkpoints: session 45's red team found them left)
        os.makedirs(os.path.join(plain, "database.h5.parts"))
        with open(os.path.join(plain, "database.h5.parts", "manifest.json"), "w") as f:
            f.write("{}")
        rc, out = make_clean(plain, d)
        check(rc == 0 and not os.path.exists(os.path.join(plain, "figures"))
              and not os.path.exists(os.path.join(plain, "database.h5.parts"))
              and open(callers).read() == "the caller's",
              "make clean of a plain OUT removes its figures/ and the sweep's checkpoints only",
              out)
        # A user's files inside figures/ and results/ stay, with the pipeline's own removed.
        # (and the completed outputs a stopped rerun kept, NAME.last-completed[-PID]: left
        # behind by clean until session 47)
        for sub, mine_name, ours in (("figures", "my_plot.png", "fig07d_load_strain.png"),
                                     ("results", "my_analysis.txt", "s312_uniform_45_wale.status")):
            os.makedirs(os.path.join(plain, sub), exist_ok=True)
            for n in (mine_name, ours):
                with open(os.path.join(plain, sub, n), "w") as f:
                    f.write(n)
        kept_runs = [os.path.join(plain, "results", "s312_uniform_45_wale.last-completed"),
                     os.path.join(plain, "results", "s312_uniform_45_wale.last-completed-77")]
        for k in kept_runs:
            os.makedirs(k)
            with open(os.path.join(k, "load_strain.csv"), "w") as f:
                f.write("step\n")
        rc, out = make_clean(plain, d)
        check(rc == 0 and os.path.exists(os.path.join(plain, "figures", "my_plot.png"))
              and os.path.exists(os.path.join(plain, "results", "my_analysis.txt"))
              and not os.path.exists(os.path.join(plain, "figures", "fig07d_load_strain.png"))
              and not os.path.exists(os.path.join(plain, "results",
                                                  "s312_uniform_45_wale.status"))
              and not any(os.path.exists(k) for k in kept_runs)
              and "kept" in out,
              "make clean keeps a user's files in figures/ and results/, removes the pipeline's",
              out)
        # Another program's output (knit-macro run writes the same marker with its own name)
        # and a dangling symbolic link are refused (session 36's red team: the first was taken
        # for the pipeline's, the second failed in mkdir with "File exists").
        other = os.path.join(d, "run_output")
        os.makedirs(other)
        with open(os.path.join(other, ".knitscale-output"), "w") as f:
            f.write("knitscale output: knit-macro run\n{}\nfile: load_strain.csv\n")
        with open(os.path.join(other, "load_strain.csv"), "w") as f:
            f.write("step\n")
        rc, out = run_sh(other)
        check(rc == 2 and "is the output of another program" in out,
              "run.sh refuses knit-macro run's output (exit %d)" % rc, out)
        rc, out = make_clean(other, d)
        check(rc != 0 and "another program's output" in out
              and os.path.exists(os.path.join(other, "load_strain.csv")),
              "make clean refuses it and removes nothing", out)
        # An OUT inside a run's output (the review of session 46: figures/, logs/ and
        # report.md went into a design's output): refused by run.sh and by the makefile.
        inside = os.path.join(other, "o")
        rc, out = run_sh(inside)
        check(rc == 2 and "lies inside " + other in out and not os.path.exists(inside),
              "run.sh refuses KNIT_OUT inside a run's output (exit %d)" % rc, out)
        r = subprocess.run(["make", "-f", os.path.join(ROOT, "scripts", "pipeline.mk"),
                            "ROOT=" + ROOT, "BUILD=" + os.path.join(d, "nobuild"),
                            "OUT=" + inside, "-n", "all"], cwd=d, capture_output=True,
                           text=True, timeout=60)
        check(r.returncode != 0 and "lies inside the output of a knitscale run" in r.stderr
              and not os.path.exists(inside),
              "the makefile refuses OUT inside a run's output", r.stdout + r.stderr)
        dangling = os.path.join(d, "dangling")
        os.symlink(os.path.join(d, "nowhere"), dangling)
        rc, out = run_sh(dangling)
        check(rc == 2 and "dangling symbolic link" in out,
              "run.sh refuses a dangling symbolic link (exit %d)" % rc, out)
        # resolve_case.py writes the database relative to the resolved case, so a copied or
        # moved output directory runs its cases against its own database (session 36).
        a = os.path.join(d, "outA")
        os.makedirs(os.path.join(a, "cases"))
        case = os.path.join(a, "cases", "s312_uniform_45_wale.json")
        subprocess.run(["/usr/bin/python3", os.path.join(ROOT, "scripts", "figures",
                                                         "resolve_case.py"),
                        os.path.join(ROOT, "cases", "paper", "s312_uniform_45_wale.json"),
                        os.path.join(a, "database.h5"), case], check=True)
        with open(case) as f:
            db = json.load(f)["material"]["database"]
        check(db == os.path.join("..", "database.h5"), "the resolved case names ../database.h5",
              db)
        b = os.path.join(d, "outB")
        os.rename(a, b)
        moved = os.path.join(b, "cases", "s312_uniform_45_wale.json")
        check(os.path.normpath(os.path.join(os.path.dirname(moved), db)) ==
              os.path.join(b, "database.h5"), "moved, it names the moved directory's database")
    # A case whose results are gone is run again (session 36: results/NAME removed, the rerun
    # re-made nothing). Needs the built executables (KNIT_BUILD, set by CTest); a synthetic
    # database and one case's status target keep it to a few seconds.
    build = os.environ.get("KNIT_BUILD", "")
    if os.path.exists(os.path.join(build, "bin", "knit-macro")):
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "o")
            target = os.path.join(out, "results", "s312_uniform_45_wale.status")
            res = os.path.join(out, "results", "s312_uniform_45_wale")

            def make_status():
                r = subprocess.run(["make", "-f", os.path.join(ROOT, "scripts", "pipeline.mk"),
                                    "ROOT=" + ROOT, "BUILD=" + build, "OUT=" + out,
                                    "DB_SOURCE=synth", target], capture_output=True, text=True,
                                   timeout=300)
                return r.returncode, r.stdout + r.stderr

            rc, log = make_status()
            check(rc == 0 and os.path.exists(os.path.join(res, "load_strain.csv")),
                  "the case runs on a synthetic database", log)
            st = json.load(open(target)) if os.path.exists(target) else {}
            check(st.get("exit_code") == 0 and st.get("wrote") is True,
                  "its status says it wrote its output (session 45)", str(st))
            rc, log = make_status()
            check(rc == 0 and "case: s312" not in log, "made again: nothing re-made", log)
            shutil.rmtree(res)
            rc, log = make_status()
            check(rc == 0 and "case: s312_uniform_45_wale" in log
                  and os.path.exists(os.path.join(res, "load_strain.csv")),
                  "its results removed: the case is run again", log)
        # The sweep input (session 45's red team): a SWEEP_INPUT given that does not exist is
        # refused (it gave the synthetic stand-in with exit 0), and database.source, on which
        # the database depends, follows the input's and its cell file's contents, not their
        # time stamps (an older file copied over the input, or an edited cell file, rebuilt
        # nothing).
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "o")
            sweep = os.path.join(d, "s.json")
            source = os.path.join(out, "database.source")

            def make_source(sweep_input):
                r = subprocess.run(["make", "-f", os.path.join(ROOT, "scripts", "pipeline.mk"),
                                    "ROOT=" + ROOT, "BUILD=" + build, "OUT=" + out,
                                    "SWEEP_INPUT=" + sweep_input, source], capture_output=True,
                                   text=True, timeout=120)
                text = open(source).read() if os.path.exists(source) else ""
                return r.returncode, r.stdout + r.stderr, text

            rc, log, _ = make_source(os.path.join(d, "missing.json"))
            check(rc != 0 and "SWEEP_INPUT=" in log and "does not exist" in log
                  and not os.path.exists(source), "a SWEEP_INPUT that does not exist: refused",
                  log)
            r = subprocess.run(["make", "-f", os.path.join(ROOT, "scripts", "pipeline.mk"),
                                "ROOT=" + ROOT, "BUILD=" + build, "OUT=" + out,
                                "SWEEP_INPUT=" + os.path.join(d, "missing.json"),
                                "DB_SOURCE=synth", "-n", source], capture_output=True,
                               text=True, timeout=60)
            check(r.returncode == 0, "... but not with DB_SOURCE=synth, which reads none",
                  r.stdout + r.stderr)
            with open(os.path.join(d, "c.json"), "w") as f:
                f.write('{"yarn": {"d": 0.38}}')
            with open(sweep, "w") as f:
                f.write('{"loop_lengths": [4.5], "cell": "c.json"}')
            rc, log, first = make_source(sweep)
            check(rc == 0 and first.startswith("sweep " + sweep + " sha256:")
                  and " cell:sha256:" in first, "database.source names the input's contents",
                  log + first)
            with open(sweep, "w") as f:
                f.write('{"loop_lengths": [5.5], "cell": "c.json"}')
            os.utime(sweep, (1, 1))  # older than database.source
            rc, log, second = make_source(sweep)
            check(rc == 0 and second != first, "an edited input with an old time stamp: "
                  "database.source changes", first + second)
            with open(os.path.join(d, "c.json"), "w") as f:
                f.write('{"yarn": {"d": 0.45}}')
            rc, log, third = make_source(sweep)
            check(rc == 0 and third != second, "an edited cell file: database.source changes",
                  second + third)
            # Fig. 5's cells take the sweep's cell parameters (the red team: the default d).
            params = os.path.join(out, "cells", "params.json")
            r = subprocess.run(["make", "-f", os.path.join(ROOT, "scripts", "pipeline.mk"),
                                "ROOT=" + ROOT, "BUILD=" + build, "OUT=" + out,
                                "SWEEP_INPUT=" + sweep, params], capture_output=True, text=True,
                               timeout=120)
            got = json.load(open(params)) if os.path.exists(params) else None
            check(r.returncode == 0 and got == {"yarn": {"d": 0.45}},
                  "the cells' parameters are the sweep's cell file", r.stdout + r.stderr + str(got))
            os.utime(source, (1000, 1000))
            rc, log, fourth = make_source(sweep)
            check(rc == 0 and fourth == third and os.path.getmtime(source) == 1000,
                  "nothing changed: database.source not rewritten (the database stays)",
                  third + fourth)
    else:
        check(False, "KNIT_BUILD names no build with bin/knit-macro: %r" % build)
    return check.exit_code()


if __name__ == "__main__":
    raise SystemExit(main())
