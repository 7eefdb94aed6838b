"""Class-IV closure: the plug-in's batched closure against a hand-written batched Newton.

The mechanism is the class-IV example (crank O-A; ternary link 2 with A, C, D; link 3
C-B; ternary link 5 with B, E and the ground pivot F; link 4 is the closure length
D-E).  The hand-written solver, written here from the geometry alone, takes the
absolute rotation ψ of link 2 as the unknown: C and D turn with it about A; B is the
intersection of the circles about C and F (the assembly mode of the file); E turns
with link 5 about F; the closure equation is g = |D - E|² - |DE|² = 0, its derivative
dg/dψ analytic (the velocity of B from the two circle conditions).  It continues on
Python complex numbers over a few stations along the path from the reference, then
runs one numpy Newton over all frames from the linearly interpolated stations, and
gives ψ' = -g_q / g_ψ.  The plug-in's :func:`~mjstruct.kinematics.closure.close`
gives the same unknown (the rotation of link 2 from the reference) with t' and t''.

Both are timed side by side in one run (``timing.race``), on a full turn of the crank
and on a rocking input (from the reference back to -1 rad, then to +1 rad: the path
turns once); the agreement of ψ with the plug-in's unknown is printed, and the number
of ``evaluate()`` calls of the plug-in.  Then the default kinematics call on the
example as a user makes it (the mechanism read from its file for each call, then
``kinematic_analysis(mechanism, frames=N)``: planning, closure, evaluation, branches,
result, every table read) and its parts are raced against the same hand-written Newton
(which reads its geometry from the same file for each call).

The default call's goal: within :data:`GOAL` (2x) of the hand-written Newton; each race
prints its ratio against it with PASS or FAIL and the machine's load average, and
``--runs N`` races it N times (a goal holds when it holds in every run).

Run: ``python benchmarks/bench_closure.py [--frames N] [--repeat N] [--cpu]
[--only-default] [--runs N]`` (``--cpu``: CPU time of the process, which the other jobs
of a loaded machine disturb less than wall time).
"""

from __future__ import annotations

import argparse
import cmath
import json
import math
import os
import time
from collections.abc import Callable
from typing import Any

import numpy as np
import numpy.typing as npt

from mjstruct.catalog_files import example_path
from mjstruct.io import read_mechanism
from mjstruct.kinematics import closure, closure_newton
from mjstruct.kinematics.model import KinematicModel
from mjstruct.kinematics.solver import kinematic_analysis
from timing import race

Arr = npt.NDArray[np.float64]

#: the default call on the class-IV example, within this factor of the hand-written
#: batched Newton (CPU or wall time, medians, raced side by side)
GOAL = 2.0


def _cross(a: Any, b: Any) -> Any:
    return (a.conjugate() * b).imag


def _dot(a: Any, b: Any) -> Any:
    return (a.conjugate() * b).real


class ClassIV:
    """Closed formulas of the class-IV example, read from its file's reference points."""

    def __init__(self) -> None:
        with open(example_path("class-iv-seed003")) as fh:
            pts = {j["id"]: complex(*j["at"]) for j in json.load(fh)["joints"]}
        self.O, self.F = pts["O"], pts["F"]
        self.A0, self.C0, self.D0 = pts["A"], pts["C"], pts["D"]
        self.B0, self.E0 = pts["B"], pts["E"]
        self.rC, self.rF = abs(self.B0 - self.C0), abs(self.B0 - self.F)
        self.L2 = abs(self.E0 - self.D0) ** 2
        self.mode = math.copysign(1.0, _cross(self.F - self.C0, self.B0 - self.C0))
        self.ua = (self.A0 - self.O) / abs(self.A0 - self.O)

    def residual(self, q: Any, psi: Any) -> tuple[Any, Any, Any]:
        """g, dg/dψ and dg/dq (complex arithmetic: works on floats and on arrays)."""
        np_ = np if isinstance(q, np.ndarray) else cmath
        A = self.O + (self.A0 - self.O) * np_.exp(1j * q)
        rot = np_.exp(1j * psi)
        C = A + rot * (self.C0 - self.A0)
        D = A + rot * (self.D0 - self.A0)
        # B on the circles about C (radius rC) and F (radius rF), the file's mode
        d = self.F - C
        dd = abs(d) ** 2
        a = (self.rC**2 - self.rF**2 + dd) / (2 * dd)
        h = (self.rC**2 / dd - a * a) ** 0.5
        B = C + d * (a + 1j * self.mode * h)
        # link 5 turns about F: E carried from its reference
        u = (B - self.F) / (self.B0 - self.F)
        E = self.F + u * (self.E0 - self.F)
        g = abs(D - E) ** 2 - self.L2

        def dB(dC: Any) -> Any:
            # (B - C)·(B' - C') = 0 and (B - F)·B' = 0, solved for B'
            p, r = B - C, B - self.F
            rhs = _dot(p, dC)
            # B' = x with p·x = rhs, r·x = 0 -> x along i r
            return 1j * r * rhs / _dot(p, 1j * r)

        def g_dot(dA: Any, drot_arm: bool) -> Any:
            dC = (1j * (C - A) if drot_arm else 0) + dA
            dD = (1j * (D - A) if drot_arm else 0) + dA
            Bp = dB(dC)
            w5 = _cross(B - self.F, Bp) / abs(B - self.F) ** 2
            Ep = 1j * w5 * (E - self.F)
            return 2 * _dot(D - E, dD - Ep)

        return g, g_dot(0, True), g_dot(1j * (A - self.O), False)


