#!/usr/bin/env python3
"""scripts/descent_ensemble.py on synthetic drops whose answers are known exactly.

Two groups of two runs, constant speed, drag coefficient and tilt per run, with the drag
built as C_D = c_g + k theta^2 (c_A = 0.85, c_B = 0.78, k = -1e-4 per deg^2):
  A: theta 10, 20 deg -> C_D 0.84, 0.81;  B: theta 5, 15 deg -> C_D 0.7775, 0.7575.
The script must give each run's means, the groups' means and standard deviations, the
difference B - A with its standard error, and recover c_A, c_B and k from the fit (the
residual is zero). It must also refuse a run shorter than the window, naming it.

Each run also has a cloth_pressure.csv whose windward_cp steps from 0.9 to 1.1 at 5.5 s
(its window mean is computed from the rows) and
whose leeward_cp is a constant per run built as c_g + k theta^2 (c_A = -0.62, c_B = -0.52,
k = +5e-5 per deg^2: A -0.615, -0.600; B -0.51875, -0.50875): the script must give the window
means, the groups' means and standard deviations, the difference of the leeward sides
B - A = +0.09375 with its standard error, and from the attitude fit of each side the
leeward intercepts, their difference +0.10 and k, and equal windward intercepts; a run
without the file leaves the section out by name.

  test_descent_ensemble.py SCRIPT     (exit 77, skipped, when no python3 with numpy is found)

The script runs under this interpreter if it has numpy, else under the system's
/usr/bin/python3 (Debian's python3-numpy, which matplotlib pulls in) if that has it.
"""
import math
import os
import subprocess
import sys
import tempfile

from drop_csv import HISTORY_HEAD, SUMMARY_HEAD, table


def python_with_numpy():
    for exe in (sys.executable, "/usr/bin/python3"):
        if exe and os.path.exists(exe) and subprocess.run([exe, "-c", "import numpy"], capture_output=True).returncode == 0:
            return exe
    return None


PYTHON = python_with_numpy()
if PYTHON is None:
    print("no python3 with numpy: skipped")
    sys.exit(77)

RUNS = {"A_o0": ("matA", 10.0, 0.84, 7.0), "A_o1": ("matA", 20.0, 0.81, 7.1),
        "B_o0": ("matB", 5.0, 0.7775, 7.2), "B_o1": ("matB", 15.0, 0.7575, 7.3)}
LEEWARD = {"A_o0": -0.615, "A_o1": -0.600, "B_o0": -0.51875, "B_o1": -0.50875}
CLOTH_HEAD = ("t,projected_area,windward_pressure,leeward_pressure,through_flow,windward_cp,leeward_cp,"
              "pressure_drag_coefficient,through_fraction")


def windward(t):
    return 0.9 if t < 5.5 else 1.1


def write_cloth(d, leeward, t_end=8.0):
    with open(os.path.join(d, "cloth_pressure.csv"), "w") as f:
        f.write(CLOTH_HEAD + "\n")
        for i in range(int(round(t_end / 0.005)) + 1):
            t = i * 0.005
            w = windward(t)
            f.write(f"{t},0.4,{30 * w},{30 * leeward},0.01,{w},{leeward},{(w - leeward) * 0.4 / 0.785},0.02\n")


def window_mean_windward(lo=3.0, hi=8.0):
    ts = [i * 0.005 for i in range(int(round(8.0 / 0.005)) + 1)]
    sel = [windward(t) for t in ts if lo <= t <= hi]
    return sum(sel) / len(sel)


def write_run(root, name, fabric, tilt, cd, v, t_end=8.0):
    d = os.path.join(root, name)
    os.makedirs(d)
    with open(os.path.join(d, "history.csv"), "w") as f:
        f.write(HISTORY_HEAD + "\n")
        n = int(round(t_end / 0.005))
        for i in range(n + 1):
            t = i * 0.005
            f.write(f"{t},0,0,0,0,0,{-v},{v},0.73,17.7,0,0,{tilt},0,90,{cd},17.7\n")
    with open(os.path.join(d, "summary.csv"), "w") as f:
        f.write(SUMMARY_HEAD + "\n")
        f.write(f"{fabric},0.7,0.8,0.75,{20 + tilt},{v},{cd},{tilt},vertical\n")
    return d



def close(a, b, tol=1e-9):
    return abs(float(a) - b) <= tol * max(1.0, abs(b))


