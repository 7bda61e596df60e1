#!/usr/bin/python3
"""Figures of the paper's examples from knit-macro results (matplotlib, PNG).

  plots.py --results DIR load --title T --out F.png CASE...      load (N) vs applied strain
  plots.py --results DIR deformed --case C --field E22 --at 0.3 --title T --out F.png
  plots.py --results DIR fields --case C --title T --out F.png   stitch value / knitting angle
  plots.py --results DIR placeholder --title T --message M --out F.png

Deformed shapes are drawn in the x1-x2 plane (the 3-D hyperbolic paraboloid is projected),
coloured by a Green-Lagrange strain component of the local Cartesian frame (E11, E22, E12 as
in the paper's figures); the reference outline is dashed. Design fields are drawn on the
reference surface with arrows along the knitting (course) direction Q(alpha) e1.
"""
import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
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


def cmd_load(a):
    fig, ax = plt.subplots(figsize=(6, 4.2))
    drawn = 0
    study = any(n.startswith(("conv", "mesh")) for n in a.cases)  # legend by mesh
    for name in a.cases:
        r = Result(a.results, name)
        if not r.ok or len(r.csv.get("strain", [])) == 0:
            continue
        eps, f = r.strain(), r.load()
        lab = label_of(name, r.case, study) + ("" if r.completed else " (stopped early)")
        ax.plot(100 * eps, f, "-" if r.completed else "--", marker=".", ms=3, label=lab)
        drawn += 1
    if drawn == 0:
        plt.close(fig)
        placeholder(a.out, a.title, "no results (the runs failed; see the report)")
        return
    ax.set_xlabel("applied strain [%]")
    ax.set_ylabel("load [N]")
    ax.set_title(a.title, fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    save(fig, a.out)


def outline(ax, P, **kw):
    """Boundary of a (n_v, n_u, 3) grid in x1-x2."""
    b = np.concatenate([P[0, :], P[:, -1], P[-1, ::-1], P[::-1, 0]])
    ax.plot(b[:, 0], b[:, 1], **kw)


def cmd_deformed(a):
    r = Result(a.results, a.case)
    step = r.step_at(a.at) if r.ok else None
    if step is None:
        placeholder(a.out, a.title, f"{a.case}: no field output (run failed)")
        return
    f = r.fields(step)
    if a.field not in f:
        placeholder(a.out, a.title, f"{a.case}: no field {a.field}")
        return
    x, v = f["x"], f[a.field]
    fig, ax = plt.subplots(figsize=(5.6, 4.6))
    lim = max(abs(v.min()), abs(v.max()))
    cmap = "RdBu_r" if v.min() < -0.25 * lim else "jet"
    pc = ax.pcolormesh(x[..., 0], x[..., 1], v, shading="gouraud", cmap=cmap,
                       vmin=-lim if cmap == "RdBu_r" else None, vmax=lim if cmap == "RdBu_r" else None)
    if "X" in f:
        outline(ax, f["X"], color="k", ls="--", lw=0.8)
    outline(ax, x, color="k", lw=1.0)
    cb = fig.colorbar(pc, ax=ax, shrink=0.85)
    cb.set_label(a.field)
    eps = r.strain_of_step(step)
    state = "" if r.completed else " [run stopped early]"
    ax.set_title(f"{a.title}\nstep {step}, applied strain {100 * eps:.1f} %, "
                 f"{a.field} in [{v.min():.3f}, {v.max():.3f}]{state}", fontsize=9)
    ax.set_aspect("equal")
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


def cmd_fields(a):
    r = Result(a.results, a.case)
    steps = r.steps() if r.ok else []
    if not steps:
        placeholder(a.out, a.title, f"{a.case}: no field output (run failed)")
        return
    f = r.fields(steps[0])
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
    s.add_argument("--title", default="")
    s.add_argument("--out", required=True)
    s = sub.add_parser("fields")
    s.add_argument("--case", required=True)
    s.add_argument("--title", default="")
    s.add_argument("--out", required=True)
    s = sub.add_parser("placeholder", help="a PNG that says why a figure is missing")
    s.add_argument("--title", default="")
    s.add_argument("--message", default="")
    s.add_argument("--out", required=True)
    a = p.parse_args()
    if a.cmd == "placeholder":
        placeholder(a.out, a.title, a.message)
        return
    {"load": cmd_load, "deformed": cmd_deformed, "fields": cmd_fields}[a.cmd](a)


if __name__ == "__main__":
    guarded_main(main)
