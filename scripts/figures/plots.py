#!/usr/bin/python3
"""Figures of the paper's examples from knit-macro results (matplotlib, PNG).

  plots.py --results DIR load --title T --out F.png CASE...      load (N) vs applied strain
  plots.py --results DIR deformed --case C --field E22 --at 0.3 --title T --out F.png
           [--share-limits CASE...]                          one colour scale with CASE...
  plots.py --results DIR fields --case C --title T --out F.png   stitch value / knitting angle
  plots.py --results DIR geometry --case C --title T --out F.png reference surface (Fig. 16a)
  plots.py --results DIR placeholder --title T --message M --out F.png
  plots.py --results DIR laws --paper-results DIR2 --title T --out F.png CASE...
           the default energy law (solid) beside the paper's eq. 17 law (dashed, DIR2's runs of
           the same cases), steps with det K < 0 on the paper law's LU path marked x

Deformed shapes are coloured by a Green-Lagrange strain component of the local Cartesian frame
(E11, E22, E12 as in the paper's figures): a planar patch in the x1-x2 plane with the reference
outline dashed, a shell that leaves the plane (the hyperbolic paraboloid) as a 3-D surface with
the reference surface as a grey wire mesh. Colour limits: colour_limits() (spikes at loaded
corners clipped to the 1st/99th percentile, the true extremes in the title; --share-limits gives
several figures one scale); the map: is_diverging() (a diverging map centred on 0 where the
field's bulk has both signs of comparable size, a sequential one otherwise). Design fields are
drawn on the reference surface with arrows along the knitting (course) direction Q(alpha) e1.
"""
import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.cm  # noqa: E402
import matplotlib.colors  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from figure_inputs import guarded_main  # noqa: E402
from results import Result  # noqa: E402

LABELS = {
    "s312_uniform_45_course": "4.5 mm course-wise",
    "s312_uniform_45_wale": "4.5 mm wale-wise",
    "s312_uniform_65_course": "6.5 mm course-wise",
    "s312_uniform_65_wale": "6.5 mm wale-wise",
    "s313_discontinuous_course": "course-wise",
    "s313_discontinuous_wale": "wale-wise",
    "s314_linear_course": "course-wise",
    "s314_linear_wale": "wale-wise",
    "s315_diagonal_45deg_vertical": "vertical",
    "s321_bilinear_diagonal": "diagonal (load along the diagonal)",
    "s322_curved_horizontal": "horizontal",
    "s323_hypar_tension": "tension",
    "s323_hypar_compression": "compression",
}


def mesh_label(case):
    """'p = P, h = H' from a case's refinement, plus the corner pad's radius when it has one
    (a mesh study compares meshes, so its legend names them and their corner condition)."""
    ref = case.get("refinement") or {}
    p, el = ref.get("degree"), ref.get("elements")
    if p is None or not el:
        return None
    h = el[0] if len(set(el)) == 1 else "x".join(str(e) for e in el)
    radii = [bc.get("radius") or 0 for bc in case.get("boundary_conditions", []) if "corner" in bc]
    grip = ""
    if radii and all(r > 0 for r in radii) and len(set(radii)) == 1:
        grip = f" ({radii[0]:g} mm pad)"
    elif radii and not any(r > 0 for r in radii):
        grip = " (corner point)"
    elif radii:
        grip = " (corner pads " + ", ".join(f"{r:g}" for r in radii) + " mm)"
    return f"p = {p}, h = {h}{grip}"


def label_of(name, case=None, study=False):
    if study and case:
        lab = mesh_label(case)
        if lab:
            return lab
    if name in LABELS:
        return LABELS[name]
    if name.startswith(("conv", "mesh")):
        tail = name.split("_")[1]  # p5h1
        p, h = tail[1:].split("h")
        return f"p = {p}, h = {h}"
    return name


def save(fig, out):
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    tmp = out + ".tmp.png"
    fig.savefig(tmp, dpi=110, bbox_inches="tight")
    plt.close(fig)
    os.replace(tmp, out)


def placeholder(out, title, message):
    fig, ax = plt.subplots(figsize=(6, 3))
    ax.axis("off")
    ax.set_title(title)
    ax.text(0.5, 0.5, message, ha="center", va="center", wrap=True, fontsize=9)
    save(fig, out)


