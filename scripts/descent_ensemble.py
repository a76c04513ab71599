#!/usr/bin/env python3
"""Compare the descent of groups of drops (fabrics, meshes, closures) with run-to-run error bars.

    scripts/descent_ensemble.py RUN_DIR [...] [--window 3 8] [--group-by fabric|REGEX] [--sub S]

A single drop's mean speed and drag over a fixed window carry the swing it happens to make:
the swing grows out of round-off, so its onset and size differ between runs that differ
only at round-off (a grid offset, a thread count), by seconds and by tens of degrees
(validation.md section 3.4). This script takes several runs of each group, e.g. the same
fabric at --grid-offset 0, 0.25, 0.5, and gives:

* per run, over --window: mean payload speed, mean drag_coefficient (2 W / (rho v^2 S0)),
  the rms canopy tilt (degrees, from canopy_phi_x and canopy_phi_y of history.csv) and the
  mean canopy_diameter (the skirt's; C_D on the projected area is C_D (D0 / D)^2);
* per run, when the histories hold the velocity: the canopy axis's angle to the flight path
  (rms, mean, largest; the angle of attack, which a gliding canopy keeps: validation.md
  section 3.7);
* per group: the number of runs n, the mean of each, its sample standard deviation s and
  the standard error s / sqrt(n);
* per pair of groups: the difference of the mean C_D with its standard error
  sqrt(s1^2/n1 + s2^2/n2), and the ratio of the two;
* per group, when the runs have summary.csv: the mean and sample standard deviation of the
  opening read-outs t_f, t_mo, t_p and F_p (their run-to-run spread);
* per run and per group, when every run has cloth_pressure.csv (the embedded coupling's): the
  window's means of windward_cp and leeward_cp (the cloth's wall pressures, windward and
  leeward, on q of the payload's speed), pressure_drag_coefficient (their difference on the
  projected area, over S0), through_fraction (the fabric law's through-flow over |V| S) and
  projected_area S (m^2),
  with the groups' means and sample standard deviations and the pairwise differences of the
  two sides: which side of the cloth a group difference in C_D comes from;
* the same fit of windward_cp and of leeward_cp when every run has cloth_pressure.csv: which
  side of the cloth differs between groups at equal swing;
* the drag at equal attitude: a least-squares fit C_D = c_g + k theta_rms^2 with one
  intercept c_g per group and a slope k shared by all (the axial drag of a canopy is even
  in its tilt), over the runs' windows or, with --sub S, over consecutive sub-windows of S
  seconds (more points, each a phase of the swing when S is shorter than its period).
  The intercepts are the groups' C_D without a swing; their difference says how much of a
  group difference remains when the swing is accounted for, with the fit's standard errors
  (from its residuals; with --sub they count the sub-windows of one run as independent,
  and a group of one run gets an intercept with no run-to-run spread behind it: the table
  gives the runs per group).

Groups: --group-by fabric (default) reads the fabric from each run's summary.csv (a run
with --permeability F reads FABRIC+F_permeability); any other value is a regular
expression that must match the whole of the run's directory name, its first group naming
the group (e.g. '(.+)_o[0-9.]+' for directories named NAME_oOFFSET).

The histories must reach the window's end (a shorter run is refused) and be finite from the
window's start on.
"""
import argparse
import itertools
import os
import re
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from descent_phases import load, require_finite  # noqa: E402


def group_of(run_dir, how):
    if how == "fabric":
        summary = os.path.join(run_dir, "summary.csv")
        try:
            with open(summary) as f:
                rows = [r.strip() for r in f if r.strip()]
        except OSError:
            sys.exit(f"descent_ensemble: {summary}: no summary file to read the fabric from (--group-by REGEX)")
        if len(rows) < 2 or not rows[0].startswith("fabric,"):
            sys.exit(f"descent_ensemble: {summary}: no fabric column")
        return rows[1].split(",")[0]
    m = re.fullmatch(how, os.path.basename(os.path.normpath(run_dir)))
    if not m or not m.groups():
        sys.exit(f"descent_ensemble: --group-by '{how}' names no group in {run_dir}")
    return m.group(1)


def window_masks(t, lo, hi, sub):
    """Row masks of [lo, hi] or of its consecutive sub-windows of `sub` s that hold two rows or more."""
    edges = [lo, hi] if not sub else list(np.arange(lo, hi - 1e-9, sub)) + [hi]
    masks = [(t >= w0) & (t <= w1) for w0, w1 in zip(edges[:-1], edges[1:])]
    return [m for m in masks if m.sum() >= 2]


