"""Run-up of a slider-crank driven by a motor's torque–speed line: error against run time.

Explicit (RK45, DOP853) against implicit (Radau, BDF) integration of
``V q̈ + W q̇² = Q(q, q̇)`` by :func:`mjstruct.dynamics.time.motion_in_time`, on a mildly
stiff and a stiff run-up (the same mechanism and resistance, a steeper line), at
tolerances 1e-3 … 1e-11.  The error is the largest difference of q over the output
times against a Radau run at rtol 1e-13 (the same interpolated coefficients, so only
the integrator's error is measured).  Times are medians (benchmarks/timing.py) of the
whole call without the error estimate, the four methods run in rotation at each
tolerance; the fixed set-up (coefficient table, load
functions) is timed separately and printed.  A third, very stiff case (stiffness ratio
above 1e6) runs the explicit methods at the loosest tolerance only: their step count is
set by stability, not by the tolerance.

Run: ``python benchmarks/dynamics_run_up.py [--plot docs/img/dyn-time-error-vs-time.png]
[--run-up-plot docs/img/dyn-time-run-up.png]`` (about 4 minutes), or ``--quick`` for a
smoke run under a minute (two tolerances, one repeat, no explicit very stiff run).
"""

from __future__ import annotations

import argparse
import functools
import time
from typing import Any

import numpy as np

from mjstruct.catalog_files import example_path
from mjstruct.dynamics.data import read_dynamics
from mjstruct.dynamics.time import motion_in_time
from mjstruct.dynamics.time_terms import reduced_equation
from mjstruct.io import mechanism_from_dict, mechanism_to_dict, read_mechanism
from mjstruct.kinematics.model import KinematicModel
from timing import median_time, race

METHODS = ("RK45", "DOP853", "Radau", "BDF")
EXPLICIT = ("RK45", "DOP853")
TOLERANCES = (1e-3, 1e-5, 1e-7, 1e-9, 1e-11)
QUICK_TOLERANCES = (1e-3, 1e-7)
T_END = 3.0
FRAMES = 201
W0 = 20.0  # the motor's no-load speed, rad/s
LOG_TIMES = np.concatenate([[0.0], np.geomspace(1e-7, T_END, 500)])

#: (name, stall torque M0): the line M = M0 (1 − q̇/ω0) is steeper for a larger M0
CASES = (("mildly stiff", 8e3), ("stiff", 4e5), ("very stiff", 8e6))