UNIAXIAL_WARNING = "warning: where the fabric is stretched uniaxially"


def uniaxial_warned(summary):
    """True when a run's summary.txt carries knit-macro's warning that the law's own uniaxial
    response departs from the unit cell's (session 41: the load-strain figures mark such runs,
    so that the reader of the curves sees it where the curves are)."""
    return any(line.startswith(UNIAXIAL_WARNING) for line in summary.splitlines())


def cmd_load(a):
    fig, ax = plt.subplots(figsize=(6, 4.2))
    drawn = 0
    warned = 0
    study = any(n.startswith(("conv", "mesh")) for n in a.cases)  # legend by mesh
    for name in a.cases:
        r = Result(a.results, name)
        if not r.ok or len(r.csv.get("strain", [])) == 0:
            continue
        eps, f = r.strain(), r.load()
        lab = label_of(name, r.case, study) + ("" if r.completed else " (stopped early)")
        if uniaxial_warned(r.summary()):
            lab += " *"
            warned += 1
        ax.plot(100 * eps, f, "-" if r.completed else "--", marker=".", ms=3, label=lab)
        drawn += 1
    finish_load_figure(fig, ax, a, drawn, 8,
                       "* knit-macro warns: the law's own uniaxial stress departs from the unit "
                       "cell's there (the report's warnings; docs/database.md)" if warned else "")


def finish_load_figure(fig, ax, a, drawn, legend_size, note):
    """Axes, legend and the note below the axis label of a load-strain figure, saved to a.out;
    its placeholder when no curve was drawn."""
    if drawn == 0:
        plt.close(fig)
        placeholder(a.out, a.title, "no results (the runs failed; see the report)")
        return
    ax.set_xlabel("applied strain [%]")
    ax.set_ylabel("load [N]")
    ax.set_title(a.title, fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=legend_size)
    if note:  # below the axis label (the saved figure's tight box takes it in)
        ax.text(0.0, -0.16, note, fontsize=6.5, color="0.3", ha="left", va="top",
                transform=ax.transAxes)
    save(fig, a.out)


def negative_determinant(sign):
    """The points of a load-strain curve (the origin first, then one per converged step) whose
    step had det K < 0: load_strain.csv's determinant_sign (-1, +1; 0 unknown), None -> none."""
    if sign is None or len(sign) == 0:
        return np.zeros(1, dtype=bool)
    return np.concatenate([[False], np.asarray(sign) < 0])


def law_of_run(summary, default):
    """The law a knit run evaluated, from its summary.txt's material report ("knit material
    (energy law): ..." or "knit material: ...", the paper's eq. 17), else `default` (session 45's
    red team: with a database without the energy law the default runs evaluated the paper's law,
    and fig07e labelled them "energy law")."""
    for line in summary.splitlines():
        if line.startswith("material report: knit material (energy law):"):
            return "energy law"
        if line.startswith("material report: knit material:"):
            return "paper's law"
    return default


