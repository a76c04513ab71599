#!/usr/bin/env python3
"""Filled contour plot of one field of an x,y CSV (isentropic_vortex, gresho_vortex).

    python3 scripts/plot_vortex.py out/vortex.csv out/vortex.png [--field rho]

--field is any column of the CSV (rho, u, v, p) or `speed` (|(u, v)|); the default
is rho for the isentropic vortex; use `--field speed` for the Gresho vortex.
"""
import argparse
import csv
import math
import os
import sys

try:
    import matplotlib
    import numpy as np
except ImportError:  # a Python without matplotlib ahead on PATH: try the system one
    if os.path.exists("/usr/bin/python3") and os.path.realpath(sys.executable) != os.path.realpath("/usr/bin/python3"):
        os.execv("/usr/bin/python3", ["/usr/bin/python3"] + sys.argv)
    raise
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("csv")
    ap.add_argument("png")
    ap.add_argument("--field", default="rho", help="column to plot, or 'speed' (default: rho)")
    ap.add_argument("--levels", type=int, default=30, help="contour levels (default: 30)")
    args = ap.parse_args()

    with open(args.csv, newline="") as fh:
        rows = list(csv.DictReader(fh))
    if not rows or "x" not in rows[0] or "y" not in rows[0]:
        sys.exit(f"{args.csv}: expected columns x,y,...")
    cols = {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}
    if args.field == "speed":
        if "u" not in cols or "v" not in cols:
            sys.exit(f"{args.csv}: 'speed' needs columns u and v")
        f = np.hypot(cols["u"], cols["v"])
    elif args.field in cols:
        f = cols[args.field]
    else:
        sys.exit(f"{args.csv}: no column '{args.field}' (have: {', '.join(cols)})")

    xs, ys = np.unique(cols["x"]), np.unique(cols["y"])
    if len(xs) * len(ys) != len(f):
        sys.exit(f"{args.csv}: the rows do not form a structured x-y grid")
    ix, iy = np.searchsorted(xs, cols["x"]), np.searchsorted(ys, cols["y"])
    grid = np.full((len(ys), len(xs)), math.nan)
    grid[iy, ix] = f

    fig, ax = plt.subplots(figsize=(6.2, 5.2), constrained_layout=True)
    cs = ax.contourf(xs, ys, grid, levels=args.levels, cmap="viridis")
    fig.colorbar(cs, ax=ax, label=args.field)
    ax.set_aspect("equal")
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_title(f"{os.path.basename(args.csv)}: {args.field} ({len(xs)} x {len(ys)} cells)")
    fig.savefig(args.png, dpi=120)
    print(f"wrote {args.png}")


if __name__ == "__main__":
    main()
