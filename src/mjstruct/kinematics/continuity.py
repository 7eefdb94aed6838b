"""Whether two neighbouring frames of a closure's sweep lie on one continuous motion.

Owns :func:`closure_walls`: between two consecutive frames of a one-driver sweep whose
closure unknowns changed by much in one step (or that the closure's branch-jump test
flagged), the branch of the first frame is continued towards the second in adaptive
steps (a tangent predictor, Newton from the previous point, the step halved where it
fails or lands far from the prediction): where the step falls below
:data:`MIN_STEP`, a fold lies between the
two frames; where the branch continued to the second frame's driver value does not
meet the second frame's unknowns, the second frame is on another branch.  Either way the
motion cannot go from one frame to the other, and the driver value between them is a
*wall* for :func:`~mjstruct.kinematics.reach.reached_frames`.  Near a fold the
closure's continuation can hop onto another root of the closure equations with the
same signs of every group determinant (the mechanism's Jacobian then keeps its sign
and no sign test sees it); this test does.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from mjstruct.kinematics.closure_newton import newton, subset_modes, tangent
from mjstruct.kinematics.steps.base import Modes
from mjstruct.kinematics.tolerances import CLOSURE_TOL
from mjstruct.typing import BoolArray, FloatArray

if TYPE_CHECKING:
    from mjstruct.kinematics.model_view import ModelView


#: rounds of the adaptive continuation between two frames
MAX_ROUNDS = 200
#: the smallest step (relative to the frames' step, at least 1 rad): below it a fold
MIN_STEP = 1e-10
#: the most the unknowns are predicted to move in one step (radians or relative slides)
MAX_MOVE = 0.1
#: a corrector may land this far from its prediction whatever the step (rounding)
NEAR_ABS = 1e-9
#: the branch continued to the second frame and the frame's own unknowns agree to this
SAME_ROOT = 1e-7
#: a step whose unknowns change by more than this (radians or relative slides) is
#: followed; smaller ones (and the others not flagged) are taken as they are
BIG_STEP = 1e-2


def closure_walls(
    model: ModelView,
    q: FloatArray,
    closed: tuple[FloatArray, FloatArray, BoolArray],
    jumps: tuple[int, ...],
    modes: dict[int, npt.NDArray[np.int8]],
    tol: float,
    turn: float | None,
) -> FloatArray:
    """Driver values between consecutive frames of the sweep ``q`` that no continuous
    motion joins (see the module docstring): ``closed`` the closure's unknowns, their
    slopes dt/dq and the frames that closed, ``jumps`` the frames its branch-jump test
    flagged, ``modes`` its inner dyads' modes per frame, ``tol`` its tolerance;
    ``turn`` (±2π) joins the last frame to frame 0, the reference, or None."""
    t, t1, ok = closed
    F = q.shape[0]
    a = np.arange(F - 1)
    b = a + 1
    qa, qb = q[a, 0], q[b, 0]
    if turn is not None and F > 2:
        a, b = np.append(a, F - 1), np.append(b, 0)
        qa, qb = np.append(qa, q[F - 1, 0]), np.append(qb, q[0, 0] + turn)
    both = ok[a] & ok[b] & np.isfinite(t1[a]).all(axis=1)
    flagged = np.zeros(a.size, bool)
    for j in jumps:
        flagged |= (a == j) | (b == j)
    step = np.abs(t[b] - t[a]).max(axis=1)
    same_modes = np.ones(a.size, bool)
    for v in modes.values():
        same_modes &= v[a] == v[b]
    follow = np.flatnonzero(both & same_modes & (flagged | (step > BIG_STEP)))
    if follow.size == 0:
        return np.zeros(0)
    ia, ib = a[follow], b[follow]
    x0, x1 = qa[follow], qb[follow]
    K = subset_modes(dict(modes) or None, ia)
    joined = _follow(model, x0, x1, t[ia], t1[ia], t[ib], K, tol)
    return np.asarray(0.5 * (x0 + x1)[~joined])


def joined_along(
    model: ModelView,
    x: FloatArray,
    t: FloatArray,
    d: FloatArray,
    K: Modes | None,
    tol: float = CLOSURE_TOL,
) -> int:
    """How many points of a one-driver path from the reference lie on one continuous
    motion: ``x`` the driver values (the reference first), ``t`` and ``d`` the unknowns
    and their slopes dt/dq there, ``K`` the modes of the path's points.  Consecutive
    points whose unknowns change by more than :data:`BIG_STEP` are followed
    (:func:`_follow`); the count stops before the first pair that is not joined."""
    n = x.size
    if n < 2:
        return n
    step = np.abs(t[1:] - t[:-1]).max(axis=1)
    same = np.ones(n - 1, bool)
    for v in (K or {}).values():
        if isinstance(v, np.ndarray):
            same &= v[1:] == v[:-1]
    pairs = np.flatnonzero((step > BIG_STEP) & same)
    joined = np.ones(n - 1, bool)
    if pairs.size:
        Kp = subset_modes(K, pairs)
        joined[pairs] = _follow(
            model, x[pairs], x[pairs + 1], t[pairs], d[pairs], t[pairs + 1], Kp
        )
    bad = np.flatnonzero(~joined)
    return n if bad.size == 0 else int(bad[0]) + 1


def _follow(
    model: ModelView,
    x0: FloatArray,
    x1: FloatArray,
    t0: FloatArray,
    d0: FloatArray,
    t1: FloatArray,
    K: Modes | None,
    tol: float = CLOSURE_TOL,
) -> BoolArray:
    """Whether the branch through (x0, t0) with slope d0 continues to (x1, t1), each
    pair on its own adaptive steps (tangent predictor, Newton corrector, a step
    halved where Newton fails or lands far from the prediction, doubled after it
    succeeds), all pairs in one Newton call per round."""
    n = x0.size
    span = x1 - x0
    kinds = [s.kind for s in model.plan.steps if s.kind in ("assume", "assume-slide")]
    angles = np.array([k == "assume" for k in kinds], bool)
    if angles.size != t0.shape[1]:
        angles = np.zeros(t0.shape[1], bool)
    cur_q, cur_t, cur_d = x0.copy(), t0.copy(), d0.copy()
    h = np.abs(span) / 4
    active = np.ones(n, bool)
    joined = np.zeros(n, bool)
    for _ in range(MAX_ROUNDS):
        idx = np.flatnonzero(active)
        if idx.size == 0:
            break
        left = x1[idx] - cur_q[idx]
        # the unknowns predicted to move at most MAX_MOVE per step: a predictor along a
        # steep tangent (next to a fold) would otherwise land near another root
        slope = np.abs(cur_d[idx]).max(axis=1)
        with np.errstate(divide="ignore"):
            hi = np.minimum(h[idx], MAX_MOVE / slope)
        last = np.abs(left) <= hi
        nxt = np.where(last, x1[idx], cur_q[idx] + np.sign(left) * hi)
        guess = cur_t[idx] + cur_d[idx] * (nxt - cur_q[idx])[:, None]
        Ki = subset_modes(K, idx)
        tn, _, _, okn = newton(model, nxt[:, None], guess, Ki, tol, maxiter=8)
        moved = np.abs(tn - guess).max(axis=1)
        # a hop lands a finite distance away whatever the step; the predictor's own
        # error shrinks with it (relative to the step in t and in the driver)
        stride = np.abs(guess - cur_t[idx]).max(axis=1) + np.abs(nxt - cur_q[idx])
        near = moved <= 0.1 * stride + NEAR_ABS
        good = okn & near
        g = idx[good]
        if g.size:
            cur_q[g], cur_t[g] = nxt[good], tn[good]
            cur_d[g] = tangent(model, cur_q[g, None], cur_t[g], subset_modes(K, g), np.ones(1))
            h[g] *= 2
            done = g[last[good]]
            # the continued branch at the second frame: the same root as the frame's
            gap = cur_t[done] - t1[done]
            # an assumed angle is the same modulo a turn (a sweep's last frame to its
            # first, one turn on)
            gap[:, angles] = np.mod(gap[:, angles] + np.pi, 2 * np.pi) - np.pi
            joined[done] = np.abs(gap).max(axis=1) <= SAME_ROOT
            active[done] = False
        b = idx[~good]
        h[b] = 0.5 * np.minimum(h[b], hi[~good])
        active[b[h[b] < MIN_STEP * np.maximum(np.abs(span[b]), 1.0)]] = False
    return joined
