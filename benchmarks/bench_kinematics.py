"""Speed of the kinematics plug-in, measured side by side in one run.

* Four-bar, 3600 frames, positions + σ + κ: the plug-in (its evaluation of the plan,
  and the whole ``kinematic_analysis()`` call with planning and branch tracking) against a
  hand-written numpy closed form of the same four-bar.
* Seed 003 class-IV mechanism, 3600 frames (Newton closure included): target < 0.2 s.
* pylinkage, when importable (installed only in a benchmark environment): the same
  four-bar sweep, positions only (what it computes).

Run: ``python benchmarks/bench_kinematics.py [--repeat N]``; prints medians and ratios.
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from mjstruct.catalog_files import example_path
from mjstruct.io import read_mechanism
from mjstruct.kinematics.evaluate import evaluate
from mjstruct.kinematics.geometry import read_geometry
from mjstruct.kinematics.model import KinematicModel
from mjstruct.kinematics.planner import plan_kinematics
from mjstruct.kinematics.solver import kinematic_analysis
from timing import median_time, race

FRAMES = 3600


def four_bar_closed_form(th: np.ndarray, a: float, b: float, c: float, d: float, mode: int):
    """Hand-written numpy: A, B, coupler/rocker angles and their analogs σ, κ."""
    A = a * np.exp(1j * th)
    dA = 1j * A
    ddA = -A
    e = d - A  # from A to O2
    D2 = (e * e.conjugate()).real
    D = np.sqrt(D2)
    al = (D2 + b * b - c * c) / (2 * D)
    h = np.sqrt(b * b - al * al)
    B = A + (al + 1j * mode * h) * e / D
    th3 = np.angle(B - A)
    th4 = np.angle(B - d)
    s43 = np.sin(th4 - th3)
    w3 = a * np.sin(th - th4) / (b * s43)
    w4 = a * np.sin(th - th3) / (c * s43)
    rhs = a * np.exp(1j * th) + b * w3**2 * np.exp(1j * th3) - c * w4**2 * np.exp(1j * th4)
    g1 = 1j * b * np.exp(1j * th3)
    g2 = -1j * c * np.exp(1j * th4)
    det = g1.real * g2.imag - g1.imag * g2.real
    e3 = (rhs.real * g2.imag - rhs.imag * g2.real) / det
    e4 = (g1.real * rhs.imag - g1.imag * rhs.real) / det
    dB = dA + 1j * w3 * (B - A)
    ddB = ddA + (1j * e3 - w3**2) * (B - A)
    return A, B, dB, ddB, th3, th4, w3, w4, e3, e4


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=21)
    args = ap.parse_args()
    R = args.repeat

    m = read_mechanism(example_path("four-bar"))
    g = read_geometry(m)
    p = plan_kinematics(m, geometry=g)
    model = KinematicModel(m, g, p)
    q = g.driver_ref["O1"] + np.linspace(0, 2 * math.pi, FRAMES, endpoint=False)[:, None]
    O1, A0, B0, O2 = (complex(*m.joint(j).at) for j in ("O1", "A", "B", "O2"))
    a, b, c, d = abs(A0 - O1), abs(B0 - A0), abs(B0 - O2), abs(O2 - O1)
    mode = 1 if ((B0 - A0) * (O2 - A0).conjugate()).imag >= 0 else -1

    ev = evaluate(model, q, order=2)
    ref = four_bar_closed_form(q[:, 0], a, b, c, d, mode)
    Bk = ev.centre("B")
    agree = max(
        float(np.abs(Bk[0] - ref[1]).max()),
        float(np.abs(Bk[1] - ref[2]).max()),
        float(np.abs(Bk[2] - ref[3]).max()),
    )

    t_closed, t_eval, t_sweep, t_full = race(
        [
            lambda: four_bar_closed_form(q[:, 0], a, b, c, d, mode),
            lambda: evaluate(model, q, order=2),
            lambda: kinematic_analysis(model, frames=FRAMES, checks=False),
            lambda: kinematic_analysis(m, frames=FRAMES, checks=False),
        ],
        R,
    )
    t_checks = median_time(lambda: kinematic_analysis(m, frames=FRAMES), max(3, R // 3))[0]

    m4 = read_mechanism(example_path("class-iv-seed003"))
    t_iv = median_time(
        lambda: kinematic_analysis(m4, frames=FRAMES, checks=False), max(3, R // 3)
    )[0]
    t_iv_checks = median_time(lambda: kinematic_analysis(m4, frames=FRAMES), max(3, R // 3))[0]

    print(f"four-bar, {FRAMES} frames, positions + sigma + kappa (median of {R})")
    print(f"  hand-written numpy closed form       {t_closed * 1e3:8.3f} ms   1.00x")
    print(
        f"  plug-in evaluate(plan)                {t_eval * 1e3:8.3f} ms   "
        f"{t_eval / t_closed:5.2f}x   (max |diff| to closed form {agree:.1e})"
    )
    print(
        f"  plug-in analysis, model reused (branches) {t_sweep * 1e3:8.3f} ms   "
        f"{t_sweep / t_closed:5.2f}x"
    )
    print(
        f"  plug-in analysis (plan+branches)          {t_full * 1e3:8.3f} ms   "
        f"{t_full / t_closed:5.2f}x"
    )
    print(
        f"  analysis with checks (Jacobian)           {t_checks * 1e3:8.3f} ms   "
        f"{t_checks / t_closed:5.2f}x"
    )
    print(f"seed 003 class-IV mechanism, {FRAMES} frames, Newton closure")
    print(f"  analysis without checks  {t_iv * 1e3:8.3f} ms   (target < 200 ms)")
    print(f"  analysis with checks            {t_iv_checks * 1e3:8.3f} ms")

    try:
        import pylinkage as pl  # only in a benchmark environment
    except ImportError:
        print("pylinkage: not installed here (pip install pylinkage in a benchmark venv)")
        return
    got = _pylinkage_four_bar(pl, a, b, c, d, A0, B0, R)
    if got is None:
        print(f"pylinkage {getattr(pl, '__version__', '?')}: API not recognised, not timed")
        return
    t_pl, diff = got
    t_pos = median_time(lambda: evaluate(model, q, order=0), R)[0]
    print(
        f"pylinkage {getattr(pl, '__version__', '?')}, same four-bar, positions only "
        f"(max |B - ours| {diff:.1e})"
    )
    print(f"  pylinkage Linkage.step() x {FRAMES}      {t_pl * 1e3:8.3f} ms")
    print(
        f"  plug-in evaluate(order=0)             {t_pos * 1e3:8.3f} ms   "
        f"pylinkage / plug-in = {t_pl / t_pos:.1f}"
    )


def _pylinkage_four_bar(pl, a, b, c, d, A0, B0, R) -> tuple[float, float] | None:
    """Time pylinkage (1.3 API) on the same sweep; (time, max |B - ours|) or None."""
    th0 = math.atan2(A0.imag, A0.real)
    try:
        O1, O2 = pl.Ground(0.0, 0.0, name="O1"), pl.Ground(d, 0.0, name="O2")
        crank = pl.Crank(
            anchor=O1, radius=a, angular_velocity=2 * math.pi / FRAMES, initial_angle=th0
        )
        dyad = pl.RRRDyad(
            anchor1=crank.output, anchor2=O2, distance1=b, distance2=c, x=B0.real, y=B0.imag
        )
        linkage = pl.Linkage([O1, O2, crank, dyad], order=[crank, dyad])

        def run() -> list:
            return list(linkage.step(iterations=FRAMES, dt=1))

        pts = run()
    except Exception as exc:  # another API version
        print(f"pylinkage failed: {exc.__class__.__name__}: {exc}")
        return None
    if len(pts) != FRAMES:
        return None
    # its frames start one step after the reference; compare B with ours on that sweep
    xs = np.array([complex(*fr[-1]) for fr in pts])
    return median_time(run, max(3, R // 3))[0], float(np.abs(xs - _our_B(a, b, c, d, th0)).max())


def _our_B(a, b, c, d, th0) -> np.ndarray:
    m = read_mechanism(example_path("four-bar"))
    q = th0 + 2 * math.pi / FRAMES * np.arange(1, FRAMES + 1)
    r = kinematic_analysis(m, q=q, checks=False)
    return r.joints["B"]["x"] + 1j * r.joints["B"]["y"]


if __name__ == "__main__":
    main()
