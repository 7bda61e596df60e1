#!/usr/bin/python3
"""scripts/calibrate.py (session 56): the calibration study's refusals, merge, cache and path
outcomes, against a fake knit-meso (no cell: the study runs in seconds).

The fake (written below) answers `knit-meso path --loop-length L --uniaxial AXIS E --steps N
--config CFG --out DIR` as knit-meso does: path.csv with the columns the study reads (lambda,
E11, E22, S11_MPa, S22_MPa), S_aa = k E (1 + 4 E) with k = 3 (4.5 mm) or 1 (6.5 mm) times
(1 + g0), the lateral strain -E/2; exit 0. It refuses gamma_over_w = 0.10 at 6.5 mm as knit-meso
has since commit 0efc2b1 (exit 2, "does not interlock"); the course path at g0 = 0.18 and 6.5
mm stops at lambda = 0.5 (exit 1, its steps kept); FAKE_MODE=stop stops every path after one
step below E = 0.1 (no observable), FAKE_MODE=start before any step (exit 1, nothing written),
FAKE_MODE=crash writes a partial path.csv (one row, no newline) and kills itself,
FAKE_MODE=interrupt kills the study too (as a power cut would: nothing cleans up). Each call
appends a line to FAKE_LOG.

Checked (each failed with the session-56 fix reverted, scripts/calibrate.py and
scripts/figures/sensitivity.py of 3ad69af): unknown --only refused and the table untouched;
`gamma` accepted as the docstring's name; a foreign --out never overwritten; --out a directory
refused without leaving DIR.tmp; --point g0 and --base foo=1 named; a missing --bin refused
before a filled cache is read; the refused path recorded (refused_*, a stderr line naming
parameter, value, loop length, axis and knit-meso's message) and the study going on; an early
stop warned and counted; a study that measured nothing exits 1 and writes nothing; --only
merges with the table's other parameters; the cache is per binary and ignores a crashed run;
the figure names the refused paths and draws no refused panel.
Run by CTest (tests/CMakeLists.txt, label report) with Debian's /usr/bin/python3.
"""
import os
import stat
import subprocess
import sys
import tempfile

from checklist import Checklist  # tests/report/checklist.py, beside this file

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(ROOT, "scripts", "calibrate.py")
sys.path.insert(0, os.path.join(ROOT, "scripts", "figures"))
import sensitivity  # noqa: E402

FAKE = r'''#!/usr/bin/python3
import json, os, signal, sys
a = sys.argv[1:]
def opt(name, n=1):
    i = a.index(name)
    return a[i + 1:i + 1 + n]
loop = float(opt("--loop-length")[0])
axis, end = int(opt("--uniaxial", 2)[0]), float(opt("--uniaxial", 2)[1])
steps = int(opt("--steps")[0])
out = opt("--out")[0]
cfg = json.load(open(opt("--config")[0]))
g0, gam = cfg["contact"]["allowance"], cfg["loop"]["gamma_over_w"]
mode = os.environ.get("FAKE_MODE", "")
with open(os.environ["FAKE_LOG"], "a") as f:
    f.write("%s %g %d %g %g\n" % (sys.argv[0], loop, axis, g0, gam))
if abs(gam - 0.10) < 1e-9 and loop > 6:
    sys.stderr.write("knit-meso path: error: %s: /loop/gamma_over_w: no cell geometry for 6.5 mm: "
                     "the loop does not interlock with the next course\n" % opt("--config")[0])
    sys.exit(2)
if mode == "start":
    sys.stderr.write("knit-meso path: a limit point; no load step converged: nothing written\n")
    sys.exit(1)
os.makedirs(out, exist_ok=True)
if mode in ("crash", "interrupt"):
    with open(os.path.join(out, "path.csv"), "w") as f:
        f.write("step,lambda,E11,E22,S11_MPa,S22_MPa\n0,0,0,0,0,0\n1,0.0833,0.03,")
    if mode == "interrupt":
        os.kill(os.getppid(), signal.SIGKILL)
    os.kill(os.getpid(), signal.SIGKILL)
last = steps
if mode == "stop":
    last = 1
elif abs(g0 - 0.18) < 1e-9 and loop > 6 and axis == 0:
    last = steps // 2
k = (3.0 if loop < 5 else 1.0) * (1 + g0)
rows = ["step,lambda,E11,E22,S11_MPa,S22_MPa"]
for n in range(last + 1):
    lam = n / steps
    e = end * lam
    if mode == "stop":
        e = 0.05 * lam
    E = [-e / 2, -e / 2]
    S = [0.0, 0.0]
    E[axis], S[axis] = e, k * e * (1 + 4 * e)
    rows.append("%d,%.12g,%.12g,%.12g,%.12g,%.12g" % (n, lam, E[0], E[1], S[0], S[1]))
with open(os.path.join(out, "path.csv"), "w") as f:
    f.write("\n".join(rows) + "\n")
print("completed" if last == steps else "stopped")
sys.exit(0 if last == steps else 1)
'''


