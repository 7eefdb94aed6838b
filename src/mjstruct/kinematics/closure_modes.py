"""Assembly modes of the dyads inside a closure group, per station and per frame.

Owns the flips of an inner dyad's assembly mode along the closure's path.  A dyad that
the closure solves inside its group (it reads the assumed unknowns) may reach its own
dead point while the group passes smoothly: the group's configuration, and so the
unknowns, go on along the path, but on the dyad's other assembly mode.  With the
dyad's mode kept, no root closes beyond that point and the continuation would stop
there (the frames on would be reported missing, and the dyad "at its dead point",
although the mechanism's Jacobian is regular there).

:func:`try_flip` is asked where the continuation meets an edge: it flips, one at a
time, the inner dyads nearest their dead point at the last station, and keeps a flip
when a station just beyond closes with it and agrees with the trapezoid of the
tangent from the last station (the unknowns and their tangent go on smoothly: the
same branch of the group).  The dyad's signed sine crosses zero linearly there, so the
flip's arc is where the line through the two stations' sines crosses zero.
:class:`ModeFlips` keeps the flips met along the path and gives the modes at any arc
position (stations, frames): the base modes, each inner dyad's flipped once per flip
before that position.

Examples
--------
>>> flips = ModeFlips({4: 1})
>>> flips.add(0.3, 4)
>>> flips.modes(None, np.array([0.1, 0.5]), np.zeros(2, np.intp))[4].tolist()
[1, -1]
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from mjstruct.kinematics.closure_newton import subset_modes
from mjstruct.kinematics.closure_path import agreement
from mjstruct.kinematics.evaluate import evaluate, reference_mode
from mjstruct.kinematics.steps.base import Modes
from mjstruct.typing import FloatArray

if TYPE_CHECKING:
    from mjstruct.kinematics.model_view import ModelView

#: inner dyads tried at an edge (those with the smallest |sine| at the last station)
FLIP_CANDIDATES = 3
#: arcs beyond the last station where a flipped station is sought
FLIP_REACH = (2e-4, 1e-3, 4e-3)
#: an inner dyad is a candidate when its |sine| at the last station is at most this
#: (its signed sine crosses zero within the step where the stations stopped)
FLIP_SINE = 0.02
#: and the flipped station beyond is kept only with |sine| at most this (just past the
#: dead point, on the dyad's other mode; a larger one is another configuration)
FLIP_SINE_BEYOND = 0.1
#: flips at most along one path (each needs the dyad to pass its dead point again)
MAX_FLIPS = 256


def inner_mode_steps(model: ModelView, only: tuple[int, ...] | None) -> tuple[int, ...]:
    """Dyad steps with two assembly modes that the closure solves with its unknowns.

    Those the closure equations read (``only``, None: every step) and that depend on an
    assumed unknown.
    """
    steps = model.plan.steps
    assumed = {k for k, s in enumerate(steps) if s.kind in ("assume", "assume-slide")}
    pool = range(len(steps)) if only is None else only
    return tuple(
        k
        for k in pool
        if steps[k].step_kind.has_modes and assumed.intersection(model.step_dependencies[k])
    )


class ModeFlips:
    """Flips of inner dyads' modes along a path: (arc, step), in the order met.

    ``reference``: each inner dyad's mode at the reference configuration (used where
    no base modes are given).
    """

    def __init__(self, reference: dict[int, int]) -> None:
        self.reference = reference
        self.arcs: list[float] = []
        self.steps: list[int] = []
        #: the last station before the edge where the continuation stopped (driver
        #: values, unknowns, modes there), if it stopped
        self.stop: tuple[FloatArray, FloatArray, Modes | None] | None = None

    def __bool__(self) -> bool:
        return bool(self.arcs)

    def add(self, arc: float, step: int) -> None:
        """Record that ``step``'s mode flips at ``arc``."""
        self.arcs.append(arc)
        self.steps.append(step)

    def signs(self, sv: FloatArray) -> dict[int, npt.NDArray[np.int8]]:
        """Per flipped step, ±1 at arc positions ``sv`` (−1 after an odd number of flips)."""
        out: dict[int, npt.NDArray[np.int8]] = {}
        for a, k in zip(self.arcs, self.steps, strict=True):
            sign = out.setdefault(k, np.ones(sv.size, np.int8))
            sign[sv > a] *= -1
        return out

    def modes(self, K: Modes | None, sv: FloatArray, frames: npt.NDArray[np.intp]) -> Modes | None:
        """The modes at arc positions ``sv`` (whose base modes are ``K`` at ``frames``)."""
        base = None if K is None else subset_modes(K, frames)
        if not self.arcs:
            return base
        out: dict[int, npt.NDArray[np.int8] | int] = {} if base is None else dict(base)
        for k, sign in self.signs(sv).items():
            b = out.get(k, self.reference[k])
            out[k] = (sign * np.asarray(b)).astype(np.int8)
        return out


def reference_modes(model: ModelView, steps: tuple[int, ...]) -> dict[int, int]:
    """Each of ``steps``' mode at the reference configuration."""
    return {k: reference_mode(model.plan, model.geometry, k) for k in steps}


def signed_sines(
    model: ModelView,
    q: FloatArray,
    t: FloatArray,
    K: Modes | None,
    steps: tuple[int, ...],
    only: tuple[int, ...] | None,
) -> dict[int, float]:
    """The signed sine of each of ``steps`` at one configuration (driver ``q``, unknowns ``t``)."""
    ev = evaluate(model, q[None, :], order=0, t=t[None, :], K=K, only=only)
    return {k: float(ev.diag[k][1][0]) for k in steps if k in ev.diag}


