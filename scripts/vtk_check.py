#!/usr/bin/python3
"""Opens every ParaView output under the given directories (or the given files) with VTK's own
readers, the library ParaView is built on, and checks what a ParaView user would trip over.

  .vtu, .vtp   read by vtkXMLUnstructuredGridReader / vtkXMLPolyDataReader with no VTK error or
               warning; at least one point and one cell; every point (cell) array has one tuple
               per point (cell); every number finite.
  .pvd         well-formed XML, a VTKFile of type Collection with at least one DataSet, strictly
               increasing timesteps, every referenced file present (and checked as above).

Needs VTK's Python module: Debian's python3-vtk9 (`apt-get install python3-vtk9`, ~300 MB with
its Qt dependencies; scripts/test.sh installs it through scripts/setup.sh, the main job does not). Session 26 found no problem in the main
job's 139 VTU/VTP files and 22 collections (VTK 9.1).

Usage: /usr/bin/python3 scripts/vtk_check.py out/results out/design out/cells
Exit codes: 0 every file reads cleanly, 1 a problem (one line each, naming the file),
2 bad usage or no file found, 3 VTK's Python module is not installed.
"""
import argparse
import os
import re
import sys
import xml.etree.ElementTree as ET

EXTENSIONS = (".vtu", ".vtp", ".pvd")


def load_vtk():
    try:
        import vtk  # noqa: F401
        from vtk.util.numpy_support import vtk_to_numpy  # noqa: F401
    except ImportError:
        return None
    return vtk


def collect(args):
    """The output files under each argument (a file or a directory), sorted, no duplicates."""
    files = set()
    for a in args:
        if os.path.isdir(a):
            for root, _dirs, names in os.walk(a):
                files.update(os.path.join(root, n) for n in names if n.endswith(EXTENSIONS))
        elif os.path.isfile(a) and a.endswith(EXTENSIONS):
            files.add(a)
        else:
            raise ValueError(f"{a}: not a directory or a .vtu/.vtp/.pvd file")
    return sorted(files)


class Messages:
    """VTK's output window as a string: every error or warning any VTK object prints while a
    file is read (the XML parser's included) is collected, not shown. A message is a problem."""

    def __init__(self, vtk):
        self.window = vtk.vtkStringOutputWindow()
        vtk.vtkOutputWindow.SetInstance(self.window)
        # VTK 9 logs the same messages to stderr as well (loguru): off.
        if hasattr(vtk, "vtkLogger"):
            vtk.vtkLogger.SetStderrVerbosity(vtk.vtkLogger.VERBOSITY_OFF)
        self.seen = 0

    def take(self):
        """What was printed since the last call."""
        text = self.window.GetOutput()
        new, self.seen = text[self.seen:], len(text)
        return new.strip()


def check_dataset(vtk, messages, path):
    """Problems of one .vtu or .vtp file (an empty list when it reads cleanly)."""
    import numpy as np
    from vtk.util.numpy_support import vtk_to_numpy
    reader = (vtk.vtkXMLUnstructuredGridReader() if path.endswith(".vtu")
              else vtk.vtkXMLPolyDataReader())
    messages.take()
    reader.SetFileName(path)
    reader.Update()
    said = messages.take()
    if said:
        # "ERROR: In <source>, line N" then "<class> (0x...): <what>": the first <what>.
        lines = [ln.strip() for ln in said.splitlines() if ln.strip()]
        what = next((ln for ln in lines if not ln.startswith(("ERROR: In", "Warning: In"))),
                    lines[0])
        what = re.sub(r" \(0x[0-9a-f]+\)", "", what)
        return [f"{path}: VTK: {what[:300]}"]
    data = reader.GetOutput()
    if data is None or data.GetNumberOfPoints() == 0 or data.GetNumberOfCells() == 0:
        return [f"{path}: no points or no cells"]
    problems = []
    counts = {"point": data.GetNumberOfPoints(), "cell": data.GetNumberOfCells()}
    pts = vtk_to_numpy(data.GetPoints().GetData())
    if not np.all(np.isfinite(pts)):
        problems.append(f"{path}: non-finite point coordinates")
    for kind, arrays in (("point", data.GetPointData()), ("cell", data.GetCellData())):
        for i in range(arrays.GetNumberOfArrays()):
            a = arrays.GetArray(i)
            if a is None:
                continue
            name = a.GetName()
            if a.GetNumberOfTuples() != counts[kind]:
                problems.append(f"{path}: {kind} array {name}: {a.GetNumberOfTuples()} tuples "
                                f"for {counts[kind]} {kind}s")
            values = vtk_to_numpy(a)
            if values.dtype.kind == "f" and not np.all(np.isfinite(values)):
                problems.append(f"{path}: {kind} array {name}: non-finite values")
    return problems


def check_collection(path):
    """Problems of one .pvd file, and the data files it names."""
    try:
        root = ET.parse(path).getroot()
    except (ET.ParseError, OSError) as e:
        return [f"{path}: not well-formed XML ({e})"], []
    coll = root.find("Collection")
    if root.tag != "VTKFile" or root.get("type") != "Collection" or coll is None:
        return [f"{path}: not a VTKFile of type Collection"], []
    sets = coll.findall("DataSet")
    if not sets:
        return [f"{path}: an empty collection"], []
    problems, files = [], []
    try:
        steps = [float(d.get("timestep")) for d in sets]
    except (TypeError, ValueError):
        return [f"{path}: a DataSet without a numeric timestep"], []
    # Per part: several parts may share a timestep (PvdCollection::add's `part`).
    by_part = {}
    for d, t in zip(sets, steps):
        by_part.setdefault(d.get("part", "0"), []).append(t)
    if any(b <= a for ts in by_part.values() for a, b in zip(ts, ts[1:])):
        problems.append(f"{path}: timesteps not strictly increasing")
    for d in sets:
        f = os.path.join(os.path.dirname(path), d.get("file") or "")
        if not os.path.isfile(f):
            problems.append(f"{path}: names {d.get('file')!r}, which does not exist")
        else:
            files.append(f)
    return problems, files


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("paths", nargs="+", help="directories to search, or .vtu/.vtp/.pvd files")
    a = ap.parse_args(argv)
    vtk = load_vtk()
    if vtk is None:
        print("vtk_check.py: VTK's Python module is not installed (Debian: apt-get install "
              "python3-vtk9)", file=sys.stderr)
        return 3
    messages = Messages(vtk)
    try:
        files = collect(a.paths)
    except ValueError as e:
        print(f"vtk_check.py: {e}", file=sys.stderr)
        return 2
    if not files:
        print("vtk_check.py: no .vtu, .vtp or .pvd file found", file=sys.stderr)
        return 2
    problems, data = [], set()
    for f in files:
        if f.endswith(".pvd"):
            p, named = check_collection(f)
            problems += p
            data.update(named)
        else:
            data.add(f)
    for f in sorted(data):
        if f.endswith((".vtu", ".vtp")):
            problems += check_dataset(vtk, messages, f)
        else:
            problems.append(f"{f}: not a .vtu or .vtp file (knitscale writes no other kind)")
    for p in problems:
        print(p)
    n_pvd = sum(f.endswith(".pvd") for f in files)
    print(f"vtk_check.py: {len(data)} data files and {n_pvd} collections read with VTK "
          f"{vtk.vtkVersion.GetVTKVersion()}: {len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