def cmd_laws(a):
    """The load-strain curves of the same cases with the two laws (issue 11 item 4, session
    43): the energy law's runs in --results (solid), the paper's law's in --paper-results
    (dashed, the same colour), its steps with det K < 0 (load_strain.csv's determinant_sign,
    the LU path's stability indicator) marked x. A run that stopped early is drawn to its last
    step and says so in the legend."""
    fig, ax = plt.subplots(figsize=(6, 4.2))
    drawn = 0
    unstable = False
    missing = []  # "NAME (law)" without a curve: said in the note (session 43's review)
    mislabelled = []  # runs whose summary names the other law (the label follows the run)
    for k, name in enumerate(a.cases):
        colour = f"C{k}"
        for results, style, law in ((a.results, "-", "energy law"),
                                    (a.paper_results, "--", "paper's law")):
            r = Result(results, name)
            if not r.ok or len(r.csv.get("strain", [])) == 0:
                missing.append(f"{label_of(name)} ({law})")
                continue
            eps, f = r.strain(), r.load()
            ran = law_of_run(r.summary(), law)
            if ran != law:
                mislabelled.append(f"{label_of(name)} ({'solid' if style == '-' else 'dashed'})")
            lab = f"{label_of(name)}, {ran}" + ("" if r.completed else " (stopped early)")
            ax.plot(100 * eps, f, style, color=colour, lw=1.2, label=lab)
            neg = negative_determinant(r.csv.get("determinant_sign"))
            if law == "paper's law" and neg.any() and len(neg) == len(eps):
                ax.plot(100 * eps[neg], f[neg], "x", color=colour, ms=6, mew=1.5)
                unstable = True
            drawn += 1
    finish_load_figure(
        fig, ax, a, drawn, 7,
        "solid: the energy law (default); dashed: the paper's eq. 17 law, the same database"
        + ("; x: det K < 0 on the paper law's LU path (an odd number of negative eigenvalues)"
           if unstable else "")
        + ("\nno curve (the run failed or converged no step; see the logs): " + ", ".join(missing)
           if missing else "")
        + ("\nby their summaries these runs evaluated the other law (labelled as they ran): "
           + ", ".join(mislabelled) if mislabelled else ""))


def outline(ax, P, **kw):
    """Boundary of a (n_v, n_u, 3) grid in x1-x2."""
    b = np.concatenate([P[0, :], P[:, -1], P[-1, ::-1], P[::-1, 0]])
    ax.plot(b[:, 0], b[:, 1], **kw)


# A colour limit moves in from the field's extreme to its 1st/99th percentile when the extreme
# lies more than this fraction of the field's range beyond it (a spike at a loaded corner: the
# E11 of Fig. 14a reaches 0.430 where its 99th percentile is 0.18, and the rest of the patch was
# drawn in two colours). The true extremes stay in the title; the colour bar's end says clipped.
SPIKE_FRACTION = 0.2


def colour_limits(values, diverging):
    """(vmin, vmax, extend) of a field's colour scale: its extremes, or its 1st/99th percentiles
    on a side where the extreme is a spike (SPIKE_FRACTION); symmetric about 0 when diverging.
    `values` holds finite numbers only."""
    v = np.asarray(values, dtype=float).ravel()
    vmin, vmax = float(v.min()), float(v.max())
    p1, p99 = (float(q) for q in np.percentile(v, [1, 99]))
    spread = vmax - vmin
    lo = p1 if p1 - vmin > SPIKE_FRACTION * spread else vmin
    hi = p99 if vmax - p99 > SPIKE_FRACTION * spread else vmax
    if diverging:
        lim = max(abs(lo), abs(hi))
        lo, hi = -lim, lim
    if hi <= lo:  # a constant field
        lo, hi = lo - 0.5, hi + 0.5
    below, above = vmin < lo, vmax > hi
    extend = "both" if below and above else "min" if below else "max" if above else "neither"
    return lo, hi, extend


# Both signs count as "of comparable size" when the smaller side reaches this fraction of the
# larger one.
DIVERGING_FRACTION = 0.25


def is_diverging(values):
    """A strain field with both signs of comparable size (each side at least DIVERGING_FRACTION
    of the other) is drawn with a diverging map centred on 0, any other with a sequential one.
    Decided on the 1st/99th percentiles, the bulk of the field, as the colour limits are: a
    spike at a loaded corner no longer picks the map (session 31: the extremes decided it, and
    the test lacked the positive side, so a field of one sign, s315's E11 in [-0.31, 0.02], was
    drawn on a diverging scale with half of it unused)."""
    p1, p99 = (float(q) for q in np.percentile(np.asarray(values, dtype=float), [1, 99]))
    lim = max(abs(p1), abs(p99))
    return bool(lim > 0 and p1 < -DIVERGING_FRACTION * lim and p99 > DIVERGING_FRACTION * lim)


def not_flat(P, rel=1e-6):
    """True when the grid P (n_v, n_u, 3) leaves the x1-x2 plane (x3 varies)."""
    size = max(np.ptp(P[..., 0]), np.ptp(P[..., 1]), 1e-300)
    return np.ptp(P[..., 2]) > rel * size


