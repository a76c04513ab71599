#!/usr/bin/env python3
"""Figures of parachute_drop runs (matplotlib, Agg).

    plot_drop.py RUN_DIR [RUN_DIR ...] [--labels a,b,c] [--out FIG_DIR]

One run: time histories (canopy diameter, open force, descent speed, trajectory,
flight-path angle, payload and canopy attitude, drag coefficient) from RUN_DIR/history.csv,
and, for every RUN_DIR/slice_<t>.csv, mid-plane contours of velocity magnitude and of the
vorticity component normal to the plane with the structure nodes overlaid.
Several runs: the same histories overlaid (one colour per run), no contours.
FIG_DIR defaults to the (first) RUN_DIR.
"""
import argparse
import glob
import os
import sys

try:
    import matplotlib
    import numpy as np
except ImportError:  # a Python without matplotlib ahead on PATH: try the system one
    if os.path.exists("/usr/bin/python3") and os.path.realpath(sys.executable) != os.path.realpath("/usr/bin/python3"):
        os.execv("/usr/bin/python3", ["/usr/bin/python3"] + sys.argv)
    sys.exit("plot_drop.py: matplotlib and numpy are needed (scripts/install_deps)")
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def load_history(d):
    h = np.genfromtxt(os.path.join(d, "history.csv"), delimiter=",", names=True)
    return h


HIST = [
    ("canopy_diameter", "canopy diameter (m)", "canopy_diameter.png"),
    ("open_force", "open force (riser tension) (N)", "open_force.png"),
    ("speed", "descent speed (m/s)", "descent_speed.png"),
    ("flight_path_angle", "flight-path angle (deg)", "flight_path_angle.png"),
    ("drag_coefficient", "drag coefficient C_D = 2W/(rho v^2 S0)", "drag_coefficient.png"),
]


def plot_histories(runs, labels, out):
    os.makedirs(out, exist_ok=True)
    for col, ylabel, fname in HIST:
        fig, ax = plt.subplots(figsize=(6.4, 4.0))
        filtered = col == "open_force" and all("open_force_filtered" in h.dtype.names for h in runs)
        for h, lab in zip(runs, labels):
            if filtered:  # raw thin, the 10 Hz zero-phase filtered force thick
                (raw,) = ax.plot(h["t"], h[col], lw=0.5, alpha=0.5)
                ax.plot(h["t"], h["open_force_filtered"], lw=1.4, color=raw.get_color(), label=lab + " (filtered)")
            else:
                ax.plot(h["t"], h[col], lw=1.2, label=lab)
        ax.set_xlabel("t (s)")
        ax.set_ylabel(ylabel)
        if col == "drag_coefficient":
            ax.axhspan(0.75, 0.80, color="0.85", label="flat circular 0.75-0.80")
            ymax = max(np.nanpercentile(h[col][h["t"] > 1.0], 99) if np.any(h["t"] > 1.0) else 2.0 for h in runs)
            ax.set_ylim(0, max(1.5, 1.3 * ymax))
        ax.grid(alpha=0.3)
        if len(runs) > 1 or col == "drag_coefficient" or filtered:
            ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(os.path.join(out, fname), dpi=120)
        plt.close(fig)
    # Trajectory: height vs horizontal displacement, both horizontal axes.
    fig, axs = plt.subplots(1, 2, figsize=(8, 4.5))
    for h, lab in zip(runs, labels):
        axs[0].plot(h["x"] - h["x"][0], h["z"], lw=1.2, label=lab)
        axs[1].plot(h["x"] - h["x"][0], h["y"] - h["y"][0], lw=1.2, label=lab)
    axs[0].set_xlabel("x - x0 (m)")
    axs[0].set_ylabel("z (m)")
    axs[1].set_xlabel("x - x0 (m)")
    axs[1].set_ylabel("y - y0 (m)")
    axs[1].set_aspect("equal", adjustable="datalim")
    for a in axs:
        a.grid(alpha=0.3)
    if len(runs) > 1:
        axs[0].legend(fontsize=8)
    fig.suptitle("payload trajectory")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "trajectory.png"), dpi=120)
    plt.close(fig)
    # Attitudes.
    fig, axs = plt.subplots(2, 1, figsize=(6.4, 6.0), sharex=True)
    for h, lab in zip(runs, labels):
        sfx = "" if len(runs) == 1 else f" {lab}"
        axs[0].plot(h["t"], h["payload_phi_x"], lw=1.0, label="phi_x" + sfx)
        axs[0].plot(h["t"], h["payload_phi_y"], lw=1.0, ls="--", label="phi_y" + sfx)
        axs[1].plot(h["t"], h["canopy_phi_x"], lw=1.0, label="phi_x" + sfx)
        axs[1].plot(h["t"], h["canopy_phi_y"], lw=1.0, ls="--", label="phi_y" + sfx)
    axs[0].set_ylabel("payload attitude (deg)")
    axs[1].set_ylabel("canopy attitude (deg)")
    axs[1].set_xlabel("t (s)")
    for a in axs:
        a.grid(alpha=0.3)
        a.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "attitude.png"), dpi=120)
    plt.close(fig)


