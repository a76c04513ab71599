#!/usr/bin/env python3
"""scripts/opening_ensemble.py on synthetic drops whose answers are known exactly.

Four runs in two groups. Each history's speed rises as v = a t to t_p and falls after it
(a later, higher speed must not count), so v_open = a t_p; F_p is built from a chosen
opening-load coefficient, F_p = C_F rho (a t_p)^2 S0 / 2, with rho = 1.2 and S0 = 0.5:
  A: C_F 1.8 and 1.6 (t_p 0.7, 0.8 s);  B: C_F 1.2 and 1.4 (t_p 0.9, 0.75 s).
The script must give each run's v_open and C_F, the groups' means and standard deviations of
F_p and C_F, and the difference B - A of C_F (-0.4) with its standard error (sqrt(0.02/2 +
0.02/2) = 0.1414...) and Welch's t (-2.83); it must refuse a run whose summary has no finite
t_p, naming the file.

  test_opening_ensemble.py SCRIPT
"""
import math
import os
import subprocess
import sys
import tempfile

from drop_csv import HISTORY_HEAD, SUMMARY_HEAD, table

RHO, S0, A = 1.2, 0.5, 8.0
RUNS = {"A_o0": ("matA", 0.7, 1.8), "A_o1": ("matA", 0.8, 1.6), "B_o0": ("matB", 0.9, 1.2), "B_o1": ("matB", 0.75, 1.4)}


def f_p(t_p, c_f):
    return c_f * 0.5 * RHO * (A * t_p) ** 2 * S0


def write_run(root, name, fabric, t_p, c_f, t_p_text=None):
    d = os.path.join(root, name)
    os.makedirs(d)
    with open(os.path.join(d, "history.csv"), "w") as f:
        f.write(HISTORY_HEAD + "\n")
        for i in range(301):
            t = i * 0.005
            v = A * t if t <= t_p + 1e-12 else A * t_p * 2.0  # after t_p: faster, not counted
            f.write(f"{t},0,0,0,0,0,{-v},{v},0.5,1,0,0,0,0,90,0.8,1\n")
    with open(os.path.join(d, "summary.csv"), "w") as f:
        f.write(SUMMARY_HEAD + "\n")
        f.write(f"{fabric},{t_p - 0.05},{t_p + 0.1},{t_p_text or t_p},{f_p(t_p, c_f)!r},5,0.8,3,vertical\n")
    return d



def main():
    script = sys.argv[1]
    failures = []

    def check(ok, what):
        if not ok:
            failures.append(what)

    def close(a, b, tol=2e-4):
        return abs(float(a) - b) <= tol * max(1.0, abs(b))

    with tempfile.TemporaryDirectory() as root:
        dirs = [write_run(root, k, *v) for k, v in RUNS.items()]
        r = subprocess.run([sys.executable, script, *dirs, "--rho", str(RHO), "--area", str(S0)], capture_output=True,
                           text=True)
        check(r.returncode == 0, f"exit {r.returncode}: {r.stderr}")
        out = r.stdout
        runs = {os.path.basename(w[1]): w for w in table(out, "group run t_f t_mo t_p F_p v_open C_F")}
        for name, (fabric, t_p, c_f) in RUNS.items():
            w = runs.get(name)
            check(w is not None and w[0] == fabric, f"{name}: group")
            if w:
                check(close(w[6], A * t_p), f"{name}: v_open {w[6]} against {A * t_p}")
                check(close(w[7], c_f), f"{name}: C_F {w[7]} against {c_f}")
        groups = {w[0]: w for w in table(out, "group n t_f t_f_s t_mo t_mo_s t_p t_p_s F_p F_p_s F_p_se v_open "
                                               "v_open_s C_F C_F_s C_F_se")}
        for g, members in (("matA", ("A_o0", "A_o1")), ("matB", ("B_o0", "B_o1"))):
            fs = [f_p(RUNS[m][1], RUNS[m][2]) for m in members]
            cs = [RUNS[m][2] for m in members]
            w = groups.get(g)
            check(w is not None and w[1] == "2", f"{g}: n")
            if w:
                check(close(w[8], sum(fs) / 2), f"{g}: F_p mean {w[8]}")
                check(close(w[9], abs(fs[0] - fs[1]) / math.sqrt(2)), f"{g}: F_p s {w[9]}")
                check(close(w[13], sum(cs) / 2), f"{g}: C_F mean {w[13]}")
                check(close(w[14], abs(cs[0] - cs[1]) / math.sqrt(2)), f"{g}: C_F s {w[14]}")
                check(close(w[15], abs(cs[0] - cs[1]) / 2), f"{g}: C_F se {w[15]}")
        diff = table(out, "a b F_p_diff F_p_se F_p_t C_F_diff C_F_se C_F_t")
        check(len(diff) == 1 and diff[0][:2] == ["matA", "matB"], f"difference rows {diff}")
        if diff:
            se = math.sqrt(0.02 / 2 + 0.02 / 2)
            check(close(diff[0][5], -0.4), f"C_F difference {diff[0][5]}")
            check(close(diff[0][6], se), f"C_F difference's se {diff[0][6]}")
            check(close(diff[0][7], -0.4 / se, 2e-3), f"C_F Welch t {diff[0][7]}")
        bad = write_run(root, "C_o0", "matC", 0.7, 1.5, t_p_text="nan")
        r = subprocess.run([sys.executable, script, dirs[0], bad], capture_output=True, text=True)
        check(r.returncode != 0 and "C_o0" in r.stderr and "not finite" in r.stderr,
              f"a run without a finite t_p: exit {r.returncode}, {r.stderr!r}")
    if failures:
        print("FAILED:\n  " + "\n  ".join(failures))
        sys.exit(1)
    print("opening_ensemble: per-run v_open and C_F, group statistics and the C_F difference exact")


if __name__ == "__main__":
    main()