def windows(a, lo, hi, sub):
    """(rms tilt, mean C_D, mean speed) over [lo, hi] or its consecutive sub-windows of `sub` s."""
    tilt = np.hypot(a["canopy_phi_x"], a["canopy_phi_y"])
    return [(np.sqrt(np.mean(tilt[m] ** 2)), a["drag_coefficient"][m].mean(), a["speed"][m].mean())
            for m in window_masks(a["t"], lo, hi, sub)]


def angle_of_attack(a, lo, hi):
    """(rms, mean, largest) angle (deg) between the canopy axis and the flight path over [lo, hi], or None.

    The axis a = (tan phi_y, -tan phi_x, 1)/|.| from canopy_phi_x, canopy_phi_y (io::axis_angles, an
    axis with a_z > 0), the stream e = -V/|V| from vx, vy, vz: the angle the canopy flies at to its path
    (its angle of attack; a trimmed, gliding canopy keeps one, validation.md section 3.7)."""
    if not all(c in a.dtype.names for c in ("vx", "vy", "vz")):
        return None
    m = (a["t"] >= lo) & (a["t"] <= hi)
    ax = np.stack([np.tan(np.radians(a["canopy_phi_y"][m])), -np.tan(np.radians(a["canopy_phi_x"][m])),
                   np.ones(int(m.sum()))], axis=1)
    ax /= np.linalg.norm(ax, axis=1)[:, None]
    v = np.stack([a["vx"][m], a["vy"][m], a["vz"][m]], axis=1)
    speed = np.linalg.norm(v, axis=1)
    ok = speed > 0
    if not ok.any():
        return None
    e = -v[ok] / speed[ok][:, None]
    ang = np.degrees(np.arccos(np.clip(np.sum(ax[ok] * e, axis=1), -1.0, 1.0)))
    return np.sqrt(np.mean(ang ** 2)), ang.mean(), ang.max()


def cloth_windows(run_dir, lo, hi, sub):
    """(windward_cp, leeward_cp) means of cloth_pressure.csv over the windows of `windows`, or None."""
    path = os.path.join(run_dir, "cloth_pressure.csv")
    if not os.path.isfile(path):
        return None
    a = np.genfromtxt(path, delimiter=",", names=True)
    return [(a["windward_cp"][m].mean(), a["leeward_cp"][m].mean()) for m in window_masks(a["t"], lo, hi, sub)]


def opening(run_dir):
    """t_f, t_mo, t_p, F_p of the run's summary.csv, or None without one."""
    path = os.path.join(run_dir, "summary.csv")
    if not os.path.isfile(path):
        return None
    with open(path) as f:
        rows = [r.strip().split(",") for r in f if r.strip()]
    if len(rows) < 2:
        return None
    head, vals = rows[0], rows[1]
    try:
        return [float(vals[head.index(k)]) for k in ("t_f", "t_mo", "t_p", "F_p")]
    except (ValueError, IndexError):
        sys.exit(f"descent_ensemble: {path}: no t_f, t_mo, t_p, F_p columns")


CLOTH = ("windward_cp", "leeward_cp", "pressure_drag_coefficient", "through_fraction", "projected_area")


def cloth_means(run_dir, lo, hi):
    """The window's means of the CLOTH columns of cloth_pressure.csv, or None without the file."""
    path = os.path.join(run_dir, "cloth_pressure.csv")
    if not os.path.isfile(path):
        return None
    a = np.genfromtxt(path, delimiter=",", names=True)
    missing = [c for c in ("t",) + CLOTH if c not in (a.dtype.names or ())]
    if missing:
        sys.exit(f"descent_ensemble: {path}: no column {', '.join(missing)}")
    t = np.atleast_1d(a["t"])
    m = (t >= lo) & (t <= hi)
    step = np.median(np.diff(t)) if len(t) > 1 else np.inf
    if m.sum() < 2 or t[m][0] > lo + step or t[m][-1] < hi - step:
        # e.g. a restart into another directory: the file starts at the checkpoint
        print(f"# {path} does not cover the window [{lo}, {hi}] s: the run's cloth sides are left out")
        return None
    vals = [np.atleast_1d(a[c])[m] for c in CLOTH]
    if not all(np.isfinite(v).all() for v in vals):
        print(f"# {path}: a value in the window [{lo}, {hi}] s is not finite: the run's cloth sides are left out")
        return None
    return [v.mean() for v in vals]


def stats(x):
    x = np.asarray(x, float)
    n = len(x)
    s = x.std(ddof=1) if n > 1 else np.nan
    return x.mean(), s, s / np.sqrt(n) if n > 1 else np.nan


