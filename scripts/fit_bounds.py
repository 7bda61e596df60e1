#!/usr/bin/python3
"""What limits the energy law's held-out error (issue 11, "Fit quality")?

For each requested loop length of a material database this prints, beside the stored energy
law's own held-out figures, four law-independent references computed from the same cell data:

  * convex bound: the smallest delta such that SOME convex strain energy W reproduces the
    cell's stresses at the sampled states within delta (fraction of the stress range). It is a
    linear program over the convex-interpolation conditions (every ordered pair i, j)
        W_j >= W_i + S'_i . (e_j - e_i),   |S'_ic - S_ic| <= delta * range,
    solved with HiGHS on every `--stride`-th state of every path, fitted and held-out ones
    (fewer states give fewer constraints, so the figure is a LOWER bound of the true one);
    with `--uniaxial-relative RHO` a second program holds the uniaxial-stress paths' states
    within RHO times their own axial stress instead;
  * monotonicity bound: the same floor from the pairs of states alone (a convex W has a
    monotone gradient), cheap enough for ALL states (docs/database.md);
  * free energy: S = grad W with W a tensor-product cubic B-spline over the box (not convex),
    least squares with a second-difference smoothing, trained on the fit paths only;
  * free interpolant: each of S11, S22, S12 its own spline of the same basis (no energy at
    all), trained likewise.

The two free fits are the best a smooth law could hope to do on states that did not enter the
fit: if they miss the held-out states too, the misses come from the sampling (states far from
every fitted path), not from the law's family. Errors are max-norm over (S11, S22, S12)
divided by the stress range of docs/database.md (largest max - min of a component over the
loop length's fit data); the threshold is 5 %.

Usage: /usr/bin/python3 scripts/fit_bounds.py DATABASE.h5 [--loops 0 4] [--stride 3]
           [--uniaxial-relative RHO]
       /usr/bin/python3 scripts/fit_bounds.py --self-check
Needs python3-numpy, python3-scipy (>= 1.8 for HiGHS), python3-h5py and python3-matplotlib
(the stored law is evaluated by scripts/figures/energy_law.py).
"""
import argparse
import os
import sys

import numpy as np
from scipy.optimize import linprog
from scipy.sparse import coo_matrix, vstack

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "figures"))
from energy_law import load_law  # noqa: E402  (the stored law, re-evaluated)
from cell_paths import load_paths, stress_range  # noqa: E402  (scripts/cell_paths.py)
from free_fit import free_fits  # noqa: E402  (scripts/free_fit.py: the two free fits)

THRESHOLD = 0.05


def convex_bound(e, s, rng, fixed=None):
    """Smallest delta (fraction of rng) of a convex W through (e_i, S'_i); the origin is added
    as a stress-free state. `fixed` (n x 3, NaN = none): a tolerance of its own (MPa) for some
    states, |S'_ic - S_ic| <= fixed_ic instead of delta * rng. Returns (delta, status message)."""
    e = np.vstack([np.zeros(3), e])
    s = np.vstack([np.zeros(3), s])
    tol = np.full(3 * len(e), np.nan)
    if fixed is not None:
        tol[3:] = np.asarray(fixed, dtype=float).ravel()
    own = ~np.isnan(tol)
    dcoef = np.where(own, 0.0, -rng)
    slack = np.where(own, tol, 0.0)
    n = len(e)
    nv = 4 * n + 1
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    m = i != j
    i, j = i[m], j[m]
    p = len(i)
    d = e[j] - e[i]
    rows = np.repeat(np.arange(p), 5)
    cols = np.stack([i, j, n + 3 * i, n + 3 * i + 1, n + 3 * i + 2], 1).ravel()
    vals = np.stack([np.ones(p), -np.ones(p), d[:, 0], d[:, 1], d[:, 2]], 1).ravel()
    pairs = coo_matrix((vals, (rows, cols)), shape=(p, nv))
    k = np.arange(3 * n)
    both = np.concatenate([k, k])
    delta_col = np.concatenate([n + k, np.full(3 * n, nv - 1)])
    upper = coo_matrix((np.concatenate([np.ones(3 * n), dcoef]),
                        (both, delta_col)), shape=(3 * n, nv))
    lower = coo_matrix((np.concatenate([-np.ones(3 * n), dcoef]),
                        (both, delta_col)), shape=(3 * n, nv))
    a = vstack([pairs, upper, lower]).tocsr()
    b = np.concatenate([np.zeros(p), s.ravel() + slack, -s.ravel() + slack])
    c = np.zeros(nv)
    c[-1] = 1.0
    bounds = [(None, None)] * nv
    bounds[0] = (0.0, 0.0)
    bounds[-1] = (0.0, None)
    r = linprog(c, A_ub=a, b_ub=b, bounds=bounds, method="highs")
    if r.status != 0:
        return float("nan"), r.message
    return float(r.x[-1]), "optimal"