def hand_written(mech: ClassIV, q: Arr, stations: int = 64, tol: float = 1e-13) -> tuple[Arr, Arr]:
    """ψ - ψ_ref and ψ' on frames q (one driver): coarse continuation, one batched Newton."""
    path = np.concatenate([[0.0], q])
    sq = np.linspace(path.min(), path.max(), stations + 1)
    # continuation from the reference (q = 0, ψ = 0) to both ends of the range, each
    # station predicted along the tangent ψ' = -g_q / g_ψ of the last one
    sv = np.empty_like(sq)
    i0 = int(np.argmin(np.abs(sq)))
    for order in (range(i0, sq.size), range(i0, -1, -1)):
        psi, slope, q_last = 0.0, 0.0, 0.0
        for i in order:
            qi = float(sq[i])
            psi += slope * (qi - q_last)
            for _ in range(30):
                g, gp, gq = mech.residual(qi, psi)
                psi -= g / gp
                if abs(g) < 1e-10:
                    break
            sv[i], slope, q_last = psi, -gq / gp, qi
    guess = np.interp(q, sq, sv)
    psi_v = guess.copy()
    active = np.arange(q.size)
    for _ in range(30):
        g, gp, gq = mech.residual(q[active], psi_v[active])
        done = np.abs(g) <= tol
        active, g, gp = active[~done], g[~done], gp[~done]
        if active.size == 0:
            break
        psi_v[active] -= g / gp
    g, gp, gq = mech.residual(q, psi_v)
    return psi_v, -gq / gp


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=3600)
    ap.add_argument("--repeat", type=int, default=15)
    ap.add_argument(
        "--cpu",
        action="store_true",
        help="CPU time of the process (time.process_time) instead of wall time",
    )
    ap.add_argument(
        "--only-default", action="store_true", help="only the race of the default call"
    )
    ap.add_argument("--runs", type=int, default=1, help="race the default call this often")
    args = ap.parse_args()
    clock = time.process_time if args.cpu else time.perf_counter
    print(f"clock: {'CPU time of the process' if args.cpu else 'wall time'}")
    model = KinematicModel.build(read_mechanism(example_path("class-iv-seed003")))
    mech = ClassIV()
    if not args.only_default:
        compare("full turn", model, mech, model.sweep(args.frames), args.repeat, clock)
    ratios = [default_call(model, mech, args.frames, args.repeat, clock) for _ in range(args.runs)]
    if args.runs > 1:
        held = sum(r <= GOAL for r in ratios)
        print(
            f"default call / hand-written Newton in {args.runs} runs: "
            f"{', '.join(f'{r:.2f}x' for r in ratios)}; goal <= {GOAL:.1f}x held in "
            f"{held} of {args.runs}: {'PASS' if held == args.runs else 'FAIL'}"
        )
    if not args.only_default:
        # a rocking input: the path goes from the reference back to -1 rad, turns, and
        # sweeps to +1 rad (the continuation's stations meet one turn of the path)
        rocking = model.q_ref + np.linspace(-1.0, 1.0, args.frames)[:, None]
        compare("rocking ±1 rad", model, mech, rocking, args.repeat, clock)


