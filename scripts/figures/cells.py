#!/usr/bin/python3
"""Fig. 5: the single-jersey unit cells (from `knit-meso cell --loop-length L --out DIR`:
DIR/cell.vtp polylines with cell arrays "piece" and "image", DIR/cell.json with w and c), seen
in the x-y plane with the neighbouring images in grey and the w x c bounding box in blue.

Usage: cells.py --out fig05.png DIR_4.5 DIR_6.5
"""
import argparse
import base64
import os
import sys
import xml.etree.ElementTree as ET

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from figure_inputs import guarded_main, read_json  # noqa: E402


_VTK_TYPES = {"Float64": np.float64, "Float32": np.float32, "Int64": np.int64, "Int32": np.int32,
              "UInt64": np.uint64, "UInt32": np.uint32, "UInt8": np.uint8, "Int8": np.int8}


def _array(da, dtype):
    """A VTK XML DataArray, ASCII or base64 'binary' (UInt64 byte-count header + data)."""
    if da.get("format") == "binary":
        raw = base64.b64decode("".join(da.text.split()))
        header = np.dtype(np.uint64).itemsize  # header_type="UInt64" (knit/io/vtk.hpp)
        data = np.frombuffer(raw[header:], dtype=_VTK_TYPES[da.get("type")])
        return data.astype(dtype)
    return np.array(da.text.split(), dtype=dtype)


def read_vtp(path):
    piece = ET.parse(path).getroot().find("./PolyData/Piece")
    pts = _array(piece.find("./Points/DataArray"), float).reshape(-1, 3)
    cell = {da.get("Name"): _array(da, int) for da in piece.findall("./CellData/DataArray")}
    lines = {da.get("Name"): _array(da, int) for da in piece.findall("./Lines/DataArray")}
    conn, offs = lines["connectivity"], lines["offsets"]
    polys, start = [], 0
    for o in offs:
        polys.append(pts[conn[start:o]])
        start = o
    return polys, cell.get("image", np.zeros(len(polys), dtype=int))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", required=True)
    ap.add_argument("dirs", nargs="+")
    a = ap.parse_args()
    fig, axs = plt.subplots(1, len(a.dirs), figsize=(5 * len(a.dirs), 5.6))
    axs = np.atleast_1d(axs)
    extent = []  # (x0, x1, y0, y1) of each panel's drawing: one scale for all (below)
    for ax, d in zip(axs, a.dirs):
        info = read_json(os.path.join(d, "cell.json"))
        polys, image = read_vtp(os.path.join(d, "cell.vtp"))
        for P, im in zip(polys, image):
            ax.plot(P[:, 0], P[:, 1], color="0.75" if im else "C1", lw=2.5 if im == 0 else 1.5,
                    zorder=1 if im else 2)
        w, c = info["w"], info["c"]
        own = np.concatenate([P for P, im in zip(polys, image) if im == 0])
        cx, cy = 0.5 * (own[:, 0].min() + own[:, 0].max()), 0.5 * (own[:, 1].min() + own[:, 1].max())
        ax.add_patch(plt.Rectangle((cx - 0.5 * w, cy - 0.5 * c), w, c, fill=False, ec="b", lw=1.5, zorder=3))
        every = np.concatenate(polys)
        if not np.all(np.isfinite(every[:, :2])):
            raise ValueError(f"{os.path.join(d, 'cell.vtp')}: a point is not finite")
        extent.append((every[:, 0].min(), every[:, 0].max(), every[:, 1].min(), every[:, 1].max()))
        ax.set_title(f"l = {info['loop_length']} mm: w = {w:.2f} mm, c = {c:.2f} mm\n"
                     f"measured length {info.get('measured_length', float('nan')):.3f} mm, "
                     f"min clearance {info.get('min_clearance', float('nan')):.3f} mm", fontsize=9)
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("y [mm]")
    # The same limits and equal aspect in every panel, so that the cells compare by size (the
    # 4.5 mm cell, 1.26 mm wide, was drawn wider than the 6.5 mm one, 1.41 mm, each panel on
    # its own scale).
    e = np.array(extent)
    pad = 0.04 * max(e[:, 1].max() - e[:, 0].min(), e[:, 3].max() - e[:, 2].min())
    for ax in axs:
        ax.set_xlim(e[:, 0].min() - pad, e[:, 1].max() + pad)
        ax.set_ylim(e[:, 2].min() - pad, e[:, 3].max() + pad)
        ax.set_aspect("equal", adjustable="box")
        ax.grid(True, alpha=0.25)
    fig.suptitle("Fig. 5: unit cells with their w x c bounding boxes (blue), on one scale",
                 fontsize=11)
    tmp = a.out + ".tmp.png"
    fig.savefig(tmp, dpi=110, bbox_inches="tight")
    os.replace(tmp, a.out)


if __name__ == "__main__":
    guarded_main(main)
