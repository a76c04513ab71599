#!/usr/bin/env python3
"""Plot a shock_tube CSV (x,rho,u,p) against the exact Riemann solution.

    python3 scripts/plot_shock_tube.py out/sod.csv out/sod.png [--problem sod] [--t 0.2]

Without --problem, the problem is recognised from the end states of the data
(the waves of Toro's tests do not reach the ends of [0, 1] by the default times);
an unknown problem is plotted without the exact solution. Exact solution: Toro
(2009), Riemann Solvers and Numerical Methods for Fluid Dynamics, ch. 4.
"""
import argparse
import csv
import math
import os
import sys

try:
    import matplotlib
except ImportError:  # a Python without matplotlib ahead on PATH: try the system one
    if os.path.exists("/usr/bin/python3") and os.path.realpath(sys.executable) != os.path.realpath("/usr/bin/python3"):
        os.execv("/usr/bin/python3", ["/usr/bin/python3"] + sys.argv)
    raise
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

GAMMA = 1.4
X0 = 0.5
# name: (rho, u, p)_L, (rho, u, p)_R, default end time
PROBLEMS = {
    "sod": ((1.0, 0.0, 1.0), (0.125, 0.0, 0.1), 0.2),
    "lax": ((0.445, 0.698, 3.528), (0.5, 0.0, 0.571), 0.14),
    "toro2": ((1.0, -2.0, 0.4), (1.0, 2.0, 0.4), 0.15),
    "toro3": ((1.0, 0.0, 1000.0), (1.0, 0.0, 0.01), 0.012),
}


class ExactRiemann:
    """Exact solution of the 1-D Euler Riemann problem for an ideal gas."""

    def __init__(self, left, right, gamma=GAMMA):
        self.L, self.R, self.g = left, right, gamma
        self.cL = math.sqrt(gamma * left[2] / left[0])
        self.cR = math.sqrt(gamma * right[2] / right[0])
        self._solve()

    def _f(self, p, state, c):
        g = self.g
        rho, _, pk = state
        if p > pk:  # shock
            a, b = 2.0 / ((g + 1.0) * rho), (g - 1.0) / (g + 1.0) * pk
            q = math.sqrt(a / (p + b))
            return (p - pk) * q, q * (1.0 - (p - pk) / (2.0 * (b + p)))
        r = p / pk  # rarefaction
        return (2.0 * c / (g - 1.0) * (r ** ((g - 1.0) / (2.0 * g)) - 1.0),
                1.0 / (rho * c) * r ** (-(g + 1.0) / (2.0 * g)))

    def _solve(self):
        g, L, R = self.g, self.L, self.R
        du = R[1] - L[1]
        z = (g - 1.0) / (2.0 * g)
        p = ((self.cL + self.cR - 0.5 * (g - 1.0) * du) / (self.cL / L[2] ** z + self.cR / R[2] ** z)) ** (1.0 / z)
        p = max(p, 1e-12)
        for _ in range(100):
            fl, dfl = self._f(p, L, self.cL)
            fr, dfr = self._f(p, R, self.cR)
            pn = max(p - (fl + fr + du) / (dfl + dfr), 1e-14)
            done = 2.0 * abs(pn - p) / (pn + p) < 1e-14
            p = pn
            if done:
                break
        fl, _ = self._f(p, L, self.cL)
        fr, _ = self._f(p, R, self.cR)
        self.ps, self.us = p, 0.5 * (L[1] + R[1]) + 0.5 * (fr - fl)

    def sample(self, s):
        """(rho, u, p) at similarity coordinate s = (x - x0)/t."""
        g, ps, us = self.g, self.ps, self.us
        if s <= us:
            rho, u, p = self.L
            c = self.cL
            if ps > p:
                sl = u - c * math.sqrt((g + 1) / (2 * g) * ps / p + (g - 1) / (2 * g))
                if s <= sl:
                    return self.L
                return (rho * ((ps / p + (g - 1) / (g + 1)) / ((g - 1) / (g + 1) * ps / p + 1)), us, ps)
            if s <= u - c:
                return self.L
            if s > us - c * (ps / p) ** ((g - 1) / (2 * g)):
                return (rho * (ps / p) ** (1 / g), us, ps)
            f = 2 / (g + 1) + (g - 1) / ((g + 1) * c) * (u - s)
            return (rho * f ** (2 / (g - 1)), 2 / (g + 1) * (c + (g - 1) / 2 * u + s), p * f ** (2 * g / (g - 1)))
        rho, u, p = self.R
        c = self.cR
        if ps > p:
            sr = u + c * math.sqrt((g + 1) / (2 * g) * ps / p + (g - 1) / (2 * g))
            if s >= sr:
                return self.R
            return (rho * ((ps / p + (g - 1) / (g + 1)) / ((g - 1) / (g + 1) * ps / p + 1)), us, ps)
        if s >= u + c:
            return self.R
        if s < us + c * (ps / p) ** ((g - 1) / (2 * g)):
            return (rho * (ps / p) ** (1 / g), us, ps)
        f = 2 / (g + 1) - (g - 1) / ((g + 1) * c) * (u - s)
        return (rho * f ** (2 / (g - 1)), 2 / (g + 1) * (-c + (g - 1) / 2 * u + s), p * f ** (2 * g / (g - 1)))


def read_csv(path):
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))
    if not rows or set(rows[0]) != {"x", "rho", "u", "p"}:
        sys.exit(f"{path}: expected the columns x,rho,u,p")
    return {k: [float(r[k]) for r in rows] for k in ("x", "rho", "u", "p")}


def recognise(data):
    """The known problem whose end states match the data's, or None."""
    left = (data["rho"][0], data["u"][0], data["p"][0])
    right = (data["rho"][-1], data["u"][-1], data["p"][-1])
    for name, (L, R, _) in PROBLEMS.items():
        if all(math.isclose(a, b, rel_tol=1e-6, abs_tol=1e-9) for a, b in zip(left + right, L + R)):
            return name
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("csv")
    ap.add_argument("png")
    ap.add_argument("--problem", choices=sorted(PROBLEMS), help="Riemann problem (default: recognised)")
    ap.add_argument("--t", type=float, help="time of the data (default: the problem's end time)")
    args = ap.parse_args()

    data = read_csv(args.csv)
    name = args.problem or recognise(data)
    fig, axes = plt.subplots(1, 3, figsize=(13, 4), constrained_layout=True)
    labels = {"rho": "density ρ", "u": "velocity u", "p": "pressure p"}
    if name:
        L, R, t_default = PROBLEMS[name]
        t = args.t if args.t is not None else t_default
        ex = ExactRiemann(L, R)
        n = 2000
        xs = [i / (n - 1) for i in range(n)]
        sol = [ex.sample((x - X0) / t) if t > 0 else (L if x < X0 else R) for x in xs]
    for ax, key, k in zip(axes, ("rho", "u", "p"), range(3)):
        if name:
            ax.plot(xs, [s[k] for s in sol], "k-", lw=1.0, label="exact")
        ax.plot(data["x"], data[key], "o", ms=2.5, mfc="none", color="tab:blue", label="parafsi")
        ax.set_xlabel("x")
        ax.set_title(labels[key])
        ax.grid(alpha=0.3)
    axes[0].legend()
    title = os.path.basename(args.csv)
    if name:
        title += f" — {name}, t = {t:g}, {len(data['x'])} cells"
    fig.suptitle(title)
    fig.savefig(args.png, dpi=120)
    print(f"wrote {args.png}")


if __name__ == "__main__":
    main()
