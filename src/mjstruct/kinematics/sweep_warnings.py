"""The warnings of a kinematics sweep, in words: one per event or interval.

Owns :func:`sweep_warnings` (the motion's own warnings, its branch events, parallel
guides, rigid dyads, runs of frames that do not assemble, frames past a gap reached
the other way round or another assembly) and :func:`denormal_outputs` (outputs that
underflowed to subnormal doubles).  Near branch points of one dyad inside one run of
low sine are one warning; a dyad whose sine never changes gets one note, no event.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from mjstruct.kinematics.branches import BranchEvent, constant_sine
from mjstruct.kinematics.evaluate import Evaluation
from mjstruct.kinematics.model import KinematicModel, Motion
from mjstruct.kinematics.planner import Plan
from mjstruct.kinematics.result import KinematicsResult
from mjstruct.kinematics.tolerances import WATCH
from mjstruct.typing import FloatArray

#: below this speed (or size) the rates may fall into the doubles' subnormal range
DENORMAL_WATCH = 1e-100


def denormal_outputs(r: KinematicsResult, km: KinematicModel) -> list[str]:
    """Outputs that underflowed to subnormal doubles (below 2.2e-308, fewer significant
    digits): one warning naming the quantities (checked only for tiny speeds or sizes,
    where they can occur)."""
    if abs(r.speed) >= DENORMAL_WATCH and km.scale >= DENORMAL_WATCH:
        return []
    tiny = np.finfo(float).tiny
    v = r.valid
    found = []
    for name, table, keys in (
        ("positions", r.joints, ("x", "y")),
        ("velocities", r.joints, ("vx", "vy")),
        ("accelerations", r.joints, ("ax", "ay")),
        ("angular velocities", r.links, ("omega",)),
        ("angular accelerations", r.links, ("eps",)),
    ):
        if not len(table):
            continue
        with np.errstate(all="ignore"):
            x = np.abs(np.concatenate([table.column(k)[:, v].ravel() for k in keys]))
        sub = (x > 0) & (x < tiny)
        if sub.any():
            worst = float(x[sub].min())
            spacing = float(np.finfo(float).smallest_subnormal)
            found.append(
                f"{name} (down to {worst:.3g}, relative error up to {spacing / worst:.2g})"
            )
    if not found:
        return []
    return [
        "values below the smallest normal double 2.2e-308 (subnormal: fewer significant "
        "digits): " + "; ".join(found) + "; use larger units or speed"
    ]


def sweep_warnings(result: KinematicsResult, motion: Motion, offset: int = 0) -> list[str]:
    """The motion's warnings, its branch events, parallel guides and infeasible runs
    (frame numbers shifted by ``offset``)."""
    warnings = list(motion.warnings)
    other = result.another_assembly
    # the branch points of another assembly (frames not reached) are not the motion's
    events = [e for e in motion.events if other is None or not other[e.frame - offset]]
    warnings += _event_messages(events, motion.evaluation, offset)
    warnings += _parallel_guides(result.plan, motion.evaluation, motion.q)
    warnings += _rigid_dyads(result.plan, motion.evaluation, result.valid)
    warnings += _infeasible(result, offset)
    return warnings


def _event_messages(events: list[BranchEvent], ev: Evaluation, offset: int = 0) -> list[str]:
    """One line per event, but one per interval for a dyad's near branch points: those
    inside one run of frames where its |sine| stays below the watch level are one
    warning with the run's q range and the smallest |sine| (a dyad that wobbles near
    its dead point gave one warning per wobble)."""
    out: list[str] = []
    done: set[int] = set()
    for n, e in enumerate(events):
        if n in done:
            continue
        if e.kind != "near branch point" or e.step not in ev.diag:
            out.append(e.message())
            continue
        sine = np.abs(ev.diag[e.step][1])
        low = np.concatenate([[False], sine < WATCH, [False]])
        starts = np.flatnonzero(low[1:] & ~low[:-1])
        ends = np.flatnonzero(~low[1:] & low[:-1]) - 1
        f = e.frame - offset
        run = next(((a, b) for a, b in zip(starts, ends, strict=True) if a <= f <= b), None)
        same = [
            k
            for k, x in enumerate(events)
            if x.kind == "near branch point" and x.step == e.step and run is not None
            and run[0] <= x.frame - offset <= run[1]
        ]  # fmt: skip
        if len(same) <= 1 or run is None:
            out.append(e.message())
            continue
        done.update(same)
        worst = min((events[k] for k in same), key=lambda x: x.sine)
        a, b = int(run[0]), int(run[1])
        out.append(
            f"near branch points for q in [{events[same[0]].q:.9g}, {events[same[-1]].q:.9g}] "
            f"(frames {a + offset}..{b + offset}, step {e.step + 1}, joint {e.joint}): "
            f"{len(same)} closest approaches of the two branches, the smallest |sin| = "
            f"{worst.sine:.3g} at q = {worst.q:.9g}; assembly mode kept"
        )
    return out


def _rigid_dyads(plan: Plan, ev: Evaluation, valid: npt.NDArray[np.bool_]) -> list[str]:
    """Once per dyad whose |sine| is small but never changes: it does not move relative
    to the links it hangs on (no branch point, whatever its sine)."""
    out = []
    for k, s in enumerate(plan.steps):
        if not s.step_kind.has_modes or k not in ev.diag:
            continue
        sine = np.abs(ev.diag[k][1][valid])
        if sine.size >= 3 and constant_sine(sine) and float(sine.max()) < WATCH:
            out.append(
                f"dyad {s.kind} (step {k + 1}, joint {s.joint}): |sin| = {float(sine[0]):.3g} "
                "on every frame: the group is rigid relative to the links it hangs on "
                "(immobile relative to them), so it has no branch point"
            )
    return out


def _parallel_guides(plan: Plan, ev: Evaluation, q: FloatArray) -> list[str]:
    """Frames where the two guides of a line-intersection dyad are parallel."""
    out = []
    for k, s in enumerate(plan.steps):
        guides_of = s.step_kind.guides
        if guides_of is not None and k in ev.diag:
            bad = ev.diag[k][0] < 0
            if bad.any():
                guides = guides_of(s)
                out.append(
                    f"dyad {s.kind} (step {k + 1}): guides {guides[0]} and {guides[1]} are "
                    f"parallel at {int(bad.sum())} frame(s), first q = "
                    f"{q[np.argmax(bad), 0]:.9g}: no intersection, values are null"
                )
    return out


def _infeasible(r: KinematicsResult, offset: int = 0) -> list[str]:
    """Runs of frames that do not assemble, with their q range; singular frames.

    ``offset``: the number of ``r``'s first frame in the sweep (a streamed chunk).
    """
    if r.valid.all():
        return []  # every frame valid (and so placed): no run to word
    gap = ~r.placed if r.another_assembly is None else ~r.placed & ~r.another_assembly
    out = [
        _unassembled(r, line, i)
        for line, i in zip(
            _runs(r, gap, "no assembly for q in [{a}, {b}] (frames {i}..{j})", offset),
            _run_starts(gap),
            strict=True,
        )
    ]
    out += _runs(
        r,
        r.placed & ~r.valid,
        "singular position for q in [{a}, {b}] (frames {i}..{j}): the Jacobian with the drivers "
        "fixed is singular; positions are given, velocities and accelerations are not (null)",
        offset,
    )
    out += _beyond_gaps(r, offset)
    return out


def _beyond_gaps(r: KinematicsResult, offset: int = 0) -> list[str]:
    """Frames past an interval that does not assemble: reached the other way round, or
    another assembly (not reached), each run once."""
    blocked = ~r.placed
    if r.another_assembly is not None:
        blocked &= ~r.another_assembly
    if not blocked.any():
        return []
    out = []
    # frames reached after a gap in the sweep's order: the driver turning the other way
    first_gap = int(np.argmax(blocked))
    later = r.placed.copy()
    later[:first_gap] = False
    out += _runs(
        r,
        later,
        "frames {i}..{j} (q in [{a}, {b}]) lie past an interval that does not assemble: "
        "reached from the reference with the driver turning the other way (the motion "
        "cannot cross the gap; the driver rocks)",
        offset,
    )
    if r.another_assembly is not None:
        out += _runs(
            r,
            r.another_assembly,
            "frames {i}..{j} (q in [{a}, {b}]) assemble again past an interval that does not "
            "assemble, but no continuous motion from the reference reaches them: another "
            "assembly, not reached; their values are null (positions under "
            "another_assembly)",
            offset,
        )
    return out


def _run_starts(mask: npt.NDArray[np.bool_]) -> list[int]:
    """The first frame of each run of ``mask``."""
    edge = np.concatenate([[False], mask])
    return [int(i) for i in np.flatnonzero(edge[1:] & ~edge[:-1])]


def _unassembled(r: KinematicsResult, line: str, i: int) -> str:
    """``line`` (a run of frames that do not assemble from frame ``i``) with what is null.

    Where only some groups assemble (``r.partial``), the joints of the others are named:
    the joints whose groups assemble keep their values.
    """
    if r.partial is None or not r.partial[i]:
        return f"{line}; values are null"
    missing = [j for j, v in r.joints.items() if not np.isfinite(v["x"][i])]
    if len(missing) == len(r.joints):
        return f"{line}; values are null"
    return (
        f"{line} of joints {', '.join(missing)}: their values are null; the groups that "
        "assemble are given"
    )


def _runs(
    r: KinematicsResult, mask: npt.NDArray[np.bool_], text: str, offset: int = 0
) -> list[str]:
    """``text`` for each run of frames in ``mask`` (``{a}``, ``{b}``: its q range)."""
    edge = np.concatenate([[False], mask, [False]])
    starts = np.flatnonzero(edge[1:] & ~edge[:-1])
    ends = np.flatnonzero(~edge[1:] & edge[:-1]) - 1
    return [
        text.format(a=f"{r.q[i, 0]:.9g}", b=f"{r.q[j, 0]:.9g}", i=i + offset, j=j + offset)
        for i, j in zip(starts, ends, strict=True)
    ]