def model_for(M0: float) -> KinematicModel:
    """The slider-crank of [Panasenko 2025]: motor line on the crank, viscous resistance 5 q̇ on
    the slider."""
    d = mechanism_to_dict(read_mechanism(example_path("slider-crank-seed000-dynamics")))
    d["loads"] = [
        {"link": "1", "moment": f"{M0}*(1 - qdot/{W0})"},
        {"link": "3", "force": ["-5*qdot", "0"]},
    ]
    d["parameters"] = {}
    return KinematicModel.build(mechanism_from_dict(d))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plot", help="write the log-log error-vs-time figure here")
    ap.add_argument("--run-up-plot", help="write q̇(t) of the three run-ups here")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument(
        "--quick",
        action="store_true",
        help="a smoke run (under a minute): tolerances 1e-3 and 1e-7, one repeat, "
        "the very stiff case with the implicit methods only",
    )
    args = ap.parse_args()
    tolerances = QUICK_TOLERANCES if args.quick else TOLERANCES
    repeat = 1 if args.quick else args.repeat

    motion_in_time(model_for(1.0), 0.01, estimate=False)  # imports and first calls
    rows: list[dict[str, Any]] = []
    curves: dict[str, Any] = {}
    for case, M0 in CASES:
        model = model_for(M0)
        data = read_dynamics(model.mechanism)
        t0 = time.perf_counter()
        reduced_equation(model, data, {})
        setup = time.perf_counter() - t0
        ref = motion_in_time(
            model, T_END, method="Radau", rtol=1e-13, estimate=False, frames=FRAMES
        )
        curves[case] = motion_in_time(model, T_END, method="Radau", rtol=1e-10, times=LOG_TIMES)
        print(
            f"\n{case}: M0 = {M0:g}, stiffness ratio S = {ref.stiffness_ratio:.3g}; "
            f"set-up (2048-point table, load functions) {setup * 1e3:.1f} ms; "
            f"reference Radau rtol 1e-13: {ref.steps} steps"
        )
        print(
            f"  {'method':7} {'rtol':>7} {'steps':>7} {'f evals':>8} {'time s':>8} {'error q':>9}"
        )
        for rtol in tolerances:
            methods = [
                x
                for x in METHODS
                if not (
                    case == "very stiff"
                    and x in EXPLICIT
                    and (args.quick or rtol != tolerances[0])
                )
            ]
            results: dict[str, Any] = {}

            def run(
                method: str, rtol: float = rtol, model: Any = model, results: Any = results
            ) -> Any:
                # explicit methods on the very stiff case take ~2e6 evaluations
                r = motion_in_time(
                    model,
                    T_END,
                    method=method,
                    rtol=rtol,
                    estimate=False,
                    frames=FRAMES,
                    max_evaluations=10**8,
                )
                results[method] = r
                return r

            # the methods in rotation, so that the shared machine's load hits them alike;
            # the very stiff explicit runs (tens of seconds) once each
            rotating = [x for x in methods if not (case == "very stiff" and x in EXPLICIT)]
            calls = [functools.partial(run, x) for x in rotating]
            secs = dict(zip(rotating, race(calls, repeat), strict=True))
            for x in methods:
                if x not in secs:
                    secs[x] = median_time(functools.partial(run, x), repeat=1)[0]
            for method in methods:
                r, sec = results[method], secs[method]
                err = float(np.max(np.abs(r.q - ref.q)))
                rows.append(
                    {
                        "case": case,
                        "method": method,
                        "rtol": rtol,
                        "time": sec,
                        "error": err,
                        "steps": r.steps,
                        "nfev": r.rhs_evaluations,
                    }
                )
        for method in METHODS:
            for row in rows:
                if row["case"] == case and row["method"] == method:
                    print(
                        f"  {method:7} {row['rtol']:7.0e} {row['steps']:7d} {row['nfev']:8d} "
                        f"{row['time']:8.3f} {row['error']:9.2e}"
                    )
        # ratios at the same tolerance, measured in this run
        for rtol in (1e-5, 1e-9):
            t = {x["method"]: x["time"] for x in rows if x["case"] == case and x["rtol"] == rtol}
            if "DOP853" in t:
                print(
                    f"  rtol {rtol:.0e}: time DOP853 / Radau = {t['DOP853'] / t['Radau']:.2f}, "
                    f"RK45 / Radau = {t['RK45'] / t['Radau']:.2f}, "
                    f"BDF / Radau = {t['BDF'] / t['Radau']:.2f}"
                )
    if args.plot:
        plot_errors(rows, args.plot)
    if args.run_up_plot:
        plot_run_up(curves, args.run_up_plot)


def plot_errors(rows: list[dict[str, Any]], path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    cases = [c for c, _ in CASES]
    fig, axes = plt.subplots(1, len(cases), figsize=(4.2 * len(cases), 3.8), sharey=True)
    style = {"RK45": "o--", "DOP853": "s--", "Radau": "^-", "BDF": "v-"}
    colour = {"RK45": "C0", "DOP853": "C1", "Radau": "C2", "BDF": "C3"}
    for ax, case in zip(axes, cases, strict=True):
        for method in METHODS:
            pts = [x for x in rows if x["case"] == case and x["method"] == method]
            if not pts:
                continue
            ax.loglog(
                [x["time"] for x in pts],
                [max(x["error"], 1e-16) for x in pts],
                style[method],
                color=colour[method],
                label=method,
            )
        ax.set_title(case)
        ax.set_xlabel("run time, s")
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("max |q − q_ref|, rad")
    axes[0].legend()
    fig.suptitle("Run-up of a slider-crank: error against run time (rtol 1e-3 … 1e-11)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


def plot_run_up(curves: dict[str, Any], path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 3.6))
    for case, r in curves.items():
        ax.semilogx(r.t[1:], r.qdot[1:], label=f"{case} (S = {r.stiffness_ratio:.2g})")
    ax.axhline(W0, color="k", lw=0.6, ls=":")
    ax.set_xlabel("t, s (logarithmic: the run-up is fast, the motion after it slow)")
    ax.set_ylabel("crank speed q̇, rad/s")
    ax.set_title("Run-up from rest under a motor's torque–speed line")
    ax.legend()
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
