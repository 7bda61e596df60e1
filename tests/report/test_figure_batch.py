#!/usr/bin/python3
"""Test of the pipeline's figure batches (scripts/figures/batch.py, docs/build.md): several
figure scripts in one Python process behave as separate processes would.

* a job that draws writes its PNG (a normal date) and its log;
* a job that fails (an exception, a non-zero exit, bad arguments) leaves its error in its log,
  becomes a placeholder PNG dated 1970 and does not stop the jobs after it;
* a job that changes matplotlib's rcParams or leaves a figure open does not affect the next one;
* the batch's own exit code is 0 (the pipeline goes on, as with single figures).

Run: /usr/bin/python3 tests/report/test_figure_batch.py   (CTest: figure_batch)
"""
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BATCH = os.path.join(ROOT, "scripts", "figures", "batch.py")
PLOTS = os.path.join(ROOT, "scripts", "figures", "plots.py")

# A figure script for the test: --mode draw | raise | exit3 | rc (changes rcParams, leaves a
# figure open, then draws) | check (fails if an earlier job's rcParams or figures leaked).
SCRIPT = '''
import argparse, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
ap = argparse.ArgumentParser()
ap.add_argument("--mode", required=True)
ap.add_argument("--out", required=True)
a = ap.parse_args()
print("job", a.mode)
if a.mode == "raise":
    raise RuntimeError("deliberate failure")
if a.mode == "exit3":
    sys.exit(3)
if a.mode == "interrupt":
    raise KeyboardInterrupt
if a.mode == "rc":
    matplotlib.rcParams["lines.linewidth"] = 7.5
    plt.figure()
if a.mode == "check":
    assert matplotlib.rcParams["lines.linewidth"] != 7.5, "rcParams leaked from an earlier job"
    assert not plt.get_fignums(), "a figure leaked from an earlier job"
fig, ax = plt.subplots(figsize=(2, 2))
ax.plot([0, 1], [0, 1])
fig.savefig(a.out, dpi=30)
plt.close(fig)
sys.exit(0)
'''

failures = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        failures.append(what)


def main():
    with tempfile.TemporaryDirectory() as d:
        script = os.path.join(d, "fig.py")
        with open(script, "w") as f:
            f.write(SCRIPT)
        logs = os.path.join(d, "logs", "figures")
        png = {k: os.path.join(d, "figures", k + ".png")
               for k in ("a_draw", "b_raise", "c_exit", "d_rc", "e_check", "f_badargs", "g_plot")}
        os.makedirs(os.path.join(d, "figures"))
        jobs = [f"{png['a_draw']} {script} --mode draw",
                f"{png['b_raise']} {script} --mode raise",
                f"{png['c_exit']} {script} --mode exit3",
                f"{png['d_rc']} {script} --mode rc",
                f"{png['e_check']} {script} --mode check",
                f"{png['f_badargs']} {script} --no-such-option",
                f"{png['g_plot']} {PLOTS} --results {d} placeholder --title 'a title' "
                f"--message 'from plots.py'"]
        r = subprocess.run([sys.executable, BATCH, "--logs", logs] + jobs, capture_output=True,
                           text=True, env=dict(os.environ, MPLBACKEND="Agg"))
        print(r.stdout + r.stderr)
        check(r.returncode == 0, "the batch exits 0 although jobs failed")
        for k in ("a_draw", "d_rc", "e_check", "g_plot"):
            ok = os.path.isfile(png[k]) and os.path.getmtime(png[k]) > 0
            check(ok, f"{k}: drawn, with a normal date")
        for k in ("b_raise", "c_exit", "f_badargs"):
            ok = os.path.isfile(png[k]) and os.path.getmtime(png[k]) == 0
            check(ok, f"{k}: a placeholder dated 1970")
            check(f"figure: {k}.png failed" in r.stdout, f"{k}: the failure is reported")
        with open(os.path.join(logs, "b_raise.log")) as f:
            check("deliberate failure" in f.read(), "the exception is in the job's log")
        with open(os.path.join(logs, "c_exit.log")) as f:
            check("exit code 3" in f.read(), "the exit code is in the job's log")
        with open(os.path.join(logs, "a_draw.log")) as f:
            check("job draw" in f.read(), "a job's output goes to its own log")
        with open(os.path.join(logs, "e_check.log")) as f:
            text = f.read()
            check("leaked" not in text, "no rcParams or figure leaks into the next job")
        # Ctrl-C (KeyboardInterrupt) stops the batch: no placeholder, no later job (session
        # 45's red team: the figure became a placeholder and the batch drew on).
        stop = {k: os.path.join(d, "figures", k + ".png") for k in ("h_interrupt", "i_after")}
        r = subprocess.run([sys.executable, BATCH, "--logs", logs,
                            f"{stop['h_interrupt']} {script} --mode interrupt",
                            f"{stop['i_after']} {script} --mode draw"], capture_output=True,
                           text=True, env=dict(os.environ, MPLBACKEND="Agg"))
        check(r.returncode != 0 and not os.path.exists(stop["h_interrupt"])
              and not os.path.exists(stop["i_after"]),
              "an interrupt stops the batch (exit %d), nothing drawn after it" % r.returncode)
    if failures:
        print(f"{len(failures)} check(s) failed")
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
