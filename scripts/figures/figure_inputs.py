"""The figure scripts' error boundary: a damaged or missing input ends the script with one line
that names the file (or the command line's inputs), exit code 1, instead of a traceback.

Session 22: `knitmap.py DIR`, `design.py DIR` and `cells.py DIR...` on a directory without their
files, or with a damaged case.json or history.csv, ended in a FileNotFoundError or
JSONDecodeError traceback. Used as `guarded_main(main)` under `if __name__ == "__main__"`; the
pipeline's batches (batch.py) run the scripts as __main__ too, so the line lands in the
figure's log and the PNG becomes the placeholder as before.
"""
import json
import os
import sys
import traceback


def guarded_main(main):
    prog = os.path.basename(sys.argv[0])
    try:
        main()
    except json.JSONDecodeError as err:
        # json names the position only: the file comes from read_json below when the script
        # reads through it, else the message shows the command line.
        where = getattr(err, "knit_path", None) or "a JSON input (" + _command_line() + ")"
        raise SystemExit(f"{prog}: {where}: not valid JSON "
                         f"(line {err.lineno}, column {err.colno}: {err.msg})")
    except OSError as err:
        where = err.filename if err.filename else "an input (" + _command_line() + ")"
        raise SystemExit(f"{prog}: {where}: {err.strerror or err}")
    except (ValueError, KeyError, IndexError, TypeError) as err:
        # Where it was raised, so that a defect of the script itself is not hidden behind the
        # input: the innermost frame's file and line.
        tb = traceback.extract_tb(err.__traceback__)[-1]
        raise SystemExit(f"{prog}: an input is damaged or not a knitscale output "
                         f"({type(err).__name__}: {err}; raised at {os.path.basename(tb.filename)}:"
                         f"{tb.lineno}; the command line: {_command_line()})")


def refused_run_placeholder(status, directory, out, title="", ok_codes=(0,)):
    """With the pipeline's status file of a run (JSON: exit_code, and since session 45 "wrote";
    `status` None or "" skips the check): when the run wrote nothing (its "wrote" false, or
    without it an exit code not in `ok_codes`), draws the figure `out` as a placeholder that
    says so, with the first error line of its log (OUT/logs/<kind>_<name>.log, kind the status
    file's directory: knitmap, design), and returns True; the caller then draws nothing else.
    Its directory may still hold an earlier run's files, which are not this run's (session 45:
    a design or knitting map refused with exit 2 was drawn from the last run). A placeholder
    with the normal date and exit 0, not a failure: the figure is right to say this, and a
    second make does not draw it again (the review of session 45).
    """
    if not status:
        return False
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from results import first_error_line, last_run_wrote  # noqa: E402 (numpy: imported here)

    with open(status) as f:
        st = json.load(f)
    code = st.get("exit_code")
    if last_run_wrote(st, ok_codes):
        return False
    kind = os.path.basename(os.path.dirname(os.path.abspath(status)))
    name = os.path.basename(status)[:-len(".status")] if status.endswith(".status") else ""
    log = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(status))), "logs",
                       f"{kind}_{name}.log")
    first = first_error_line(log)
    message = (f"the run exited with {code} and wrote nothing"
               + (f":\n{first}" if first else f" (its log: {log})")
               + f"\n({directory} is not its output)")
    import plots  # noqa: E402 (plots imports this module)

    plots.placeholder(out, title or os.path.basename(out), message)
    print(f"{os.path.basename(sys.argv[0])}: {status}: the run exited with {code} and wrote "
          f"nothing: drew a placeholder {out}")
    return True


def save_figure(fig, out, **savefig_args):
    """Writes `fig` to `out` through a temporary beside it and a rename, so a figure killed
    while it is drawn leaves no empty or half-written PNG that make would take as complete
    (session 36's red team: a SIGKILL left a 0-byte fig06e_energy_law.png, never redrawn and
    embedded in the report). The temporary's name is that of plots.save."""
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    tmp = out + ".tmp.png"
    fig.savefig(tmp, **savefig_args)
    os.replace(tmp, out)


def read_json(path):
    """json.load of `path`; a parse error keeps the path for guarded_main's message."""
    with open(path) as f:
        try:
            return json.load(f)
        except json.JSONDecodeError as err:
            err.knit_path = path
            raise


def _command_line():
    return " ".join(sys.argv[1:]) or "no arguments"
