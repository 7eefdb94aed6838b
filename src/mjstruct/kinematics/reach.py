"""Which frames a continuous motion from the reference configuration reaches.

Owns the one rule for frames beyond an interval that does not assemble: a frame is
*reached* when the driver, moving continuously from its reference value in one
direction or the other, gets there without passing a frame where the mechanism does
not assemble (a revolute driver's angle taken modulo 2π, so a rocking input's frames
past the gap are reached with the driver turning the other way).  Every other frame
that assembles belongs to *another assembly*: the same mechanism put together anew
beyond a gap the motion cannot cross, not a motion from the reference.  Its positions
are kept apart (``KinematicsResult.another_assembly``, JSON ``another_assembly``) and
its frames are null in the tables.

A frame blocks the motion where some group has no position (``placed`` false, or a
frame where only some groups assemble); frames where positions exist but the
Jacobian with the drivers fixed is singular (a dead point met exactly, a change point)
do not block.

>>> import numpy as np
>>> q = np.array([0.0, 1.0, 2.0, 3.0, 4.0, 5.0])[:, None]
>>> blocked = np.array([False, False, True, False, True, False])
>>> reached_frames(q, 0.0, blocked, turns=True).tolist()    # 3 lies between two gaps
[True, True, False, False, False, True]
"""

from __future__ import annotations

import numpy as np

from mjstruct.typing import BoolArray, FloatArray


def reached_frames(
    q: FloatArray,
    q_ref: float,
    blocked: BoolArray,
    turns: bool,
    walls: FloatArray | None = None,
) -> BoolArray:
    """Frames of a one-driver path ``q`` (frames × 1) reached from ``q_ref``.

    ``blocked``: frames where the mechanism does not assemble; ``turns``: the driver is
    an angle (its values taken modulo 2π, so that both ways around lead to a frame);
    ``walls``: further driver values the motion cannot pass (between two frames where
    the mechanism's Jacobian changes sign: a fold passed by a jump).  A frame is
    reached when no blocked frame or wall lies between it and the reference on the way
    forwards or on the way backwards; a blocked frame itself is not reached.
    """
    stops = q[blocked, 0] if walls is None else np.concatenate([q[blocked, 0], walls])
    fwd, back = _distances(q[:, 0] - q_ref, turns)
    wf, wb = _distances(stops - q_ref, turns)
    out = np.zeros(q.shape[0], dtype=bool)
    for dist, wall in ((fwd, wf), (back, wb)):
        # the nearest stop that way: frames nearer than it are reached
        near = float(wall.min()) if wall.size else np.inf
        out |= (dist < near) & np.isfinite(dist)
    out &= ~blocked
    return out


def _distances(d: FloatArray, turns: bool) -> tuple[FloatArray, FloatArray]:
    """How far forwards and backwards each offset ``d`` from the reference lies."""
    if turns:
        fwd = np.mod(d, 2 * np.pi)
        return fwd, np.where(fwd > 0, 2 * np.pi - fwd, 0.0)
    return np.where(d >= 0, d, np.inf), np.where(d <= 0, -d, np.inf)


def sign_walls(
    q: FloatArray, sign: FloatArray, placed: BoolArray, quiet: BoolArray, turn: float | None
) -> FloatArray:
    """Driver values between two consecutive placed frames of a sweep where the sign of
    the driver-fixed Jacobian's determinant changes (``sign``: its sign per frame).

    Along a motion in the driver the determinant keeps its sign except where it touches
    zero (a change point, a fold); a continuous motion cannot cross a fold, so a change
    between two frames the sweep joined means it jumped.  ``quiet``: frames next to a
    change point or a mode flip (there the sign may change legitimately);
    ``turn``: the sweep's full turn (±2π; its last frame is next to the reference,
    frame 0) or None.

    >>> q = np.array([0.0, 1.0, 2.0, 3.0])[:, None]
    >>> sign_walls(q, np.array([1.0, 1.0, -1.0, -1.0]), np.ones(4, bool), np.zeros(4, bool), None)
    array([1.5])
    """
    s = np.where(placed & np.isfinite(sign), sign, 0.0)
    change = (s[1:] * s[:-1] < 0) & ~quiet[1:] & ~quiet[:-1]
    out = list(0.5 * (q[1:, 0] + q[:-1, 0])[change])
    if turn is not None and q.shape[0] > 2 and s[0] * s[-1] < 0 and not (quiet[0] or quiet[-1]):
        out.append(0.5 * (q[-1, 0] + q[0, 0] + turn))
    return np.array(out, dtype=float)
