#!/usr/bin/python3
"""Beside Fig. 6: the energy-based law of one loop length (issue 11; docs/database.md "The
energy-based law") -- W(E11, E22), S11 and S22 over the (E11, E22) plane at E12 = 0, with the
homogenized data points of that loop length (converged steps with |E12| small, held-out
states as crosses), from /energy_law of the material database.

The law is re-evaluated here from the stored coefficients (schemas/database.layout.json):
f_g'' = sum_ij c[g, i + n_s j] N_i(clamp(s, a_g, b_g)) M_j(l); f' and f are integrated
numerically from 0 on a fine grid (a plot, not the C++ evaluator). A network-family law
(attribute family = "network") is evaluated in closed form (NetworkLaw).

Usage: energy_law.py --database DB.h5 --loop-length 6.5 --out fig06e_energy_law.png
"""
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(1, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from figure_inputs import guarded_main, save_figure  # noqa: E402
from cell_paths import open_database, path_set  # noqa: E402  (scripts/cell_paths.py)
from surfaces import basis, database_figure_args, pick_loop  # noqa: E402
import plots  # noqa: E402


def uniform_clamped(p, n, a, b):
    return np.concatenate([[a] * p, np.linspace(a, b, n + 1), [b] * p])


class Law:
    def __init__(self, g, l):
        self.D = np.array(g["directions"])
        self.fn = np.array(g["function_of"])
        self.sr = np.array(g["s_range"])
        self.C = np.array(g["coefficients"])
        self.p = int(g.attrs["s_degree"])
        self.n = int(g.attrs["s_spans"])
        self.floor = float(g.attrs["floor"])
        q = int(g.attrs["l_degree"])
        lk = np.array(g["l_knots"])
        M = basis(q, lk, l)[0]
        ns = self.n + self.p
        self.a = np.stack([sum(M[j] * self.C[gi, j * ns:(j + 1) * ns] for j in range(len(M)))
                           for gi in range(self.C.shape[0])])
        # f, f' tabulated from 0 by cumulative trapezoids on a fine grid per function.
        self.tab = []
        for gi in range(self.C.shape[0]):
            a, b = self.sr[gi]
            w = b - a
            s = np.linspace(a - 2 * w, b + 2 * w, 6001)
            U = uniform_clamped(self.p, self.n, a, b)
            g2 = basis(self.p, U, np.clip(s, a, b)) @ self.a[gi]
            d1 = np.concatenate([[0], np.cumsum(0.5 * (g2[1:] + g2[:-1]) * np.diff(s))])
            d1 -= np.interp(0.0, s, d1)
            f = np.concatenate([[0], np.cumsum(0.5 * (d1[1:] + d1[:-1]) * np.diff(s))])
            f -= np.interp(0.0, s, f)
            self.tab.append((s, f, d1))

    def eval(self, e):
        """W and S at strains e (..., 3) = (E11, E22, 2E12)."""
        W = 0.5 * self.floor * np.sum(e * e, axis=-1)
        S = self.floor * e.copy()
        for k, d in enumerate(self.D):
            s, f, d1 = self.tab[self.fn[k]]
            x = e @ d
            W = W + np.interp(x, s, f)
            S = S + np.interp(x, s, d1)[..., None] * d
        return W, S


def _sigma(x):
    """The network's activation and its derivative (knit/material/convex_network.hpp)."""
    xc = np.clip(x, -1.0, 1.0)
    s = np.where(x >= 1.0, x, np.where(x <= -1.0, 0.0,
                                       0.75 * (xc**2 / 2 - xc**4 / 12) + xc / 2 + 3.0 / 16))
    ds = np.where(x >= 1.0, 1.0, np.where(x <= -1.0, 0.0, 0.75 * (xc - xc**3 / 3) + 0.5))
    return s, ds


def _rho(x):
    """The stiffening activation max(0, x)^3 / 6 and its derivative (convex_network.hpp)."""
    xp = np.maximum(x, 0.0)
    return xp**3 / 6.0, 0.5 * xp**2


def _layer(x, stiff):
    """sigma on a layer's units, rho on its last `stiff` (option stiff1 / stiff2)."""
    s, ds = _sigma(x)
    if stiff > 0:
        s[..., -stiff:], ds[..., -stiff:] = _rho(x[..., -stiff:])
    return s, ds


class NetworkLaw:
    """The network family of /energy_law (attribute family = "network"), re-evaluated."""

    def __init__(self, g, l, row=None):
        """The network at theta(l) (piecewise linear in l), or at theta row `row`."""
        h1, h2 = int(g.attrs["h1"]), int(g.attrs["h2"])
        self.stiff1 = int(g.attrs.get("stiff1", 0))
        self.stiff2 = int(g.attrs.get("stiff2", 0))
        knots, theta = np.array(g["l_knots"]), np.array(g["theta"])
        if row is not None:
            t = theta[row].copy()
        else:
            t = np.array([np.interp(l, knots, theta[:, k]) for k in range(theta.shape[1])])
        o = 0
        self.A0 = t[o:o + 3 * h1].reshape(h1, 3); o += 3 * h1
        self.b0 = t[o:o + h1]; o += h1
        self.w1 = t[o:o + h1]; o += h1
        self.V = t[o:o + h2 * h1].reshape(h2, h1); o += h2 * h1
        self.A1 = t[o:o + 3 * h2].reshape(h2, 3); o += 3 * h2
        self.b1 = t[o:o + h2]; o += h2
        self.w = t[o:o + h2]; o += h2
        L = t[o:o + 9].reshape(3, 3)
        self.Q = L @ L.T
        self.floor = float(g.attrs["floor"])
        # The outer function (session 15, NetworkShape::outer): N replaced by c g(N),
        # g = exp up to the cap, its C2 quadratic continuation beyond.
        outer = g.attrs.get("outer", "none")
        outer = outer.decode() if isinstance(outer, bytes) else str(outer)
        if outer not in ("none", "exp"):
            raise ValueError(f"{g.file.filename}: {g.name}: attribute outer is {outer!r}; "
                             "this script reads 'none' and 'exp'")
        self.outer = outer == "exp"
        if self.outer:
            self.c = float(g.attrs["outer_scale"])
            self.cap = float(g.attrs["outer_cap"])
        W0, S0 = self._raw(np.zeros((1, 3)))
        self.W0, self.S0 = W0[0], np.array([S0[0, 0], S0[0, 1], 0.0])

    def _raw(self, e):
        h, dh = _layer(e @ self.A0.T + self.b0, self.stiff1)
        u, du = _layer(h @ self.V.T + e @ self.A1.T + self.b1, self.stiff2)
        W = u @ self.w + h @ self.w1 + 0.5 * np.einsum("...i,ij,...j->...", e, self.Q, e)
        kappa = self.w1 + (du * self.w) @ self.V
        S = (kappa * dh) @ self.A0 + (du * self.w) @ self.A1 + e @ self.Q
        if self.outer:
            d = np.maximum(W - self.cap, 0.0)
            ec = np.exp(np.minimum(W, self.cap))
            g, dg = ec * (1.0 + d + 0.5 * d * d), ec * (1.0 + d)
            return self.c * g, (self.c * dg)[..., None] * S
        return W, S

    def eval(self, e):
        """W and S at strains e (..., 3) = (E11, E22, 2E12)."""
        M = np.array([1.0, 1.0, -1.0])
        Wa, Sa = self._raw(e)
        Wb, Sb = self._raw(e * M)
        W = 0.5 * (Wa + Wb) - self.W0 - e @ self.S0 + 0.5 * self.floor * np.sum(e * e, axis=-1)
        S = 0.5 * (Sa + Sb * M) - self.S0 + self.floor * e
        return W, S


class BlendedLaw:
    """W(e; l) = (1 - t) W_j(e) + t W_j+1(e) between two knots' laws (attribute
    l_interpolation = "energy", session 16; knit/material/convex_network.hpp LInterpolation),
    or sum_k c_k W_k(e) over three knots' laws in a rounding window (attribute l_blend, session
    44): `a`, `b` and `t`, or `laws` and `weights`."""

    def __init__(self, a=None, b=None, t=None, laws=None, weights=None):
        if laws is None:
            laws, weights = [a, b], [1.0 - t, t]
        self.laws, self.weights = laws, weights
        self.floor = laws[0].floor

    def eval(self, e):
        W, S = 0.0, 0.0
        for law, c in zip(self.laws, self.weights):
            Wk, Sk = law.eval(e)
            W, S = W + c * Wk, S + c * Sk
        return W, S


def knot_weights(knots, l, l_blend):
    """The knot laws' weights [(j, c_j)] of the law at l (NetworkLawData::weights of
    knit/material/convex_network.hpp): one knot beyond the ends, two in a span, three within
    d = l_blend x the shorter neighbouring span of an interior knot, where the kink is rounded
    by the quadratic Bezier curve through the piecewise-linear law at l_j - d, l_j, l_j + d."""
    n = len(knots)
    if n == 1 or l <= knots[0]:
        return [(0, 1.0)]
    if l >= knots[-1]:
        return [(n - 1, 1.0)]
    up = int(np.searchsorted(knots, l, side="right"))
    if l_blend > 0.0:
        for j in (up - 1, up):
            if j < 1 or j > n - 2:
                continue
            hl, hr = knots[j] - knots[j - 1], knots[j + 1] - knots[j]
            d = l_blend * min(hl, hr)
            if abs(l - knots[j]) < d:
                s = (l - knots[j] + d) / (2.0 * d)
                c0, c2 = d / hl * (1.0 - s) ** 2, d / hr * s * s
                return [(j - 1, c0), (j, 1.0 - c0 - c2), (j + 1, c2)]
    j = up - 1
    t = (l - knots[j]) / (knots[j + 1] - knots[j])
    return [(j, 1.0 - t), (j + 1, t)]


def stored_l_interpolation(g):
    """The network law's attribute l_interpolation ("parameters" when absent); refuses any
    other value with the file and the HDF5 path."""
    li = g.attrs.get("l_interpolation", "parameters")
    li = li.decode() if isinstance(li, bytes) else str(li)
    if li not in ("parameters", "energy"):
        raise ValueError(f"{g.file.filename}: {g.name}: attribute l_interpolation is {li!r}; "
                         "this script reads 'parameters' and 'energy'")
    return li


def check_law_group(g, fam):
    """Refuses, as the C++ reader does, a stored law that cannot be evaluated as written:
    ValueError naming the file and the HDF5 path (session 47's red team: a NaN in theta gave
    "nan" figures and a blank plot with exit 0, h1 not matching theta's width re-read theta
    silently, unsorted knots and a negative floor were taken)."""
    where = f"{g.file.filename}: {g.name}"

    def real(name, ndim):
        if name not in g:
            raise ValueError(f"{where}/{name}: dataset missing")
        a = np.asarray(g[name][()])
        if a.dtype.kind != "f" or a.ndim != ndim or not np.all(np.isfinite(a)):
            raise ValueError(f"{where}/{name}: expected finite real numbers in {ndim}-D, found "
                             f"{a.dtype} of shape {a.shape}" +
                             ("" if a.dtype.kind != "f" or np.all(np.isfinite(a))
                              else " holding a NaN or inf"))
        return a

    def number(name, kind=float):
        v = g.attrs.get(name)
        try:
            return kind(v)
        except (TypeError, ValueError):  # missing, h5py.Empty, a string or an array
            raise ValueError(f"{where}: attribute {name} must be one number, got {v!r}") from None

    floor = number("floor")
    if not np.isfinite(floor) or floor < 0.0:
        raise ValueError(f"{where}: attribute floor must be finite and >= 0, got {floor!r}")
    knots = real("l_knots", 1)
    if fam == "network":
        if np.any(np.diff(knots) <= 0.0):
            raise ValueError(f"{where}/l_knots: must increase strictly, got {knots.tolist()}")
        theta = real("theta", 2)
        h1, h2 = number("h1", int), number("h2", int)
        width = 3 * h1 + 2 * h1 + h2 * h1 + 3 * h2 + 2 * h2 + 9
        if theta.shape != (len(knots), width):
            raise ValueError(f"{where}/theta: shape {theta.shape}, but h1 = {h1} and h2 = {h2} "
                             f"with {len(knots)} loop-length knots need ({len(knots)}, {width})")
    else:
        if np.any(np.diff(knots) < 0.0):
            raise ValueError(f"{where}/l_knots: must not decrease, got {knots.tolist()}")
        if np.any(real("coefficients", 2) < 0.0):
            raise ValueError(f"{where}/coefficients: must be >= 0 (a convex law)")


def load_law(g, l):
    """The stored law of /energy_law at loop length l, either family; a law that cannot be
    evaluated as written raises ValueError naming the file and the HDF5 path."""
    fam = g.attrs.get("family", "ridge")
    fam = fam.decode() if isinstance(fam, bytes) else str(fam)
    check_law_group(g, fam)
    if fam != "network":
        return Law(g, l)
    return network_law(g, l, stored_l_interpolation(g))


def network_law(g, l, mode):
    """The network law of /energy_law at loop length l with the interpolation `mode`
    ("parameters" or "energy"), whatever the file says."""
    if mode == "parameters":
        return NetworkLaw(g, l)
    knots = np.array(g["l_knots"])
    l_blend = float(g.attrs.get("l_blend", 0.0))
    if not 0.0 <= l_blend <= 0.5:  # as the C++ reader (NetworkLawData::validate)
        raise ValueError(f"{g.file.filename}: {g.name}: attribute l_blend is {l_blend}; "
                         "it must be in [0, 0.5]")
    w = [(j, c) for j, c in knot_weights(knots, l, l_blend) if c != 0.0]
    if len(w) == 1:
        return NetworkLaw(g, l, row=w[0][0])
    return BlendedLaw(laws=[NetworkLaw(g, l, row=j) for j, _ in w], weights=[c for _, c in w])


def main():
    a = database_figure_args(absent_placeholder=True)
    with open_database(a.database, "energy_law.py") as f:
        if "energy_law" not in f:
            why = (f"{a.database}: /energy_law: group missing (run `knit-meso fit "
                   f"{a.database} --law energy`)")
            if not a.absent_placeholder:
                sys.exit(why)
            # The pipeline on a sweep input with "energy_fit": false (session 46): the figure
            # says the database has no such law, a final placeholder with exit 0, not a failed
            # figure script (the report's law table says "absent" as well).
            plots.placeholder(a.out, "Fig. 6e: energy-based law",
                              why + "\n(the database holds no energy-based law, e.g. from a "
                              "sweep input with \"energy_fit\": false)")
            print(f"energy_law.py: {why}: drew a placeholder {a.out}")
            return
        k, l = pick_loop(f, a.loop_length, "energy_law.py")
        try:
            law = load_law(f["energy_law"], l)
        except ValueError as err:
            sys.exit(f"energy_law.py: {err}")
        # The stored family (a law between knots or in a rounding window is a BlendedLaw).
        fam = f["energy_law"].attrs.get("family", "ridge")
        fam = fam.decode() if isinstance(fam, bytes) else str(fam)
        family = "input-convex network" if fam == "network" else "convex ridge-spline"
        box_min, box_max = np.array(f["energy_law/box_min"]), np.array(f["energy_law/box_max"])
        pts, held = [], []
        raw = f[f"loop_{k}/raw"]
        for name in sorted(raw):
            p = raw[name]
            st = np.array(p["status"])
            E, S = np.array(p["E"]), np.array(p["S"])
            sel = (st == 0) & (np.abs(E[:, 2]) < 0.02)
            # A missing set is refused from format 2 on (it read as "paper": a held-out state
            # drawn as fit data).
            try:
                target = held if path_set(f, p) == "holdout" else pts
            except ValueError as err:
                sys.exit(str(err))
            for i in np.nonzero(sel)[0]:
                target.append((E[i, 0], E[i, 1], S[i, 0], S[i, 1]))
    pts, held = np.array(pts).reshape(-1, 4), np.array(held).reshape(-1, 4)
    e11 = np.linspace(min(box_min[0], -0.2) * 1.2, box_max[0] * 1.2, 121)
    e22 = np.linspace(min(box_min[1], -0.2) * 1.2, box_max[1] * 1.2, 121)
    X, Y = np.meshgrid(e11, e22)
    e = np.stack([X, Y, np.zeros_like(X)], axis=-1)
    W, S = law.eval(e)
    fig, ax = plt.subplots(1, 3, figsize=(15, 4.6), constrained_layout=True)
    panels = [(W, "W (MPa)", None), (S[..., 0], "S11 (MPa)", 2), (S[..., 1], "S22 (MPa)", 3)]
    for axk, (Z, title, col) in zip(ax, panels):
        lim = np.percentile(np.abs(Z), 99)
        cs = axk.contourf(X, Y, Z, levels=30, cmap="viridis" if col is None else "RdBu_r",
                          vmin=None if col is None else -lim, vmax=None if col is None else lim)
        fig.colorbar(cs, ax=axk)
        axk.add_patch(plt.Rectangle((box_min[0], box_min[1]), box_max[0] - box_min[0],
                                    box_max[1] - box_min[1], fill=False, ls="--", ec="k", lw=0.8))
        if col is None:
            axk.plot(pts[:, 0], pts[:, 1], "k.", ms=2, label="data (|E12| < 0.02)")
        else:
            axk.scatter(pts[:, 0], pts[:, 1], c=pts[:, col], cmap="RdBu_r", vmin=-lim, vmax=lim,
                        edgecolors="k", linewidths=0.4, s=14, label="data, same colour scale")
        if len(held):
            axk.plot(held[:, 0], held[:, 1], "kx", ms=5, label="held out")
        axk.set_xlabel("E11 (course)")
        axk.set_ylabel("E22 (wale)")
        axk.set_title(f"{title}, l = {l:g} mm, E12 = 0")
        axk.legend(loc="lower right", fontsize=7)
    fig.suptitle(f"Energy-based law ({family} W; dashed: data strain box)")
    save_figure(fig, a.out, dpi=130)
    print(f"wrote {a.out}")


if __name__ == "__main__":
    guarded_main(main)