def attitude_fit(points, groups):
    """Least squares C_D = c_g + k theta^2: intercepts, slope, their standard errors, rms residual."""
    A = np.zeros((len(points), len(groups) + 1))
    y = np.array([p[2] for p in points])
    for r, (g, th, _) in enumerate(points):
        A[r, groups.index(g)] = 1.0
        A[r, -1] = th**2
    dof = len(points) - A.shape[1]
    if dof < 1 or np.linalg.matrix_rank(A) < A.shape[1]:
        return None
    coef, *_ = np.linalg.lstsq(A, y, rcond=None)
    res = y - A @ coef
    s2 = res @ res / dof
    cov = s2 * np.linalg.inv(A.T @ A)
    return coef, cov, np.sqrt(s2), dof


def cloth(rows, groups):
    """The cloth's two sides (cloth_pressure.csv) per run and per group, and the groups' differences."""
    if any(r[7] is None for r in rows):
        print("# the cloth's two sides left out: not every run has a cloth_pressure.csv (embedded coupling)")
        return
    print("# the cloth's two sides (cloth_pressure.csv), window means per run")
    print("group run " + " ".join(CLOTH))
    for r in sorted(rows, key=lambda r: r[:2]):
        print(f"{r[0]} {r[1]} " + " ".join(f"{x:.5f}" for x in r[7]))
    print("# per group: n, mean and sample standard deviation of each")
    print("group n " + " ".join(f"{c} {c}_s" for c in CLOTH))
    means = {}
    for g in groups:
        sel = np.array([r[7] for r in rows if r[0] == g])
        st = [stats(sel[:, k]) for k in range(len(CLOTH))]
        means[g] = (len(sel), st)
        print(f"{g} {len(sel)} " + " ".join(f"{m:.5f} {s:.5f}" for m, s, _ in st))
    if len(groups) > 1:
        print("# the two sides' differences: group_b - group_a, standard error sqrt(s_a^2/n_a + s_b^2/n_b)")
        print("a b windward_cp_diff se leeward_cp_diff se pressure_drag_diff se projected_area_diff se")
        for ga, gb in itertools.combinations(groups, 2):
            (na, sa), (nb, sb) = means[ga], means[gb]
            out = []
            for k in (0, 1, 2, 4):
                d = sb[k][0] - sa[k][0]
                se = np.sqrt(sa[k][1] ** 2 / na + sb[k][1] ** 2 / nb) if na > 1 and nb > 1 else np.nan
                out.append(f"{d:+.5f} {se:.5f}")
            print(f"{ga} {gb} " + " ".join(out))


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("runs", nargs="+", help="run directories (history.csv, and summary.csv for --group-by fabric)")
    p.add_argument("--window", type=float, nargs=2, default=(3.0, 8.0), help="averaging window (s)")
    p.add_argument("--group-by", default="fabric", help="'fabric' or a regex whose first group names the group")
    p.add_argument("--sub", type=float, default=0.0, help="attitude fit over sub-windows of this many s (0: whole)")
    o = p.parse_args()
    lo, hi = o.window
    if not hi > lo or o.sub < 0 or (o.sub and o.sub > hi - lo):
        sys.exit("descent_ensemble: the window's end must follow its start, and 0 <= --sub <= its length")
    rows, points, side_points, aoa = [], [], [], {}
    for r in o.runs:
        path, a = load(r)
        require_finite(path, a, lo)
        if a["t"][-1] < hi - 1e-9:
            sys.exit(f"descent_ensemble: {path} ends at {a['t'][-1]:.3f} s, before the window's end {hi} s")
        run_dir = os.path.dirname(path) or "."
        g = group_of(run_dir, o.group_by)
        whole = windows(a, lo, hi, 0.0)
        if not whole:
            sys.exit(f"descent_ensemble: {path} holds fewer than two rows in the window [{lo}, {hi}] s")
        (tilt, cd, v), = whole
        win = (a["t"] >= lo) & (a["t"] <= hi)
        diameter = a["canopy_diameter"][win].mean() if "canopy_diameter" in a.dtype.names else np.nan
        rows.append((g, run_dir, v, cd, tilt, opening(run_dir), diameter, cloth_means(run_dir, lo, hi)))
        aoa[run_dir] = angle_of_attack(a, lo, hi)
        sw = windows(a, lo, hi, o.sub)
        points += [(g, th, c) for th, c, _ in sw]
        cw = cloth_windows(run_dir, lo, hi, o.sub) if rows[-1][7] is not None else None
        if cw is None or len(cw) != len(sw):
            if side_points:
                print(f"# the attitude fits of the cloth's sides are left out: {run_dir} has no matching cloth file")
            side_points = None
        elif side_points is not None:
            side_points += [(g, th, w, le) for (th, _, _), (w, le) in zip(sw, cw)]
    groups = sorted({r[0] for r in rows})
    print(f"# window [{lo}, {hi}] s; per run: mean speed (m/s), mean C_D, rms canopy tilt (deg), mean skirt "
          "diameter (m)")
    print("group run v cd tilt_rms diameter")
    for g, d, v, cd, tilt, _, dia, _ in sorted(rows, key=lambda r: r[:2]):
        print(f"{g} {d} {v:.4f} {cd:.4f} {tilt:.2f} {dia:.4f}")
    if all(x is not None for x in aoa.values()):
        print("# per run: the canopy axis's angle to the flight path (deg), rms, mean and largest over the window "
              "(its angle of attack: a trimmed canopy keeps one; the tilt above is from the vertical)")
        print("group run aoa_rms aoa_mean aoa_max")
        for g, d, *_ in sorted(rows, key=lambda r: r[:2]):
            print(f"{g} {d} {aoa[d][0]:.2f} {aoa[d][1]:.2f} {aoa[d][2]:.2f}")
    print("# per group: n, mean, sample standard deviation s, standard error s/sqrt(n)")
    print("group n v_mean v_s cd_mean cd_s cd_se tilt_mean tilt_s diameter_mean diameter_s")
    summary = {}
    for g in groups:
        sel = [r for r in rows if r[0] == g]
        v, vs, _ = stats([r[2] for r in sel])
        cd, cds, cdse = stats([r[3] for r in sel])
        ti, tis, _ = stats([r[4] for r in sel])
        dm, ds, _ = stats([r[6] for r in sel])
        summary[g] = (len(sel), cd, cds)
        print(f"{g} {len(sel)} {v:.4f} {vs:.4f} {cd:.4f} {cds:.4f} {cdse:.4f} {ti:.2f} {tis:.2f} {dm:.4f} {ds:.4f}")
    if any(r[5] is None for r in rows):
        print("# opening read-outs left out: not every run has a summary.csv with t_f, t_mo, t_p, F_p")
    else:
        print("# opening read-outs of summary.csv per group: mean and sample standard deviation")
        print("group n t_f t_f_s t_mo t_mo_s t_p t_p_s F_p F_p_s")
        for g in groups:
            op = np.array([r[5] for r in rows if r[0] == g])
            cols = " ".join(f"{stats(op[:, k])[0]:.4f} {stats(op[:, k])[1]:.4f}" for k in range(4))
            print(f"{g} {len(op)} {cols}")
    cloth(rows, groups)
    if len(groups) > 1:
        print("# C_D differences: group_b - group_a, standard error sqrt(s_a^2/n_a + s_b^2/n_b), ratio b/a")
        print("a b diff se ratio")
        for ga, gb in itertools.combinations(groups, 2):
            (na, ca, sa), (nb, cb, sb) = summary[ga], summary[gb]
            se = np.sqrt(sa**2 / na + sb**2 / nb) if na > 1 and nb > 1 else np.nan
            print(f"{ga} {gb} {cb - ca:+.4f} {se:.4f} {cb / ca:.4f}")
    what = f"sub-windows of {o.sub} s" if o.sub else "whole windows"
    report_fit("C_D", points, groups, rows, what, "")
    if side_points:
        for k, name in ((2, "windward_cp"), (3, "leeward_cp")):
            report_fit(name, [(p[0], p[1], p[k]) for p in side_points], groups, rows, what, f"{name} ")


