"""Hand-made database pieces shared by the report scripts' tests (h5py, numpy)."""
import numpy as np


def linear_network_law(f, floor, loop_length=5.0):
    """/energy_law of an open file: a network law with one unit per layer and all parameters 0
    at one loop length, so S = floor (E11, E22, 2 E12) exactly (floor 0: S = 0)."""
    law = f.create_group("energy_law")
    law.attrs["family"] = "network"
    law.attrs["h1"], law.attrs["h2"], law.attrs["floor"] = 1, 1, float(floor)
    law["l_knots"] = [loop_length]
    law["theta"] = np.zeros((1, 20))
    return law


def raw_path(f, name, set_, E, S, loop=0):
    """A converged /loop_<loop>/raw/<name> of an open file (E with tensor E12, as the sweep
    writes it)."""
    g = f.create_group(f"loop_{loop}/raw/{name}")
    g["E"], g["S"] = np.array(E, float), np.array(S, float)
    g["status"] = np.zeros(len(E), dtype=np.int32)
    g.attrs["set"], g.attrs["kind"], g.attrs["axis"] = set_, "gradient", 0
    return g


def script_refuses(c, script, args, needle, what):
    """Checks with the Checklist `c` that `script` run on `args` by this Python exits non-zero
    with `needle` on stderr and no traceback; `what` names the check."""
    import subprocess
    import sys
    out = subprocess.run([sys.executable, script, *args], capture_output=True, text=True)
    c(out.returncode != 0 and needle in out.stderr and "Traceback" not in out.stderr,
      "%s: %s" % (what, out.stderr.strip()[-200:]))


def call_refuses(c, call, needle, what):
    """Checks with the Checklist `c` that call() raises a ValueError whose text holds
    `needle`; `what` names the check."""
    try:
        call()
    except ValueError as e:
        c(needle in str(e), "%s: %s" % (what, e))
        return
    c(False, "%s: no error" % what)


def write_tiny_png(path):
    """A complete 1 x 1 grey PNG image at `path` (signature, IHDR, IDAT, IEND)."""
    import struct
    import zlib

    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data
                + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 1, 1, 8, 0, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(b"\x00\x80")) + chunk(b"IEND", b""))
