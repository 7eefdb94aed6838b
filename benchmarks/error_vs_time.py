"""Error against run time of the kinematics plug-in: one table, one log-log plot.

1. Iterative closure (the class-IV mechanism of [Zinchenko], 3600 frames): Newton
   tolerance -> the true position error (every joint centre, metres) against an
   independent reference (``tests/high_precision.py``: every joint's constraints at
   once solved in 60 digits, no plan) on 12 frames spread over the turn, the
   kinematics' own estimate there (``r.error.position``), the closure residual
   (max | |DE| - l_DE |, metres: smaller than the true error, which the residual
   leaves out: it grows by the conditioning), and the time.
2. Frame counts 36 ... 36 000 (the slider-crank of [Slider-crank Mathcad], closed form
   known): time of the analysis, error of the exact analog velocities and of central
   finite differences of the positions, both against the closed form (m/s,
   ω = 0.5 rad/s); and for [Zinchenko] the true error of the analog velocities against
   the independent reference (on 6 frames) and the gap between analogs and finite
   differences.

The keys in brackets are those of docs/references.md.

Run: ``python benchmarks/error_vs_time.py [--plot docs/img/kin-error-vs-time.png]``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from mjstruct.catalog_files import example_path
from mjstruct.io import read_mechanism
from mjstruct.kinematics.solver import kinematic_analysis
from timing import median_time

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from high_precision import Reference

#: frames of a sweep checked against the independent reference
SAMPLE = 12


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
    ref4 = Reference(m4)
    print(
        "closure ([Zinchenko] class IV, 3600 frames): tolerance -> true position error "
        f"against the independent reference ({SAMPLE} frames), its estimate, residual, time"
    )
    print(
        f"{'tol':>8} {'true error (m)':>15} {'estimate (m)':>13} {'residual (m)':>13} "
        f"{'iterations':>10} {'time (s)':>9}"
    )
    clos = []
    truth: dict[int, dict[str, complex]] = {}
    for tol in (1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12, 1e-14):
        t, r = median_time(
            lambda tol=tol: kinematic_analysis(m4, frames=3600, tol=tol, checks=False), 3
        )
        D = r.joints["D"]["x"] + 1j * r.joints["D"]["y"]
        E = r.joints["E"]["x"] + 1j * r.joints["E"]["y"]
        residual = float(np.nanmax(np.abs(np.abs(E - D) - 0.554)))
        true, est = 0.0, 0.0
        for i in range(0, 3600, 3600 // SAMPLE):
            if i not in truth:
                truth[i] = ref4.positions(float(r.q[i, 0]))
            z = truth[i]
            got = {j: complex(r.joints[j]["x"][i], r.joints[j]["y"][i]) for j in z}
            true = max(true, max(abs(got[j] - z[j]) for j in z))
            assert r.error is not None
            est = max(est, float(r.error.position[i]))
        print(
            f"{tol:8.0e} {true:15.3e} {est:13.3e} {residual:13.3e} "
            f"{r.closure.iterations:10d} {t:9.4f}"
        )
        clos.append((t, true))
        rows.append(("closure", tol, t, true, est, residual))

    # 2. frame counts: analogs vs finite differences
    m1 = read_mechanism(example_path("slider-crank"))
    w = 0.5
    print(
        "\nslider-crank ([Slider-crank Mathcad]): frames -> time, "
        "velocity error vs closed form (m/s)"
    )
    print(
        f"{'frames':>7} {'time (s)':>9} {'analog err':>11} {'FD err':>11} "
        f"{'[Zinchenko] analog err':>23} {'[Zinchenko] FD-analog':>22}"
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
        e4 = 0.0  # the analog velocities against the independent reference
        for i in range(0, n, max(n // 6, 1)):
            _, sig, _ = ref4.analogs(float(r4.q[i, 0]))
            e4 = max(
                e4,
                max(
                    abs(complex(r4.joints[j]["sx"][i], r4.joints[j]["sy"][i]) - s)
                    for j, s in sig.items()
                ),
            )
        print(f"{n:7d} {t:9.4f} {e_an:11.2e} {e_fd:11.2e} {e4:23.2e} {gap:22.2e}")
        ana.append((t, max(e_an, 1e-17)))
        fdp.append((t, e_fd))
        rows.append(("frames", n, t, e_an, e_fd, e4, gap))

    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6.4, 4.4))
        ct, ce = zip(*clos, strict=True)
        ax.loglog(ct, ce, "o-", label="[Zinchenko] true position error: Newton tol 1e-2 … 1e-14")
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
