"""The window of continuation stations: the bookkeeping of stations solved together.

Owns :class:`StationWindow`, the stations of the closure's continuation being solved together
by one vectorised Newton (one evaluation per round for the whole window), in order
along the path: their guesses (the cubic through the nearest known points, held
beyond :data:`REACH`), the halving of trials that do not assemble, new guesses for
stuck stations once more is known (at most :data:`RENEWALS` times), a station halfway
between two closed neighbours that disagree, and the front given up as stations are
accepted (:mod:`mjstruct.kinematics.closure_continuation` drives it).

Examples
--------
>>> import numpy as np
>>> w = StationWindow(k=1, drivers=1)
>>> w.insert(np.zeros(2, np.intp), np.array([0.1, 0.2]), np.array([[0.1], [0.2]]),
...          np.zeros((2, 1)))
>>> w.size, w.s.tolist()
(2, [0.1, 0.2])
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from mjstruct.kinematics.closure_path import agreement, cubic, last_two
from mjstruct.typing import BoolArray, FloatArray

#: a guess extrapolated from the last known stations is held beyond this arc from them
#: (a cubic drifts off fast; a held value still converges from most of the turn)
REACH = 0.5
#: a window station this close to closing (relative error) is known well enough to
#: guess its neighbours from and to test their agreement (Newton is then one or two
#: steps from its root)
SETTLED = 1e-6
#: a stuck window station is guessed again at most this often (then, at the front, it
#: is sought alone): bounds the rounds where the path leaves the feasible range
RENEWALS = 2


class StationWindow:
    """Continuation stations being solved together, in order along the path.

    Per station: arc position ``s`` and driver values ``q`` there; trial unknowns
    ``t``; the last point evaluated without halving, ``base``, with its Newton ``step``
    and the fraction ``alpha`` of it tried (``halved`` times), max |R| ``rbase``, error
    ``err``, tangent ``d`` there and whether it ``closed``; evaluations ``evals``;
    whether it was ``refused`` once (closed too far from the last station); ``known``,
    how many points were known when it was last guessed (it is guessed again only once
    more are), and how many ``renewals`` it had (at most :data:`RENEWALS`).
    """

    _FIELDS = (
        "s",
        "q",
        "t",
        "base",
        "step",
        "d",
        "alpha",
        "halved",
        "rbase",
        "err",
        "evals",
        "closed",
        "refused",
        "known",
        "renewals",
    )

    def __init__(self, k: int, drivers: int) -> None:
        self.checked = 0  # settled stations when the pairs were last tested
        fresh = self._fresh(np.zeros(0), np.zeros((0, drivers)), np.zeros((0, k)), 0)
        self.s, self.q, self.t, self.base = (fresh[n] for n in self._FIELDS[:4])
        self.step, self.d, self.alpha, self.halved = (fresh[n] for n in self._FIELDS[4:8])
        self.rbase, self.err, self.evals = (fresh[n] for n in self._FIELDS[8:11])
        self.closed, self.refused = fresh["closed"], fresh["refused"]
        self.known, self.renewals = fresh["known"], fresh["renewals"]

    @property
    def size(self) -> int:
        """Stations in the window."""
        return int(self.s.size)

    def _fresh(
        self, sv: FloatArray, qv: FloatArray, g: FloatArray, known: int
    ) -> dict[str, npt.NDArray[Any]]:
        n = sv.size
        # np.zeros and np.empty + fill: np.full/ones/zeros_like cost several times more
        # on these few stations
        unknown = np.empty(n)
        unknown.fill(np.inf)
        count = np.empty(n, np.int64)
        count.fill(known)
        alpha = np.empty(n)
        alpha.fill(1.0)
        return {
            "s": sv,
            "q": qv,
            "t": g,
            "base": g.copy(),
            "step": np.zeros(g.shape),
            "d": np.zeros(g.shape),
            "alpha": alpha,
            "halved": np.zeros(n, np.int64),
            "rbase": unknown,
            "err": unknown.copy(),
            "evals": np.zeros(n, np.int64),
            "closed": np.zeros(n, bool),
            "refused": np.zeros(n, bool),
            "known": count,
            "renewals": np.zeros(n, np.int64),
        }

    def _anchors(
        self, S: list[float], TT: list[FloatArray], DD: list[FloatArray]
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        # the last two accepted stations and the window's closed stations
        c = self.closed
        S, TT, DD = last_two(S, TT, DD)
        return (
            np.concatenate([S, self.s[c]]),
            np.concatenate([TT, self.base[c]]),
            np.concatenate([DD, self.d[c]]),
        )

    def guess(
        self,
        sv: FloatArray,
        S: list[float],
        TT: list[FloatArray],
        DD: list[FloatArray],
        ahead: bool = True,
    ) -> FloatArray:
        """Unknowns at positions ``sv``: the cubic through the nearest known points.

        Between two known points (with ``ahead``, the window's closed stations count),
        the cubic through them; else extrapolated from the last two, held beyond
        :data:`REACH`.
        """
        if ahead:
            x, y, dy = self._anchors(S, TT, DD)
        else:
            x, y, dy = (np.asarray(v) for v in last_two(S, TT, DD))
        if x.size == 1:
            line: FloatArray = y[0] + dy[0] * (np.minimum(sv, x[0] + REACH) - x[0])[:, None]
            return line
        j = np.minimum(np.maximum(x.searchsorted(sv), 1), x.size - 1)
        inside = sv < x[-1]
        i0 = np.where(inside, j - 1, x.size - 2)
        i1 = np.where(inside, j, x.size - 1)
        held = np.where(inside, sv, np.minimum(sv, x[-1] + REACH))
        return cubic(x[i0], y[i0], dy[i0], x[i1], y[i1], dy[i1], held)

    def insert(
        self,
        at: npt.NDArray[np.intp],
        sv: FloatArray,
        qv: FloatArray,
        g: FloatArray,
        known: int = 0,
    ) -> None:
        """New stations at ``sv`` (driver values ``qv``), guesses ``g``, before ``at``."""
        n, m = self.size, sv.size
        if n == 0:  # an empty window: the new stations are the window
            for name, v in self._fresh(sv, qv, g, known).items():
                setattr(self, name, v)
            return
        # np.insert's result in one gather per field: new station j lands at at[j] + j
        slot = np.zeros(n + m, bool)
        slot[at + np.arange(m)] = True
        perm = np.empty(n + m, np.intp)
        perm[~slot] = np.arange(n)
        perm[slot] = n + np.arange(m)
        for name, v in self._fresh(sv, qv, g, known).items():
            setattr(self, name, np.concatenate([getattr(self, name), v])[perm])

    def drop_front(self, n: int) -> None:
        """Forget the first ``n`` stations."""
        if n:
            for name in self._FIELDS:
                setattr(self, name, getattr(self, name)[n:])

    def renew(
        self,
        mask: BoolArray,
        S: list[float],
        TT: list[FloatArray],
        DD: list[FloatArray],
        ahead: bool = True,
    ) -> BoolArray:
        """Guess the ``mask`` stations again where more points are known; which were."""
        if not np.count_nonzero(mask):
            return mask
        known = len(S) + int(np.count_nonzero(self.closed))
        # at most RENEWALS times each: the count of closed stations can go up and down
        redo = mask & (self.known < known) & (self.renewals < RENEWALS)
        if np.count_nonzero(redo):
            self.renewals[redo] += 1
            for name, v in self._fresh(
                self.s[redo], self.q[redo], self.guess(self.s[redo], S, TT, DD, ahead), known
            ).items():
                if name not in ("s", "q", "renewals"):
                    getattr(self, name)[redo] = v
        return redo

    def split_disagreeing(self) -> None:
        """A station halfway between each closed neighbour pair that disagrees."""
        settled = int(np.count_nonzero(self.closed))
        if settled == self.checked:  # no station settled since the last look
            return
        self.checked = settled
        ds = self.s[1:] - self.s[:-1]
        pair = self.closed[1:] & self.closed[:-1] & (ds > 1e-4)
        if not np.count_nonzero(pair):
            return
        # every neighbour pair at once (slices: cheaper than gathering the closed ones)
        far = pair & ~agreement(self.base[:-1], self.d[:-1], self.base[1:], self.d[1:], ds)
        if np.count_nonzero(far):
            i = far.nonzero()[0]
            mid = 0.5 * (self.s[i] + self.s[i + 1])
            # within a run the path is straight in q: the midpoint in arc is in q too
            qmid = 0.5 * (self.q[i] + self.q[i + 1])
            g = cubic(
                self.s[i],
                self.base[i],
                self.d[i],
                self.s[i + 1],
                self.base[i + 1],
                self.d[i + 1],
                mid,
            )
            self.insert(i + 1, mid, qmid, g)

    def advance(
        self,
        newton: FloatArray,
        d: FloatArray,
        rmax: FloatArray,
        e: FloatArray,
        bad: BoolArray,
        closed: BoolArray,
        live: BoolArray,
        accepted: int = 0,
    ) -> None:
        """One round for the ``live`` stations: ``bad`` trials halved, the rest take
        their Newton step (``newton``, the step from each station's trial point; ``d``
        the finite tangents there); then the first ``accepted`` stations (not live) are
        forgotten."""
        # (np.count_nonzero: a fraction of the cost of any/all on these few stations)
        alive = np.count_nonzero(live)
        n = accepted
        if alive == live.size - n and not np.count_nonzero(bad[n:]):
            # the usual round: every station after the accepted ones steps; the round's
            # arrays become the window's (no copies into the old ones)
            self.s, self.q = self.s[n:], self.q[n:]
            self.err, self.rbase, self.step, self.d = e[n:], rmax[n:], newton[n:], d[n:]
            self.base = self.t[n:]
            self.t = self.base + self.step
            self.closed = closed[n:] | (self.err <= SETTLED)
            self.evals = self.evals[n:] + 1
            m = self.s.size
            self.alpha = np.empty(m)
            self.alpha.fill(1.0)
            self.halved = np.zeros(m, np.int64)
            self.refused, self.known = self.refused[n:], self.known[n:]
            self.renewals = self.renewals[n:]
            return
        first = int(live.argmax()) if alive else live.size
        g: slice | BoolArray
        if alive == live.size - first and not np.count_nonzero(bad[first:]):
            g = slice(first, None)  # every station from the first live one steps
        else:
            b = bad & live
            if np.count_nonzero(b):
                self.alpha[b] *= 0.5
                self.halved[b] += 1
                self.t[b] = self.base[b] + self.alpha[b, None] * self.step[b]
            g = ~bad & live
            if not np.count_nonzero(g):
                self.drop_front(n)
                return
        self.err[g] = e[g]
        self.base[g] = self.t[g]
        self.rbase[g] = rmax[g]
        self.d[g] = d[g]
        self.closed[g] = closed[g] | (e[g] <= SETTLED)
        self.evals[g] += 1
        self.step[g] = newton[g]
        self.alpha[g], self.halved[g] = 1.0, 0
        self.t[g] += newton[g]  # base + step
        self.drop_front(n)