def monotonicity_bound(e, s, rng):
    """A lower bound of the convex bound over ALL states, cheap enough for every one: the
    gradient of a convex W is monotone, (S_i - S_j) . (e_i - e_j) >= 0, and perturbations
    |d_ic| <= delta * rng change the product by at most 2 delta rng |e_i - e_j|_1, so each pair
    needs delta >= -(S_i - S_j) . (e_i - e_j) / (2 rng |e_i - e_j|_1). The origin is added as a
    stress-free state. Returns (delta, i, j) of the worst pair (indices into e, -1 = origin)."""
    e = np.vstack([np.zeros(3), e])
    s = np.vstack([np.zeros(3), s])
    best, bi, bj = 0.0, -1, -1
    for i in range(len(e)):
        de = e[i] - e
        num = -np.sum((s[i] - s) * de, axis=1)
        den = 2.0 * rng * np.abs(de).sum(axis=1)
        d = np.where(den > 0, num / np.where(den > 0, den, 1.0), 0.0)
        j = int(np.argmax(d))
        if d[j] > best:
            best, bi, bj = float(d[j]), i - 1, j - 1
    return best, bi, bj


def summary(err):
    return "%3d / %3d within 5 %%, max %5.1f %%" % (np.sum(err <= THRESHOLD), len(err),
                                                     100 * err.max())


def uniaxial_tolerances(paths, stride, rho):
    """The `fixed` argument of convex_bound for the sub-sampled states: on the uniaxial-stress
    paths every component within rho times the state's axial stress (the lateral one too: the
    law's own lateral contraction needs its lateral stress near zero); NaN elsewhere."""
    out = []
    for p in paths:
        sub = p[2][stride - 1::stride]
        t = np.full(sub.shape, np.nan)
        if p[3] == "uniaxial":
            t[:] = rho * np.abs(sub[:, p[4]])[:, None]
        out.append(t)
    return np.concatenate(out)


def analyse(f, loop, stride, n, lam, uniaxial_relative=None):
    paths = load_paths(f, loop)
    loop_length = float(f["loop_lengths"][loop])
    rng = stress_range(paths)
    fit = [p for p in paths if p[0] != "holdout"]
    held = [p for p in paths if p[0] == "holdout"]
    if not held:
        print("l = %.2f mm: no held-out paths" % loop_length)
        return
    tr_e = np.concatenate([p[1] for p in fit])
    tr_s = np.concatenate([p[2] for p in fit])
    te_e = np.concatenate([p[1] for p in held])
    te_s = np.concatenate([p[2] for p in held])
    energy, interp = free_fits(tr_e, tr_s, te_e, n, lam)
    err = lambda s: np.abs(s - te_s).max(1) / rng  # noqa: E731
    sub_e = np.concatenate([p[1][stride - 1::stride] for p in paths])
    sub_s = np.concatenate([p[2][stride - 1::stride] for p in paths])
    delta, status = convex_bound(sub_e, sub_s, rng)
    print("l = %.2f mm (stress range %.2f MPa), %d held-out states of %d paths:" %
          (loop_length, rng, len(te_e), len(held)))
    if "energy_law" in f:
        law = load_law(f["energy_law"], loop_length)
        print("  stored energy law           : %s" % summary(err(law.eval(te_e)[1])))
    print("  free energy (grad of spline): %s" % summary(err(energy)))
    print("  free interpolant (no energy): %s" % summary(err(interp)))
    print("  convex bound, %d states incl. held-out, in-sample: delta* >= %.2f %% (%s)" %
          (len(sub_e) + 1, 100 * delta, status))
    all_e = np.concatenate([p[1] for p in paths])
    all_s = np.concatenate([p[2] for p in paths])
    mono, i, j = monotonicity_bound(all_e, all_s, rng)
    state = lambda k: ("E = %s S = %s" % (np.round(all_e[k], 3), np.round(all_s[k], 2))  # noqa
                       if k >= 0 else "the origin")
    print("  monotonicity bound, all %d states: delta* >= %.2f %% (the pair %s and %s)" %
          (len(all_e) + 1, 100 * mono, state(i), state(j)))
    if uniaxial_relative is not None:
        fixed = uniaxial_tolerances(paths, stride, uniaxial_relative)
        d2, st2 = convex_bound(sub_e, sub_s, rng, fixed)
        print("  convex bound with the uniaxial-stress states within %.0f %% of their axial "
              "stress (%d states): delta* >= %.2f %% (%s)" %
              (100 * uniaxial_relative, int(np.sum(~np.isnan(fixed[:, 0]))), 100 * d2, st2))