def report_fit(name, points, groups, rows, what, prefix):
    """The fit y = c_group + k theta_rms^2 of `points` (group, tilt, y): slope, intercepts, their differences."""
    fit = attitude_fit(points, groups)
    if fit is None:
        print(f"# attitude fit {name} = c_group + k theta_rms^2 over {what}: too few points or no spread in tilt")
        return
    coef, cov, rms, dof = fit
    se = np.sqrt(np.diag(cov))
    print(f"# attitude fit {name} = c_group + k theta_rms^2 over {what}: {len(points)} points, {dof} degrees of "
          f"freedom, rms residual {rms:.4f}; k = {coef[-1]:.3e} +- {se[-1]:.1e} per deg^2")
    print(f"{prefix}group runs c_at_zero_tilt se")
    for i, g in enumerate(groups):
        print(f"{g} {sum(r[0] == g for r in rows)} {coef[i]:.4f} {se[i]:.4f}")
    if len(groups) > 1:
        print("# intercept differences at equal attitude: b - a, standard error from the fit's covariance")
        print(f"{prefix}a b diff se")
        for (i, ga), (j, gb) in itertools.combinations(enumerate(groups), 2):
            d = coef[j] - coef[i]
            print(f"{ga} {gb} {d:+.4f} {np.sqrt(cov[i, i] + cov[j, j] - 2 * cov[i, j]):.4f}")


if __name__ == "__main__":
    main()
