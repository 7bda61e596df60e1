#!/usr/bin/env python3
"""Fuzz the command lines of knit-macro and knit-meso (session 24; docs/io.md, "Hostile input").

Every option that takes a number gets 0, -1, +-1e308, nan, +-inf, 1e-300, "", abc, 123456789,
2.5, "1,2", 0x10 and 1e3000; every option or positional that takes a path gets "", /,
/dev/null, /proc/self, a directory of user files, a user file, a missing parent, 5,000
characters, ".", dir/../dir and a symbolic link; each command also gets an unknown flag and an
extra positional. Each run is in a fresh sandbox holding "user files", hashed before and after.

A run is flagged (and the script exits with 1) when
  * its exit code is not 0, 1 or 2, or it times out;
  * its output holds crash text (terminate called, Segmentation, AddressSanitizer, ...);
  * a user file was deleted or changed, or /dev/null stopped being a character device (the
    script puts it back);
  * it exits with 2 and says nothing on stderr.
Runs that end with exit 0 are listed (RC0) for a reader: each must be a valid input.

  /usr/bin/python3 scripts/fuzz_cli.py build/bin --out /tmp/fuzz_cli [--only "meso path"]

Needs a material database for the case files: `knit-meso synth` writes one first (13 s). The
whole set, 531 runs, takes about 10 minutes on 2 cores (the sweep runs use cases/sweep/reduced.json).
Run it as a user that cannot write /dev (not root) unless in a throw-away machine.
"""
import argparse
import hashlib
import json
import os
import re
import shutil
import stat
import subprocess
import sys

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
NUMBERS = ["0", "-1", "1e308", "-1e308", "nan", "inf", "-inf", "1e-300", "", "abc", "123456789",
           "2.5", "1,2", "0x10", "1e3000"]
CRASH = re.compile(r"terminate called|Segmentation|Aborted|AddressSanitizer|runtime error|"
                   r"core dumped|what\(\)", re.I)

# name: (executable, base arguments, options taking numbers, options/positionals taking paths)
COMMANDS = {
    "macro run": ("knit-macro", ["run", "case.json", "-o", "o"], ["--max-output-size"],
                  ["-o", "POS"]),
    "macro knitmap": ("knit-macro", ["knitmap", "case.json", "-o", "o"], ["--angle-tolerance"],
                      ["-o", "POS"]),
    "macro design": ("knit-macro", ["design", "design.json", "--check"], [], ["-o", "POS"]),
    "meso cell": ("knit-meso", ["cell", "--loop-length", "5", "-o", "o"],
                  ["--loop-length", "--diameter", "--gamma-over-w"], ["-o", "--config"]),
    "meso path": ("knit-meso", ["path", "--loop-length", "5", "--biaxial", "0.05", "0.05",
                                "--steps", "2", "--no-vtp", "-o", "o"],
                  ["--loop-length", "--steps", "--elements", "--penalty", "--allowance",
                   "--delta", "--mu", "--stick", "--shear", "--uniaxial"], ["-o", "--config"]),
    "meso rod": ("knit-meso", ["rod", "rod.json", "-o", "o", "-q"], [], ["-o", "POS"]),
    "meso fit": ("knit-meso", ["fit", "db.h5", "--law", "paper", "-o", "o.h5"], ["--threads"],
                 ["-o", "POS", "--options"]),
    "meso synth": ("knit-meso", ["synth", "-o", "o.h5", "--steps", "4", "--no-fit"],
                   ["--steps", "--loop-lengths"], ["-o"]),
    "meso synth options": ("knit-meso", ["synth", "-o", "o.h5", "--steps", "4"], [],
                           ["--fit-options", "--energy-options"]),
    "meso sweep": ("knit-meso", ["sweep", "sweep.json", "-o", "o.h5", "--threads", "2",
                                 "--no-progress"], ["--threads"], ["-o", "POS"]),
}


def path_values(sb):
    return ["", "/", "/dev/null", "/proc/self", f"{sb}/user", f"{sb}/user/keep.txt",
            f"{sb}/nope/deeper/out", "a" * 5000, f"{sb}/user/../user", ".",
            f"{sb}/link_to_user"]


def set_option(args, opt, value):
    """args with opt's value(s) replaced by value (POS: the first positional)."""
    a = list(args)
    if opt == "POS":
        a[1] = value
        return a
    if opt in a:
        i = a.index(opt)
        j = i + 1
        while j < len(a) and not a[j].startswith("-"):
            j += 1
        a[i + 1:j] = [value, value] if opt == "--biaxial" else [value]
        return a
    if opt in ("--shear", "--uniaxial") and "--biaxial" in a:  # exactly one kind of path
        i = a.index("--biaxial")
        del a[i:i + 3]
    return a + [opt, value]