def self_check():
    """The bound must be ~0 for the gradient of a convex W and > 0 when monotonicity fails."""
    rng = np.random.default_rng(1)
    e = rng.uniform(-0.3, 0.3, (60, 3))
    c = np.array([[4.0, 1.0, 0.0], [1.0, 3.0, 0.5], [0.0, 0.5, 2.0]])
    s = e @ c + 2.0 * e ** 3
    ok_delta, _ = convex_bound(e, s, 10.0)
    bad = s.copy()
    bad[:, 0] = -bad[:, 0]  # S11 decreasing in E11: no convex W
    bad_delta, _ = convex_bound(e, bad, 10.0)
    # States with tolerances of their own: loose ones free the non-monotone data entirely,
    # zero ones keep the convex data exact.
    loose_delta, _ = convex_bound(e, bad, 10.0, np.full(bad.shape, 1e3))
    exact_delta, _ = convex_bound(e, s, 10.0, np.zeros(s.shape))
    mono_ok, _, _ = monotonicity_bound(e, s, 10.0)
    mono_bad, _, _ = monotonicity_bound(e, bad, 10.0)
    print("self-check: monotonicity bound %.2e (convex data), %.3f (non-monotone data, at most "
          "the convex bound)" % (mono_ok, mono_bad))
    print("self-check: convex data delta* = %.2e, non-monotone data delta* = %.3f; with loose "
          "tolerances of their own %.2e, with exact ones (convex data) %.2e" %
          (ok_delta, bad_delta, loose_delta, exact_delta))
    if not (ok_delta < 1e-6 and bad_delta > 0.01 and loose_delta < 1e-6 and exact_delta < 1e-6
            and mono_ok == 0.0 and 0.01 < mono_bad <= bad_delta + 1e-9):
        print("self-check FAILED", file=sys.stderr)
        return 1
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("database", nargs="?")
    ap.add_argument("--loops", type=int, nargs="+", default=None,
                    help="loop indices (default: the first and the last)")
    ap.add_argument("--stride", type=int, default=3,
                    help="every STRIDE-th state of each path enters the convex bound (3)")
    ap.add_argument("--spline-functions", type=int, default=8,
                    help="B-spline functions per strain axis of the free fits (8)")
    ap.add_argument("--smoothing", type=float, default=1e-3,
                    help="second-difference smoothing of the free fits (1e-3)")
    ap.add_argument("--uniaxial-relative", type=float, default=None, metavar="RHO",
                    help="also the convex bound with the uniaxial-stress paths' states held "
                         "within RHO times their axial stress (relative, not delta * range)")
    ap.add_argument("--self-check", action="store_true")
    a = ap.parse_args()
    if a.self_check:
        return self_check()
    if not a.database:
        ap.error("a database is required (or --self-check)")
    import h5py
    try:
        f = h5py.File(a.database, "r")
    except OSError as err:
        print("fit_bounds.py: %s: %s" % (a.database, err), file=sys.stderr)
        return 2
    if "loop_lengths" not in f:
        print("fit_bounds.py: %s: /loop_lengths: dataset missing (not a material database)"
              % a.database, file=sys.stderr)
        return 2
    count = len(f["loop_lengths"])
    loops = a.loops if a.loops is not None else sorted({0, count - 1})
    for loop in loops:
        if not 0 <= loop < count:
            print("fit_bounds.py: %s: no /loop_%d (%d loop lengths)" % (a.database, loop, count),
                  file=sys.stderr)
            return 2
        analyse(f, loop, a.stride, a.spline_functions, a.smoothing, a.uniaxial_relative)
    return 0


if __name__ == "__main__":
    sys.exit(main())
