#!/usr/bin/python3
"""scripts/figures/energy_law.py's law between loop-length knots with the rounding of the kinks
(attribute l_blend of /energy_law, session 44; knit/material/convex_network.hpp
NetworkLawData::weights, whose C++ twin is tested in tests/common/test_material_energy_law.cpp).

Three knots 4.5, 5.5, 6.5 mm, each a network law whose only parameters are L = sqrt(q_j) I, so
S = (floor + q_j) e exactly, and the law at l has S11(e = (1, 0, 0)) = floor + sum_k c_k q_k:

* without l_blend: the piecewise-linear law (a kink at 5.5);
* with l_blend 0.2: the same outside [5.3, 5.7], inside the quadratic Bezier curve through the
  piecewise-linear law at 5.3, 5.5 and 5.7, with the derivative in l continuous (the one-sided
  differences agree at 5.3, 5.5 and 5.7);
* the weights are nonnegative and sum to 1 on a fine grid.
Run by CTest (tests/CMakeLists.txt, label report) with Debian's /usr/bin/python3.
"""
import os
import sys
import tempfile

import h5py
import numpy as np

from checklist import Checklist  # tests/report/checklist.py, beside this file

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "scripts", "figures"))
from energy_law import knot_weights, load_law  # noqa: E402

FLOOR, Q = 0.2, [1.0, 3.0, 2.0]  # q_j at 4.5, 5.5, 6.5 mm: slopes +2 and -1 per mm


def write_law(path, l_blend, knots=(4.5, 5.5, 6.5)):
    with h5py.File(path, "w") as f:
        law = f.create_group("energy_law")
        law.attrs["family"], law.attrs["l_interpolation"] = "network", "energy"
        law.attrs["h1"], law.attrs["h2"], law.attrs["floor"] = 1, 1, FLOOR
        if l_blend:
            law.attrs["l_blend"] = l_blend
        law["l_knots"] = list(knots)
        theta = np.zeros((3, 20))
        for j, q in enumerate(Q):
            theta[j, 11:20] = (np.sqrt(q) * np.eye(3)).ravel()  # L, the last 3 x 3
        law["theta"] = theta


def s11(db, l):
    with h5py.File(db, "r") as f:
        return float(load_law(f["energy_law"], l).eval(np.array([1.0, 0.0, 0.0]))[1][0])


def sharp(l):  # the piecewise-linear law's S11 at e = (1, 0, 0)
    return FLOOR + np.interp(l, [4.5, 5.5, 6.5], Q)


def main():
    c = Checklist()
    with tempfile.TemporaryDirectory(prefix="energy_law_blend_test_") as tmp:
        plain, round_ = os.path.join(tmp, "plain.h5"), os.path.join(tmp, "round.h5")
        write_law(plain, 0.0)
        write_law(round_, 0.2)
        ls = [4.5, 4.9, 5.3, 5.4, 5.5, 5.6, 5.7, 6.1, 6.5]
        err = max(abs(s11(plain, l) - sharp(l)) for l in ls)
        c(err < 1e-12, "without l_blend: the piecewise-linear law (largest difference %.2e)" % err)
        err = max(abs(s11(round_, l) - sharp(l)) for l in (4.5, 4.9, 5.29, 5.71, 6.1, 6.5))
        c(err < 1e-12, "with l_blend 0.2, outside [5.3, 5.7]: the same (%.2e)" % err)
        worst = 0.0
        for l in (5.35, 5.5, 5.62):
            s = (l - 5.3) / 0.4
            want = (1 - s) ** 2 * sharp(5.3) + 2 * s * (1 - s) * sharp(5.5) + s * s * sharp(5.7)
            worst = max(worst, abs(s11(round_, l) - want))
        c(worst < 1e-12, "inside: the quadratic Bezier curve of the piecewise-linear law (%.2e)"
          % worst)
        # At 5.5 the value is d / 4 x (slope_right - slope_left) off the knot's: 0.05 x (-3).
        v = s11(round_, 5.5)
        c(abs(v - (FLOOR + 3.0 - 0.15)) < 1e-12, "at the knot: %.12f (the knot's own %.1f)"
          % (v, FLOOR + 3.0))
        h, gap_sharp, gap_round = 1e-6, 0.0, 0.0
        for l in (5.3, 5.5, 5.7):
            fwd = (s11(round_, l + h) - s11(round_, l)) / h
            bwd = (s11(round_, l) - s11(round_, l - h)) / h
            gap_round = max(gap_round, abs(fwd - bwd))
        fwd = (s11(plain, 5.5 + h) - s11(plain, 5.5)) / h
        bwd = (s11(plain, 5.5) - s11(plain, 5.5 - h)) / h
        gap_sharp = abs(fwd - bwd)
        c(gap_round < 1e-4 and gap_sharp > 2.9,
          "C1 with l_blend: one-sided slopes differ by %.2e at 5.3, 5.5, 5.7 (%.3f at the "
          "unrounded kink)" % (gap_round, gap_sharp))
        # Unequal spans (session 44's review: with equal spans the two windows' fractions are
        # equal, and swapping them passed): knots 4.5, 5.0, 6.5, the window [4.9, 5.1].
        uneven = os.path.join(tmp, "uneven.h5")
        write_law(uneven, 0.2, (4.5, 5.0, 6.5))

        def sharp_u(l):
            return FLOOR + np.interp(l, [4.5, 5.0, 6.5], Q)
        worst, gap = 0.0, 0.0
        for l in (4.93, 5.0, 5.07):
            s = (l - 4.9) / 0.2
            want = (1 - s) ** 2 * sharp_u(4.9) + 2 * s * (1 - s) * sharp_u(5.0) + s * s * sharp_u(5.1)
            worst = max(worst, abs(s11(uneven, l) - want))
        for l in (4.9, 5.0, 5.1):
            fwd = (s11(uneven, l + h) - s11(uneven, l)) / h
            bwd = (s11(uneven, l) - s11(uneven, l - h)) / h
            gap = max(gap, abs(fwd - bwd))
        c(worst < 1e-12 and gap < 1e-3,
          "unequal spans: the Bezier curve (%.2e) and C1 at 4.9, 5.0, 5.1 (one-sided slopes "
          "%.2e apart)" % (worst, gap))
        bad = []
        for l in np.linspace(4.0, 7.0, 2401):
            w = knot_weights(np.array([4.5, 5.5, 6.5]), l, 0.2)
            cs = [x for _, x in w]
            if min(cs) < 0 or abs(sum(cs) - 1) > 1e-14:
                bad.append(l)
        c(not bad, "weights nonnegative and summing to 1 on 2401 loop lengths (%d not)" % len(bad))
    return c.exit_code()


if __name__ == "__main__":
    sys.exit(main())
