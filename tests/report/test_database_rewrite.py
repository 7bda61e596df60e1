#!/usr/bin/python3
"""Databases rewritten by another program are refused by knit-macro's reader (session 47's red
team), each by the file and the field, exit 2:

* a format-3 database copied value by value with h5py (no Fletcher32 filters, no digests, no
  structure checksum), which was read as an old, unverifiable file: with /energy_law/theta
  scaled by 1.5 a tensile case carried 17,408 N for 82.8 N, exit 0;
* the same copy relabelled format_version 2 (older files are read unverified), holding a
  network law, which came with format 3;
* in an old (format 2, checksum-free) file, an attribute with a null dataspace (read as 0:
  /energy_law@floor), real data stored as integers (truncated) or in 4-byte floats, and a
  dataset under HDF5's scale-offset filter (lossy), a fixed-length string with a NUL byte inside
  it (session 49); and knit-meso fit of such an old file warns
  that its contents are not verified (the refit writes them with checksums of its own).

The intact copies of each kind run (exit 0), so each refusal is the damage's. Run by CTest
(tests/CMakeLists.txt, label report) with /usr/bin/python3; KNIT_BIN_DIR names the directory of
knit-meso and knit-macro.
"""
import json
import os
import subprocess
import tempfile

import h5py
import numpy as np

from checklist import Checklist  # tests/report/checklist.py, beside this file

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BIN = os.environ.get("KNIT_BIN_DIR", os.path.join(ROOT, "build", "bin"))


def rewrite_without_checksums(src, dst, version=None):
    """Every group, dataset and attribute of src copied by value into dst (what "load it all
    and save it again" with h5py does), without the checksums; format_version set to
    `version` when given."""
    with h5py.File(src, "r") as s, h5py.File(dst, "w") as d:
        def attrs(a, b):
            for k, v in a.attrs.items():
                if k != "knit_fnv1a64":
                    b.attrs[k] = v

        attrs(s, d)

        def visit(name, obj):
            if isinstance(obj, h5py.Group):
                attrs(obj, d.require_group(name))
            else:
                attrs(obj, d.create_dataset(name, data=obj[()]))

        s.visititems(visit)
        if version is not None:
            d.attrs["format_version"] = version


def replace(f, name, data, **kw):
    a = dict(f[name].attrs)
    del f[name]
    f.create_dataset(name, data=data, **kw)
    for k, v in a.items():
        f[name].attrs[k] = v


def set_fixed_string(obj, name, data, pad, utf8=False):
    """Attribute `name` of `obj` as one fixed-length string of the bytes `data`, padded `pad`
    (h5py.h5t.STR_NULLTERM, STR_NULLPAD or STR_SPACEPAD), ASCII or UTF-8."""
    tid = h5py.h5t.C_S1.copy()
    tid.set_size(len(data))
    tid.set_strpad(pad)
    if utf8:
        tid.set_cset(h5py.h5t.CSET_UTF8)
    if name in obj.attrs:
        del obj.attrs[name]
    aid = h5py.h5a.create(obj.id, name.encode(), tid, h5py.h5s.create(h5py.h5s.SCALAR))
    aid.write(np.array(data, dtype="S%d" % len(data)), mtype=tid)


def run_case(tmp, db, tag):
    """A small wale-wise tensile case on `db` at l = 5 mm: (exit code, stderr)."""
    case = {
        "units": "mm, N, MPa",
        "geometry": {"degrees": [1, 1], "knots_u": [0, 0, 1, 1], "knots_v": [0, 0, 1, 1],
                     "control_points": [[0, 0, 0], [50, 0, 0], [0, 50, 0], [50, 50, 0]],
                     "thickness": 0.76},
        "refinement": {"degree": 2, "elements": [1, 1]},
        "material": {"type": "knit", "database": db, "stitch_value": 5.0},
        "boundary_conditions": [{"all": True, "fix": ["z"]}, {"edge": "v0", "fix": ["x", "y"]},
                                {"edge": "v1", "fix": ["x"], "prescribe": {"y": 5.0}}],
        "solver": {"steps": 2},
        "output": {"vtk": False, "hdf5": False}}
    path = os.path.join(tmp, tag + ".json")
    with open(path, "w") as f:
        json.dump(case, f)
    r = subprocess.run([os.path.join(BIN, "knit-macro"), "run", path, "-o",
                        os.path.join(tmp, tag + "_out")], capture_output=True, text=True)
    return r.returncode, r.stderr


