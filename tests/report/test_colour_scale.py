#!/usr/bin/python3
"""The colour scale of the deformed-shape figures (scripts/figures/plots.py): the map chosen by
is_diverging() and the limits of colour_limits(), on hand-made fields. Both are decided on the
bulk of the field (1st/99th percentiles), not on a spike at a loaded corner (session 31), and a
field of one sign is never drawn on a diverging scale. Run by CTest (tests/CMakeLists.txt,
label report) with Debian's /usr/bin/python3.
"""
import os
import sys

import numpy as np

from checklist import Checklist  # tests/report/checklist.py, beside this file

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "scripts", "figures"))
os.environ.setdefault("MPLBACKEND", "Agg")
import plots  # noqa: E402


def main():
    c = Checklist()
    ramp = np.linspace(0.0, 1.0, 1001)
    # One sign, whatever its extremes: a sequential map (s315's E11 lies in [-0.31, 0.02]).
    c(not plots.is_diverging(-0.3 * ramp), "an all-negative field is not diverging")
    c(not plots.is_diverging(0.4 * ramp), "an all-positive field is not diverging")
    c(not plots.is_diverging(np.concatenate([-0.3 * ramp, [0.02]])),
      "a negative field with one small positive value is not diverging")
    # Both signs of comparable size: diverging.
    c(plots.is_diverging(np.linspace(-0.1, 0.2, 1001)), "[-0.1, 0.2]: diverging")
    c(not plots.is_diverging(np.linspace(-0.04, 0.2, 1001)),
      "[-0.04, 0.2]: the negative side is below a quarter of the positive one")
    # A spike does not decide the map: the bulk in [-0.07, 0.18] with one corner value of 0.43
    # (s321's E11) is diverging; the bulk in [0.13, 0.39] with one corner value of -0.5 is not.
    bulk = np.linspace(-0.07, 0.18, 1000)
    c(plots.is_diverging(np.concatenate([bulk, [0.43]])),
      "a corner spike of 0.43 over a bulk in [-0.07, 0.18]: diverging (the bulk's two signs)")
    c(not plots.is_diverging(np.concatenate([np.linspace(0.13, 0.39, 1000), [-0.5]])),
      "a corner spike of -0.5 under a positive bulk: sequential")
    c(not plots.is_diverging(np.zeros(10)), "a zero field: sequential")
    # Limits: a spike is clipped to the 99th percentile and the bar extended; symmetric when
    # diverging; the extremes kept without a spike.
    lo, hi, ext = plots.colour_limits(np.concatenate([0.4 * ramp, [2.0]]), False)
    c(lo == 0.0 and abs(hi - np.percentile(np.concatenate([0.4 * ramp, [2.0]]), 99)) < 1e-12
      and ext == "max", "a spike of 2.0 over [0, 0.4]: clipped at the 99th percentile, "
      "extended above (got %g, %g, %s)" % (lo, hi, ext))
    lo, hi, ext = plots.colour_limits(np.linspace(-0.1, 0.2, 1001), True)
    c(lo == -0.2 and hi == 0.2 and ext == "neither",
      "diverging [-0.1, 0.2]: symmetric limits +-0.2 (got %g, %g, %s)" % (lo, hi, ext))
    lo, hi, ext = plots.colour_limits(np.full(5, 0.3), False)
    c(lo < 0.3 < hi and ext == "neither", "a constant field: a scale around it (%g, %g)"
      % (lo, hi))
    return c.exit_code()


if __name__ == "__main__":
    sys.exit(main())
