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

  sensitivity.py TABLE.csv --out F.png    one panel per observable, one line per parameter
                                          (each parameter on its own x axis: g0 and gamma first)
"""
import argparse
import math
import os

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


def draw(rows, out):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    params = sorted({r[0] for r in rows}, key=lambda p: (p not in FIRST, FIRST.index(p)
                                                           if p in FIRST else 0, p))
    obs = sorted({r[2] for r in rows})
    fig, axes = plt.subplots(len(obs), len(params), figsize=(3.2 * len(params),
                                                             2.4 * len(obs)), squeeze=False)
    for i, o in enumerate(obs):
        for j, p in enumerate(params):
            ax = axes[i][j]
            pts = sorted((r[1], r[3]) for r in rows if r[0] == p and r[2] == o)
            if pts:
                ax.plot([a for a, _ in pts], [b for _, b in pts], "o-")
            if i == len(obs) - 1:
                ax.set_xlabel(p)
            if j == 0:
                ax.set_ylabel(o, fontsize=8)
            ax.grid(alpha=0.3)
    fig.suptitle("Observables against the unit-cell parameters (others at their defaults)")
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    tmp = out + ".tmp.png"
    fig.savefig(tmp, dpi=100, bbox_inches="tight")
    plt.close(fig)
    os.replace(tmp, out)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("table")
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    draw(read_table(a.table), a.out)


if __name__ == "__main__":
    main()
