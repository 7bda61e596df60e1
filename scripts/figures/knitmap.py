#!/usr/bin/python3
"""The knitting map as a picture (matplotlib, PNG), from a `knit-macro knitmap` directory.

  knitmap.py DIR [--out F.png] [--title T] [--status NAME.status]

Left: the machine's view, course (row) by needle (column), coloured by the loop length;
needles out of work are blank. Right: the stitches at their positions in the patch's plane
(mm), same colours. Writes DIR_knitmap.png (beside DIR) unless --out is given. The pipeline calls it; the
C++ command never needs python. With --status (the pipeline's status file of the run, JSON with
its exit_code), a run that did not exit with 0 is an error (exit 1) and nothing is drawn: DIR
may still hold an earlier run's map, which is not this run's (session 45).
"""
import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from figure_inputs import guarded_main, refused_run_placeholder, save_figure  # noqa: E402


def read_map(path):
    with open(path) as f:
        lines = [line for line in f if not line.startswith("#")]
    return np.atleast_1d(np.genfromtxt(lines, delimiter=",", names=True))


def read_summary(path):
    out = {}
    with open(path) as f:
        for line in f:
            if line.startswith("#") or ":" not in line:
                continue
            k, v = line.split(":", 1)
            out.setdefault(k.strip(), v.strip())
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dir")
    ap.add_argument("--out")
    ap.add_argument("--title", default="")
    ap.add_argument("--status", help="the pipeline's status file of the knitmap run")
    a = ap.parse_args()
    out = a.out or os.path.normpath(a.dir) + "_knitmap.png"
    if refused_run_placeholder(a.status, a.dir, out, a.title):
        return
    m = read_map(os.path.join(a.dir, "knitmap.csv"))
    s = read_summary(os.path.join(a.dir, "summary.txt"))
    courses = int(m["course"].max())
    needles = int(m["needle"].max())
    grid = np.full((courses, needles), np.nan)
    grid[m["course"].astype(int) - 1, m["needle"].astype(int) - 1] = m["l_mm"]
    lo, hi = float(np.nanmin(grid)), float(np.nanmax(grid))
    if hi - lo < 1e-9:
        lo, hi = lo - 0.05, hi + 0.05

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.8))
    im = ax1.imshow(grid, origin="lower", aspect="auto", cmap="viridis", vmin=lo, vmax=hi,
                    extent=(0.5, needles + 0.5, 0.5, courses + 0.5), interpolation="nearest")
    ax1.set_xlabel("needle")
    ax1.set_ylabel("course")
    ax1.set_title("machine view (%d needles x %d courses)" % (needles, courses))
    ax2.scatter(m["x_mm"], m["y_mm"], c=m["l_mm"], s=max(1.0, 4000.0 / len(m)), cmap="viridis",
                vmin=lo, vmax=hi, marker="s", linewidths=0)
    ax2.set_aspect("equal")
    ax2.set_xlabel("x (mm)")
    ax2.set_ylabel("y (mm)")
    ax2.set_title("stitch centres in the patch")
    fig.colorbar(im, ax=[ax1, ax2], label="loop length l (mm)")
    fig.suptitle("%s  stitches %s, yarn %.1f mm" % (
        a.title, s.get("stitches", "?"), float(s.get("yarn_length_mm", "nan"))))
    # Beside DIR, not inside it: DIR is the C++ command's output, replaced by its next run only
    # while it holds nothing else (its manifest; docs/io.md, session 29).
    out = a.out or os.path.normpath(a.dir) + "_knitmap.png"
    save_figure(fig, out, dpi=120)
    print("wrote", out)


if __name__ == "__main__":
    guarded_main(main)
