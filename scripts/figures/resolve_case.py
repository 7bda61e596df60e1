#!/usr/bin/python3
"""Copies a case file with its knit material's database path set to DATABASE.

Usage: resolve_case.py CASE.json DATABASE.h5 OUT.json [LAW]   (used by scripts/pipeline.mk)
LAW ("energy" or "paper") sets the knit material's law (the side-by-side runs of fig07e).
The case's own "database" entry (relative to cases/paper/) names the default location; the
pipeline runs every case against the database it built, wherever OUT is. The path is written
relative to OUT.json's directory (knit-macro resolves it from the case file), so an output
directory copied or moved elsewhere runs its cases against its own database (session 36's red
team: a copy re-made with DB_SOURCE=synth ran every case on the original's sweep database,
which the absolute path named, and reported "SYNTHETIC stand-in" beside its numbers).
"""
import json
import os
import sys

if len(sys.argv) not in (4, 5) or (len(sys.argv) == 5 and sys.argv[4] not in ("energy", "paper")):
    sys.exit("usage: resolve_case.py CASE.json DATABASE.h5 OUT.json [energy|paper]")
src, db, dst = sys.argv[1:4]
with open(src) as f:
    case = json.load(f)
if case.get("material", {}).get("type") == "knit":
    case["material"]["database"] = os.path.relpath(os.path.abspath(db),
                                                   os.path.dirname(os.path.abspath(dst)))
    if len(sys.argv) == 5:
        case["material"]["law"] = sys.argv[4]
tmp = dst + ".tmp"
with open(tmp, "w") as f:
    json.dump(case, f, indent=1)
    f.write("\n")
os.replace(tmp, dst)
