#!/usr/bin/python3
"""Our ParaView outputs read with VTK's own readers (scripts/vtk_check.py; session 26: until
then only our own parser had read them): a shell run's VTU files and collection, a unit-cell
path's and a rod's VTP files pass; a truncated file, a collection naming a missing file, a
non-finite value, an array with the wrong number of tuples and an empty directory are each
refused by name. Skipped (exit 77) without Debian's python3-vtk9, which scripts/test.sh installs
(KNIT_SETUP_TESTS=1 scripts/setup.sh) since session 39. Run by CTest (tests/CMakeLists.txt, label report) with /usr/bin/python3;
KNIT_BIN_DIR names the directory of knit-macro and knit-meso.
"""
import os
import shutil
import subprocess
import sys
import tempfile

from checklist import Checklist  # tests/report/checklist.py, beside this file

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CHECK = os.path.join(ROOT, "scripts", "vtk_check.py")
BIN = os.environ.get("KNIT_BIN_DIR", os.path.join(ROOT, "build", "bin"))

# A one-quad VTU in ASCII with a point array whose values are given.
QUAD = """<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian">
  <UnstructuredGrid>
    <Piece NumberOfPoints="4" NumberOfCells="1">
      <PointData>
        <DataArray type="Float64" Name="E11" format="ascii">{values}</DataArray>
      </PointData>
      <Points>
        <DataArray type="Float64" NumberOfComponents="3" format="ascii">0 0 0 1 0 0 1 1 0 0 1 0</DataArray>
      </Points>
      <Cells>
        <DataArray type="Int64" Name="connectivity" format="ascii">0 1 2 3</DataArray>
        <DataArray type="Int64" Name="offsets" format="ascii">4</DataArray>
        <DataArray type="UInt8" Name="types" format="ascii">9</DataArray>
      </Cells>
    </Piece>
  </UnstructuredGrid>
</VTKFile>
"""


def run(*args):
    return subprocess.run([sys.executable, CHECK] + list(args), capture_output=True, text=True)


def main():
    try:
        import vtk  # noqa: F401
    except ImportError:
        print("skipped: VTK's Python module is not installed (apt-get install python3-vtk9)")
        return 77
    c = Checklist()
    with tempfile.TemporaryDirectory(prefix="vtk_check_test_") as tmp:
        shell = os.path.join(tmp, "shell")
        cell = os.path.join(tmp, "cell")
        rod = os.path.join(tmp, "rod")
        jobs = [
            [os.path.join(BIN, "knit-macro"), "run",
             os.path.join(ROOT, "cases", "verification", "tensile_svk.json"), "-o", shell],
            [os.path.join(BIN, "knit-meso"), "path", "--loop-length", "5", "--biaxial", "0.05",
             "0.02", "--steps", "2", "-o", cell],
            [os.path.join(BIN, "knit-meso"), "rod",
             os.path.join(ROOT, "cases", "rod", "arc_unbend.json"), "-o", rod],
        ]
        for cmd in jobs:
            r = subprocess.run(cmd, capture_output=True, text=True)
            c(r.returncode == 0, f"{os.path.basename(cmd[0])} {cmd[1]} ran", r.stderr[-400:])
        for d, ext in ((shell, ".vtu"), (cell, ".vtp"), (rod, ".vtp")):
            r = run(d)
            found = any(n.endswith(ext) for _, _, ns in os.walk(d) for n in ns)
            c(found and r.returncode == 0 and "0 problem(s)" in r.stdout,
              f"{os.path.basename(d)}: every {ext} file and the collection read cleanly",
              r.stdout[-400:] + r.stderr[-400:])

        # The report's own VTU reader (scripts/figures/results.py, its fallback when results.h5
        # is missing) reads knit-macro's inline binary VTU files as results.h5 holds the same
        # fields (session 42's red team: only ASCII was read, and the fallback failed with 54 kB
        # of base64 in the report).
        sys.path.insert(0, os.path.join(ROOT, "scripts", "figures"))
        import numpy as np
        from results import _fields_from_h5, read_vtu
        vtus = sorted(os.path.join(dp, n) for dp, _, ns in os.walk(shell) for n in ns
                      if n.endswith(".vtu"))
        same = bool(vtus)
        for v in vtus:
            step = int(os.path.splitext(os.path.basename(v))[0].split("_")[-1])
            pts, f = read_vtu(v)
            h = _fields_from_h5(os.path.join(shell, "results.h5"), step)
            same = same and h is not None and np.array_equal(pts, h[0]) and all(
                np.array_equal(f[k], h[1][k]) for k in h[1] if k in f) and "E11" in f
        c(same, f"the report's VTU reader gives results.h5's fields ({len(vtus)} VTU files)")

        # Damage, one kind per copy; each is refused with the file's name.
        def damaged(name, edit):
            d = os.path.join(tmp, name)
            shutil.copytree(cell, d)
            edit(d)
            return d

        def truncate(d):
            f = os.path.join(d, "yarn_0001.vtp")
            with open(f, "rb") as h:
                data = h.read()
            with open(f, "wb") as h:
                h.write(data[: len(data) // 2])

        cases = [
            (damaged("truncated", truncate), "yarn_0001.vtp: VTK: "),
            (damaged("missing", lambda d: os.remove(os.path.join(d, "yarn_0002.vtp"))),
             "yarn.pvd: names 'yarn_0002.vtp', which does not exist"),
        ]
        for name, values, expect in (("nan", "0 1 nan 2", "point array E11: non-finite values"),
                                     ("short", "0 1 2", 'VTK: vtkXMLUnstructuredGridReader: Cannot read point data array "E11"')):
            d = os.path.join(tmp, name)
            os.makedirs(d)
            with open(os.path.join(d, "q.vtu"), "w") as h:
                h.write(QUAD.format(values=values))
            cases.append((d, "q.vtu: " + expect))
        for d, expect in cases:
            r = run(d)
            c(r.returncode == 1 and expect in r.stdout,
              f"{os.path.basename(d)}: refused, naming the file ({expect!r})", r.stdout[-400:])
        good = os.path.join(tmp, "good")
        os.makedirs(good)
        with open(os.path.join(good, "q.vtu"), "w") as h:
            h.write(QUAD.format(values="0 1 2 3"))
        r = run(good)
        c(r.returncode == 0, "the same quad with 4 finite values passes", r.stdout[-400:])
        empty = os.path.join(tmp, "empty")
        os.makedirs(empty)
        r = run(empty)
        c(r.returncode == 2 and "no .vtu, .vtp or .pvd file found" in r.stderr,
          "an empty directory: exit 2", r.stderr[-300:])
    return c.exit_code()


if __name__ == "__main__":
    sys.exit(main())
