"""Judging a design with the kinematics itself: does it move through the driver range
the task needs, on one branch, without a dead point, and where does it go?

Owns :func:`check_motion`: the design's own :class:`~mjstruct.kinematics.model.
KinematicModel` moved along the required driver range (a fine sweep with the targets'
driver values inserted) by :meth:`~mjstruct.kinematics.model.KinematicModel.motion`,
whose branch tracking reports every change point, dead point and singular frame.  A
design passes when every frame assembles and no such event lies in the range; the
positions at the targets come from that same motion.  The searches' margins
(:mod:`mjstruct.design.constraints`) only guide them: this is the verdict.

The final verdict, :func:`final_verdict`, re-checks from a written design's own
geometry everything the contract promises of it: the motion above over the required
range (which must hold the reference and every target's driver value), untimed
targets met in their order along one turn, the timing as given, the transmission
bound, ``lengths``, ``region``, ``fixed``, the four-bar ``motion`` type and the
reported errors.  Every synthesis passes through it before a design is returned.

Examples
--------
>>> import numpy as np
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> m = read_mechanism(example_path("four-bar"))
>>> c = check_motion(m, np.array([0.5, 1.0]), full_turn=True, frames=120)
>>> c.ok, c.reason, c.track["M"].shape
(True, '', (2,))
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from mjstruct.design.constraints import MIN_SINE
from mjstruct.design.task import DRIVER_LIMIT, Task
from mjstruct.errors import MechanismError
from mjstruct.kinematics.branches import masked_sine
from mjstruct.kinematics.model import KinematicModel, Motion
from mjstruct.mechanism import Mechanism
from mjstruct.typing import ComplexArray, FloatArray

#: branch events that break a design's motion inside its driver range
BREAKING = ("change point", "dead point", "singular frame")
#: driver values of untimed targets this close (radians, along the turn) are one: the
#: local stage leaves rounding between targets met at one driver value
TIE = 1e-9
#: a reported error and the verdict's own may differ by this (relative to the size)
ERROR_SLACK = 1e-9
#: margins (relative to the size or the frame, and sines) down to this count as met
MARGIN_SLACK = 1e-9


@dataclass(frozen=True)
class MotionCheck:
    """The verdict of the kinematics on a design.

    Attributes
    ----------
    ok : every frame of the range assembles, no branch event breaks the motion.
    reason : why not (empty when ok).
    q : the driver values at the targets, as moved (continued from the reference).
    track : point or joint id -> its positions at the targets (complex).
    angles : link id -> its angle at the targets.
    sine : the smallest |sine| at a dyad's joint over the range (1 without dyads).
    range : (from, to) of the driver range checked.
    motion : the motion over the range (None when the model could not be built).
    """

    ok: bool
    reason: str
    q: FloatArray
    track: dict[str, ComplexArray] = field(default_factory=dict)
    angles: dict[str, FloatArray] = field(default_factory=dict)
    sine: float = 1.0
    range: tuple[float, float] = (0.0, 0.0)
    motion: Motion | None = None


def required_range(q_ref: float, q: FloatArray, full_turn: bool) -> tuple[float, float]:
    """The driver range a design must move through: a full turn from its reference,
    or the smallest interval holding the targets' values and the reference (brought
    by whole turns next to them)."""
    if full_turn:
        return q_ref, q_ref + 2 * math.pi
    mid = 0.5 * (float(q.min()) + float(q.max()))
    ref = q_ref + 2 * math.pi * round((mid - q_ref) / (2 * math.pi))
    return min(ref, float(q.min())), max(ref, float(q.max()))


def ordered_along_turn(q: FloatArray) -> tuple[FloatArray, str]:
    """Untimed targets' driver values with ties made one, and why they are not met in
    their order along one turn starting anywhere (empty when they are).

    Values closer than :data:`TIE` along the turn (rounding between targets met at one
    driver value) take the earlier one's value.  Target i must then come no earlier
    than target i - 1 on the turn that starts at target 0.

    >>> ordered_along_turn(np.array([6.0, 0.5, 1.0]))[1]
    ''
    >>> why = ordered_along_turn(np.array([1.84, 1.64, 3.66]))[1]
    >>> print(why)  # doctest: +NORMALIZE_WHITESPACE
    targets met out of order: target 2 (q = 3.66) comes before target 1 (q = 1.64)
    on the turn from target 0
    """
    out = np.array(q, dtype=float)
    turn = 2 * math.pi
    for i in range(1, len(out)):
        gap = abs(float(np.mod(out[i] - out[i - 1] + math.pi, turn)) - math.pi)
        if gap <= TIE:
            out[i] = out[i - 1]
    along = np.mod(out - out[0], turn)
    for i in range(1, len(out)):
        if along[i] < along[i - 1]:
            return out, (
                f"targets met out of order: target {i} (q = {out[i]:.6g}) comes before "
                f"target {i - 1} (q = {out[i - 1]:.6g}) on the turn from target 0"
            )
    return out, ""


def _range_trouble(lo: float, hi: float, q_ref: float, qq: FloatArray, unit: float) -> str:
    """Why the range [lo, hi] cannot be checked as the contract says: it must hold the
    reference (by whole turns) and every target's value, each within
    :data:`~mjstruct.design.task.DRIVER_LIMIT` (``unit``: 1 for an angle, the size for
    a slide), where a double still resolves the driver finely."""
    if not (math.isfinite(lo) and math.isfinite(hi)) or not np.isfinite(qq).all():
        return "the driver range is not finite"
    top = max(abs(lo), abs(hi))
    if top > DRIVER_LIMIT * unit:
        return (
            f"the driver range [{lo:.6g}, {hi:.6g}] reaches beyond {DRIVER_LIMIT:g} "
            f"{'rad' if unit == 1.0 else 'mechanism sizes'}"
        )
    turns = (q_ref - lo) / (2 * math.pi)
    ref = q_ref - 2 * math.pi * math.floor(turns)  # the reference's first turn >= lo
    slack = 1e-12 * max(top, unit)
    if ref > hi + slack or float(qq.min()) < lo - slack or float(qq.max()) > hi + slack:
        return (
            f"the driver range [{lo:.6g}, {hi:.6g}] does not hold the reference "
            f"and every target's driver value"
        )
    return ""


def check_motion(
    m: Mechanism,
    q: FloatArray,
    full_turn: bool,
    frames: int = 360,
    ids: Sequence[str] = (),
    links: Sequence[str] = (),
    ordered: bool = False,
) -> MotionCheck:
    """Move ``m`` through its required range and read it at the driver values ``q``.

    For a full turn, ``q`` is taken modulo a turn from the reference (the targets of a
    cyclic task); otherwise as given.  ``ids``: points and joints whose positions to
    return (default every point); ``links``: links whose angles to return.
    ``ordered``: the values are untimed targets' (:func:`ordered_along_turn`: ties
    made one, and out of order is a failed check).
    """
    try:
        model = KinematicModel.build(m)
    except MechanismError as exc:
        return MotionCheck(False, f"no model: {exc}", q)
    q_ref = float(model.q_ref[0])
    q = np.asarray(q, float)
    if not np.isfinite(q).all():
        return MotionCheck(False, "a target's driver value is not finite", q)
    lo, hi = required_range(q_ref, q, full_turn)
    qq = q_ref + np.mod(q - q_ref, 2 * math.pi) if full_turn else np.asarray(q, float)
    order = ""
    if ordered:
        qq, order = ordered_along_turn(qq)
    slide = m.joint(model.drivers[0]).kind == "P"
    trouble = _range_trouble(lo, hi, q_ref, qq, model.scale if slide else 1.0)
    if trouble:
        return MotionCheck(False, trouble, qq, range=(lo, hi))
    sweep = np.linspace(lo, hi, frames + 1)
    if full_turn:
        sweep = sweep[:-1]
    path = np.unique(np.concatenate([sweep, qq]))
    motion = model.motion(path, order=1)
    where = np.searchsorted(path, qq)
    ids = tuple(ids) or tuple(p.id for p in m.points)
    g = model.geometry
    track: dict[str, ComplexArray] = {}
    for pid in ids:
        if pid in g.points:
            link, z = g.points[pid]
            track[pid] = motion.point(link, z)[0][where]
        else:
            track[pid] = motion.centre(pid)[0][where]
    angles = {x: motion.angle(x)[0][where] for x in links}
    sine = 1.0
    for disc, det in motion.evaluation.diag.values():
        s = masked_sine(disc, det)
        sine = min(sine, float(np.nanmin(s)) if np.isfinite(s).any() else 0.0)
    bad = [e for e in motion.events if e.kind in BREAKING]
    reason = ""
    if not motion.valid.all():
        first = float(path[np.argmin(motion.valid)])
        reason = f"does not assemble at q = {first:.6g} (of [{lo:.6g}, {hi:.6g}])"
    elif bad:
        reason = f"{bad[0].kind} at q = {bad[0].q:.6g} (joint {bad[0].joint})"
    elif sine < MIN_SINE:
        reason = f"passes within |sin| = {sine:.2g} of a dead point"
    elif order:
        reason = order
    return MotionCheck(not reason, reason, qq, track, angles, sine, (lo, hi), motion)


def final_verdict(
    task: Task,
    m: Mechanism,
    timing: Sequence[float] | FloatArray,
    errors: Sequence[float] | None = None,
    angle_offset: float = 0.0,
    frames: int = 360,
) -> list[str]:
    """Everything the contract promises of a design, checked from its own geometry.

    ``m`` is the design as written, ``timing`` the driver value at each target as
    reported, ``errors`` the errors reported (re-measured here when given),
    ``angle_offset`` a function task's common offset.  Returns why the design breaks
    the contract (empty: it keeps every promise): its motion over the required range
    (:func:`check_motion`: assembly, branch events, dead points, the range holding the
    reference and every target), untimed targets in order along one turn, the timing
    as the task gives it, the transmission bound, ``lengths``, ``region``, ``fixed``,
    the four-bar ``motion`` and the errors.
    """
    from mjstruct.design.constraints import fourbar_lengths, link_pairs
    from mjstruct.design.task import is_fourbar
    from mjstruct.singular.fourbar import fourbar_theory

    start = task.mechanism
    assert start is not None
    q = np.asarray(timing, float)
    if q.shape != (len(task.targets),):
        return [f"timing: {q.size} driver values for {len(task.targets)} targets"]
    out: list[str] = []
    timed = task.kind == "function" or task.timing is not None
    point = task.point if task.kind != "function" else None
    ids = (point,) if point is not None else ()
    links = (task.link,) if task.link is not None and task.kind != "path" else ()
    check = check_motion(m, q, task.full_turn, frames, ids, links, ordered=not timed)
    if not check.ok:
        return [check.reason]
    size = KinematicModel.build(start).scale
    if timed:  # the driver values the task gives (relative: up to a common offset)
        given = task.targets[:, 0] if task.kind == "function" else task.timing
        assert given is not None
        shift = check.q - given
        if task.timing_offset:
            shift = shift - shift[0]
        if task.full_turn:
            shift = np.mod(shift + math.pi, 2 * math.pi) - math.pi
        if not np.all(np.abs(shift) <= 1e-9 * np.maximum(1.0, np.abs(given))):
            out.append("timing: the targets are not met at the driver values the task gives")
    need = 0.0 if task.transmission_deg is None else math.sin(math.radians(task.transmission_deg))
    if check.sine < max(need, MIN_SINE) - MARGIN_SLACK:
        angle = math.degrees(math.asin(min(1.0, max(check.sine, 0.0))))
        out.append(f"transmission_deg: the smallest dyad angle is {angle:.4g} deg")
    at = {j.id: j.at for j in m.joints} | {p.id: p.at for p in m.points}
    where = {k: complex(*v) for k, v in at.items() if v is not None}
    slack = MARGIN_SLACK * size
    if task.lengths is not None:
        lo, hi = task.lengths
        for a, b in link_pairs(m):
            d = abs(where[a] - where[b])
            if d > 0 and not lo - slack <= d <= hi + slack:
                out.append(f"lengths: {a!r} and {b!r} are {d:.6g} apart")
                break
    for key, ((x0, y0), (x1, y1)) in task.region.items():
        z = where[key]
        if not (x0 - slack <= z.real <= x1 + slack and y0 - slack <= z.imag <= y1 + slack):
            out.append(f"region.{key}: the design puts it at [{z.real:.6g}, {z.imag:.6g}]")
    first = {j.id: j.at for j in start.joints} | {p.id: p.at for p in start.points}
    for key in task.fixed:
        was = first[key]
        if was is not None and abs(where[key] - complex(*was)) > slack:
            out.append(f"fixed: {key!r} moved from its starting position")
    if task.motion is not None and is_fourbar(m):
        L = fourbar_lengths(m, {k: np.array([z]) for k, z in where.items()})
        crank, coupler, rocker, frame = (float(L[k][0]) for k in "abcd")
        try:
            kind = fourbar_theory(crank / frame, coupler / frame, rocker / frame).motion
        except MechanismError:
            kind = "four-bar that cannot move"
        got = str(kind)
        if got != task.motion and not (task.motion == "double-rocker" and got == "triple-rocker"):
            out.append(f"motion: the design is a {got}, not a {task.motion}")
    if errors is not None:
        mine = _errors(task, check, size, angle_offset)
        if len(errors) != len(mine) or not np.all(
            np.abs(np.asarray(errors, float) - mine) <= ERROR_SLACK * max(size, 1.0)
        ):
            out.append("errors: the reported errors are not the design's own")
    return out


def _errors(task: Task, check: MotionCheck, size: float, angle_offset: float) -> FloatArray:
    """Per target, the distance between it and what the design does there."""
    t = task.targets
    sq = np.zeros(len(t))
    if task.kind in ("path", "motion"):
        assert task.point is not None
        sq += np.abs(check.track[task.point] - (t[:, 0] + 1j * t[:, 1])) ** 2
    if task.kind in ("function", "motion"):
        assert task.link is not None
        goal = t[:, 1] + angle_offset if task.kind == "function" else t[:, 2]
        weight = size if task.kind == "motion" else 1.0
        diff = np.mod(check.angles[task.link] - goal + math.pi, 2 * math.pi) - math.pi
        sq += (weight * diff) ** 2
    out: FloatArray = np.sqrt(sq)
    return out


def fourbar_ms_verdict(
    m: Mechanism,
    motion: str,
    system4: Sequence[int],
    line: int | None = None,
    swing: float | None = None,
    time_ratio: float | None = None,
) -> list[str]:
    """What a ``fourbar-ms`` result promises, re-checked from its written geometry: the
    kinematics builds and assembles it at its reference configuration, and the four
    lengths its joint centres give are a four-bar of the ``motion`` reported, on the
    lines ``system4`` of system (4) (the required ``line`` among them), with the
    required ``swing`` (rad) and ``time_ratio`` (to 1e-6).  Empty: it keeps them."""
    from mjstruct.design.constraints import fourbar_lengths
    from mjstruct.singular.fourbar import fourbar_theory

    try:
        model = KinematicModel.build(m)
    except MechanismError as exc:
        return [f"the written four-bar has no kinematic model ({exc})"]
    if not model.motion(model.q_ref[None, :], order=0).valid.all():
        return ["the written four-bar does not assemble at its reference configuration"]
    where = {j.id: np.array([complex(*j.at)]) for j in m.joints if j.at is not None}
    L = fourbar_lengths(m, where)
    crank, coupler, rocker, frame = (float(L[k][0]) for k in "abcd")
    try:
        fb = fourbar_theory(crank / frame, coupler / frame, rocker / frame)
    except MechanismError as exc:
        return [f"the written four-bar cannot move ({exc})"]
    out = []
    if fb.motion != motion:
        out.append(f"motion: the written four-bar is a {fb.motion}, not a {motion}")
    if tuple(fb.system4) != tuple(system4) or (line is not None and line not in fb.system4):
        out.append(f"change_point: the written four-bar lies on (4.k) for k in {fb.system4}")
    for name, want, got in (
        ("swing_deg", swing, fb.swing),
        ("time_ratio", time_ratio, fb.time_ratio),
    ):
        if want is not None and (got is None or abs(got - want) > 1e-6 * max(1.0, abs(want))):
            out.append(f"{name}: the written four-bar gives {got}")
    return out
