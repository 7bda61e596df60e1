#!/usr/bin/python3
"""Sensitivity of the paper's observables to the open unit-cell parameters (issue #12).

Table format (CSV, '#' starts a comment line, header required):

    parameter,value,observable,result
    g0,0.02,max_E22_45_wale_30,0.371
    gamma,0.25,F45_over_F65_wale_30,2.4

parameter: the varied mesoscale choice (g0, gamma, normal_stiffness, friction, thickness, ...);
value: its value in the run (the other parameters at their defaults); observable: a name of
the measured quantity (free text without commas, the same name across the parameters);
result: the measured number. One row per (parameter, value, observable).

  sensitivity.py TABLE.csv --out F.png [--params g0,gamma]
      one column per parameter (its own x axis: g0 and gamma first; --params selects), one row
      per panel of observables, one line per observable of the panel. Observables group into
      panels by name (issue #12 item 4): "<panel>@<line>" (e.g. ratio_wale@E0.2: panel
      ratio_wale, line E0.2), otherwise "<panel>_<line>" split at the last underscore
      (stiffening_wale_45: panel stiffening_wale, line 45). Ratio panels show the reference
      lines 1 and 1.5 (the report's "much stiffer" factor), stiffening panels the line 1; a
      panel whose values span more than a factor 20 (all positive) is drawn on a log scale.
"""
import argparse
import math
import os
import sys
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from figure_inputs import guarded_main  # noqa: E402

FIGURE = "sensitivity.png"
COLUMNS = ["parameter", "value", "observable", "result"]
FIRST = ("g0", "gamma")


def read_table(path):
    """-> list of (parameter, value, observable, result). ValueError names the line."""
    rows = []
    header = None
    with open(path) as f:
        for k, line in enumerate(f, 1):
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            cells = [c.strip() for c in line.split(",")]
            if header is None:
                if cells != COLUMNS:
                    raise ValueError(f"{path}:{k}: header must be {','.join(COLUMNS)}")
                header = cells
                continue
            if len(cells) != 4:
                raise ValueError(f"{path}:{k}: 4 columns expected, got {len(cells)}")
            try:
                value, result = float(cells[1]), float(cells[3])
            except ValueError:
                raise ValueError(f"{path}:{k}: value and result must be numbers") from None
            if not (math.isfinite(value) and math.isfinite(result)):
                raise ValueError(f"{path}:{k}: non-finite number")
            rows.append((cells[0], value, cells[2], result))
    if header is None:
        raise ValueError(f"{path}: no header")
    return rows


def panel_of(observable):
    """-> (panel, line) of an observable name (see the module text)."""
    if "@" in observable:
        panel, line = observable.split("@", 1)
    elif "_" in observable:
        panel, line = observable.rsplit("_", 1)
    else:
        panel, line = observable, ""
    return panel, line


# Headline panels first (the paper's observations), the rest alphabetically.
PANEL_ORDER = ("min_ratio", "ratio_wale", "ratio_course", "S_wale_45", "S_wale_65",
               "S_course_45", "S_course_65", "stiffening_wale", "stiffening_course",
               "extensibility", "lateral_wale", "lateral_course")
RATIO_LINES = (1.0, 1.5)  # equal stiffness; the report's "much stiffer" factor


def draw(rows, out, params=None):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    allp = sorted({r[0] for r in rows}, key=lambda p: (p not in FIRST, FIRST.index(p)
                                                         if p in FIRST else 0, p))
    params = [p for p in allp if not params or p in params] or allp
    panels = sorted({panel_of(r[2])[0] for r in rows},
                    key=lambda q: (PANEL_ORDER.index(q) if q in PANEL_ORDER else len(PANEL_ORDER),
                                   q))
    fig, axes = plt.subplots(len(panels), len(params), figsize=(3.2 * len(params),
                                                                2.3 * len(panels)), squeeze=False)
    for i, q in enumerate(panels):
        for j, p in enumerate(params):
            ax = axes[i][j]
            lines = sorted({panel_of(r[2])[1] for r in rows if panel_of(r[2])[0] == q})
            ys = []
            for ln in lines:
                pts = sorted((r[1], r[3]) for r in rows
                             if r[0] == p and panel_of(r[2]) == (q, ln))
                if pts:
                    ax.plot([a for a, _ in pts], [b for _, b in pts], "o-", ms=3,
                            label=ln or None)
                    ys += [b for _, b in pts]
            if ys and min(ys) > 0 and max(ys) > 20 * min(ys):
                ax.set_yscale("log")
            if "ratio" in q:
                for y in RATIO_LINES:
                    ax.axhline(y, color="k", lw=0.8, ls="--" if y == 1 else ":")
            if q.startswith("stiffening"):
                ax.axhline(1.0, color="k", lw=0.8, ls="--")
            if i == len(panels) - 1:
                ax.set_xlabel(p)
            if j == 0:
                ax.set_ylabel(q, fontsize=8)
                if any(lines):
                    ax.legend(fontsize=6, loc="best")
            ax.tick_params(labelsize=7)
            ax.grid(alpha=0.3)
    height = 2.3 * len(panels)
    width = 3.2 * len(params)
    # Fixed margins (in inches, as fractions of the figure) instead of bbox_inches="tight",
    # which draws all the axes twice (11 of the script's 14 CPU s were those two draws).
    fig.subplots_adjust(top=1 - 0.5 / height, bottom=0.55 / height, left=0.75 / width,
                        right=1 - 0.15 / width, hspace=0.3, wspace=0.3)
    fig.suptitle("Observables against the unit-cell parameters (others at their defaults)",
                 y=1 - 0.15 / height)
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    tmp = out + ".tmp.png"
    fig.savefig(tmp, dpi=80)
    plt.close(fig)
    os.replace(tmp, out)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("table")
    ap.add_argument("--out", required=True)
    ap.add_argument("--params", default="",
                    help="comma-separated parameters to draw (default: all in the table)")
    a = ap.parse_args()
    draw(read_table(a.table), a.out, [p for p in a.params.split(",") if p])


if __name__ == "__main__":
    guarded_main(main)