def field_at(results, case, field, at):
    """(Result, step, fields) of `case` at `at`, or a message saying what is missing."""
    r = Result(results, case)
    step = r.step_at(at) if r.ok else None
    if step is None:
        return f"{case}: no field output (run failed)"
    f = r.fields(step)
    if field not in f:
        return f"{case}: no field {field}"
    if not np.isfinite(f[field]).any():
        return f"{case}: field {field} has no finite value at step {step}"
    return r, step, f


def cmd_deformed(a):
    got = field_at(a.results, a.case, a.field, a.at)
    if isinstance(got, str):
        placeholder(a.out, a.title, got)
        return
    r, step, f = got
    x, v = f["x"], f[a.field]
    finite = np.isfinite(v)
    pool = [v[finite]]
    shared, unshared = [], []
    for other in a.share_limits or []:  # one colour scale for the figures of a comparison
        g = field_at(a.results, other, a.field, a.at)
        if isinstance(g, str):  # this figure is still drawn, on the scale of what there is
            print(f"plots.py: warning: --share-limits: {g}", file=sys.stderr)
            unshared.append(other)
            continue
        w = g[2][a.field]
        pool.append(w[np.isfinite(w)])
        shared.append(other)
    pool = np.concatenate(pool)
    diverging = is_diverging(pool)
    cmap = "RdBu_r" if diverging else "jet"
    lo, hi, extend = colour_limits(pool, diverging)
    norm = matplotlib.colors.Normalize(lo, hi)
    X = f.get("X")
    three_d = not_flat(x) or (X is not None and not_flat(X))
    if three_d:
        fig = plt.figure(figsize=(7.2, 5.6))
        ax = fig.add_subplot(projection="3d")
        colours = plt.get_cmap(cmap)(norm(np.where(finite, v, np.nan)))
        colours[~finite] = (0.8, 0.8, 0.8, 1.0)
        ax.plot_surface(x[..., 0], x[..., 1], x[..., 2], facecolors=colours, rstride=1,
                        cstride=1, linewidth=0, antialiased=False, shade=False)
        if X is not None:  # the reference surface: a grey wire mesh
            sk = max(1, X.shape[1] // 10)
            ax.plot_wireframe(X[..., 0], X[..., 1], X[..., 2], rstride=sk, cstride=sk,
                              color="0.35", lw=0.5, ls="--", label="reference surface")
            ax.legend(fontsize=7, loc="upper left")
        ax.set_zlabel("x3 [mm]")
        pts = x.reshape(-1, 3) if X is None else np.vstack([x.reshape(-1, 3), X.reshape(-1, 3)])
        ax.set_box_aspect(np.maximum(np.ptp(pts, axis=0), 1e-3 * np.ptp(pts).max()))
        ax.view_init(elev=28, azim=-60)
        sm = matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap)
        cb = fig.colorbar(sm, ax=ax, shrink=0.7, pad=0.1, extend=extend)
        u3 = f["u"][..., 2] if "u" in f else x[..., 2] - (X[..., 2] if X is not None else 0.0)
        geo = f"\nout-of-plane displacement u3 in [{np.nanmin(u3):.1f}, {np.nanmax(u3):.1f}] mm"
    else:
        fig, ax = plt.subplots(figsize=(5.6, 4.6))
        pc = ax.pcolormesh(x[..., 0], x[..., 1], np.ma.masked_invalid(v), shading="gouraud",
                           cmap=cmap, norm=norm)
        if X is not None:
            outline(ax, X, color="k", ls="--", lw=0.8)
        outline(ax, x, color="k", lw=1.0)
        cb = fig.colorbar(pc, ax=ax, shrink=0.85, extend=extend)
        ax.set_aspect("equal")
        geo = ""
    cb.set_label(f"{a.field} [-]")
    eps = r.strain_of_step(step)
    state = "" if r.completed else " [run stopped early]"
    vf = v[finite]
    scale = ""
    if extend != "neither" or a.share_limits:
        scale = f", colour scale [{lo:.3g}, {hi:.3g}]"
    if shared:
        scale += " shared with " + ", ".join(shared)
    if unshared:
        scale += " (not shared with " + ", ".join(unshared) + ": no field)"
    bad = "" if finite.all() else (f"\n{(~finite).sum()} points with non-finite {a.field} "
                                   + ("(grey)" if three_d else "(left blank)"))
    ax.set_title(f"{a.title}\nstep {step}, applied strain {100 * eps:.1f} %, "
                 f"{a.field} in [{vf.min():.3g}, {vf.max():.3g}]{scale}{state}{geo}{bad}",
                 fontsize=9)
    ax.set_xlabel("x1 [mm]")
    ax.set_ylabel("x2 [mm]")
    save(fig, a.out)


