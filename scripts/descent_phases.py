#!/usr/bin/env python3
"""Split a drop's descent into its hanging and swinging phases and give the drag of each.

    scripts/descent_phases.py RUN_DIR_OR_HISTORY.csv [...] [--settle 2.25] [--tilt 10]
                              [--window 3 6]

After the opening the canopy rides nearly straight above the payload (a tilt of a few
degrees) until a swing grows out of round-off; its onset time varies from run to run by
seconds (validation.md section 3.2), and while it swings the speed and drag oscillate and
their means shift. A mean over a fixed window (e.g. 3-6 s) therefore mixes the two phases in
proportions set by the onset, so two runs are compared phase by phase:

* t_swing: the first time after --settle at which the canopy tilt (canopy_phi_x,
  canopy_phi_y of history.csv), averaged over 0.1 s, exceeds --tilt degrees (a run still
  above it at --settle, its opening's own swing not yet died down, is refused);
* the hanging phase [settle, t_swing): mean payload speed and drag_coefficient;
* the common hanging window [settle, earliest t_swing of the runs given]: mean speed and
  drag_coefficient of each run over the same times (the speed still falls after the
  opening, so hanging phases of different lengths do not compare);
* the fixed --window: mean speed, drag_coefficient and canopy tilt.

One row per run on stdout (whitespace-separated, a header first), with the mean tilt over
the common window; a comment line names the run whose onset (or end) closes that window.
The common window depends on which runs are given: quote results with the list of runs.
"""
import argparse
import os
import sys

import numpy as np


def load(path):
    if os.path.isdir(path):
        path = os.path.join(path, "history.csv")
    if not os.path.isfile(path):
        sys.exit(f"descent_phases: no history file {path}")
    try:
        a = np.atleast_1d(np.genfromtxt(path, delimiter=",", names=True, invalid_raise=False))
    except ValueError as e:
        sys.exit(f"descent_phases: {path}: {e}")
    if a.dtype.names is None or a.size < 2:
        sys.exit(f"descent_phases: {path} holds fewer than two history rows")
    for col in ("t", "speed", "drag_coefficient", "canopy_phi_x", "canopy_phi_y"):
        if col not in a.dtype.names:
            sys.exit(f"descent_phases: {path} has no column '{col}'")
    return path, a


def require_finite(path, a, settle):
    """Every column used finite from --settle on (C_D is undefined at rest, before it)."""
    rows = a["t"] >= settle
    for col in ("t", "speed", "drag_coefficient", "canopy_phi_x", "canopy_phi_y"):
        if not np.all(np.isfinite(a[col][rows])):
            sys.exit(f"descent_phases: {path}: non-finite values in column '{col}' after --settle {settle} s")


def running_mean(x, t, width):
    """Mean of x over the trailing window of `width` seconds at each sample."""
    c = np.concatenate(([0.0], np.cumsum(x)))
    lo = np.searchsorted(t, t - width, side="left")
    n = np.arange(1, len(x) + 1) - lo
    return (c[1:] - c[lo]) / n


def swing_onset(path, a, settle, tilt_limit):
    t = a["t"]
    smooth = running_mean(np.hypot(a["canopy_phi_x"], a["canopy_phi_y"]), t, 0.1)
    from_settle = np.nonzero(t >= settle)[0]
    if not from_settle.size:
        sys.exit(f"descent_phases: {path} ends at {t[-1]:.3f} s, before --settle {settle} s")
    if smooth[from_settle[0]] > tilt_limit:
        sys.exit(f"descent_phases: {path}: the canopy tilt is {smooth[from_settle[0]]:.1f} deg at --settle "
                 f"{settle} s, above --tilt {tilt_limit}: the opening's swing has not died down (a later --settle)")
    after = from_settle[smooth[from_settle] > tilt_limit]
    return t[after[0]] if after.size else np.nan


def phases(path, a, settle, tilt_limit, window, common_end):
    t = a["t"]
    tilt = np.hypot(a["canopy_phi_x"], a["canopy_phi_y"])
    t_swing = swing_onset(path, a, settle, tilt_limit)
    end = t[-1] if np.isnan(t_swing) else t_swing
    hang = (t >= settle) & (t < end)
    common = (t >= settle) & (t < common_end)
    win = (t >= window[0]) & (t <= window[1])
    mean = lambda col, m: a[col][m].mean() if m.any() else np.nan
    return {
        "v_common": mean("speed", common),
        "cd_common": mean("drag_coefficient", common),
        "tilt_common": tilt[common].mean() if common.any() else np.nan,
        "t_swing": t_swing,
        "hang_s": max(0.0, end - settle) if hang.any() else 0.0,
        "v_hang": mean("speed", hang),
        "cd_hang": mean("drag_coefficient", hang),
        "v_window": mean("speed", win),
        "cd_window": mean("drag_coefficient", win),
        "tilt_window": tilt[win].mean() if win.any() else np.nan,
        "t_end": t[-1],
    }


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("runs", nargs="+", help="run directories or history.csv files")
    p.add_argument("--settle", type=float, default=2.25, help="start of the hanging phase (s), after the opening")
    p.add_argument("--tilt", type=float, default=10.0, help="canopy tilt that starts the swing (deg)")
    p.add_argument("--window", type=float, nargs=2, default=(3.0, 6.0), help="fixed window (s)")
    o = p.parse_args()
    if not (o.tilt > 0 and o.window[1] > o.window[0]):
        sys.exit("descent_phases: --tilt must be > 0 and the window's end after its start")
    runs = [load(r) for r in o.runs]
    ends = []
    for path, a in runs:
        require_finite(path, a, o.settle)
        onset = swing_onset(path, a, o.settle, o.tilt)
        ends.append((a["t"][-1] if np.isnan(onset) else onset, path, "ends" if np.isnan(onset) else "swings"))
        if a["t"][-1] < o.window[1]:
            print(f"# {path} ends at {a['t'][-1]:.3f} s, inside --window: its window means are partial")
    common_end, closer, how = min(ends)
    if not common_end > o.settle:
        sys.exit(f"descent_phases: {closer} {how} at {common_end:.3f} s: no hanging window after --settle")
    print(f"# common hanging window: [{o.settle}, {common_end:.3f}] s, closed as {closer} {how}")
    cols = ["t_swing", "hang_s", "v_hang", "cd_hang", "v_common", "cd_common", "tilt_common", "v_window",
            "cd_window", "tilt_window", "t_end"]
    print("run " + " ".join(cols))
    for path, a in runs:
        r = phases(path, a, o.settle, o.tilt, o.window, common_end)
        print(os.path.dirname(path) or path, " ".join(f"{r[c]:.4f}" for c in cols))


if __name__ == "__main__":
    main()
