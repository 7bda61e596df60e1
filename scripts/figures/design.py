#!/usr/bin/python3
"""The objective history and the designed fields of a `knit-macro design` directory (PNG).

  design.py DIR [--out F.png] [--title T] [--section E22] [--design DESIGN.json]

Panels: J per iteration (history.csv, log scale), and the J of the design written (J_final of
summary.txt: the best of all evaluations, which can lie below the last accepted iteration's);
the designed case's stitch-value field l and knitting-angle field alpha (case.json) over the
parameter domain, with the profile at mid-height when a field varies; the final run's
load-strain curve (run/load_strain.csv: the reaction an objective names, else the first) with
the objectives drawn on it: a `reaction` objective's targets as points, a `reaction_linearity`
objective's straight line through the origin and the curve at its last strain; `displacement`
objectives' targets and the values reached (summary.txt) in a panel of their own; with
--section, that strain component of the final run along the central section v = 0.5
(run/results.h5, last step), with the targets of `target_strain` objectives of that component
whose region holds the section. The objectives are read from the design file
(--design; by default the pipeline's DIR/../inputs/NAME.json when it exists). Writes
DIR_design.png (beside DIR) unless --out is given. The pipeline calls it (make -f scripts/pipeline.mk
designs); the C++ command never needs python.
"""
import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402

try:
    import h5py  # noqa: E402
except ImportError:  # the section panel is then left out
    h5py = None
from scipy.interpolate import BSpline  # noqa: E402
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from figure_inputs import guarded_main, read_json, refused_run_placeholder, save_figure  # noqa: E402


def read_history(path):
    with open(path) as f:
        lines = [line for line in f if not line.startswith("#")]
    return np.atleast_1d(np.genfromtxt(lines, delimiter=",", names=True))


def field_grid(spec, n=81):
    """Values of a scalar spline field {degrees, knots_u, knots_v, values (u fastest)}."""
    if not isinstance(spec, dict) or "values" not in spec:
        return None
    pu, pv = spec["degrees"]
    U, V = np.array(spec["knots_u"], float), np.array(spec["knots_v"], float)
    nu, nv = len(U) - pu - 1, len(V) - pv - 1
    C = np.array(spec["values"], float).reshape(nv, nu)
    scale = np.pi / 180.0 if spec.get("unit") == "deg" else 1.0
    u = np.linspace(U[0], U[-1], n)
    v = np.linspace(V[0], V[-1], n)

    def basis(knots, p, count, x):
        B = np.zeros((len(x), count))
        for i in range(count):
            c = np.zeros(count)
            c[i] = 1.0
            B[:, i] = BSpline(knots, c, p, extrapolate=False)(np.clip(x, knots[0], knots[-1] - 1e-12))
        return np.nan_to_num(B)

    Bu, Bv = basis(U, pu, nu, u), basis(V, pv, nv, v)
    return u, v, Bv @ C @ Bu.T, C, scale


def field_unit(name, scale):
    """The unit of a designed field's values as the case gives them (field_grid's values are
    not converted): mm for the stitch value, the angle field's own "unit" (scale pi/180: deg)
    for the knitting angle. Session 39's walkthrough: a field in degrees was labelled rad."""
    if name == "stitch_value":
        return "mm"
    return "deg" if scale != 1.0 else "rad"


def colour_limits(F, flat=1e-6, span=0.01):
    """(vmin, vmax, uniform) of a designed field's map. A field whose values differ by at most
    `flat` x their size (or 1) is uniform: drawn in one colour on a scale of +-`span` x its
    value (session 40's walkthrough: l = 5.982232096 +- 1e-11 was drawn as a full gradient, its
    colour bar read 0.6 ... 2.0 mm under an offset 'le-11+5.98' that ran into the title)."""
    lo, hi = float(np.nanmin(F)), float(np.nanmax(F))
    size = max(abs(lo), abs(hi), 1.0)
    if hi - lo > flat * size:
        return lo, hi, False
    mid = 0.5 * (lo + hi)
    return mid - span * size, mid + span * size, True


def read_summary(path):
    """summary.txt of a design -> {key: text} of its 'key: value' lines ({} when missing)."""
    out = {}
    try:
        with open(path) as f:
            for line in f:
                key, sep, value = line.partition(":")
                if sep and key.strip() not in out:
                    out[key.strip()] = value.strip()
    except OSError:  # missing or unreadable: the callers say what is missing
        return {}
    return out


