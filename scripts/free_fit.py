"""Free (law-free) reference fits of the cell's stresses, for the held-out criterion of issue 11:
how well a smooth function trained on the fit paths alone predicts the held-out states, with no
energy and no convexity (docs/law-experiments.md, "What predicts the held-out states"). Used by
fit_bounds.py and by report.py (the reference printed beside the held-out verdict). numpy only.

  * free energy: S = grad W with W a tensor-product cubic B-spline over the strain box;
  * free interpolant: each of S11, S22, S12 its own spline of the same basis.
Both are least squares with a second-difference smoothing.
"""
import numpy as np


def bspline_basis(x, knots, p, deriv=0):
    """Values (deriv 0) or first derivatives (deriv 1) of the B-splines of degree p on the
    clamped knot vector `knots` at x (inside [knots[p], knots[-p-1]]; the right end belongs to the
    last span): a len(x) x (len(knots) - p - 1) matrix (Cox-de Boor; The NURBS Book, A2.2)."""
    x = np.asarray(x, dtype=float)
    t = np.asarray(knots, dtype=float)
    n = len(t) - p - 1
    # Degree 0: the span of each x (the last non-empty span holds the right end).
    span = np.clip(np.searchsorted(t, x, side="right") - 1, p, n - 1)
    q = p - deriv
    B = np.zeros((len(x), len(t) - 1))
    B[np.arange(len(x)), span] = 1.0
    for d in range(1, q + 1):
        Bn = np.zeros((len(x), len(t) - 1 - d))
        for i in range(len(t) - 1 - d):
            den1 = t[i + d] - t[i]
            den2 = t[i + d + 1] - t[i + 1]
            a = (x - t[i]) / den1 * B[:, i] if den1 > 0 else 0.0
            b = (t[i + d + 1] - x) / den2 * B[:, i + 1] if den2 > 0 else 0.0
            Bn[:, i] = a + b
        B = Bn
    if deriv == 0:
        return B
    # First derivative from the degree p-1 functions: p (N_i,p-1 / (t_i+p - t_i)
    # - N_i+1,p-1 / (t_i+p+1 - t_i+1)).
    D = np.zeros((len(x), n))
    for i in range(n):
        den1 = t[i + p] - t[i]
        den2 = t[i + p + 1] - t[i + 1]
        if den1 > 0:
            D[:, i] += p / den1 * B[:, i]
        if den2 > 0:
            D[:, i] -= p / den2 * B[:, i + 1]
    return D


class SplineBox:
    """Tensor-product cubic B-splines over the strain box, n functions per axis."""

    def __init__(self, e, n, p=3):
        self.lo = e.min(0) - 0.05
        self.hi = e.max(0) + 0.05
        self.n, self.p = n, p

    def _axis(self, x, k, deriv):
        t = np.concatenate([[self.lo[k]] * self.p, np.linspace(self.lo[k], self.hi[k],
                                                               self.n - self.p + 1),
                            [self.hi[k]] * self.p])
        return bspline_basis(np.clip(x, self.lo[k], self.hi[k]), t, self.p, deriv)

    def matrix(self, e, deriv_axis=-1):
        a = [self._axis(e[:, k], k, 1 if k == deriv_axis else 0) for k in range(3)]
        return np.einsum("pi,pj,pk->pijk", *a).reshape(len(e), -1)

    def smoothing(self, lam):
        eye = np.eye(self.n)
        d2 = np.diff(eye, 2, axis=0)
        blocks = [np.kron(np.kron(d2, eye), eye), np.kron(np.kron(eye, d2), eye),
                  np.kron(np.kron(eye, eye), d2)]
        return np.sqrt(lam) * np.vstack(blocks)


def free_fits(train_e, train_s, test_e, n=8, lam=1e-3):
    """Held-out predictions (test_e) of the free energy (S = grad W) and of the free
    interpolant, trained on (train_e, train_s)."""
    box = SplineBox(np.vstack([train_e, test_e]), n)
    reg = box.smoothing(lam)
    zeros = np.zeros(len(reg))
    grads = [box.matrix(train_e, c) for c in range(3)]
    x = np.linalg.lstsq(np.vstack(grads + [reg]), np.concatenate([train_s.T.ravel(), zeros]),
                        rcond=None)[0]
    energy = np.stack([box.matrix(test_e, c) @ x for c in range(3)], 1)
    v, vt = box.matrix(train_e), box.matrix(test_e)
    interp = np.stack([vt @ np.linalg.lstsq(np.vstack([v, reg]),
                                            np.concatenate([train_s[:, c], zeros]),
                                            rcond=None)[0] for c in range(3)], 1)
    return energy, interp
