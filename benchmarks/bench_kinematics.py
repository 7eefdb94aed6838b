"""Speed of the kinematics plug-in, measured side by side in one run.

* Four-bar, 3600 frames, positions + σ + κ: the plug-in (its evaluation of the plan,
  and the whole ``kinematic_analysis()`` call with planning and branch tracking) against a
  hand-written numpy closed form of the same four-bar.
* Watt six-bar (two four-bars in series), 3600 frames: the default call against a
  hand-written numpy closed form of both stages (chain rule for the analogs).
* Class-IV mechanism, 3600 frames (Newton closure included): target < 0.2 s.
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


WATT = {
    "O1": ((0.0, 0.0), ["0", "1"]),
    "A": ((0.3, 0.4), ["1", "2"]),
    "B": ((1.2, 0.9), ["2", "3"]),
    "O2": ((1.0, 0.0), ["0", "3"]),
    "C": ((1.6, 0.5), ["3", "5"]),
    "D": ((2.3, 0.8), ["5", "4"]),
    "O3": ((2.2, -0.2), ["0", "4"]),
}


def watt_mechanism():  # type: ignore[no-untyped-def]
    from mjstruct.io import mechanism_from_dict

    joints = [{"id": k, "links": v[1], "at": list(v[0])} for k, v in WATT.items()]
    return mechanism_from_dict({"frame": "0", "drivers": ["O1"], "joints": joints})


def _mode(P1: complex, P2: complex, X: complex) -> int:
    return 1 if ((X - P1) * (P2 - P1).conjugate()).imag >= 0 else -1


def watt_closed_form(th: np.ndarray):  # type: ignore[no-untyped-def]
    """Hand-written numpy: D of the Watt six-bar with its analogs (two stages)."""
    z = {k: complex(*v[0]) for k, v in WATT.items()}
    a, b = abs(z["A"] - z["O1"]), abs(z["B"] - z["A"])
    c, d = abs(z["B"] - z["O2"]), abs(z["O2"] - z["O1"])
    m1 = _mode(z["A"], z["O2"], z["B"])
    th0 = np.angle(z["A"] - z["O1"])
    # stage 1 (ground O1 -> O2 along x): rocker angle th4 and its analogs
    _, _, _, _, _, th4, _, w4, _, e4 = four_bar_closed_form(th0 + th, a, b, c, d, m1)
    # stage 2 in the frame of its ground O2 -> O3: input = the rocker's C
    g = z["O3"] - z["O2"]
    rot = g / abs(g)
    c0 = (z["C"] - z["O2"]) / rot
    b0 = z["B"] - z["O2"]
    phi = np.angle(c0) + (th4 - np.angle(b0))  # C turns with the rocker
    a2, b2 = abs(z["C"] - z["O2"]), abs(z["D"] - z["C"])
    c2, d2 = abs(z["D"] - z["O3"]), abs(g)
    m2 = _mode((z["C"] - z["O2"]) / rot, d2 + 0j, (z["D"] - z["O2"]) / rot)
    _, D, dD, ddD, *_ = four_bar_closed_form(phi, a2, b2, c2, d2, m2)
    # chain rule: phi' = w4, phi'' = e4
    D1 = dD * w4
    D2 = ddD * w4 * w4 + dD * e4
    return z["O2"] + rot * D, rot * D1, rot * D2


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=41)
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

    # one race: the machine's load hits every variant alike
    t_closed, t_eval, t_sweep, t_full, t_default, t_read = race(
        [
            lambda: four_bar_closed_form(q[:, 0], a, b, c, d, mode),
            lambda: evaluate(model, q, order=2),
            lambda: kinematic_analysis(model, frames=FRAMES, checks=False),
            lambda: kinematic_analysis(m, frames=FRAMES, checks=False),
            lambda: kinematic_analysis(m, frames=FRAMES),
            lambda: kinematic_analysis(m, frames=FRAMES).checks,
        ],
        R,
    )

    mw = watt_mechanism()
    rw = kinematic_analysis(mw, frames=FRAMES)
    thw = rw.q[:, 0] - rw.q[0, 0]
    Dw, D1w, D2w = watt_closed_form(thw)
    jd = rw.joints["D"]
    agree_w = max(
        float(np.abs(jd["x"] + 1j * jd["y"] - Dw).max()),
        float(np.abs(jd["sx"] + 1j * jd["sy"] - D1w).max()),
        float(np.abs(jd["kx"] + 1j * jd["ky"] - D2w).max()),
    )
    t_wclosed, t_wdefault, t_wfast, t_wread = race(
        [
            lambda: watt_closed_form(thw),
            lambda: kinematic_analysis(mw, frames=FRAMES),
            lambda: kinematic_analysis(mw, frames=FRAMES, checks=False),
            lambda: kinematic_analysis(mw, frames=FRAMES).checks,
        ],
        R,
    )

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
        f"  default call (checks on)                  {t_default * 1e3:8.3f} ms   "
        f"{t_default / t_closed:5.2f}x   (target within 3x)"
    )
    print(
        f"  default call, every check read            {t_read * 1e3:8.3f} ms   "
        f"{t_read / t_closed:5.2f}x   (link lengths, analogs computed on reading)"
    )
    print(
        f"Watt six-bar, {FRAMES} frames (max |diff| of D, sigma, kappa to closed form "
        f"{agree_w:.1e})"
    )
    print(f"  hand-written numpy closed form       {t_wclosed * 1e3:8.3f} ms   1.00x")
    print(
        f"  default call (checks on)             {t_wdefault * 1e3:8.3f} ms   "
        f"{t_wdefault / t_wclosed:5.2f}x"
    )
    print(
        f"  checks off                           {t_wfast * 1e3:8.3f} ms   "
        f"{t_wfast / t_wclosed:5.2f}x"
    )
    print(
        f"  default call, every check read       {t_wread * 1e3:8.3f} ms   "
        f"{t_wread / t_wclosed:5.2f}x"
    )
    print(f"class-IV mechanism, {FRAMES} frames, Newton closure")
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
