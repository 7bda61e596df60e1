"""The unit cell's raw load paths in a material database (/loop_<k>/raw), for the analysis
scripts (fit_bounds.py, path_consistency.py): numpy and h5py only."""
import numpy as np


def load_paths(f, loop):
    """[(set, e (n x 3, e3 = 2 E12), S (n x 3), kind, axis)] of the converged steps of
    /loop_<loop>/raw, in the order of the path names."""
    g = f["loop_%d/raw" % loop]
    out = []
    for name in sorted(g):
        ok = g[name]["status"][:] == 0
        e = g[name]["E"][:][ok].copy()
        e[:, 2] *= 2.0
        s = g[name].attrs.get("set", "paper")
        kind = g[name].attrs.get("kind", "biaxial")
        kind = kind.decode() if isinstance(kind, bytes) else str(kind)
        out.append((s.decode() if isinstance(s, bytes) else str(s), e, g[name]["S"][:][ok], kind,
                    int(g[name].attrs.get("axis", 0))))
    return out


def stress_range(paths):
    """The loop length's stress range of docs/database.md: the largest max - min of a stress
    component over its fit data (every path but the held-out ones)."""
    s = np.concatenate([p[2] for p in paths if p[0] != "holdout"])
    return max(s[:, c].max() - s[:, c].min() for c in range(3))