def reached_values(summary, name):
    """The values an objective reached and their unit, from summary.txt's 'reached NAME: v1 v2
    ... UNIT (target ...; at strain ...)' line (read_summary's dict); None when there is none
    (only reaction and displacement objectives have one)."""
    line = summary.get("reached " + str(name))
    if not line:
        return None
    words = line.split("(")[0].split()
    try:
        values = [float(w) for w in words[:-1]]
    except ValueError:
        return None
    return (values, words[-1]) if values and len(words) > 1 else None


def design_file(a):
    """The design file whose objectives are drawn: --design, else the pipeline's
    OUT/design/inputs/NAME.json beside DIR = OUT/design/NAME (None when there is none)."""
    if a.design:
        return a.design
    d = os.path.normpath(os.path.abspath(a.dir))
    guess = os.path.join(os.path.dirname(d), "inputs", os.path.basename(d) + ".json")
    return guess if os.path.exists(guess) else None


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dir")
    ap.add_argument("--out")
    ap.add_argument("--title", default="")
    ap.add_argument("--section", default="", help="strain field along v = 0.5 of the final run (E11, E22, E12)")
    ap.add_argument("--design", default="",
                    help="the design file, for its objectives (default: DIR/../inputs/NAME.json)")
    ap.add_argument("--status", help="the pipeline's status file of the design run: a run "
                    "that exited with 2 or more wrote nothing, and DIR is not its output")
    a = ap.parse_args()
    if refused_run_placeholder(a.status, a.dir, a.out or os.path.normpath(a.dir) + "_design.png", a.title,
                               ok_codes=(0, 1)):  # 1: an iteration limit, its outputs written
        return
    history = os.path.join(a.dir, "history.csv")
    h = read_history(history)
    if h.dtype.names is None or not {"iteration", "J"} <= set(h.dtype.names):
        raise ValueError(f"{history}: the columns iteration and J are missing")
    if not np.all(np.isfinite(np.atleast_1d(h["J"]))):
        raise ValueError(f"{history}: J has a non-finite value")
    case = read_json(os.path.join(a.dir, "case.json"))
    summary = read_summary(os.path.join(a.dir, "summary.txt"))
    dfile = design_file(a)
    objectives = read_json(dfile).get("objectives", []) if dfile else None
    # A twin experiment's targets are computed by knit-macro design: summary.txt's
    # 'twin target NAME: v1 v2 ...' lines (docs/design.md, `twin`).
    for k, o in enumerate(objectives or []):
        if "target" not in o:
            name = o.get("name", o.get("type"))
            line = summary.get("twin target " + str(name))
            if line:
                try:
                    o["target"] = [float(x) for x in line.split()]
                    o["twin"] = True
                except ValueError:
                    pass  # drawn without its target
    fields = [(k, case["material"].get(k)) for k in ("stitch_value", "knitting_angle")]
    fields = [(k, field_grid(s)) for k, s in fields if field_grid(s) is not None]
    run = os.path.join(a.dir, "run")
    curve = None
    if os.path.exists(os.path.join(run, "load_strain.csv")):
        ls = read_history(os.path.join(run, "load_strain.csv"))
        loads = [n for n in ls.dtype.names if n.endswith("_N")]
        named = [o.get("reaction", "") + "_N" for o in objectives or []
                 if o.get("type") in ("reaction", "reaction_linearity")]
        loads = [n for n in named if n in loads][:1] + loads
        if loads:
            curve = (np.atleast_1d(ls["strain"]), np.atleast_1d(ls[loads[0]]), loads[0])
    section = None
    h5 = os.path.join(run, "results.h5")
    if a.section and h5py is not None and os.path.exists(h5):
        with h5py.File(h5, "r") as f:
            last = sorted(f["fields"].keys())[-1]
            g = f["fields"][last]
            nu, nv = int(g.attrs["grid_u"]), int(g.attrs["grid_v"])
            E = np.array(g[a.section]).reshape(nv, nu)  # u fastest
            # The step drawn is the run's last output step: its load factor goes in the title
            # (session 39's walkthrough: a design at 10 % strain was drawn at 30 % unsaid).
            section = (np.linspace(0, 1, nu), E[nv // 2], float(g.attrs.get("load_factor", np.nan)))
    # Displacement objectives (session 40's walkthrough: the figure drew none): their targets
    # and what the final design reached, from summary.txt's 'reached' lines.
    moved = []
    for o in objectives or []:
        if o.get("type") != "displacement":
            continue
        tag = o.get("name", o.get("type"))
        at = np.atleast_1d(np.array(o.get("at_strain", []), float))
        got = reached_values(summary, tag)
        target = o.get("target", [])
        if len(at) and (got is not None or len(target) == len(at)):
            moved.append((tag, o.get("component", ""), at, target, got))
    npan = 1 + len(fields) + (curve is not None) + (section is not None) + bool(moved)
    fig, axes = plt.subplots(1, npan, figsize=(4.2 * npan, 3.8), squeeze=False)
    ax = axes[0][0]
    J = np.maximum(np.atleast_1d(h["J"]), 1e-300)
    it = np.atleast_1d(h["iteration"])
    ax.semilogy(it, J, "o-", label="accepted iterations (history.csv)")
    status = summary.get("status", "")
    try:
        j_final = float(summary["J_final"])
    except (KeyError, ValueError):
        j_final = None
    if j_final is not None and np.isfinite(j_final):
        # The design written is the best of all evaluations (docs/design.md): its J can lie below
        # the last accepted iteration's (uniform_load: 2.44e-26 against 3.08e-18).
        x_final = it[-1]
        ax.semilogy([x_final], [max(j_final, 1e-300)], "*", ms=13, color="tab:red", zorder=3,
                    label=f"final design (summary.txt): J = {j_final:.3g}")
    ax.set_xlabel("iteration")
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_ylabel("objective J")
    missing = "" if j_final is not None else "\n(no J_final in summary.txt)"
    ax.set_title("objective history" + (f" ({status})" if status else "") + missing,
                 fontsize=11 if len(status) < 20 else 9)
    ax.legend(fontsize=7, loc="best")
    ax.grid(True, which="both", alpha=0.3)
    for i, (name, (u, v, F, C, scale)) in enumerate(fields):
        ax = axes[0][i + 1]
        unit = field_unit(name, scale)
        vmin, vmax, uniform = colour_limits(F)
        im = ax.imshow(F, origin="lower", extent=(u[0], u[-1], v[0], v[-1]), aspect="equal",
                       cmap="viridis", vmin=vmin, vmax=vmax)
        cb = fig.colorbar(im, ax=ax, label=("l" if name == "stitch_value" else "alpha") + f" ({unit})")
        cb.formatter.set_useOffset(False)
        cb.update_ticks()
        ax.set_xlabel("theta1 (u)")
        ax.set_ylabel("theta2 (v)")
        ax.set_title(f"designed {name}" + (f": uniform {0.5 * (vmin + vmax):.6g} {unit}"
                                           if uniform else ""), fontsize=11 if not uniform else 9)
        if C.shape[1] > 1 and not uniform:  # the profile along u at mid-height, in an inset
            # (until session 25 it was drawn over the map in the map's coordinates, where it
            # read as a line of the domain at theta2 ~ 0.2)
            prof = F[F.shape[0] // 2]
            ins = ax.inset_axes([0.08, 0.06, 0.5, 0.28])
            ins.plot(u, prof, "k-", lw=1.2)
            ins.set_facecolor((1, 1, 1, 0.85))
            ins.set_title(f"along v = 0.5: {prof.min():.3g} ... {prof.max():.3g} {unit}",
                          fontsize=6, pad=2)
            ins.tick_params(labelsize=6, pad=1, length=2)
            ins.ticklabel_format(axis="y", useOffset=False)
            ins.margins(x=0)
    k = 1 + len(fields)
    if curve is not None:
        ax = axes[0][k]
        e, F, name = curve
        ax.plot(100 * e, F, "o-", ms=3, label="designed")
        reaction = name[:-len("_N")]
        e0, F0 = np.concatenate([[0.0], e]), np.concatenate([[0.0], F])  # the unloaded start
        for o in objectives or []:
            if o.get("reaction") != reaction:
                continue
            at = np.atleast_1d(np.array(o.get("at_strain", []), float))
            tag = o.get("name", o.get("type"))
            if o.get("type") == "reaction" and len(o.get("target", [])) == len(at):
                ax.plot(100 * at, o["target"], "D", ms=8, mfc="none", mec="tab:red", mew=1.6,
                        zorder=3, label=f"{'twin ' if o.get('twin') else ''}target of {tag}: "
                        + ", ".join(
                            f"{t:.4g} N at {100 * x:.3g} %" for x, t in zip(at, o["target"])))
            elif o.get("type") == "reaction_linearity" and len(at):
                # The objective: the curve's distance from the line through the origin and
                # its value at the last strain of the objective (docs/design.md).
                R = np.interp(at, e0, F0)
                ax.plot([0, 100 * at[-1]], [0, R[-1]], "k--", lw=1,
                        label=f"{tag}: line through 0 and the last point")
                ax.plot(100 * at, R, "s", ms=6, mfc="none", mec="tab:red", zorder=3,
                        label=f"{tag}: strains of the objective")
        ax.set_xlabel("applied strain (%)")
        ax.set_ylabel(reaction + " (N)")
        note = "" if objectives is not None else "\n(no design file: objectives not drawn)"
        ax.set_title("final run: load-strain" + note, fontsize=11 if not note else 9)
        ax.legend(fontsize=7)
        ax.grid(True, alpha=0.3)
        k += 1
    if moved:
        ax = axes[0][k]
        for tag, comp, at, target, got in moved:
            if len(target) == len(at):
                ax.plot(100 * at, target, "D", ms=8, mfc="none", mec="tab:red", mew=1.6, zorder=3,
                        label=f"target of {tag} ({comp})")
            if got is not None and len(got[0]) == len(at):
                ax.plot(100 * at, got[0], "o", ms=6, label=f"{tag} reached ({got[1]})")
        ax.set_xlabel("applied strain (%)")
        ax.set_ylabel("displacement (mm)")
        ax.set_title("displacement objectives:\ntargets and the final design (summary.txt)",
                     fontsize=9)
        ax.legend(fontsize=7)
        ax.grid(True, alpha=0.3)
        k += 1
    if section is not None:
        ax = axes[0][k]
        u, E, load_factor = section
        ax.plot(u, E, "-", label="final run")
        # target_strain objectives of this component whose region holds the section v = 0.5:
        # each target over its region's u interval (session 40's walkthrough: not drawn).
        drawn = []
        for o in objectives or []:
            reg = o.get("region", {})
            if (o.get("type") != "target_strain" or o.get("component") != a.section
                    or not reg or not reg["v"][0] <= 0.5 <= reg["v"][1]):
                continue
            for x, t in zip(np.atleast_1d(o.get("at_strain", [])), o.get("target", [])):
                ax.plot(reg["u"], [t, t], color="tab:red", ls="--", lw=1.4,
                        label=f"target of {o.get('name', o['type'])}: {t:.3g} at {100 * x:.3g} %")
                drawn.append(t)
            ax.legend(fontsize=7)
        if any(o.get("type") == "strain_variance" and o.get("component") == a.section
               for o in objectives or []):  # the objective's ideal: a uniform strain
            ax.axhline(np.mean(E), color="tab:red", ls="--", lw=1,
                       label=f"uniform (strain_variance target): mean {np.mean(E):.3g}")
            ax.legend(fontsize=7)
        lo, hi, flat = colour_limits(E, span=0.01)
        if flat:  # a uniform strain: no offset axis of round-off (session 40's walkthrough),
            # with the targets drawn kept in view (the session's review: they were clipped)
            lo, hi = min([lo] + drawn), max([hi] + drawn)
            pad = 0.05 * (hi - lo)
            ax.set_ylim(lo - pad, hi + pad)
        ax.ticklabel_format(axis="y", useOffset=False)
        ax.set_xlabel("theta1 (u) at v = 0.5")
        ax.set_ylabel(a.section + " [-]")
        ax.set_title(f"final run: {a.section} along the section at load factor {load_factor:.3g}\n"
                     f"(the run's last output step; std {np.std(E):.2g})", fontsize=9)
        ax.grid(True, alpha=0.3)
    if a.title:
        fig.suptitle(a.title)
    fig.tight_layout()
    # Beside DIR, not inside it: DIR is the C++ command's output, replaced by its next run only
    # while it holds nothing else (its manifest; docs/io.md, session 29).
    out = a.out or os.path.normpath(a.dir) + "_design.png"
    save_figure(fig, out, dpi=110)
    print(out)


if __name__ == "__main__":
    guarded_main(main)
