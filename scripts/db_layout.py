#!/usr/bin/python3
"""A material database against its documented layout, both ways (session 37).

schemas/database.layout.json describes every group, dataset and attribute of the material
database (docs/database.md). This script walks a database with h5py and prints

  * what the file holds that the layout does not describe (an undocumented item), and
  * what the layout describes that the file lacks, unless the layout says it may be absent
    (its description contains "optional", "absent", "only" or "when").

    /usr/bin/python3 scripts/db_layout.py out/database.h5
    /usr/bin/python3 scripts/db_layout.py out/database.h5 --layout schemas/database.layout.json

Exit 0 when both lists are empty, 1 when either is not (each item printed with its HDF5 path),
2 for a file that cannot be read. Groups, datasets, and the attributes of groups and of the
root are compared; the attributes of datasets (units, checksums) are not. Placeholders of the
layout (`loop_<k>`, `path_<qq>`, an attribute `<name>`) match any name of that shape.
Session 37's red team found the layout silent on /sweep/report, on
/energy_law/diagnostics/monotonicity_bound, on /energy_law@outer_law and on the provenance
attributes, with no check to notice.
"""
import argparse
import json
import os
import re
import sys

import h5py

_HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_LAYOUT = os.path.join(_HERE, "..", "schemas", "database.layout.json")
OPTIONAL_WORDS = ("optional", "absent", "only", "when")


def pattern(name):
    """A layout name as a regular expression: <k>, <qq> digits; <name> any name."""
    out = ""
    for part in re.split(r"(<[^>]+>)", name):
        if part.startswith("<") and part.endswith(">"):
            out += r"\d+" if part in ("<k>", "<qq>", "<i>") else r"[^/]+"
        else:
            out += re.escape(part)
    return re.compile("^" + out + "$")


def describe(entry):
    """The text of a layout entry (a string, or a dict's values) for the optional words."""
    if isinstance(entry, str):
        return entry
    if isinstance(entry, dict):
        return " ".join(describe(v) for k, v in entry.items()
                        if k not in ("groups", "datasets", "attributes"))
    if isinstance(entry, list):
        return " ".join(describe(v) for v in entry)
    return str(entry)


def optional(entry):
    text = describe(entry).lower()
    return any(w in text for w in OPTIONAL_WORDS)


def find(section, name):
    """(layout name, entry) of the layout section's entry matching `name`, or (None, None)."""
    if name in section:
        return name, section[name]
    for key, entry in section.items():
        if "<" in key and pattern(key).match(name):
            return key, entry
    return None, None


def compare(f, node, path, undocumented, missing):
    """Walks the open group `f` at `path` against the layout node (x-root or a group)."""
    attrs = node.get("attributes", {})
    datasets = node.get("datasets", {})
    groups = node.get("groups", {})
    seen_attrs, seen_datasets, seen_groups = set(), set(), set()
    for a in f.attrs:
        key, _ = find(attrs, a)
        if key is None:
            undocumented.append("%s@%s (attribute)" % (path or "/", a))
        else:
            seen_attrs.add(key)
    for name, obj in f.items():
        full = path + "/" + name
        if isinstance(obj, h5py.Dataset):
            key, _ = find(datasets, name)
            if key is None:
                undocumented.append("%s (dataset)" % full)
            else:
                seen_datasets.add(key)
        else:
            key, entry = find(groups, name)
            if key is None:
                undocumented.append("%s (group)" % full)
            else:
                seen_groups.add(key)
                compare(obj, entry if isinstance(entry, dict) else {}, full, undocumented,
                        missing)
    for section, seen, what in ((attrs, seen_attrs, "attribute"),
                                (datasets, seen_datasets, "dataset"),
                                (groups, seen_groups, "group")):
        for key, entry in section.items():
            if key not in seen and not optional(entry):
                sep = "@" if what == "attribute" else "/"
                missing.append("%s%s%s (%s)" % (path if what != "attribute" else (path or "/"),
                                               sep, key, what))


def check(db, layout_path=DEFAULT_LAYOUT):
    """(undocumented, missing) lists of HDF5 paths."""
    with open(layout_path) as fh:
        layout = json.load(fh)
    undocumented, missing = [], []
    with h5py.File(db, "r") as f:
        compare(f, layout["x-root"], "", undocumented, missing)
    return undocumented, missing


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("database")
    ap.add_argument("--layout", default=DEFAULT_LAYOUT)
    a = ap.parse_args()
    try:
        undocumented, missing = check(a.database, a.layout)
    except (OSError, ValueError, KeyError) as e:
        print("db_layout.py: %s: %s" % (a.database, e), file=sys.stderr)
        return 2
    for u in undocumented:
        print("%s: not in the layout: %s" % (a.database, u))
    for m in missing:
        print("%s: missing (the layout does not say it may be absent): %s" % (a.database, m))
    if not undocumented and not missing:
        print("%s: every group, dataset and attribute as %s describes"
              % (a.database, os.path.relpath(a.layout)))
    return 1 if undocumented or missing else 0


if __name__ == "__main__":
    sys.exit(main())
