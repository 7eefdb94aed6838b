"""Error against run time of the kinematics plug-in: one table, one log-log plot.

1. Iterative closure (the class-IV mechanism of [Zinchenko], 3600 frames): Newton
   tolerance -> achieved closure error (max | |DE| - l_DE |, metres) and time.
2. Frame counts 36 ... 36 000 (the slider-crank of [Slider-crank Mathcad], closed form
   known): time of the analysis, error of the exact analog velocities and of central
   finite differences of the positions, both against the closed form (m/s,
   ω = 0.5 rad/s); and for [Zinchenko] (no closed form) the gap between analogs and
   finite differences.

The keys in brackets are those of docs/references.md.

Run: ``python benchmarks/error_vs_time.py [--plot docs/img/kin-error-vs-time.png]``.
"""

from __future__ import annotations

import argparse

import numpy as np

from mjstruct.catalog_files import example_path
from mjstruct.io import read_mechanism
from mjstruct.kinematics.solver import kinematic_analysis
from timing import median_time


def slider_exact(th: np.ndarray, w: float) -> tuple[np.ndarray, np.ndarray]:
    L1, L2 = 0.1, 0.35
    g = L2**2 - (L1 * np.sin(th)) ** 2
    x = L1 * np.cos(th) + np.sqrt(g)
    v = (-L1 * np.sin(th) - L1**2 * np.sin(2 * th) / (2 * np.sqrt(g))) * w
    return x, v


def fd_velocity(x: np.ndarray, dt: float) -> np.ndarray:
    """Central differences over a closed cycle (periodic)."""
    return (np.roll(x, -1) - np.roll(x, 1)) / (2 * dt)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plot", help="write the log-log plot (PNG) here")
    args = ap.parse_args()

    rows = []
    # 1. closure tolerance -> achieved error and time
    m4 = read_mechanism(example_path("class-iv-seed003"))
    print("closure ([Zinchenko] class IV, 3600 frames): tolerance -> achieved error, time")
    print(f"{'tol':>8} {'error |DE|-l (m)':>18} {'iterations':>10} {'time (s)':>9}")
    clos = []
    for tol in (1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12, 1e-14):
        t, r = median_time(
            lambda tol=tol: kinematic_analysis(m4, frames=3600, tol=tol, checks=False), 3
        )
        D = r.joints["D"]["x"] + 1j * r.joints["D"]["y"]
        E = r.joints["E"]["x"] + 1j * r.joints["E"]["y"]
        err = float(np.nanmax(np.abs(np.abs(E - D) - 0.554)))
        ok = int(r.valid.sum())
        print(f"{tol:8.0e} {err:18.3e} {r.closure.iterations:10d} {t:9.4f}  ({ok} frames)")
        clos.append((t, err))
        rows.append(("closure", tol, t, err))

    # 2. frame counts: analogs vs finite differences
    m1 = read_mechanism(example_path("slider-crank"))
    w = 0.5
    print(
        "\nslider-crank ([Slider-crank Mathcad]): frames -> time, "
        "velocity error vs closed form (m/s)"
    )
    print(
        f"{'frames':>7} {'time (s)':>9} {'analog err':>11} {'FD err':>11} "
        f"{'[Zinchenko] FD-analog':>22}"
    )
    ana, fdp = [], []
    for n in (36, 360, 3600, 36000):
        t, r = median_time(lambda n=n: kinematic_analysis(m1, frames=n, speed=w, checks=False), 3)
        th = r.q[:, 0]
        _, v = slider_exact(th, w)
        e_an = float(np.abs(r.joints["B"]["vx"] - v).max())
        dt = (2 * np.pi / n) / w
        e_fd = float(np.abs(fd_velocity(r.joints["B"]["x"], dt) - v).max())
        r4 = kinematic_analysis(m4, frames=n, checks=False)
        gap = 0.0
        dt4 = 2 * np.pi / n
        for j in ("B", "E"):
            X = r4.joints[j]["x"] + 1j * r4.joints[j]["y"]
            V = r4.joints[j]["vx"] + 1j * r4.joints[j]["vy"]
            gap = max(gap, float(np.abs(fd_velocity(X, dt4) - V).max()))
        print(f"{n:7d} {t:9.4f} {e_an:11.2e} {e_fd:11.2e} {gap:22.2e}")
        ana.append((t, max(e_an, 1e-17)))
        fdp.append((t, e_fd))
        rows.append(("frames", n, t, e_an, e_fd, gap))

    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6.4, 4.4))
        ct, ce = zip(*clos, strict=True)
        ax.loglog(ct, ce, "o-", label="[Zinchenko] closure: Newton tol 1e-2 … 1e-14")
        at, ae = zip(*ana, strict=True)
        ax.loglog(
            at, ae, "s-", label="[Slider-crank Mathcad] analog velocity (exact) vs closed form"
        )
        ft, fe = zip(*fdp, strict=True)
        ax.loglog(ft, fe, "^-", label="[Slider-crank Mathcad] finite differences vs closed form")
        for (t, e), n in zip(fdp, (36, 360, 3600, 36000), strict=True):
            ax.annotate(f"{n}", (t, e), textcoords="offset points", xytext=(4, 4), fontsize=8)
        ax.set_xlabel("run time (s)")
        ax.set_ylabel("error (m or m/s)")
        ax.set_title("kinematics plug-in: error against run time")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(args.plot, dpi=110)
        print(f"\nplot written to {args.plot}")


if __name__ == "__main__":
    main()