def main():
    c = Checklist()
    with tempfile.TemporaryDirectory(prefix="db_rewrite_test_") as tmp:
        with open(os.path.join(tmp, "net.json"), "w") as f:
            json.dump({"family": "network", "network_iterations": 50}, f)
        made = {}
        for name, extra in (("ridge", []), ("net", ["--energy-options", "net.json"])):
            r = subprocess.run([os.path.join(BIN, "knit-meso"), "synth", "-o", name + ".h5",
                                "--loop-lengths", "4.5", "5.5", "--steps", "6"] + extra,
                               cwd=tmp, capture_output=True, text=True)
            c(r.returncode == 0, "knit-meso synth wrote the %s database" % name, r.stderr[-500:])
            made[name] = os.path.join(tmp, name + ".h5")
        rc, err = run_case(tmp, made["net"], "intact")
        c(rc == 0, "the intact network database runs", err[-800:])

        # A format-3 copy without checksums, intact and with the law scaled.
        plain = os.path.join(tmp, "plain.h5")
        rewrite_without_checksums(made["net"], plain)
        scaled = os.path.join(tmp, "scaled.h5")
        rewrite_without_checksums(made["net"], scaled)
        with h5py.File(scaled, "r+") as f:
            replace(f, "energy_law/theta", f["energy_law/theta"][()] * 1.5)
        for tag, db in (("plain", plain), ("scaled", scaled)):
            rc, err = run_case(tmp, db, tag)
            c(rc == 2 and db + ": format_version 3 databases are written with checksums, and this "
              "one has none" in err, "a format-3 copy without checksums (%s) is refused" % tag,
              err[-800:])
        # Relabelled format 2, with its network law.
        relabelled = os.path.join(tmp, "relabelled.h5")
        rewrite_without_checksums(made["net"], relabelled, version=2)
        rc, err = run_case(tmp, relabelled, "relabelled")
        c(rc == 2 and relabelled + ": /energy_law: attribute family is \"network\" in a "
          "format_version 2 database" in err,
          "a network law in a file labelled format 2 is refused", err[-800:])

        # An old file (format 2, ridge law, no checksums): intact, it runs; each damage refused.
        old = os.path.join(tmp, "old.h5")
        rewrite_without_checksums(made["ridge"], old, version=2)
        rc, err = run_case(tmp, old, "old")
        c(rc == 0, "an intact old (format 2, checksum-free) ridge database runs", err[-800:])
        # ... and says that its contents were not verified (session 54: it said nothing).
        c("warning: " + old + ": written without checksums (format_version 2" in err,
          "knit-macro warns that an old file's contents are not verified", err[-800:])
        c("written without checksums" not in run_case(tmp, made["ridge"], "sealed")[1],
          "a database with checksums is not warned of", "")
        # A refit of the old file says that its contents were not verified.
        r = subprocess.run([os.path.join(BIN, "knit-meso"), "fit", old, "--law", "paper", "-o",
                            os.path.join(tmp, "refit.h5")], capture_output=True, text=True)
        c(r.returncode == 0 and "warning: " + old + ": written without checksums" in r.stderr,
          "knit-meso fit of an old file warns that its contents are not verified",
          r.stdout[-500:] + r.stderr[-800:])
        damages = {
            "an attribute with a null dataspace": (
                lambda f: f["energy_law"].attrs.__setitem__("floor", h5py.Empty("f8")),
                "/energy_law: attribute floor is empty (a null dataspace, no value)"),
            "real data stored as integers": (
                lambda f: replace(f, "energy_law/coefficients",
                                  np.round(f["energy_law/coefficients"][()]).astype(np.int64)),
                "/energy_law/coefficients: expected 8-byte floating-point values (double), "
                "found integer"),
            "real data stored in 4-byte floats": (
                lambda f: replace(f, "energy_law/coefficients",
                                  f["energy_law/coefficients"][()].astype(np.float32)),
                "/energy_law/coefficients: expected 8-byte floating-point values (double), "
                "found 4-byte floats"),
            # Session 49's red team: "ridge\0network" was read as "ridge", the rest dropped.
            "a fixed-length string with a NUL inside it": (
                lambda f: f["energy_law"].attrs.__setitem__("family", np.bytes_(b"ridge\0network")),
                "/energy_law: a string with a NUL byte inside it (at character 6 of 13)"),
            # The review of session 49: stored null-terminated, HDF5's conversion hid it.
            "a null-terminated fixed-length string with a NUL inside it": (
                lambda f: set_fixed_string(f["energy_law"], "family", b"ridge\0network",
                                           h5py.h5t.STR_NULLTERM),
                "/energy_law: a string with a NUL byte inside it (at character 6 of 13)"),
            "a dataset under the scale-offset filter": (
                lambda f: replace(f, "energy_law/coefficients", f["energy_law/coefficients"][()],
                                  scaleoffset=2, chunks=True),
                "/energy_law/coefficients: stored with the HDF5 filter"),
        }
        # Fixed-length strings without damage are read, whatever their padding and character
        # set (the review of session 49: UTF-8 ones failed with "cannot read string data").
        for tag, pad, text, utf8 in (("nullterm", h5py.h5t.STR_NULLTERM, b"ridge\0\0\0", False),
                                     ("spacepad", h5py.h5t.STR_SPACEPAD, b"ridge   ", False),
                                     ("utf8", h5py.h5t.STR_NULLPAD, b"ridge", True)):
            db = os.path.join(tmp, "old_%s.h5" % tag)
            rewrite_without_checksums(made["ridge"], db, version=2)
            with h5py.File(db, "r+") as f:
                set_fixed_string(f["energy_law"], "family", text, pad, utf8)
            rc, err = run_case(tmp, db, "old_" + tag)
            c(rc == 0, "a fixed-length string (%s) is read" % tag, err[-800:])
        for k, (what, (damage, message)) in enumerate(damages.items()):
            db = os.path.join(tmp, "old_%d.h5" % k)
            rewrite_without_checksums(made["ridge"], db, version=2)
            with h5py.File(db, "r+") as f:
                damage(f)
            rc, err = run_case(tmp, db, "old_%d" % k)
            c(rc == 2 and db + ": " + message in err, "%s is refused, by its HDF5 path" % what,
              err[-800:])
    return c.exit_code()


if __name__ == "__main__":
    raise SystemExit(main())