def course_direction(X, alpha):
    """Q(alpha) e1 with e1 = A1/|A1| (local Cartesian frame), e2 = A3 x e1; also e1."""
    A1 = np.gradient(X, axis=1)
    A2 = np.gradient(X, axis=0)
    e1 = A1 / np.linalg.norm(A1, axis=2, keepdims=True)
    A3 = np.cross(A1, A2)
    A3 /= np.linalg.norm(A3, axis=2, keepdims=True)
    e2 = np.cross(A3, e1)
    c, s = np.cos(alpha)[..., None], np.sin(alpha)[..., None]
    return c * e1 + s * e2, e1


def first_fields(a):
    """The fields of the first output step of `a.case`, or None after drawing a placeholder
    that says the run wrote none."""
    r = Result(a.results, a.case)
    steps = r.steps() if r.ok else []
    if not steps:
        placeholder(a.out, a.title, f"{a.case}: no field output (run failed)")
        return None
    return r.fields(steps[0])


def cmd_geometry(a):
    """The reference mid-surface X of a case (paper Fig. 16a: the hyperbolic paraboloid
    x3 = 0.24 (x1 - 2.5)(x2 - 2.5) mm, corners moved up or down by 15 mm) in 3-D, coloured by
    its height x3, the corners labelled with their x3."""
    f = first_fields(a)
    if f is None:
        return
    X = f.get("X")
    if X is None or not np.all(np.isfinite(X)):
        placeholder(a.out, a.title, f"{a.case}: no finite reference coordinates")
        return
    z = X[..., 2]
    fig = plt.figure(figsize=(6.4, 5.2))
    ax = fig.add_subplot(projection="3d")
    lo, hi = float(z.min()), float(z.max())
    norm = matplotlib.colors.Normalize(lo, hi if hi > lo else lo + 1.0)
    ax.plot_surface(X[..., 0], X[..., 1], z, facecolors=plt.get_cmap("viridis")(norm(z)),
                    rstride=1, cstride=1, linewidth=0, antialiased=False, shade=False)
    for j, i in ((0, 0), (0, -1), (-1, 0), (-1, -1)):
        p = X[j, i]
        ax.scatter([p[0]], [p[1]], [p[2]], color="k", s=12)
        ax.text(p[0], p[1], p[2], f"  x3 = {p[2]:+.1f}", fontsize=8)
    ax.set_box_aspect(np.maximum(np.ptp(X.reshape(-1, 3), axis=0), 1e-3 * np.ptp(X).max()))
    ax.view_init(elev=28, azim=-60)
    sm = matplotlib.cm.ScalarMappable(norm=norm, cmap="viridis")
    fig.colorbar(sm, ax=ax, shrink=0.7, pad=0.1).set_label("x3 [mm]")
    ax.set_xlabel("x1 [mm]")
    ax.set_ylabel("x2 [mm]")
    ax.set_zlabel("x3 [mm]")
    ax.set_title(f"{a.title}\nreference mid-surface of {a.case}: x3 in [{lo:.1f}, {hi:.1f}] mm",
                 fontsize=9)
    save(fig, a.out)


