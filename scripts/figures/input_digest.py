#!/usr/bin/python3
"""The contents of a sweep input as one line, for the pipeline's database.source (session 45).

  input_digest.py SWEEP.json      -> "sha256:<input> [cell:sha256:<cell file>]"

The sha256 of the sweep input's bytes and, when its "cell" is the path of a cell parameter
file (relative to the input, schemas/sweep.schema.json), of that file's bytes too. The
pipeline rewrites database.source when this line changes, so the database is rebuilt when the
input is edited, replaced by an older file (make compares time stamps only), or its cell file
changes. An input that is not JSON still gets its digest (knit-meso sweep then says what is
wrong with it); a cell file that cannot be read is named in the line ("cell:missing"), so that
its later appearance rebuilds the database too.
"""
import hashlib
import json
import os
import sys


def digest(path):
    with open(path, "rb") as f:
        return "sha256:" + hashlib.sha256(f.read()).hexdigest()


def main():
    if len(sys.argv) != 2:
        raise SystemExit("usage: input_digest.py SWEEP.json")
    path = sys.argv[1]
    try:
        words = [digest(path)]
    except OSError as e:
        raise SystemExit(f"input_digest.py: {path}: {e.strerror or e}")
    try:
        with open(path) as f:
            cell = json.load(f).get("cell")
    except (OSError, ValueError, AttributeError):
        cell = None
    if isinstance(cell, str):
        cell_path = os.path.join(os.path.dirname(os.path.abspath(path)), cell)
        try:
            words.append("cell:" + digest(cell_path))
        except OSError:
            words.append("cell:missing")
    print(" ".join(words))


if __name__ == "__main__":
    main()
