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
      Parameter names head the columns; panels are labelled with units (panel_label); a panel
      whose every value is the same number (reached_*: the paths' end strain) is left out and
      named in a note at the bottom. Rows refused_<dir>_<l> (= 1: knit-meso refused that cell
      as input, scripts/calibrate.py, so the parameter value has no observable on that path)
      are no panel: the note names the parameter values and paths.
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


# Readable names with units (schemas/cell.schema.json; scripts/calibrate.py's observables).
PARAM_LABELS = {
    "g0": "contact allowance g0 [mm]",
    "gamma": "loop bulge gamma/w [-]",
    "diameter": "yarn diameter d [mm]",
    "friction": "friction coefficient mu [-]",
    "normal_stiffness": "contact penalty k_N [MPa]",
}


def _dirname(text):
    return {"wale": "wale", "course": "course"}.get(text, text)


def panel_label(q):
    """A panel key as an axis label with its unit: S_* in MPa, strains and ratios dimensionless
    (unknown keys as they are)."""
    parts = q.split("_")
    if q == "min_ratio":
        return "min S(4.5)/S(6.5)\nover E = 0.05-0.4 [-]"
    if parts[0] == "ratio" and len(parts) == 2:
        return f"S(4.5)/S(6.5), {parts[1]} [-]"
    if parts[0] == "S" and len(parts) == 3 and parts[2] in ("45", "65"):
        return f"S_{parts[1]}, l = {int(parts[2]) / 10:g} mm\n[MPa]"
    if parts[0] == "stiffening" and len(parts) == 2:
        return f"stiffening, {parts[1]}\nsecant E0.3 / E0.1 [-]"
    if q == "extensibility":
        return "extensibility\nE(0.5 MPa) course/wale [-]"
    if parts[0] == "lateral" and len(parts) == 2:
        return f"lateral E at E = 0.3,\n{parts[1]} [-]"
    if q.startswith("E_at_") and q.endswith(("_course", "_wale")):
        stress = q[len("E_at_"):].rsplit("_", 1)[0].replace("MPa", " MPa")
        return f"E at S = {stress},\n{q.rsplit('_', 1)[1]} [-]"
    if parts[0] == "reached" and len(parts) == 2:
        return f"largest E reached,\n{parts[1]} [-]"
    return q


def line_label(ln):
    """A line key as a legend entry: 45 -> l = 4.5 mm, E0.2 -> E = 0.2."""
    if ln in ("45", "65"):
        return f"l = {int(ln) / 10:g} mm"
    if ln.startswith("E") and ln[1:].replace(".", "", 1).isdigit():
        return f"E = {ln[1:]}"
    return ln or None


def constant_panels(rows, panels):
    """{panel: value} of the panels whose every result is the same number (drawn, they carry
    nothing: the reached_* strains are the paths' end 0.4 for every parameter)."""
    out = {}
    for q in panels:
        ys = [r[3] for r in rows if panel_of(r[2])[0] == q]
        if ys and max(ys) - min(ys) <= 1e-12 * max(1.0, abs(max(ys))):
            out[q] = ys[0]
    return out


REFUSED = "refused_"


def split_refused(rows):
    """-> (the rows that are observables, {(parameter, value): [path, ...]} of the refused_*
    rows; path as in the observable name, e.g. course_65)."""
    kept, refused = [], {}
    for r in rows:
        if r[2].startswith(REFUSED):
            refused.setdefault((r[0], r[1]), []).append(r[2][len(REFUSED):])
        else:
            kept.append(r)
    return kept, refused


def refused_note(refused):
    """The figure's note on the refused paths ("" if none): gamma = 0.1 (course, l = 6.5 mm;
    wale, l = 6.5 mm)."""
    def path(tag):
        d, ln = panel_of(tag)
        return f"{d}, {line_label(ln)}" if ln in ("45", "65") else tag
    return "; ".join(f"{p} = {v:g} ({'; '.join(path(t) for t in sorted(tags))})"
                     for (p, v), tags in sorted(refused.items()))


def draw(rows, out, params=None):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    allp = sorted({r[0] for r in rows}, key=lambda p: (p not in FIRST, FIRST.index(p)
                                                         if p in FIRST else 0, p))
    params = [p for p in allp if not params or p in params] or allp
    rows, refused = split_refused([r for r in rows if r[0] in params])
    panels = sorted({panel_of(r[2])[0] for r in rows},
                    key=lambda q: (PANEL_ORDER.index(q) if q in PANEL_ORDER else len(PANEL_ORDER),
                                   q))
    if not panels:
        raise ValueError("the sensitivity table has no row to draw")
    constant = constant_panels(rows, panels)
    if len(constant) < len(panels):
        panels = [q for q in panels if q not in constant]
    else:  # all constant: draw them rather than nothing
        constant = {}
    notes = []
    if constant:
        notes.append("Not drawn, constant for every parameter value: " + "; ".join(
            f"{panel_label(q).replace(chr(10), ' ').replace(' [-]', '')} = {v:g}"
            for q, v in constant.items()))
    if refused:
        notes.append("Refused by knit-meso as input (no observables): " + refused_note(refused))
    note_h = 0.3 * len(notes) + (0.15 if notes else 0.0)
    height = 2.3 * len(panels) + note_h
    width = 3.2 * len(params)
    fig, axes = plt.subplots(len(panels), len(params), figsize=(width, height), squeeze=False)
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
                            label=line_label(ln))
                    ys += [b for _, b in pts]
            if ys and min(ys) > 0 and max(ys) > 20 * min(ys):
                ax.set_yscale("log")
            if "ratio" in q:
                for y in RATIO_LINES:
                    ax.axhline(y, color="k", lw=0.8, ls="--" if y == 1 else ":")
            if q.startswith("stiffening"):
                ax.axhline(1.0, color="k", lw=0.8, ls="--")
            if i == 0:
                ax.set_title(PARAM_LABELS.get(p, p), fontsize=10, fontweight="bold")
            if i == len(panels) - 1:
                ax.set_xlabel(PARAM_LABELS.get(p, p), fontsize=9)
            if j == 0:
                ax.set_ylabel(panel_label(q), fontsize=9)
                if any(lines):
                    ax.legend(fontsize=7, loc="best")
            ax.tick_params(labelsize=8)
            ax.grid(alpha=0.3)
    # Fixed margins (in inches, as fractions of the figure) instead of bbox_inches="tight",
    # which draws all the axes twice (11 of the script's 14 CPU s were those two draws).
    fig.subplots_adjust(top=1 - 0.75 / height, bottom=(0.6 + note_h) / height,
                        left=0.95 / width, right=1 - 0.15 / width, hspace=0.3, wspace=0.3)
    fig.suptitle("Observables against the unit-cell parameters (one varied per column, the "
                 "others at their defaults)", y=1 - 0.15 / height)
    for k, text in enumerate(reversed(notes)):
        fig.text(0.5, (0.15 + 0.3 * k) / height, text, ha="center", va="bottom", fontsize=9,
                 style="italic")
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    tmp = out + ".tmp.png"
    fig.savefig(tmp, dpi=120)
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
