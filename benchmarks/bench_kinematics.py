"""Speed of the kinematics plug-in, measured side by side in one run, the same work on
both sides.

* Four-bar, 3600 frames, positions + σ + κ: the user's call, a ``Mechanism`` read from
  its file afresh for every call (planning included, no cache carried between calls)
  and every table of the result read (joints, points, links, stacked), against a
  hand-written numpy closed form that computes the same positions, velocity and
  acceleration analogs and link angles.  The lazy call (tables not read), the same
  mechanism object reused, the plug-in's evaluation of a kept plan and the checks are
  printed beside it for where the time goes.
* Watt six-bar (two four-bars in series), 3600 frames: the same, against a hand-written
  numpy closed form of both stages (chain rule for the analogs).
* Class-IV mechanism, 3600 frames (Newton closure included): target < 0.2 s.
* pylinkage with numba, when importable (``pip install -e ".[bench]"``): its
  compiled sweep with velocities and accelerations (``step_fast_with_kinematics``,
  warm: its linkage object built and compiled once) on the same four-bar and Watt
  six-bar, raced beside the fresh call with every table read.

Every row of one mechanism runs in one race (rotation, CPU time of the process,
medians): the machine is shared, so only ratios measured together compare.  Goals:
the fresh call with every table read within 1.6x of the closed form and faster than
pylinkage.

Run: ``python benchmarks/bench_kinematics.py [--repeat N]``; prints medians and ratios.
"""

from __future__ import annotations

import argparse
import json
import math
import tempfile
import time
from pathlib import Path

import numpy as np

from mjstruct.catalog_files import example_path
from mjstruct.io import mechanism_to_dict, read_mechanism
from mjstruct.kinematics.evaluate import evaluate
from mjstruct.kinematics.geometry import read_geometry
from mjstruct.kinematics.model import KinematicModel
from mjstruct.kinematics.planner import plan_kinematics
from mjstruct.kinematics.solver import kinematic_analysis
from timing import race

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