#: a station solve: (arc, guess, modes) -> (unknowns, tangent or None)
StationSolve = Callable[[float, FloatArray, Modes | None], tuple[FloatArray, FloatArray | None]]


def try_flip(
    model: ModelView,
    flips: ModeFlips,
    inner: tuple[int, ...],
    at: Callable[[float], FloatArray],
    modes: Callable[[float], Modes | None],
    solve: StationSolve,
    last: tuple[float, FloatArray, FloatArray],
    limit: float,
    only: tuple[int, ...] | None,
) -> tuple[float, FloatArray, FloatArray] | None:
    """A station just beyond the last one with an inner dyad's mode flipped, or None.

    ``last`` is the last station (arc, unknowns, tangent); ``at`` gives the driver
    values at an arc, ``modes`` the modes there (the flips so far), ``solve`` closes a
    station from a guess with given modes.  Candidates are the inner dyads with the
    smallest |sine| at the last station; a flipped station at an arc of
    :data:`FLIP_REACH` beyond (at most ``limit``) that closes and agrees with the
    tangent is kept: the flip is added to ``flips`` where the dyad's signed sine crosses
    zero, and the station (arc, unknowns, tangent) is returned.
    """
    if len(flips.arcs) >= MAX_FLIPS or not inner:
        return None
    s0, t0, d0 = last
    K0 = modes(s0)
    sines = signed_sines(model, at(s0), t0, K0, inner, only)
    near = [k for k in sines if abs(sines[k]) <= FLIP_SINE]
    order = sorted(near, key=lambda k: abs(sines[k]))
    for k in order[:FLIP_CANDIDATES]:
        for reach in FLIP_REACH:
            s1 = min(s0 + reach, limit)
            ds = s1 - s0
            if ds <= 0:
                break
            base = modes(s1)
            b = flips.reference[k] if base is None or k not in base else base[k]
            Kf: dict[int, npt.NDArray[np.int8] | int] = {} if base is None else dict(base)
            Kf[k] = -np.asarray(b).astype(np.int8) if isinstance(b, np.ndarray) else -int(b)
            guess = t0 + d0 * ds
            t1, d1 = solve(s1, guess, Kf)
            if d1 is None:
                # near the dead point the flipped mode assembles only in a band of
                # width ~ds² beside the tangent: start Newton from inside that band
                start = _inside(model, at(s1), guess, Kf, k, only)
                if start is None:
                    continue
                t1, d1 = solve(s1, start, Kf)
            if d1 is None:
                continue
            if not agreement(t0[None], d0[None], t1[None], d1[None], np.array([ds]))[0]:
                continue
            s_new = signed_sines(model, at(s1), t1, Kf, (k,), only).get(k, np.nan)
            a0, a1 = abs(sines[k]), abs(s_new)
            if not a1 <= FLIP_SINE_BEYOND:
                continue  # not the dyad's own dead point: another configuration
            # the signed sine crosses zero between the two stations, linearly in the arc
            frac = a0 / (a0 + a1) if np.isfinite(a1) and a0 + a1 > 0 else 0.5
            flips.add(s0 + frac * ds, k)
            return s1, t1, d1
    return None


#: offsets into the band where a flipped dyad assembles (relative to the step back
#: from the guess to the band's edge, and absolute in the unknowns)
BAND_OFFSETS = (1e-6, 1e-4, 1e-2, 1.0, 1e2)


def _inside(
    model: ModelView,
    q: FloatArray,
    guess: FloatArray,
    K: Modes,
    k: int,
    only: tuple[int, ...] | None,
) -> FloatArray | None:
    """A start for Newton from which dyad ``k`` assembles near ``guess``, or None.

    The dyad's discriminant (h²/r², smooth in the unknowns) is followed from ``guess``
    along its gradient (by differences) to its zero, the edge of the band where the
    dyad assembles; the start is the closed point nearest the guess found by Newton
    from a few offsets into the band.
    """
    from mjstruct.kinematics.closure_newton import newton

    n = guess.size
    h = 1e-7 * max(1.0, float(np.abs(guess).max()))
    pts = np.vstack([guess, guess + h * np.eye(n)])
    ev = evaluate(model, np.repeat(q[None, :], n + 1, 0), order=0, t=pts, K=K, only=only)
    disc = ev.diag[k][0]
    if not np.isfinite(disc).all():
        return None
    grad = (disc[1:] - disc[0]) / h
    g2 = float(grad @ grad)
    if g2 == 0.0:
        return None
    # the edge along the gradient: disc is smooth there (a Newton step or two)
    edge = guess - disc[0] * grad / g2
    for _ in range(3):
        ev = evaluate(model, q[None, :], order=0, t=edge[None, :], K=K, only=only)
        d = float(ev.diag[k][0][0])
        if not np.isfinite(d):
            return None
        edge = edge - d * grad / g2
    unit = grad / np.sqrt(g2)
    back = max(float(np.abs(edge - guess).max()), 1e-12)
    offsets = np.array([o * back for o in BAND_OFFSETS])
    starts = edge[None, :] + offsets[:, None] * unit[None, :]
    Ks = {
        kk: (np.repeat(v, offsets.size) if isinstance(v, np.ndarray) else v) for kk, v in K.items()
    }
    t, _, _, ok = newton(model, np.repeat(q[None, :], offsets.size, 0), starts, Ks, maxiter=40)
    if not ok.any():
        return None
    best = int(np.argmin(np.where(ok, np.abs(t - guess).max(axis=1), np.inf)))
    return np.asarray(t[best], dtype=float)