def write_fake(path, extra=""):
    with open(path, "w") as f:
        f.write(FAKE + extra)
    os.chmod(path, os.stat(path).st_mode | stat.S_IXUSR | stat.S_IXGRP | stat.S_IXOTH)


def table(path):
    """-> {(parameter, value, observable): result} of a sensitivity table ({} if none: the
    checks go on when a reverted script wrote nothing)."""
    try:
        return {(p, v, o): r for p, v, o, r in sensitivity.read_table(path)}
    except (OSError, ValueError):
        return {}


def text(path):
    """The file's text, None if it cannot be read."""
    try:
        with open(path) as f:
            return f.read()
    except OSError:
        return None


def calls(log):
    if not os.path.exists(log):
        return 0
    with open(log) as f:
        return len(f.read().splitlines())


def main():
    c = Checklist()
    with tempfile.TemporaryDirectory(prefix="calibrate_test_") as tmp:
        fake = os.path.join(tmp, "knit-meso")
        write_fake(fake)
        log = os.path.join(tmp, "calls.log")
        work = os.path.join(tmp, "work")
        env = dict(os.environ, FAKE_LOG=log, FAKE_MODE="")

        def run(*args, mode=""):
            e = dict(env, FAKE_MODE=mode)
            return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True,
                                  text=True, env=e)

        def study(out, *args, binary=fake, mode=""):
            return run("--bin", binary, "--work", work, "--out", out, *args, mode=mode)

        def clean(r, code):
            return r.returncode == code and "Traceback" not in r.stderr

        # -- g0 and gamma: the refused path, the early stop ------------------------------------
        out = os.path.join(tmp, "sens.csv")
        r = study(out, "--only", "g0,gamma")
        t = table(out)
        c(clean(r, 0) and {k[0] for k in t} == {"g0", "gamma"},
          "--only g0,gamma (the docstring's example) runs both g0 and gamma: exit %d, %s"
          % (r.returncode, sorted({k[0] for k in t})), r.stderr[-2000:])
        c(t.get(("gamma", 0.1, "refused_course_65")) == 1 and t.get(("gamma", 0.1,
                                                                  "refused_wale_65")) == 1
          and ("gamma", 0.1, "S_course_45@E0.2") in t
          and not any(k[:2] == ("gamma", 0.1) and ("_65" in k[2] or "ratio" in k[2])
                      and not k[2].startswith("refused_") for k in t),
          "gamma = 0.1: the 6.5 mm paths refused (refused_* = 1, none of their observables or "
          "ratios), the 4.5 mm ones measured",
          sorted(k for k in t if k[:2] == ("gamma", 0.1)))
        lines = [x for x in r.stderr.splitlines() if "refused:" in x]
        c(len(lines) == 2 and all("gamma_over_w = 0.1" in x and "l = 6.5 mm" in x
                                  and "axis" in x and "does not interlock" in x for x in lines),
          "a stderr line per refused path names parameter, value, loop length, axis and "
          "knit-meso's message", "\n".join(lines) or r.stderr[-1500:])
        warned = [x for x in r.stderr.splitlines() if "warning" in x and "stopped" in x]
        c(len(warned) == 1 and "g0 = 0.18" in warned[0] and "l = 6.5 mm" in warned[0]
          and "0.2" in warned[0] and t.get(("g0", 0.18, "reached_course_65")) == 0.2
          and ("g0", 0.18, "S_course_65@E0.3") not in t and ("g0", 0.18, "S_course_65@E0.2") in t,
          "g0 = 0.18: the 6.5 mm course path that stops at 0.2 is warned once, naming the path "
          "and its strain (recorded in reached_*, the observables beyond it left out)",
          "\n".join(warned))
        c("52 paths: 1 stopped before E = 0.4, 2 refused" in r.stderr,
          "the count at the end", r.stderr[-400:])

        # -- refusals before any run -----------------------------------------------------------
        before = text(out)
        n0 = calls(log)
        r = study(out, "--only", "foo")
        c(clean(r, 2) and "foo" in r.stderr and "gamma_over_w" in r.stderr
          and "normal_stiffness" in r.stderr and text(out) == before
          and calls(log) == n0,
          "--only foo: exit 2 listing the allowed names, the table untouched, nothing run",
          r.stderr)
        foreign = os.path.join(tmp, "notes.txt")
        with open(foreign, "w") as f:
            f.write("my notes, not a table\n")
        r = study(foreign, "--only", "g0")
        c(clean(r, 2) and "not a sensitivity table" in r.stderr
          and text(foreign) == "my notes, not a table\n" and calls(log) == n0,
          "--out a foreign file: exit 2, not overwritten, nothing run", r.stderr)
        adir = os.path.join(tmp, "adir")
        os.mkdir(adir)
        r = study(adir, "--only", "g0")
        c(clean(r, 2) and "directory" in r.stderr and not os.path.exists(adir + ".tmp")
          and calls(log) == n0,
          "--out a directory: exit 2, no adir.tmp left, nothing run", r.stderr)
        r = study(out, "--point", "g0")
        c(clean(r, 2) and "--point" in r.stderr and "NAME=VALUE" in r.stderr,
          "--point g0 (no '='): exit 2, named, no traceback", r.stderr[-600:])
        r = study(out, "--base", "foo=1")
        c(clean(r, 2) and "--base: unknown parameter foo" in r.stderr
          and text(out) == before,
          "--base foo=1: named as --base, exit 2", r.stderr[-600:])
        r = study(out, "--only", "g0", binary=os.path.join(tmp, "missing", "knit-meso"))
        c(clean(r, 2) and "--bin" in r.stderr and text(out) == before,
          "a missing --bin with a filled cache: exit 2 before anything runs", r.stderr[-600:])

        # -- --only merges with the table's other parameters ------------------------------------
        edited = (before or "").replace("gamma,0.15,S_wale_45@E0.2,", "gamma,0.15,S_wale_45@E0.2,9")
        with open(out, "w") as f:
            f.write(edited)  # a marker: the gamma rows must be kept as they are, not rerun
        r = study(out, "--only", "g0")
        t2 = table(out)
        g_old = {k: v for k, v in t.items() if k[0] == "g0"}
        c(clean(r, 0) and {k for k in t2 if k[0] == "gamma"} == {k for k in t if k[0] == "gamma"}
          and str(t2.get(("gamma", 0.15, "S_wale_45@E0.2"))).startswith("9")
          and {k: v for k, v in t2.items() if k[0] == "g0"} == g_old
          and "kept from" in r.stdout and "gamma" in r.stdout,
          "--only g0 keeps the gamma rows of the existing table (said on stdout) and rewrites "
          "g0's: %s" % r.stdout.strip(), r.stderr[-600:])
        r = study(out, "--only", "g0", "--base", "gamma_over_w=0.198413")
        c(clean(r, 2) and "other settings" in r.stderr and table(out) == t2,
          "--only with another --base than the table's: refused, not merged", r.stderr[-600:])

        # -- nothing measured: exit 1, nothing written -----------------------------------------
        for mode in ("stop", "start"):
            fresh = os.path.join(tmp, f"fresh_{mode}.csv")
            r = study(fresh, "--only", "mu", "--work", os.path.join(tmp, "w_" + mode),
                      mode=mode)
            c(clean(r, 1) and not os.path.exists(fresh) and "nothing written" in r.stderr
              and "20 paths: 20 stopped" in r.stderr,
              f"FAKE_MODE={mode}: every path stops without an observable: exit 1, nothing "
              f"written, 20 warned", r.stderr[-800:])

        # -- the cache: per binary; a crashed run is not reused --------------------------------
        n0 = calls(log)
        r = study(out, "--only", "mu")
        n1 = calls(log)
        r = study(out, "--only", "mu")
        n2 = calls(log)
        other = os.path.join(tmp, "other", "knit-meso")
        os.mkdir(os.path.dirname(other))
        write_fake(other, "# another build\n")
        # Into the table of the first binary: refused, not merged (the review of session 56:
        # the rows of two builds were mixed without a word).
        before_other = text(out)
        r = study(out, "--only", "mu", binary=other)
        c(clean(r, 2) and "another knit-meso" in r.stderr and text(out) == before_other
          and calls(log) == n2,
          "--only with another knit-meso than the table's: refused before any run, the table "
          "untouched", r.stderr[-600:])
        r = study(os.path.join(tmp, "other.csv"), "--only", "mu", binary=other)
        # 16 = mu's 5 values x 4 paths, less mu = 0.15 (the defaults, cached by the g0 study)
        c(clean(r, 0) and (n1 - n0, n2 - n1, calls(log) - n2) == (16, 0, 20),
          "the cache is the binary's: the same binary reruns nothing, another reruns all: "
          "%d, %d, %d calls" % (n1 - n0, n2 - n1, calls(log) - n2), r.stderr[-600:])
        cwork = os.path.join(tmp, "w_crash")
        r = run("--bin", fake, "--work", cwork, "--point", "", mode="crash")
        c(r.returncode == 1 and "Traceback" not in r.stderr and "failed" in r.stderr,
          "a crashed knit-meso: exit 1 naming it", r.stderr[-600:])
        killed = run("--bin", fake, "--work", cwork, "--point", "", mode="interrupt").returncode
        r = run("--bin", fake, "--work", cwork, "--point", "")
        got = dict(x.split() for x in r.stdout.splitlines() if len(x.split()) == 2)
        c(killed == -9 and r.returncode == 0 and got.get("reached_course_45") == "0.4000"
          and "S_course_45@E0.4" in got,
          "the run after one killed with its knit-meso (exit %d) does not reuse the partial "
          "path.csv: %s"
          % (killed, {k: v for k, v in got.items() if k.startswith("reached")}),
          r.stderr[-600:])

        # -- the figure: refused paths in a note, no panel -------------------------------------
        rows = [(p, v, o, x) for (p, v, o), x in table(out).items()]
        try:
            kept, refused = sensitivity.split_refused(rows)
            note = sensitivity.refused_note(refused)
        except AttributeError as e:  # the figure script of before session 56
            kept, note = rows, str(e)
        png = os.path.join(tmp, "fig", "sensitivity.png")
        r = subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "figures",
                                                         "sensitivity.py"), out, "--out", png],
                           capture_output=True, text=True, env=dict(os.environ, MPLBACKEND="Agg"))
        c(not any(x[2].startswith("refused_") for x in kept)
          and note == "gamma = 0.1 (course, l = 6.5 mm; wale, l = 6.5 mm)"
          and r.returncode == 0 and os.path.exists(png),
          "the figure: refused_* rows are no panel, its note names the refused paths (%s), and "
          "it is drawn" % note, r.stderr[-600:])
    return c.exit_code()


if __name__ == "__main__":
    sys.exit(main())
