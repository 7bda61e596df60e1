#!/usr/bin/python3
"""Fig. 6: the stress response surfaces S11(E11, E22), S22(E11, E22) and the curve S12(E12)
of one loop length, with the homogenized data points (black dots), from the material database
(schemas/database.layout.json: /loop_k/fit/{knots_1, knots_2, E_ctrl, S_ctrl}, /loop_k/fit/shear,
/loop_k/raw/path_qq/{E, S, status}).

The data drawn as the surface's data are the paths of set "paper" (the paper's fan, to which
eq. 17 is fitted; scripts/cell_paths.py path_set). The "coverage" biaxial paths are drawn faint
(faint red x), only where they lie inside the surface's strain range (the image of [0, 1]^2 in the
E11-E22 plane): outside it the surface says nothing about them.

The surfaces are drawn as the paper defines them (eq. 17): E(xi) and S(xi) evaluated on a grid
of the shared parameter domain [0, 1]^2, plotted as S over E.

Usage: surfaces.py --database DB.h5 --loop-length 6.5 --out fig06.png
"""
import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.path import Path as MplPath  # noqa: E402

sys.path.insert(1, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from cell_paths import open_database, path_set  # noqa: E402  (scripts/cell_paths.py)
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from figure_inputs import guarded_main  # noqa: E402


def basis(p, U, x):
    """All B-spline basis values N_{i,p}(x) (Cox-de Boor), x in [U[0], U[-1]]."""
    U = np.asarray(U, dtype=float)
    n = len(U) - p - 1
    x = np.clip(np.atleast_1d(x), U[0], U[-1])
    N = np.zeros((len(x), len(U) - 1))
    for k in range(len(U) - 1):
        N[:, k] = (U[k] <= x) & (x < U[k + 1])
    last = np.max(np.nonzero(U < U[-1])[0])
    N[x >= U[-1], :] = 0.0
    N[x >= U[-1], last] = 1.0
    for d in range(1, p + 1):
        M = np.zeros((len(x), len(U) - 1 - d))
        for k in range(len(U) - 1 - d):
            a = U[k + d] - U[k]
            b = U[k + d + 1] - U[k + 1]
            if a > 0:
                M[:, k] += (x - U[k]) / a * N[:, k]
            if b > 0:
                M[:, k] += (U[k + d + 1] - x) / b * N[:, k + 1]
        N = M
    return N[:, :n]


def pick_loop(f, l, prog="figure"):
    """The database's loop length nearest to l, (index, value); a note on stderr when it is not
    l itself (session 48's walkthrough: --loop-length 4.5 on a 5-6 mm database drew 5 mm, and
    the default 6.5 drew 6.0, without a word)."""
    ls = np.array(f["loop_lengths"])
    k = int(np.argmin(abs(ls - l)))
    if abs(float(ls[k]) - l) > 1e-9:
        have = ", ".join(f"{v:g}" for v in ls)
        print(f"{prog}: note: the database has no loop length {l:g} mm (it has {have} mm); "
              f"the figure shows the nearest, {float(ls[k]):g} mm", file=sys.stderr)
    return k, float(ls[k])


def database_figure_args(absent_placeholder=False):
    """The command line of the database figures: --database, --loop-length (6.5), --out, and
    with `absent_placeholder` (Fig. 6e) the flag --absent-placeholder."""
    ap = argparse.ArgumentParser()
    ap.add_argument("--database", required=True)
    ap.add_argument("--loop-length", type=float, default=6.5)
    ap.add_argument("--out", required=True)
    if absent_placeholder:
        ap.add_argument("--absent-placeholder", action="store_true",
                        help="a database without /energy_law gets a placeholder figure that "
                             "says so, exit 0 (the pipeline); without it, an error, exit 1")
    return ap.parse_args()


def main():
    a = database_figure_args()
    # A missing or non-HDF5 file: named, no traceback (session 21).
    with open_database(a.database, "surfaces.py") as f:
        k, l = pick_loop(f, a.loop_length, "surfaces.py")
        g = f[f"loop_{k}"]
        gen = f.attrs.get("generator", b"?")
        gen = gen.decode() if isinstance(gen, bytes) else str(gen)
        fit = g["fit"]
        p1, p2 = int(fit.attrs["degree_1"]), int(fit.attrs["degree_2"])
        n1 = int(fit.attrs["n1"])
        U1, U2 = np.array(fit["knots_1"]), np.array(fit["knots_2"])
        Ec, Sc = np.array(fit["E_ctrl"]), np.array(fit["S_ctrl"])
        sh = fit["shear"]
        ps, Us = int(sh.attrs["degree"]), np.array(sh["knots"])
        E12c, S12c = np.array(sh["E12_ctrl"]), np.array(sh["S12_ctrl"])
        data = []
        if "raw" in g:
            for name in g["raw"]:
                pg = g["raw"][name]
                E, S = np.array(pg["E"]), np.array(pg["S"])
                st = np.array(pg["status"]) if "status" in pg else np.zeros(len(E))
                kind = pg.attrs.get("kind", b"biaxial")
                kind = kind.decode() if isinstance(kind, bytes) else str(kind)
                ok = (st == 0) & np.all(np.isfinite(E), axis=1) & np.all(np.isfinite(S), axis=1)
                data.append((path_set(f, pg), kind, E[ok], S[ok]))
    n2 = Ec.shape[0] // n1
    xi = np.linspace(0, 1, 41)
    B1, B2 = basis(p1, U1, xi), basis(p2, U2, xi)  # (41, n1), (41, n2)

    def surf(C, c):
        return B2 @ C[:, c].reshape(n2, n1) @ B1.T  # (xi2, xi1)

    E1, E2, S1, S2 = surf(Ec, 0), surf(Ec, 1), surf(Sc, 0), surf(Sc, 1)
    if not all(np.all(np.isfinite(v)) for v in (E1, E2, S1, S2)):
        raise SystemExit(f"surfaces.py: {a.database}: loop_{k}/fit: the surface has "
                         "non-finite values (E_ctrl or S_ctrl)")
    paper = [(E, Sd) for st, kind, E, Sd in data if st == "paper" and kind == "biaxial" and len(E)]
    if not paper:
        raise SystemExit(f"surfaces.py: {a.database}: loop_{k}/raw: no converged biaxial path "
                         "of set \"paper\" (the data of the surface)")
    Ep, Sp = np.vstack([E for E, _ in paper]), np.vstack([S for _, S in paper])
    # The surface's strain range: the image of the boundary of [0, 1]^2 in the E11-E22 plane.
    rim = np.concatenate([np.c_[E1[0, :], E2[0, :]], np.c_[E1[:, -1], E2[:, -1]],
                          np.c_[E1[-1, ::-1], E2[-1, ::-1]], np.c_[E1[::-1, 0], E2[::-1, 0]]])
    cov = [(E, Sd) for st, kind, E, Sd in data if st == "coverage" and kind == "biaxial"]
    Ec_all = np.vstack([E for E, _ in cov]) if cov else np.zeros((0, 3))
    Sc_all = np.vstack([S for _, S in cov]) if cov else np.zeros((0, 3))
    inside = MplPath(rim).contains_points(Ec_all[:, :2]) if len(Ec_all) else np.zeros(0, bool)
    Ecov, Scov = Ec_all[inside], Sc_all[inside]
    fig = plt.figure(figsize=(17, 5))
    fig.subplots_adjust(wspace=0.35)
    for c, (S, lab) in enumerate(((S1, "S11"), (S2, "S22"))):
        ax = fig.add_subplot(1, 3, c + 1, projection="3d")
        ax.plot_surface(E1, E2, S, cmap="viridis", alpha=0.75, linewidth=0)
        ax.scatter(Ep[:, 0], Ep[:, 1], Sp[:, c], color="k", s=4,
                   label=f"data: paper fan ({len(paper)} paths, {len(Ep)} points)")
        if len(Ecov):
            ax.scatter(Ecov[:, 0], Ecov[:, 1], Scov[:, c], color="tab:red", marker="x", s=12,
                       linewidths=0.8, alpha=0.6,
                       label=f"coverage paths inside the range ({len(Ecov)} of {len(Ec_all)} "
                       "points)")
        ax.legend(fontsize=7, loc="upper left")
        ax.set_xlabel("E11 [-]")
        ax.set_ylabel("E22 [-]")
        ax.set_zlabel(f"{lab} [MPa]")
        ax.set_title(f"({'ab'[c]}) {lab}(E11, E22)", fontsize=10)
    ax = fig.add_subplot(1, 3, 3)
    t = np.linspace(0, 1, 200)
    Bs = basis(ps, Us, t)
    ax.plot(Bs @ E12c, Bs @ S12c, "-", label="response curve")
    shear = [(E, Sd) for st, kind, E, Sd in data if st == "paper" and kind == "shear" and len(E)]
    for i, (E, Sd) in enumerate(shear):
        ax.plot(E[:, 2], Sd[:, 2], "k.", label="data" if i == 0 else None)
    ax.set_xlabel("E12 [-]")
    ax.set_ylabel("S12 [MPa]")
    ax.set_title("(c) S12(E12)", fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    note = " - SYNTHETIC stand-in database" if gen == "synth" else ""
    fig.suptitle(f"Fig. 6: response surfaces, l = {l} mm (database generator: {gen}){note}",
                 fontsize=11)
    tmp = a.out + ".tmp.png"
    fig.savefig(tmp, dpi=100, bbox_inches="tight")
    os.replace(tmp, a.out)


if __name__ == "__main__":
    guarded_main(main)
