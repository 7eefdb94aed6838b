"""The closure's path in driver space and the interpolation along it.

Owns :class:`ClosurePath` (the reference followed by the frames, parametrised by arc length
in q, its runs of one direction and its turns), the cubic and Hermite interpolation of
the unknowns between stations (:func:`cubic`, :func:`hermite`: cubic, or quintic
with t'') and the test that keeps the continuation on its branch: a station's change
of the unknowns against the trapezoid of their tangents (:func:`agreement`).

Examples
--------
>>> import numpy as np
>>> path = ClosurePath(np.zeros(1), np.array([[0.5], [1.0], [0.25]]))
>>> path.total, path.turns.tolist()
(1.75, [1.0])
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from mjstruct.typing import BoolArray, FloatArray


class ClosurePath:
    """The reference followed by the frames, parametrised by arc length in q.

    Arc length is the max norm of the driver steps, so a direction's largest component
    is 1; a position on a segment's end takes that segment's direction, and the
    assembly modes of the last frame reached.  Consecutive segments of one direction
    form a run (a sweep is one run).
    """

    def __init__(self, q_ref: FloatArray, q: FloatArray) -> None:
        n = q.shape[0]
        self.points = np.concatenate([q_ref[None, :], q])
        # (row_max, cumsum into the array, concatenate instead of np.r_: the same
        # numbers with fewer passes over the frames)
        step = self.points[1:] - self.points[:-1]
        seg = row_max(np.abs(step))
        self.arc = np.empty(n + 1)
        self.arc[0] = 0.0
        np.cumsum(seg, out=self.arc[1:])
        self.total = float(self.arc[-1])
        self.moving = np.flatnonzero(seg > 0)
        self.frames = int(n)
        if self.moving.size == n:  # every segment moves (a sweep): no gathers
            self.ends, d = self.arc[1:], step
        else:
            after = self.moving + 1
            self.ends, d = self.arc[after], self.points[after] - self.points[self.moving]
        self.dirs: FloatArray = d / (np.abs(d) if d.shape[1] == 1 else row_max(np.abs(d))[:, None])
        # where each moving segment's run of one direction ends (none: a path at rest)
        change = row_max(self.dirs[1:] != self.dirs[:-1])
        starts = (
            np.concatenate(([0], np.flatnonzero(change) + 1)) if self.moving.size else self.moving
        )
        stops = np.append(starts[1:], self.moving.size)[: starts.size]
        self.run_ends: FloatArray = np.repeat(self.ends[stops - 1], stops - starts)
        #: arc positions where the direction changes (a rocking input reverses there)
        self.turns: FloatArray = self.ends[stops[:-1] - 1]

    def _segment(self, sv: FloatArray) -> npt.NDArray[np.intp]:
        out: npt.NDArray[np.intp] = np.minimum(
            np.searchsorted(self.ends, sv, side="left"), self.moving.size - 1
        )
        return out

    def at(self, sv: FloatArray) -> FloatArray:
        """Driver values at arc positions ``sv`` (positions × drivers)."""
        cols = [np.interp(sv, self.arc, self.points[:, c]) for c in range(self.points.shape[1])]
        return np.stack(cols, axis=1)

    def directions(self, sv: FloatArray) -> FloatArray:
        """dq/ds at arc positions ``sv`` (zero on a path that does not move)."""
        if self.moving.size == 0:
            return np.zeros((sv.size, self.points.shape[1]))
        out: FloatArray = self.dirs[self._segment(sv)]
        return out

    def run_end(self, sv: float) -> float:
        """The arc where the run through ``sv`` ends (one direction up to there)."""
        if self.moving.size == 0:
            return self.total
        return float(self.run_ends[self._segment(np.array([sv]))[0]])

    def next_turn(self, sv: float) -> float:
        """The first arc position beyond ``sv`` where the direction changes (or the end)."""
        i = int(np.searchsorted(self.turns, sv, side="right"))
        return float(self.turns[i]) if i < self.turns.size else self.total

    def direction_after(self, sv: float) -> FloatArray:
        """dq/ds just beyond ``sv`` (at a turn: the new run's direction)."""
        if self.moving.size == 0:
            return np.zeros(self.points.shape[1])
        i = min(int(np.searchsorted(self.ends, sv, side="right")), self.moving.size - 1)
        out: FloatArray = self.dirs[i]
        return out

    def frames_at(self, sv: FloatArray) -> npt.NDArray[np.intp]:
        """The frame whose assembly modes a position takes (the last one reached)."""
        out: npt.NDArray[np.intp] = np.minimum(
            np.maximum(self.arc.searchsorted(sv, side="right") - 2, 0), self.frames - 1
        )
        return out


def cubic(
    s0: FloatArray | float,
    t0: FloatArray,
    d0: FloatArray,
    s1: FloatArray | float,
    t1: FloatArray,
    d1: FloatArray,
    s: FloatArray,
) -> FloatArray:
    """The cubic through (s0, t0) and (s1, t1) with slopes d0, d1, at positions ``s``.

    Interpolates between s0 and s1, extrapolates beyond; the ends may be one per
    position (arrays along the first axis).
    """
    h = np.asarray(s1 - s0, dtype=float).reshape(-1, 1)
    u = (s - s0).reshape(-1, 1) / h
    u2 = u * u
    u3 = u2 * u
    out: FloatArray = (
        (2 * u3 - 3 * u2 + 1) * t0
        + (u3 - 2 * u2 + u) * h * d0
        + (3 * u2 - 2 * u3) * t1
        + (u3 - u2) * h * d1
    )
    return out


def agreement(
    t0: FloatArray, d0: FloatArray, t1: FloatArray, d1: FloatArray, ds: FloatArray
) -> BoolArray:
    """Whether each station's change of the unknowns agrees with the trapezoid of t'.

    Rows are station pairs (from ``t0``, slope ``d0``, to ``t1``, ``d1``, ``ds``
    apart).  The test that keeps the continuation on its branch: a hop to another root
    changes the unknowns by much more than the tangent integrates to.
    """
    pred = 0.5 * (d0 + d1) * ds[:, None]
    with np.errstate(invalid="ignore"):  # a tangent that is not finite: disagrees
        out: BoolArray = row_max(np.abs(t1 - t0 - pred)) <= 0.05 * row_max(np.abs(pred)) + 1e-4
    return out


def row_max(x: FloatArray) -> FloatArray:
    """The largest entry of each row (of one column: the column, without a reduction)."""
    out: FloatArray = x[:, 0] if x.shape[1] == 1 else x.max(axis=1)
    return out


def finite_or_zero(d: FloatArray) -> FloatArray:
    out: FloatArray = np.where(np.isfinite(d), d, 0.0)
    return out


def last_two(
    S: list[float], TT: list[FloatArray], DD: list[FloatArray]
) -> tuple[list[float], list[FloatArray], list[FloatArray]]:
    """The last two stations, or the last alone when the one before is its twin at a turn."""
    n = 2 if len(S) > 1 and S[-2] < S[-1] else 1
    return S[-n:], TT[-n:], DD[-n:]


def hermite(
    x: FloatArray,
    y: FloatArray,
    dy: FloatArray,
    xi: FloatArray,
    d2y: FloatArray | None = None,
) -> FloatArray:
    """Hermite interpolation of columns of y (slopes dy) at xi: cubic, or quintic with d2y."""
    if x.size == 1:
        line: FloatArray = np.repeat(y, xi.size, axis=0) + (xi - x[0])[:, None] * dy
        return line
    i = np.minimum(np.maximum(x.searchsorted(xi, side="right") - 1, 0), x.size - 2)
    # each point's interval ends gathered once (take: numpy's fast gather along an axis)
    j = i + 1
    x0 = x.take(i)
    h = (x.take(j) - x0)[:, None]
    s = ((xi - x0)[:, None]) / h
    # the basis by products (numpy's power takes a slow general path for the cube)
    s2 = s * s
    s3 = s2 * s
    if d2y is not None:
        s4 = s3 * s
        s5 = s4 * s
        g0 = 10 * s3 - 15 * s4 + 6 * s5
        s5x3 = 3 * s5
        quintic: FloatArray = (
            (1 - g0) * y.take(i, axis=0)
            + g0 * y.take(j, axis=0)
            + h
            * (
                (s - 6 * s3 + 8 * s4 - s5x3) * dy.take(i, axis=0)
                + (-4 * s3 + 7 * s4 - s5x3) * dy.take(j, axis=0)
            )
            + 0.5
            * h
            * h
            * (
                (s2 - 3 * s3 + 3 * s4 - s5) * d2y.take(i, axis=0)
                + (s3 - 2 * s4 + s5) * d2y.take(j, axis=0)
            )
        )
        return quintic
    h01 = 3 * s2 - 2 * s3
    h00 = 1 - h01
    h10 = s3 - 2 * s2 + s
    h11 = s3 - s2
    cubic_: FloatArray = h00 * y[i] + h10 * h * dy[i] + h01 * y[j] + h11 * h * dy[j]
    return cubic_
