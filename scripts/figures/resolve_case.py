#!/usr/bin/python3
"""Copies a case file with its knit material's database path set to DATABASE (absolute).

Usage: resolve_case.py CASE.json DATABASE.h5 OUT.json   (used by scripts/pipeline.mk)
The case's own "database" entry (relative to cases/paper/) names the default location; the
pipeline runs every case against the database it built, wherever OUT is.
"""
import json
import os
import sys

src, db, dst = sys.argv[1:4]
with open(src) as f:
    case = json.load(f)
if case.get("material", {}).get("type") == "knit":
    case["material"]["database"] = os.path.abspath(db)
tmp = dst + ".tmp"
with open(tmp, "w") as f:
    json.dump(case, f, indent=1)
    f.write("\n")
os.replace(tmp, dst)