def mutants():
    for name, (exe, base, numeric, paths) in COMMANDS.items():
        yield name, exe, base
        for opt in numeric:
            for v in NUMBERS:
                yield name, exe, set_option(base, opt, v)
        for opt in paths:
            for v in path_values("SANDBOX"):
                yield name, exe, set_option(base, opt, v)
        yield name, exe, base + ["--unknown-flag"]
        yield name, exe, base + ["extra_positional"]


def make_sandbox(root, db):
    shutil.rmtree(root, ignore_errors=True)
    os.makedirs(f"{root}/user/sub")
    for f in ["user/keep.txt", "user/sub/data.h5", "user/summary.txt", "user/results.h5"]:
        with open(f"{root}/{f}", "w") as fh:
            fh.write("user data " + f)
    os.symlink(f"{root}/user", f"{root}/link_to_user")

    def copy_case(src, dst):
        c = json.load(open(src))
        c["material"]["database"] = db
        json.dump(c, open(dst, "w"))

    copy_case(f"{REPO}/cases/paper/s312_uniform_45_course.json", f"{root}/case.json")
    d = json.load(open(f"{REPO}/cases/design/uniform_load.json"))
    case = os.path.basename(d["case"])
    copy_case(os.path.join(f"{REPO}/cases/design", d["case"]), f"{root}/{case}")
    d["case"] = case
    json.dump(d, open(f"{root}/design.json", "w"))
    shutil.copy(f"{REPO}/cases/rod/elastica.json", f"{root}/rod.json")
    shutil.copy(f"{REPO}/cases/sweep/reduced.json", f"{root}/sweep.json")
    shutil.copy(db, f"{root}/db.h5")


def snapshot(root):
    h = {}
    for base, _, files in os.walk(f"{root}/user"):
        for f in files:
            p = os.path.join(base, f)
            h[p] = hashlib.md5(open(p, "rb").read()).hexdigest()
    return h


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("bin", help="directory of knit-macro and knit-meso (build/bin)")
    ap.add_argument("--out", required=True, help="work directory (sandboxes, the database)")
    ap.add_argument("--only", help="run only the commands whose name contains this")
    ap.add_argument("--timeout", type=float, default=120.0, help="seconds per run")
    a = ap.parse_args()
    a.bin, a.out = os.path.abspath(a.bin), os.path.abspath(a.out)  # the runs start in a sandbox
    os.makedirs(a.out, exist_ok=True)
    db = os.path.join(a.out, "synth.h5")
    if not os.path.exists(db):
        subprocess.run([f"{a.bin}/knit-meso", "synth", "-o", db], check=True,
                       stdout=subprocess.DEVNULL)
    flagged, zero, total = 0, 0, 0
    for k, (name, exe, args) in enumerate(mutants()):
        if a.only and a.only not in name:
            continue
        total += 1
        sb = os.path.join(a.out, "sandbox")
        make_sandbox(sb, db)
        before = snapshot(sb)
        argv = [f"{a.bin}/{exe}"] + [x.replace("SANDBOX", sb) for x in args]
        try:
            p = subprocess.run(argv, cwd=sb, capture_output=True, text=True, timeout=a.timeout)
            rc, out, err = p.returncode, p.stdout, p.stderr
        except subprocess.TimeoutExpired:
            rc, out, err = "timeout", "", ""
        after = snapshot(sb)
        flags = []
        if rc not in (0, 1, 2):
            flags.append(f"exit {rc}")
        if CRASH.search(err) or CRASH.search(out):
            flags.append("crash text")
        flags += [f"lost {p}" for p in before if p not in after]
        flags += [f"changed {p}" for p in before if p in after and before[p] != after[p]]
        if not stat.S_ISCHR(os.stat("/dev/null").st_mode):
            flags.append("/dev/null replaced")
            os.remove("/dev/null")
            os.system("mknod -m 666 /dev/null c 1 3")
        if rc == 2 and not err.strip():
            flags.append("exit 2 without a message")
        shown = " ".join(x[:60] for x in argv[1:])
        last = err.strip().splitlines()[-1][:200] if err.strip() else ""
        if flags:
            flagged += 1
            print(f"FLAG {k} {name}: {shown}: {'; '.join(flags)} | {last}", flush=True)
        elif rc == 0:
            zero += 1
            print(f"RC0  {k} {name}: {shown}", flush=True)
    shutil.rmtree(os.path.join(a.out, "sandbox"), ignore_errors=True)
    print(f"{total} runs, {flagged} flagged, {zero} with exit 0 (review them: each must be a "
          f"valid input)")
    return 1 if flagged else 0


if __name__ == "__main__":
    sys.exit(main())
