#!/usr/bin/env python3
"""The opening of groups of drops with run-to-run error bars, and its load on the speed reached.

    scripts/opening_ensemble.py RUN_DIR [...] [--group-by fabric|REGEX] [--rho 1.18] [--area 0.7775]

A drop's peak opening load F_p moves by up to ±30 % between runs that differ only in where
the packed canopy falls on the grid (--grid-offset; validation.md sections 3.4 and 3.6):
the filling of the packed mouth starts earlier or later, and the payload falls faster the
longer it waits. This script separates the two. Per run it reads summary.csv (t_f, t_mo,
t_p and F_p, the filtered riser force's peak) and history.csv (t, speed), and gives

* v_open, the payload's largest speed up to t_p (the speed at which the inflation starts to
  decelerate it), and the opening-load coefficient C_F = F_p / (rho v_open^2 S0 / 2) with
  --rho the air's density and --area S0 the canopy's reference area (defaults: the paper
  scene's 1.18 kg/m^3 and 0.99 pi/4 m^2 of its 1 m canopy less the vent);
* per group: n, the mean and sample standard deviation of t_f, t_mo, t_p, F_p, v_open and
  C_F, and the standard error of F_p and C_F;
* per pair of groups: the difference of the mean F_p and of the mean C_F with the standard
  error sqrt(s1^2/n1 + s2^2/n2) and Welch's t.

Runs of 1.5 s hold the paper canopy's opening (t_mo below 1.1 s at D0/15). Groups as in
descent_ensemble.py: --group-by fabric (default) reads summary.csv's fabric column; any other
value is a regular expression matching the whole directory name, its first group naming
the group.
"""
import argparse
import csv
import itertools
import math
import os
import re
import sys

KEYS = ("t_f", "t_mo", "t_p", "F_p")


def fail(msg):
    sys.exit(f"opening_ensemble: {msg}")


def read_run(run_dir):
    """(fabric, t_f, t_mo, t_p, F_p, v_open) of one run directory."""
    sp, hp = os.path.join(run_dir, "summary.csv"), os.path.join(run_dir, "history.csv")
    for p in (sp, hp):
        if not os.path.isfile(p):
            fail(f"{p}: no such file")
    with open(sp) as f:
        rows = list(csv.DictReader(f))
    if not rows or any(k not in rows[0] for k in ("fabric",) + KEYS):
        fail(f"{sp}: no row with fabric, {', '.join(KEYS)}")
    try:
        vals = [float(rows[0][k]) for k in KEYS]
    except ValueError:
        fail(f"{sp}: t_f, t_mo, t_p, F_p are not numbers")
    if not all(math.isfinite(x) for x in vals):
        fail(f"{sp}: the opening read-outs are not finite (did the canopy open?)")
    t_p = vals[2]
    v_open = -math.inf
    with open(hp) as f:
        for r in csv.DictReader(f):
            t, v = float(r["t"]), float(r["speed"])
            if t > t_p + 1e-12:
                break
            if not math.isfinite(v):
                fail(f"{hp}: speed not finite at t = {t} s")
            v_open = max(v_open, v)
    if not v_open > 0:
        fail(f"{hp}: no positive speed up to t_p = {t_p} s")
    return rows[0]["fabric"], *vals, v_open


def group_of(run_dir, fabric, how):
    if how == "fabric":
        return fabric
    name = os.path.basename(os.path.normpath(run_dir))
    m = re.fullmatch(how, name)
    if not m or not m.groups():
        fail(f"--group-by {how!r} names no group in {run_dir}")
    return m.group(1)


def stats(x):
    n = len(x)
    m = sum(x) / n
    s = math.sqrt(sum((v - m) ** 2 for v in x) / (n - 1)) if n > 1 else math.nan
    return m, s


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("runs", nargs="+", help="run directories (summary.csv and history.csv)")
    p.add_argument("--group-by", default="fabric", help="'fabric' or a regex whose first group names the group")
    p.add_argument("--rho", type=float, default=1.18, help="air density (kg/m^3)")
    p.add_argument("--area", type=float, default=0.99 * math.pi / 4, help="reference area S0 (m^2)")
    o = p.parse_args()
    if not (o.rho > 0 and o.area > 0):
        fail("--rho and --area must be positive")
    runs = []
    for d in o.runs:
        fabric, t_f, t_mo, t_p, F_p, v = read_run(d)
        c_f = F_p / (0.5 * o.rho * v * v * o.area)
        runs.append((group_of(d, fabric, o.group_by), d, t_f, t_mo, t_p, F_p, v, c_f))
    print(f"# per run: opening read-outs of summary.csv, v_open = the largest payload speed up to t_p (m/s), "
          f"C_F = F_p / (rho v_open^2 S0 / 2), rho {o.rho} kg/m^3, S0 {o.area:.6g} m^2")
    print("group run t_f t_mo t_p F_p v_open C_F")
    for r in sorted(runs, key=lambda r: r[:2]):
        print(f"{r[0]} {r[1]} {r[2]:.4f} {r[3]:.4f} {r[4]:.4f} {r[5]:.4f} {r[6]:.4f} {r[7]:.4f}")
    groups = sorted({r[0] for r in runs})
    print("# per group: n, mean and sample standard deviation s; se = s/sqrt(n)")
    print("group n t_f t_f_s t_mo t_mo_s t_p t_p_s F_p F_p_s F_p_se v_open v_open_s C_F C_F_s C_F_se")
    g_stats = {}
    for g in groups:
        sel = [r for r in runs if r[0] == g]
        n = len(sel)
        cols = [stats([r[k] for r in sel]) for k in range(2, 8)]
        g_stats[g] = (n, cols[3], cols[5])
        se = lambda s: s / math.sqrt(n)  # noqa: E731
        print(f"{g} {n} " + " ".join(f"{m:.4f} {s:.4f}" for m, s in cols[:3]) +
              f" {cols[3][0]:.4f} {cols[3][1]:.4f} {se(cols[3][1]):.4f} {cols[4][0]:.4f} {cols[4][1]:.4f}"
              f" {cols[5][0]:.4f} {cols[5][1]:.4f} {se(cols[5][1]):.4f}")
    if len(groups) > 1:
        print("# differences group_b - group_a: F_p and C_F, standard error sqrt(s_a^2/n_a + s_b^2/n_b), Welch's t")
        print("a b F_p_diff F_p_se F_p_t C_F_diff C_F_se C_F_t")
        for ga, gb in itertools.combinations(groups, 2):
            (na, fa, ca), (nb, fb, cb) = g_stats[ga], g_stats[gb]
            out = []
            for (ma, sa), (mb, sb) in ((fa, fb), (ca, cb)):
                se = math.sqrt(sa**2 / na + sb**2 / nb) if na > 1 and nb > 1 else math.nan
                t = (mb - ma) / se if se > 0 else math.nan
                out.append(f"{mb - ma:+.4f} {se:.4f} {t:.2f}")
            print(f"{ga} {gb} " + " ".join(out))


if __name__ == "__main__":
    main()