def compare(
    label: str,
    model: KinematicModel,
    mech: ClassIV,
    q: Arr,
    repeat: int,
    clock: Callable[[], float] = time.perf_counter,
) -> None:
    """Race the plug-in's closure against the hand-written one on frames ``q``; print."""
    qv = q[:, 0] - model.q_ref[0]
    calls = [0]
    real = closure_newton.evaluate

    def counting(*a: Any, **k: Any) -> Any:
        calls[0] += 1
        return real(*a, **k)

    closure_newton.evaluate = counting
    sol = closure.close(model, q)
    closure_newton.evaluate = real
    psi, psi1 = hand_written(mech, qv)
    agree = float(np.abs(np.angle(np.exp(1j * (psi - sol.t[:, 0])))).max())
    agree1 = float(np.abs(psi1 - sol.t1[:, 0]).max())
    t_first, t_ours, t_hand = race(
        [
            lambda: closure.close(model, q, order=1),
            lambda: closure.close(model, q),
            lambda: hand_written(mech, qv),
        ],
        repeat,
        clock,
    )
    print(f"class-IV closure, {label}, {q.shape[0]} frames (median of {repeat}, raced)")
    print(f"  hand-written batched Newton (ψ, ψ')      {t_hand * 1e3:8.2f} ms   1.00x")
    print(
        f"  plug-in closure.close, order 1 (t, t')   {t_first * 1e3:8.2f} ms   "
        f"{t_first / t_hand:5.2f}x   (the same output; target within 2x)"
    )
    print(
        f"  plug-in closure.close, order 2 (t, t', t'') {t_ours * 1e3:5.2f} ms   "
        f"{t_ours / t_hand:5.2f}x   (t'' too)"
    )
    print(
        f"  agreement: max |ψ - t| {agree:.1e}, max |ψ' - t'| {agree1:.1e}; "
        f"plug-in evaluate() calls {calls[0]}, Newton rounds on all frames {sol.iterations}"
    )


def default_call(
    model: KinematicModel,
    mech: ClassIV,
    frames: int,
    repeat: int,
    clock: Callable[[], float] = time.perf_counter,
) -> float:
    """Race the default kinematics call on the class-IV example (a full turn in ``frames``
    frames, as a user calls it: the mechanism read from its file for every call, so the
    plan and the closure's reference tangent are built each time; every table of the
    result read) against the hand-written Newton (its geometry read from the same file
    for every call); print the parts beside them, and return the ratio."""
    mechanism = model.mechanism
    path = example_path("class-iv-seed003")
    q = model.sweep(frames)
    qv = q[:, 0] - model.q_ref[0]

    def fresh() -> None:
        r = kinematic_analysis(read_mechanism(path), frames=frames)
        for table in (r.joints, r.points, r.links):
            table.stacks()

    t_hand, t_close, t_motion, t_model, t_reused, t_default = race(
        [
            lambda: hand_written(ClassIV(), qv),
            lambda: closure.close(model, q),
            lambda: model.motion(q),
            lambda: kinematic_analysis(model, frames=frames),
            lambda: kinematic_analysis(mechanism, frames=frames),
            fresh,
        ],
        repeat,
        clock,
    )
    ratio = t_default / t_hand
    verdict = "PASS" if ratio <= GOAL else "FAIL"
    load = ", ".join(f"{x:.1f}" for x in os.getloadavg())
    print(
        f"class-IV example, default call, {frames} frames (median of {repeat}, raced; "
        f"load average {load})"
    )
    rows = (
        ("hand-written batched Newton (file read, ψ, ψ')", t_hand, ""),
        ("closure.close (t, t', t''), model kept", t_close, ""),
        ("model.motion (closure, evaluation, branches)", t_motion, ""),
        ("kinematic_analysis(model kept), tables not read", t_model, ""),
        ("kinematic_analysis(mechanism object reused)", t_reused, ""),
        ("fresh from file, every table read: the goal", t_default, f"   goal <= {GOAL:.1f}x"),
    )
    for name, t, note in rows:
        print(f"  {name:<48} {t * 1e3:7.2f} ms  {t / t_hand:5.2f}x{note}")
    print(
        f"  fresh default call / hand-written Newton: {ratio:.2f}x (goal <= {GOAL:.1f}x): "
        f"{verdict}"
    )
    return ratio


if __name__ == "__main__":
    main()
