#!/usr/bin/python3
"""The cell parameters a sweep input uses, as a cell parameter file (session 45).

  sweep_cell.py SWEEP.json OUT.json      (SWEEP.json "" for the synthetic stand-in: {})

The sweep input's "cell" (schemas/sweep.schema.json): inline as an object, or the path of a cell
parameter file relative to the input; absent, the cell's defaults ({}). The pipeline passes
OUT.json to `knit-meso cell --config` for Fig. 5, so that the drawn unit cells are the sweep's
(a red team found Fig. 5 drawn with the default yarn diameter 0.38 mm beside a database swept
with 0.45 mm). Errors end with one line naming the file (figure_inputs.guarded_main).
"""
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from figure_inputs import guarded_main, read_json  # noqa: E402


def main():
    if len(sys.argv) != 3:
        raise SystemExit("usage: sweep_cell.py SWEEP.json OUT.json")
    sweep, out = sys.argv[1], sys.argv[2]
    cell = read_json(sweep).get("cell", {}) if sweep else {}
    if isinstance(cell, str):
        cell = read_json(os.path.join(os.path.dirname(os.path.abspath(sweep)), cell))
    if not isinstance(cell, dict):
        raise SystemExit(f"sweep_cell.py: {sweep}: /cell is neither an object nor a file name")
    tmp = out + ".tmp"
    with open(tmp, "w") as f:
        json.dump(cell, f, indent=1)
        f.write("\n")
    os.replace(tmp, out)


if __name__ == "__main__":
    guarded_main(main)
