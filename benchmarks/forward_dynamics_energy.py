"""Forward dynamics of several drivers: energy error against run time, explicit against implicit.

Two tables, both from :func:`mjstruct.dynamics.forward.forward_dynamics` (Lagrange's
equations ``M(q) q̈ + h = Q`` with the force elements):

1. **Energy error against run time.**  The five-bar with springs
   (``catalogs/examples/five-bar-springs-dynamics.json``, two free drivers, gravity, two
   line springs and a torsion spring, no damper) swings for 1 s from rest; its energy
   T + U must stay constant.  At each tolerance, DOP853 and Radau: CPU time of the
   call (no error estimate, no reactions), right-hand-side evaluations, the largest
   relative change of the energy over 201 output times, and the largest difference of
   q against a DOP853 run at rtol 1e-12.
2. **Explicit against implicit on a stiff chain.**  The prosthesis-like leg
   (``prosthesis-leg-dynamics.json``) with unit masses and both elastic slides of
   stiffness C, without and with slide dampers (rate 5000: the slides' fast mode then
   decays instead of vibrating), 0.2 s at rtol 1e-3 and 1e-6: CPU time and evaluations
   of DOP853 and Radau side by side, the stiffness ratio ``ρ · t_end`` and what
   ``auto`` chooses (:func:`~mjstruct.dynamics.forward.auto_method`).

Run: ``python benchmarks/forward_dynamics_energy.py [--plot
docs/img/dyn-forward-energy.png]`` (about 3 minutes on a quiet machine) or ``--quick``
(two tolerances, two stiffnesses).
"""

from __future__ import annotations

import argparse
import copy
import time
from typing import Any

import numpy as np

from mjstruct.catalog_files import example_path
from mjstruct.dynamics.data import read_dynamics
from mjstruct.dynamics.forward import auto_method, forward_dynamics
from mjstruct.io import mechanism_from_dict, mechanism_to_dict, read_mechanism

TOLERANCES = (1e-4, 1e-6, 1e-8, 1e-10)
STIFFNESSES = (1e4, 1e5, 1e6, 1e7)
DAMPERS = (0.0, 5000.0)
STIFF_TOLERANCES = (1e-3, 1e-6)


def cpu(fn: Any) -> tuple[float, Any]:
    t0 = time.process_time()
    out = fn()
    return time.process_time() - t0, out


def energy_table(tolerances: tuple[float, ...]) -> dict[str, list[tuple[float, float]]]:
    """Print the table; per method the (CPU s, energy error) points."""
    m = read_mechanism(example_path("five-bar-springs-dynamics"))
    kw: dict[str, Any] = {"frames": 201, "estimate": False, "reactions": False}
    ref = forward_dynamics(m, 1.0, rtol=1e-12, method="DOP853", **kw)  # also the warm-up
    print("five-bar with springs, 1 s from rest, no damper: energy error against run time")
    print(
        f"{'rtol':>8} {'method':>7} {'CPU s':>7} {'rhs':>6} {'energy error':>13} {'q error':>10}"
    )
    points: dict[str, list[tuple[float, float]]] = {"DOP853": [], "Radau": []}
    for rtol in tolerances:
        for method in ("DOP853", "Radau"):
            t, r = cpu(lambda: forward_dynamics(m, 1.0, rtol=rtol, method=method, **kw))  # noqa: B023
            E = r.kinetic + r.potential
            err_E = float(np.abs(E - E[0]).max() / np.abs(r.kinetic).max())
            err_q = float(np.abs(r.q - ref.q).max())
            print(
                f"{rtol:8.0e} {method:>7} {t:7.2f} {r.rhs_evaluations:6d} {err_E:13.2e} "
                f"{err_q:10.2e}"
            )
            points[method].append((t, err_E))
    return points


def plot(points: dict[str, list[tuple[float, float]]], path: str) -> None:
    """The energy error against CPU time, one line per method."""
    import matplotlib
    import matplotlib.ticker

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5.5, 3.6))
    for method, pts in points.items():
        ax.loglog([p[0] for p in pts], [p[1] for p in pts], "o-", label=method)
    ax.set_xlabel("CPU time of the call, s")
    ax.set_ylabel("largest relative energy change")
    ax.set_title("five-bar with springs, 1 s of free motion")
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def leg(C: float, rate: float) -> Any:
    d = mechanism_to_dict(read_mechanism(example_path("prosthesis-leg-dynamics")))
    d = copy.deepcopy(d)
    for link in d["inertia"].values():
        link.update(mass=1.0, J=0.01)
    d["elements"][0]["stiffness"] = d["elements"][1]["stiffness"] = C
    if rate:
        d["elements"] += [
            {"type": "slide_damper", "joint": "S1", "rate": rate},
            {"type": "slide_damper", "joint": "S2", "rate": rate},
        ]
    return mechanism_from_dict(d)


def chosen(r: Any, rtol: float) -> str:
    """What ``auto`` chooses for the run ``r`` at ``rtol``."""
    t = float(r.t[-1])
    return auto_method(r.decay_rate * t, r.vibration_rate * t, r.vibration_rate, rtol)[0]


def stiff_table(stiffnesses: tuple[float, ...]) -> None:
    print()
    print("leg with unit masses, elastic slides of stiffness C, 0.2 s")
    print(
        f"{'C':>8} {'damper':>6} {'rtol':>6} {'ratio':>8} {'auto':>7} {'DOP853 s':>9} "
        f"{'rhs':>6} {'Radau s':>8} {'rhs':>6} {'Radau/DOP853':>12} {'|dq|':>8}"
    )
    for C in stiffnesses:
        for rate in DAMPERS:
            for rtol in STIFF_TOLERANCES:
                m = leg(C, rate)
                read_dynamics(m)  # the laws compiled before the clocks start
                kw: dict[str, Any] = {
                    "frames": 5,
                    "estimate": False,
                    "reactions": False,
                    "rtol": rtol,
                }
                te, re = cpu(lambda: forward_dynamics(m, 0.2, method="DOP853", **kw))  # noqa: B023
                ti, ri = cpu(lambda: forward_dynamics(m, 0.2, method="Radau", **kw))  # noqa: B023
                print(
                    f"{C:8.0e} {rate:6g} {rtol:6.0e} {re.stiffness_ratio:8.3g} "
                    f"{chosen(re, rtol):>7} {te:9.2f} {re.rhs_evaluations:6d} {ti:8.2f} "
                    f"{ri.rhs_evaluations:6d} {ti / te:12.2f} {np.abs(re.q - ri.q).max():8.1e}"
                )


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="two tolerances, two stiffnesses")
    p.add_argument("--plot", metavar="PNG", help="draw the energy error against run time")
    args = p.parse_args()
    points = energy_table((1e-4, 1e-8) if args.quick else TOLERANCES)
    if args.plot:
        plot(points, args.plot)
    stiff_table((1e4, 1e6) if args.quick else STIFFNESSES)


if __name__ == "__main__":
    main()
