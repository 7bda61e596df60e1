#!/usr/bin/python3
"""Draws several figures in one Python process (the pipeline's figure batches, docs/build.md).

  batch.py --logs DIR JOB...      JOB = "OUT.png SCRIPT ARG..." (one shell-quoted string)

Each job is what `SCRIPT ARG... --out OUT.png` would draw as a process of its own: the script
runs as __main__ (runpy) with that argv, its output goes to DIR/<OUT's stem>.log. Importing
matplotlib, numpy and h5py costs ~0.9 CPU s per process, more than drawing most figures; here
it is paid once per batch. A job that fails (exception or non-zero exit) does not stop the
others: as in the pipeline's single-figure rule, its error stays in the log, the PNG becomes
a placeholder that says so (plots.py placeholder), dated 1970 so that the next run draws the
batch again. Exit code 0 unless a placeholder could not be written.
"""
import argparse
import contextlib
import os
import runpy
import shlex
import sys
import traceback

HERE = os.path.dirname(os.path.abspath(__file__))


def run_script(script, argv, log):
    """Runs `script argv...` as __main__ with stdout/stderr into `log`; -> True on success."""
    import matplotlib

    saved_rc = matplotlib.rcParams.copy()
    saved_argv, saved_path = sys.argv, list(sys.path)
    ok = True
    with open(log, "w") as f, contextlib.redirect_stdout(f), contextlib.redirect_stderr(f):
        sys.argv = [script] + argv
        try:
            runpy.run_path(script, run_name="__main__")
        except SystemExit as e:
            ok = e.code in (None, 0)
            if not ok:
                print(f"exit code {e.code}")
        except KeyboardInterrupt:
            # Ctrl-C stops the batch, not the figure alone (session 45's red team: the figure
            # became a placeholder and the rest of the batch was drawn for seconds more).
            raise
        except BaseException:  # noqa: B902 (the figure's error goes to its log)
            traceback.print_exc()
            ok = False
        finally:
            sys.argv, sys.path[:] = saved_argv, saved_path
            import matplotlib.pyplot as plt

            plt.close("all")
            matplotlib.rcParams.update(saved_rc)
    return ok


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--logs", required=True)
    ap.add_argument("jobs", nargs="*")
    a = ap.parse_args()
    import matplotlib

    matplotlib.use("Agg")
    os.makedirs(a.logs, exist_ok=True)
    rc = 0
    for job in a.jobs:
        words = shlex.split(job)
        out, script, args = words[0], words[1], words[2:]
        name = os.path.splitext(os.path.basename(out))[0]
        log = os.path.join(a.logs, name + ".log")
        if run_script(script, args + ["--out", out], log):
            continue
        print(f"figure: {os.path.basename(out)} failed, see {log}", flush=True)
        with open(log, "a") as f, contextlib.redirect_stdout(f), contextlib.redirect_stderr(f):
            try:
                sys.path.insert(0, HERE)
                import plots

                plots.placeholder(out, os.path.basename(out),
                                  "the figure script failed (logs/figures)")
                os.utime(out, (0, 0))
            except BaseException:  # noqa: B902
                traceback.print_exc()
                rc = 1
    return rc


if __name__ == "__main__":
    sys.exit(main())