def plot_slices(run, out):
    files = sorted(f for f in glob.glob(os.path.join(run, "slice_*.csv")) if not f.endswith("_nodes.csv"))
    if not files:
        return []
    made = []
    for f in files:
        t = float(os.path.basename(f)[6:-4])
        s = np.genfromtxt(f, delimiter=",", names=True)
        xi = np.unique(s["xi"])
        ze = np.unique(s["zeta"])
        nx, nz = len(xi), len(ze)
        if nx * nz != len(s):
            continue
        nodes_f = f[:-4] + "_nodes.csv"
        nodes = np.genfromtxt(nodes_f, delimiter=",", names=True) if os.path.exists(nodes_f) else None
        fig, axs = plt.subplots(1, 2, figsize=(10, 6))
        for ax, col, cmap, title in ((axs[0], "speed", "viridis", "|u| (m/s)"),
                                     (axs[1], "omega_n", "RdBu_r", "vorticity normal to the plane (1/s)")):
            v = s[col].reshape(nz, nx)
            if col == "omega_n":
                lim = np.nanpercentile(np.abs(v), 99.5) or 1.0
                pc = ax.pcolormesh(xi, ze, v, shading="nearest", cmap=cmap, vmin=-lim, vmax=lim)
            else:
                pc = ax.pcolormesh(xi, ze, v, shading="nearest", cmap=cmap)
            fig.colorbar(pc, ax=ax, shrink=0.8)
            if nodes is not None:
                c = nodes["canopy"] > 0.5
                ax.plot(nodes["xi"][c], nodes["zeta"][c], "k.", ms=1.0)
                ax.plot(nodes["xi"][~c], nodes["zeta"][~c], ".", color="0.4", ms=1.0)
            ax.set_aspect("equal")
            ax.set_xlabel("box x (m)")
            ax.set_ylabel("box z (m), payload at 0, flight direction -z")
            ax.set_title(title, fontsize=9)
        fig.suptitle(f"mid-plane of the following box, t = {t:.3g} s")
        fig.tight_layout()
        name = os.path.join(out, f"slice_{t:06.3f}.png")
        fig.savefig(name, dpi=110)
        plt.close(fig)
        made.append(name)
    return made


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--labels", default="")
    ap.add_argument("--out", default="")
    a = ap.parse_args()
    labels = a.labels.split(",") if a.labels else [os.path.basename(os.path.normpath(r)) for r in a.runs]
    out = a.out or a.runs[0]
    runs = [load_history(r) for r in a.runs]
    plot_histories(runs, labels, out)
    if len(a.runs) == 1:
        plot_slices(a.runs[0], out)
    print(f"plot_drop.py: figures in {out}")


if __name__ == "__main__":
    main()