def cmd_fields(a):
    f = first_fields(a)
    if f is None:
        return
    if "stitch_value" not in f or "X" not in f:
        placeholder(a.out, a.title, f"{a.case}: the material wrote no design fields")
        return
    X, l, alpha = f["X"], f["stitch_value"], f.get("knitting_angle", np.zeros_like(f["stitch_value"]))
    d, e1 = course_direction(X, alpha)
    nv, nu = l.shape
    sk = max(1, nu // 10)
    sl = (slice(None, None, sk), slice(None, None, sk))
    fig, axs = plt.subplots(1, 2, figsize=(11, 4.6))
    for ax, val, lab, cmap in ((axs[0], l, "stitch value l [mm]", "viridis"),
                               (axs[1], alpha, "knitting angle alpha [rad]", "coolwarm")):
        pc = ax.pcolormesh(X[..., 0], X[..., 1], val, shading="gouraud", cmap=cmap)
        fig.colorbar(pc, ax=ax, shrink=0.85).set_label(lab)
        if ax is axs[1]:
            ax.quiver(X[sl][..., 0], X[sl][..., 1], e1[sl][..., 0], e1[sl][..., 1], color="0.6",
                      angles="xy", pivot="mid", scale=18, width=0.004, label="a1 (theta1)")
        ax.quiver(X[sl][..., 0], X[sl][..., 1], d[sl][..., 0], d[sl][..., 1], color="k",
                  angles="xy", pivot="mid", scale=18, width=0.005, label="course direction")
        outline(ax, X, color="k", lw=0.8)
        ax.set_aspect("equal")
        ax.set_xlabel("x1 [mm]")
        ax.set_ylabel("x2 [mm]")
        ax.set_title(f"{lab}: [{val.min():.3f}, {val.max():.3f}]", fontsize=9)
    axs[1].legend(fontsize=7, loc="upper right")
    fig.suptitle(a.title, fontsize=10)
    save(fig, a.out)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--results", required=True)
    sub = p.add_subparsers(dest="cmd", required=True)
    s = sub.add_parser("load")
    s.add_argument("--title", default="")
    s.add_argument("--out", required=True)
    s.add_argument("cases", nargs="+")
    s = sub.add_parser("deformed")
    s.add_argument("--case", required=True)
    s.add_argument("--field", required=True)
    s.add_argument("--at", default="last")
    s.add_argument("--share-limits", nargs="+", metavar="CASE",
                   help="one colour scale for this case and these (same field, same --at)")
    s.add_argument("--title", default="")
    s.add_argument("--out", required=True)
    s = sub.add_parser("fields")
    s.add_argument("--case", required=True)
    s.add_argument("--title", default="")
    s.add_argument("--out", required=True)
    s = sub.add_parser("geometry", help="the reference surface in 3-D (Fig. 16a)")
    s.add_argument("--case", required=True)
    s.add_argument("--title", default="")
    s.add_argument("--out", required=True)
    s = sub.add_parser("laws", help="the energy law beside the paper's law (load-strain)")
    s.add_argument("--paper-results", required=True,
                   help="the results directory of the same cases run with the paper's law")
    s.add_argument("--title", default="")
    s.add_argument("--out", required=True)
    s.add_argument("cases", nargs="+")
    s = sub.add_parser("placeholder", help="a PNG that says why a figure is missing")
    s.add_argument("--title", default="")
    s.add_argument("--message", default="")
    s.add_argument("--out", required=True)
    a = p.parse_args()
    if a.cmd == "placeholder":
        placeholder(a.out, a.title, a.message)
        return
    # A results directory or a case the pipeline never made is a mistake on the command line,
    # not a failed run (session 36's red team: a typo drew "no results (the runs failed)" with
    # exit 0). A case counts as made once its status file or its output exists.
    if not os.path.isdir(a.results):
        p.error(f"--results: {a.results} is not a directory")
    dirs = [a.results] + ([a.paper_results] if a.cmd == "laws" else [])
    for d in dirs[1:]:
        if not os.path.isdir(d):
            p.error(f"--paper-results: {d} is not a directory")
    for d in dirs:
        for name in getattr(a, "cases", None) or [a.case] + (getattr(a, "share_limits", None)
                                                               or []):
            if not (os.path.exists(os.path.join(d, name + ".status"))
                    or os.path.isdir(os.path.join(d, name))):
                p.error(f"{name}: no status file and no output in {d} (a misspelt case?)")
    {"load": cmd_load, "deformed": cmd_deformed, "fields": cmd_fields,
     "geometry": cmd_geometry, "laws": cmd_laws}[a.cmd](a)


if __name__ == "__main__":
    guarded_main(main)
