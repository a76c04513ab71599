#!/usr/bin/env python3
"""Table-driven command-line robustness test of every example program.

For each program, the numeric flags are read from its own --help (CLI11: `--name FLOAT`,
`--name INT`, `--name TEXT:X,Y,Z`); each is given each of the values nan, inf, -1, 0,
1e300 and 1e-300 on top of a short base run; a flag whose meaning depends on another
flag (--packed-parameter) also on the variants of that run in VARIANTS. A case passes when
the program either runs to a clean exit (0) within the time limit or exits non-zero with a
message that names the flag. A timeout, a crash (signal) or a refusal that does not name the flag fails.

  cli_robustness.py --bin <build>/examples [--timeout 20] [--jobs 2] [--only prog,...]
"""
import argparse
import concurrent.futures as cf
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

VALUES = ["nan", "inf", "-1", "0", "1e300", "1e-300"]

# A short valid run of each program ({tmp}: a scratch directory). Flags under test
# replace these values; the flag's own value comes last.
BASE = {
    "bluff_body_drag": ["--cells", "4", "--time", "2e-4", "--out", "{tmp}/bluff.csv", "--quiet"],
    "drop_guide": ["--t-end", "1e-3", "--out", "{tmp}/drop_guide"],
    "fluid_guide": ["--t-end", "1e-3", "--h-fine", "0.5", "--out", "{tmp}/line.csv"],
    "gresho_vortex": ["--cells", "8", "--t-end", "0.01", "--out", "{tmp}/gresho.csv", "--quiet"],
    "hanging_chain": ["--links", "8", "--length", "1.2", "--span", "1", "--out", "{tmp}/chain.csv"],
    "inflated_membrane": ["--radius", "0.5", "--thickness", "1e-3", "--E", "1e7", "--nu", "0.3", "--pressure",
                          "100", "--elements", "2", "--out", "{tmp}/membrane.csv"],
    "isentropic_vortex": ["--cells", "8", "--t-end", "0.01", "--out", "{tmp}/vortex.csv", "--quiet"],
    "leak_box": ["--cells", "10", "--time", "1e-4", "--out", "{tmp}/leak.csv", "--quiet"],
    "moving_box": ["--cells", "2", "--steps", "2", "--quiet"],
    "parachute_drop": ["--resolution", "tiny", "--t-end", "1e-4", "--out", "", "--quiet"],
    "piston": ["--cells", "20", "--time", "1e-3", "--out", "{tmp}/piston.csv", "--quiet"],
    "porous_screen": ["--cells", "10", "--time", "1e-4", "--out", "{tmp}/screen.csv", "--quiet"],
    "shock_tube": ["--cells", "8", "--t-end", "1e-3", "--out", "{tmp}/tube.csv", "--quiet"],
    "tumbling_box": ["--omega", "0.1,2,0.1", "--inertia", "1,2,3", "--t-end", "0.01", "--out", "{tmp}/tumble.csv"],
}

# Variants of a program's base run for the flags whose meaning depends on another flag:
# (label, program, extra base flags, flags to vary). The label names the case in the report.
VARIANTS = [
    ("parachute_drop --packed bundle", "parachute_drop", ["--packed", "bundle"], ["--packed-parameter"]),
    ("parachute_drop --packed reduced_radius", "parachute_drop", ["--packed", "reduced_radius"],
     ["--packed-parameter"]),
]

OPTION = re.compile(r"^\s+(?:-\w,)?(--[\w-]+)\s+(FLOAT|INT|UINT|TEXT:X,Y,Z)\b")


def numeric_flags(exe):
    out = subprocess.run([exe, "--help"], capture_output=True, text=True, timeout=20).stdout
    flags = []
    for line in out.splitlines():
        m = OPTION.match(line)
        if m and m.group(1) not in ("--threads", "--help"):
            flags.append((m.group(1), m.group(2)))
    return flags


def with_flag(base, flag, value):
    args, i = [], 0
    while i < len(base):
        if base[i] == flag:
            i += 2
            continue
        args.append(base[i])
        i += 1
    return args + [flag, value]


def run_case(exe, prog, flag, kind, value, timeout, base=None):
    tmp = tempfile.mkdtemp(prefix="parafsi_cli_")
    try:
        v = value if kind != "TEXT:X,Y,Z" else value + ",1,1"
        args = [a.replace("{tmp}", tmp) for a in with_flag(base or BASE[prog], flag, v)]
        t0 = time.monotonic()
        try:
            p = subprocess.run([exe] + args, capture_output=True, text=True, timeout=timeout,
                               env=dict(os.environ, OMP_NUM_THREADS="1"))
        except subprocess.TimeoutExpired:
            return (prog, flag, value, False, "timeout after %g s" % timeout, timeout)
        dt = time.monotonic() - t0
        text = p.stdout + p.stderr
        if p.returncode == 0:
            return (prog, flag, value, True, "ran", dt)
        if p.returncode < 0:
            return (prog, flag, value, False, "killed by signal %d: %s" % (-p.returncode, text.strip()[-300:]), dt)
        if flag in text:
            return (prog, flag, value, True, "refused", dt)
        return (prog, flag, value, False, "exit %d without naming %s: %s" % (p.returncode, flag,
                                                                            text.strip()[-300:]), dt)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--timeout", type=float, default=20)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--only", default="")
    a = ap.parse_args()
    progs = [p for p in sorted(BASE) if not a.only or p in a.only.split(",")]
    cases = []
    for prog in progs:
        exe = os.path.join(a.bin, prog)
        if not os.access(exe, os.X_OK):
            print("cli_robustness: %s is not built" % exe)
            return 1
        flags = numeric_flags(exe)
        if not flags:
            print("cli_robustness: no numeric flags in %s --help" % prog)
            return 1
        cases += [(exe, prog, f, k, v, a.timeout) for f, k in flags for v in VALUES]
        for label, vprog, extra, vflags in VARIANTS:
            if vprog != prog:
                continue
            kinds = dict(flags)
            for f in vflags:
                if f not in kinds:
                    print("cli_robustness: %s has no numeric flag %s" % (prog, f))
                    return 1
                cases += [(exe, label, f, kinds[f], v, a.timeout, BASE[prog] + extra) for v in VALUES]
    t0 = time.monotonic()
    with cf.ThreadPoolExecutor(a.jobs) as pool:
        results = list(pool.map(lambda c: run_case(*c), cases))
    failed = [r for r in results if not r[3]]
    for r in failed:
        print("FAIL %s %s %s: %s" % (r[0], r[1], r[2], r[4]))
    ran = sum(1 for r in results if r[4] == "ran")
    print("cli_robustness: %d programs, %d cases (%d ran, %d refused naming the flag, %d failed) in %.1f s; "
          "slowest case %.1f s" % (len(progs), len(results), ran, len(results) - ran - len(failed), len(failed),
                                   time.monotonic() - t0, max(r[5] for r in results)))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