def fresh_call(path: Path, read_tables: bool = True):  # type: ignore[no-untyped-def]
    """The user's call: the mechanism read from its file, analysed, every table read."""

    def call():  # type: ignore[no-untyped-def]
        r = kinematic_analysis(read_mechanism(path), frames=FRAMES)
        if read_tables:
            _read_all(r)
        return r

    return call


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=41)
    args = ap.parse_args()
    R = args.repeat
    cpu = time.process_time
    try:
        import pylinkage as pl  # the optional ``bench`` extra
    except ImportError:
        pl = None

    path = example_path("four-bar")
    m = read_mechanism(path)
    g = read_geometry(m)
    p = plan_kinematics(m, geometry=g)
    model = KinematicModel(m, g, p)
    q = g.driver_ref["O1"] + np.linspace(0, 2 * math.pi, FRAMES, endpoint=False)[:, None]
    O1, A0, B0, O2 = (complex(*m.joint(j).at) for j in ("O1", "A", "B", "O2"))
    a, b, c, d = abs(A0 - O1), abs(B0 - A0), abs(B0 - O2), abs(O2 - O1)
    mode = 1 if ((B0 - A0) * (O2 - A0).conjugate()).imag >= 0 else -1

    ref = four_bar_closed_form(q[:, 0], a, b, c, d, mode)
    jb = fresh_call(path)().joints["B"]
    Bk = (jb["x"] + 1j * jb["y"], jb["sx"] + 1j * jb["sy"], jb["kx"] + 1j * jb["ky"])
    agree = max(float(np.abs(Bk[k] - ref[k + 1]).max()) for k in range(3))
    fns = [
        lambda: four_bar_closed_form(q[:, 0], a, b, c, d, mode),
        fresh_call(path),
        fresh_call(path, read_tables=False),
        lambda: _read_all(kinematic_analysis(m, frames=FRAMES)),
        lambda: kinematic_analysis(m, frames=FRAMES),
        lambda: evaluate(model, q, order=2),
        lambda: kinematic_analysis(m, frames=FRAMES).checks,
        lambda: kinematic_analysis(m, frames=FRAMES, checks="full").checks,
    ]
    pl4 = None if pl is None else _pylinkage_four_bar(pl, m)
    if pl4 is not None:
        fns.append(pl4[0])
    # one race: the machine's load hits every variant alike
    t = race(fns, R, clock=cpu)
    t_closed = t[0]

    def row(label: str, tk: float, note: str = "") -> None:
        print(f"  {label:<50} {tk * 1e3:8.3f} ms   {tk / t_closed:5.2f}x   {note}")

    print(f"four-bar, {FRAMES} frames, positions + sigma + kappa (CPU time, median of {R})")
    row("hand-written numpy closed form", t[0])
    row("fresh mechanism from file, every table read", t[1], f"goal <= 1.60x (B: {agree:.1e})")
    row("  the same, tables not read (lazy)", t[2])
    row("  mechanism object reused, every table read", t[3])
    row("  mechanism object reused, tables not read", t[4])
    row("  plug-in evaluate(kept plan)", t[5])
    row("  reused, checks read", t[6])
    row("  reused, checks='full' (Jacobian rank/det), read", t[7])
    if pl4 is not None:
        row(f"pylinkage {pl.__version__} + numba, pos+vel+acc", t[8], f"(max |diff| {pl4[1]:.1e})")
        print(f"  fresh call, every table read / pylinkage: {t[1] / t[8]:.2f} (goal < 1)")
    else:
        print("  pylinkage: not installed (pip install -e '.[bench]'): column skipped")

    with tempfile.TemporaryDirectory() as tmp:
        wpath = Path(tmp) / "watt.json"
        wpath.write_text(json.dumps(mechanism_to_dict(watt_mechanism())))
        watt(wpath, pl, R)

    m4 = read_mechanism(example_path("class-iv-seed003"))
    t_iv, t_iv_checks = race(
        [
            lambda: kinematic_analysis(m4, frames=FRAMES, checks=False),
            lambda: kinematic_analysis(m4, frames=FRAMES),
        ],
        max(3, R // 3),
        clock=cpu,
    )
    print(f"class-IV mechanism, {FRAMES} frames, Newton closure (mechanism object reused)")
    print(f"  analysis without checks  {t_iv * 1e3:8.3f} ms   (target < 200 ms)")
    print(f"  default call             {t_iv_checks * 1e3:8.3f} ms")


def watt(path: Path, pl, R: int) -> None:  # type: ignore[no-untyped-def]
    """The Watt six-bar's race (its file at ``path``)."""
    cpu = time.process_time
    mw = read_mechanism(path)
    rw = kinematic_analysis(mw, frames=FRAMES)
    thw = rw.q[:, 0] - rw.q[0, 0]
    Dw, D1w, D2w = watt_closed_form(thw)
    jd = fresh_call(path)().joints["D"]
    agree_w = max(
        float(np.abs(jd["x"] + 1j * jd["y"] - Dw).max()),
        float(np.abs(jd["sx"] + 1j * jd["sy"] - D1w).max()),
        float(np.abs(jd["kx"] + 1j * jd["ky"] - D2w).max()),
    )
    fns = [
        lambda: watt_closed_form(thw),
        fresh_call(path),
        fresh_call(path, read_tables=False),
        lambda: _read_all(kinematic_analysis(mw, frames=FRAMES)),
        lambda: kinematic_analysis(mw, frames=FRAMES),
        lambda: kinematic_analysis(mw, frames=FRAMES, checks=False),
        lambda: kinematic_analysis(mw, frames=FRAMES, checks="full").checks,
    ]
    plw = None if pl is None else _pylinkage_watt(pl, mw)
    if plw is not None:
        fns.append(plw[0])
    t = race(fns, R, clock=cpu)
    t_closed = t[0]

    def row(label: str, tk: float, note: str = "") -> None:
        print(f"  {label:<50} {tk * 1e3:8.3f} ms   {tk / t_closed:5.2f}x   {note}")

    print(
        f"Watt six-bar, {FRAMES} frames (max |diff| of D, sigma, kappa to closed form "
        f"{agree_w:.1e})"
    )
    row("hand-written numpy closed form", t[0])
    row("Watt: fresh mechanism from file, every table read", t[1], "goal <= 1.60x")
    row("  the same, tables not read (lazy)", t[2])
    row("  mechanism object reused, every table read", t[3])
    row("  mechanism object reused, tables not read", t[4])
    row("  reused, checks off", t[5])
    row("  reused, checks='full', read", t[6])
    if plw is not None:
        row(f"pylinkage {pl.__version__} + numba, pos+vel+acc", t[7], f"(max |diff| {plw[1]:.1e})")
        print(f"  fresh call, every table read / pylinkage: {t[1] / t[7]:.2f} (goal < 1)")


def _read_all(r) -> None:  # type: ignore[no-untyped-def]
    """Every table of a result made (stacked), as the JSON object or the table reads them."""
    for table in (r.joints, r.points, r.links):
        table.stacks()


def _pylinkage_sweep(pl, linkage, crank, comps, ours):  # type: ignore[no-untyped-def]
    """pylinkage's compiled sweep with its rates, and its largest difference to ours.

    Its frames start one step after the reference, at unit input speed: ``ours`` is
    the joint table (x, y, sigma, kappa) of the same frames.
    """
    linkage.set_input_velocity(crank, omega=1.0, alpha=0.0)

    def run():  # type: ignore[no-untyped-def]
        return linkage.step_fast_with_kinematics(iterations=FRAMES, dt=1)

    pos, vel, acc = run()
    diff = 0.0
    for k, joint in comps:
        o = ours[joint]
        diff = max(
            diff,
            float(np.abs(pos[:, k, 0] - o["x"]).max()),
            float(np.abs(pos[:, k, 1] - o["y"]).max()),
            float(np.abs(vel[:, k, 0] - o["sx"]).max()),
            float(np.abs(acc[:, k, 1] - o["ky"]).max()),
        )
    return run, diff


def _shifted(mech):  # type: ignore[no-untyped-def]
    """Our joint table on pylinkage's frames (one step after the reference)."""
    km = KinematicModel.build(mech)
    q = km.q_ref[0] + 2 * math.pi / FRAMES * np.arange(1, FRAMES + 1)
    return kinematic_analysis(mech, q=q, checks=False).joints


def _pylinkage_four_bar(pl, m):  # type: ignore[no-untyped-def]
    """The four-bar in pylinkage (1.3 API): (sweep, max |difference|) or None."""
    z = {j: complex(*m.joint(j).at) for j in ("O1", "A", "B", "O2")}
    try:
        from pylinkage.actuators import Crank
        from pylinkage.components import Ground
        from pylinkage.dyads import RRRDyad
        from pylinkage.simulation import Linkage

        O1, O2 = Ground(0.0, 0.0, name="O1"), Ground(z["O2"].real, z["O2"].imag, name="O2")
        th0 = math.atan2(z["A"].imag, z["A"].real)
        crank = Crank(
            anchor=O1, radius=abs(z["A"]), angular_velocity=2 * math.pi / FRAMES, initial_angle=th0
        )
        B = RRRDyad(
            anchor1=crank.output, anchor2=O2, distance1=abs(z["B"] - z["A"]),
            distance2=abs(z["B"] - z["O2"]), x=z["B"].real, y=z["B"].imag,
        )  # fmt: skip
        linkage = Linkage([O1, O2, crank, B], order=[crank, B])
        comps = [(linkage.components.index(B), "B")]
        return _pylinkage_sweep(pl, linkage, crank, comps, _shifted(m))
    except Exception as exc:  # another API version
        print(f"pylinkage failed: {exc.__class__.__name__}: {exc}")
        return None


def _pylinkage_watt(pl, mw):  # type: ignore[no-untyped-def]
    """The Watt six-bar in pylinkage: crank, dyad B, C fixed on the rocker, dyad D."""
    z = {k: complex(*v[0]) for k, v in WATT.items()}
    try:
        from pylinkage.actuators import Crank
        from pylinkage.components import Ground
        from pylinkage.dyads import FixedDyad, RRRDyad
        from pylinkage.simulation import Linkage

        O1 = Ground(z["O1"].real, z["O1"].imag, name="O1")
        O2 = Ground(z["O2"].real, z["O2"].imag, name="O2")
        O3 = Ground(z["O3"].real, z["O3"].imag, name="O3")
        th0 = math.atan2((z["A"] - z["O1"]).imag, (z["A"] - z["O1"]).real)
        crank = Crank(
            anchor=O1, radius=abs(z["A"] - z["O1"]), angular_velocity=2 * math.pi / FRAMES,
            initial_angle=th0,
        )  # fmt: skip
        B = RRRDyad(
            anchor1=crank.output, anchor2=O2, distance1=abs(z["B"] - z["A"]),
            distance2=abs(z["B"] - z["O2"]), x=z["B"].real, y=z["B"].imag,
        )  # fmt: skip
        turn = (z["C"] - z["O2"]) / (z["B"] - z["O2"])
        C = FixedDyad(
            anchor1=O2, anchor2=B, distance=abs(z["C"] - z["O2"]),
            angle=math.atan2(turn.imag, turn.real),
        )  # fmt: skip
        D = RRRDyad(
            anchor1=C, anchor2=O3, distance1=abs(z["D"] - z["C"]),
            distance2=abs(z["D"] - z["O3"]), x=z["D"].real, y=z["D"].imag,
        )  # fmt: skip
        linkage = Linkage([O1, O2, O3, crank, B, C, D], order=[crank, B, C, D])
        comps = [(linkage.components.index(B), "B"), (linkage.components.index(D), "D")]
        return _pylinkage_sweep(pl, linkage, crank, comps, _shifted(mw))
    except Exception as exc:  # another API version
        print(f"pylinkage failed: {exc.__class__.__name__}: {exc}")
        return None


if __name__ == "__main__":
    main()