def main():
    script = sys.argv[1]
    failures = []

    def check(ok, what):
        if not ok:
            failures.append(what)

    with tempfile.TemporaryDirectory() as root:
        dirs = [write_run(root, k, *v) for k, v in RUNS.items()]
        for k, d in zip(RUNS, dirs):
            write_cloth(d, LEEWARD[k])
        r = subprocess.run([PYTHON, script, *dirs, "--window", "3", "8"], capture_output=True, text=True)
        check(r.returncode == 0, f"exit {r.returncode}: {r.stderr}")
        out = r.stdout
        runs = {os.path.basename(w[1]): w for w in table(out, "group run v cd tilt_rms diameter")}
        # The synthetic canopy tilts about X by `tilt` while the payload falls straight down:
        # its angle to the flight path is the tilt, at every row.
        aoa = {os.path.basename(w[1]): w for w in table(out, "group run aoa_rms aoa_mean aoa_max")}
        for name, (fabric, tilt, cd, v) in RUNS.items():
            w = aoa[name]
            check(all(close(x, tilt, 1e-3) for x in w[2:5]), f"angle to the path of {name}: {w} against {tilt}")
        for name, (fabric, tilt, cd, v) in RUNS.items():
            w = runs[name]
            check(w[0] == fabric and close(w[2], v, 1e-4) and close(w[3], cd, 1e-4) and close(w[4], tilt, 1e-3),
                  f"run {name}: {w}")
        groups = {w[0]: w for w in table(out, "group n v_mean v_s cd_mean cd_s cd_se tilt_mean tilt_s diameter_mean "
                                               "diameter_s")}
        sA = math.sqrt(2) * 0.015  # sample standard deviation of 0.84, 0.81
        sB = math.sqrt(2) * 0.01
        check(close(groups["matA"][4], 0.825, 1e-4) and close(groups["matA"][5], sA, 1e-3), f"A: {groups['matA']}")
        check(close(groups["matB"][4], 0.7675, 1e-4) and close(groups["matB"][5], sB, 1e-3), f"B: {groups['matB']}")
        diff = table(out, "a b diff se ratio")[0]
        check(diff[:2] == ["matA", "matB"] and close(diff[2], 0.7675 - 0.825, 1e-3)
              and close(diff[3], math.sqrt(sA**2 / 2 + sB**2 / 2), 1e-3), f"difference: {diff}")
        fit = {w[0]: w for w in table(out, "group runs c_at_zero_tilt se")}
        check(close(fit["matA"][2], 0.85, 1e-4) and close(fit["matB"][2], 0.78, 1e-4), f"fit: {fit}")
        kline = [line for line in out.splitlines() if line.startswith("# attitude fit")]
        check(bool(kline) and "k = -1.000e-04" in kline[0], f"slope: {kline}")
        opening = {w[0]: w for w in table(out, "group n t_f t_f_s t_mo t_mo_s t_p t_p_s F_p F_p_s")}
        check(close(opening["matA"][8], 35.0, 1e-4), f"F_p mean: {opening['matA']}")
        # The cloth's two sides: run means, group means and deviations, the leeward difference.
        cols = "windward_cp leeward_cp pressure_drag_coefficient through_fraction projected_area"
        crun = {os.path.basename(w[1]): w for w in table(out, "group run " + cols)}
        ww = window_mean_windward()
        for name, lw in LEEWARD.items():
            w = crun[name]
            check(close(w[2], ww, 1e-5) and close(w[3], lw, 1e-5) and close(w[4], (ww - lw) * 0.4 / 0.785, 1e-4)
                  and close(w[5], 0.02, 1e-5) and close(w[6], 0.4, 1e-5), f"cloth run {name}: {w}")
        cg = {w[0]: w for w in table(out, "group n " + " ".join(f"{c} {c}_s" for c in cols.split()))}
        sLA, sLB = math.sqrt(2) * 0.0075, math.sqrt(2) * 0.005
        check(close(cg["matA"][4], -0.6075, 1e-5) and close(cg["matA"][5], sLA, 1e-4)
              and close(cg["matB"][4], -0.51375, 1e-5) and close(cg["matB"][5], sLB, 1e-4), f"cloth groups: {cg}")
        cd_ = table(out, "a b windward_cp_diff se leeward_cp_diff se pressure_drag_diff se projected_area_diff "
                         "se")[0]
        check(close(cd_[2], 0.0, 1e-6) and close(cd_[4], 0.09375, 1e-5) and close(cd_[8], 0.0, 1e-6)
              and close(cd_[5], math.sqrt(sLA**2 / 2 + sLB**2 / 2), 1e-4), f"cloth difference: {cd_}")
        lfit = {w[0]: w for w in table(out, "leeward_cp group runs c_at_zero_tilt se")}
        check(close(lfit["matA"][2], -0.62, 1e-4) and close(lfit["matB"][2], -0.52, 1e-4), f"leeward fit: {lfit}")
        ldiff = table(out, "leeward_cp a b diff se")[0]
        check(close(ldiff[2], 0.10, 1e-4), f"leeward fit difference: {ldiff}")
        lk = [line for line in out.splitlines() if line.startswith("# attitude fit leeward_cp")]
        check(bool(lk) and "k = 5.000e-05" in lk[0], f"leeward slope: {lk}")
        wdiff = table(out, "windward_cp a b diff se")[0]
        check(close(wdiff[2], 0.0, 1e-6), f"windward fit difference: {wdiff}")
        os.remove(os.path.join(dirs[3], "cloth_pressure.csv"))
        r = subprocess.run([PYTHON, script, *dirs, "--window", "3", "8"], capture_output=True, text=True)
        check(r.returncode == 0 and "not every run has a cloth_pressure.csv" in r.stdout,
              f"a run without cloth_pressure.csv: exit {r.returncode}, {r.stdout[-300:]}")
        # A run that stops before the window's end is refused by name.
        short = write_run(root, "C_o0", "matC", 5.0, 0.8, 7.0, t_end=6.0)
        r = subprocess.run([PYTHON, script, dirs[0], short, "--window", "3", "8"], capture_output=True,
                           text=True)
        check(r.returncode != 0 and "C_o0" in r.stderr and "before the window's end" in r.stderr,
              f"short run: exit {r.returncode}, {r.stderr}")
    for f in failures:
        print("FAILED:", f)
    print("descent_ensemble:", "all checks passed" if not failures else f"{len(failures)} failed")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
