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


def refuse_failed_run(status, directory, ok_codes=(0,)):
    """With the pipeline's status file of a run (JSON with its exit_code; `status` None or ""
    skips the check), exits with one line unless the run's exit code is one of `ok_codes`: its
    output directory may still hold an earlier run's files, which are not this run's
    (session 45: a design or knitting map refused with exit 2 was drawn from the last run)."""
    if not status:
        return
    with open(status) as f:
        code = json.load(f).get("exit_code")
    if code not in ok_codes:
        raise SystemExit(f"{os.path.basename(sys.argv[0])}: {status}: the run exited with {code} "
                         f"(its log is in the pipeline's logs/); {directory} is not its output")


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
