"""Judging a design with the kinematics itself: does it move through the driver range
the task needs, on one branch, without a dead point, and where does it go?

Owns :func:`check_motion`: the design's own :class:`~mjstruct.kinematics.model.
KinematicModel` moved along the required driver range (a fine sweep with the targets'
driver values inserted) by :meth:`~mjstruct.kinematics.model.KinematicModel.motion`,
whose branch tracking reports every change point, dead point and singular frame.  A
design passes when every frame assembles and no such event lies in the range; the
positions at the targets come from that same motion.  The searches' margins
(:mod:`mjstruct.design.constraints`) only guide them: this is the verdict.

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
from mjstruct.errors import MechanismError
from mjstruct.kinematics.branches import masked_sine
from mjstruct.kinematics.model import KinematicModel, Motion
from mjstruct.mechanism import Mechanism
from mjstruct.typing import ComplexArray, FloatArray

#: branch events that break a design's motion inside its driver range
BREAKING = ("change point", "dead point", "singular frame")


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


def check_motion(
    m: Mechanism,
    q: FloatArray,
    full_turn: bool,
    frames: int = 360,
    ids: Sequence[str] = (),
    links: Sequence[str] = (),
) -> MotionCheck:
    """Move ``m`` through its required range and read it at the driver values ``q``.

    For a full turn, ``q`` is taken modulo a turn from the reference (the targets of a
    cyclic task); otherwise as given.  ``ids``: points and joints whose positions to
    return (default every point); ``links``: links whose angles to return.
    """
    try:
        model = KinematicModel.build(m)
    except MechanismError as exc:
        return MotionCheck(False, f"no model: {exc}", q)
    q_ref = float(model.q_ref[0])
    lo, hi = required_range(q_ref, q, full_turn)
    qq = q_ref + np.mod(q - q_ref, 2 * math.pi) if full_turn else np.asarray(q, float)
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
    return MotionCheck(not reason, reason, qq, track, angles, sine, (lo, hi), motion)
