"""Closure of groups no triangle sequence solves: Newton on the fewest unknowns.

Owns the iteration for groups of class III and higher: assume the angle of one link
(the planner picks the fewest such unknowns), solve the class-II steps that follow,
and drive the closure equations (a computed length against the given one) to zero.
Newton runs on all frames at once with per-frame convergence masks; its Jacobian is
analytic (the same jet propagation as the analogs, seeded on the unknowns; the seeds
sit on the evaluation's seed axis, positions computed once for all, so one iteration
is one evaluation of the steps the closure reads).  Initial values come from
continuation along the path starting at the reference configuration (where every
unknown is 0, the rotation from the reference): stations not tied to the frames, a
window of up to :data:`MAX_BLOCK` of them solved together by the same vectorised
Newton (one evaluation per round for the whole
window: stations far ahead start from rough guesses and close while the ones before
them are accepted, in order, each checked against the tangent from the last), then a
quintic Hermite prediction on every frame (the stations' t and t', and t'' from one
more evaluation), close enough that Newton on the frames takes two rounds (the
second also seeded along the path: it gives t').  The number of evaluations depends
on the path's length and curvature, not on the number of frames.

The unknowns' derivatives follow from the differentiated closure equations,
``R_t t' = -R_q`` and ``R_t t'' = -R''`` (t'' by one more evaluation, when asked
for), so σ and κ stay exact.

This is Zinchenko's method for a class-IV mechanism [1]_: split the group into
class-II groups by assuming one link's position, and iterate on one length until the
group closes.

References
----------
.. [1] O. I. Zinchenko, "Kinematic analysis of a high-class mechanism using a library of
   subroutines for the analysis of second-class groups" (in Ukrainian), NTU "Kharkiv
   Polytechnic Institute", collection of papers (journal and year not given in the
   copy). [Zinchenko] in docs/references.md.

Examples
--------
>>> import numpy as np
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.kinematics.model import KinematicModel
>>> model = KinematicModel.build(read_mechanism(example_path("class-iv-seed003")))
>>> q = model.q_ref + np.linspace(0, 2 * np.pi, 73)[:-1, None]
>>> sol = close(model, q)
>>> bool(sol.converged.all()), bool(sol.error.max() < 1e-12)
(True, True)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from mjstruct.kinematics.evaluate import Evaluation, evaluate
from mjstruct.kinematics.steps.base import Modes
from mjstruct.kinematics.tolerances import (
    NEWTON_TOL,
    STALL_ERROR,
    STATION_STEP,
    STATION_TOL,
)

if TYPE_CHECKING:
    from mjstruct.kinematics.model import KinematicModel

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]

#: continuation stations solved together at most (one evaluation per Newton round:
#: on a sweep, every station of the turn); 1 is the one-station-at-a-time continuation
MAX_BLOCK = 64
#: evaluation rounds of a window station from one guess; a station still open is
#: guessed again once more is known around it (at the front: sought alone)
BLOCK_ROUNDS = 8
#: spacing of the window's stations along the path (radians of the driver, or scale
#: units): below STATION_STEP so that the quintic Hermite guess between stations is
#: good to ~1e-7 and Newton on the frames closes in two rounds
WINDOW_STEP = 0.125
#: a guess extrapolated from the last known stations is held beyond this arc from them
#: (a cubic drifts off fast; a held value still converges from most of the turn)
REACH = 0.5
#: a window station this close to closing (relative error) is known well enough to
#: guess its neighbours from and to test their agreement (Newton is then one or two
#: steps from its root)
SETTLED = 1e-6
#: a window station converging quadratically (error e at most NEAR and 1/100 of the
#: last, so the next is about e³/e_last²) whose next point is predicted within this
#: fraction of the tolerance is taken at that point without evaluating it: a round
#: less for most windows.  Its tangent is the one at the point evaluated (off by
#: about the step, ~1e-7 at most): stations only guide the frames' own Newton
PREDICTED = 1e-2
NEAR = 1e-8
#: a stuck window station is guessed again at most this often (then, at the front, it
#: is sought alone): bounds the rounds where the path leaves the feasible range
RENEWALS = 2
#: Newton iterations of a station sought alone: from the cubic through the last two it
#: converges in a few, and one that does not is tried again from half the step (near
#: the edge of the feasible range a full maxiter per try made a sweep take seconds)
STATION_ITERATIONS = 12


@dataclass(frozen=True)
class Closure:
    """Closure unknowns over the frames and how well they close.

    ``t``, ``t1``, ``t2``: the unknowns (frames × unknowns) and their first and second
    derivatives along the path (``t2`` NaN when :func:`close` was asked for less
    than order 2); ``error`` the achieved closure error per frame (max
    |R|, in lengths); ``iterations`` the Newton iterations on the full frame set;
    ``converged`` per-frame mask; ``jumps`` frames whose change of the unknowns from
    the previous frame (frame 0: from the reference) disagrees with the integrated
    derivative — a possible jump to another branch of the closure.
    """

    t: FloatArray
    t1: FloatArray
    t2: FloatArray
    error: FloatArray
    iterations: int
    converged: BoolArray
    tol: float
    jumps: tuple[int, ...] = ()
    #: frames closed by continuation from the reference the other way (past a gap)
    reseeded: tuple[int, ...] = ()


def closing_steps(model: KinematicModel) -> tuple[int, ...] | None:
    """Steps the closure equations read (in plan order), or None when that is every step.

    Newton and the derivatives of the unknowns evaluate only these: a group placed
    after the closure, that no closure equation reads, is left out.
    """
    steps = model.plan.steps
    need: set[int] = set()
    for k, s in enumerate(steps):
        if s.equations:
            need.update(model.step_dependencies[k])
    return None if len(need) == len(steps) else tuple(sorted(need))


def _seeded(
    model: KinematicModel,
    q: FloatArray,
    t: FloatArray,
    K: Modes | None,
    only: tuple[int, ...] | None,
    rates: FloatArray | None = None,
    lead: FloatArray | None = None,
    order: int = 1,
) -> tuple[Evaluation, list[FloatArray]]:
    """One evaluation seeded on every unknown (t' = e_j at rest), after a first seed
    along ``rates`` with t' = ``lead`` (0 if None) when ``rates`` is given.

    Returns the evaluation and its closure equations' derivatives 1 .. ``order``, each
    (seeds, frames, equations).
    """
    F, k = t.shape
    first = 0 if rates is None else 1
    n = k + first
    seeds = np.zeros((n, 1 if lead is None else F, k))
    seeds[first:] = np.eye(k)[:, None, :]
    dq = np.zeros((n, q.shape[1]))
    if rates is not None:
        dq[0] = rates
        if lead is not None:
            seeds[0] = lead
    ev = evaluate(model, q, order=order, rates=dq, t=t, t1=seeds, K=K, only=only)
    shape = (n, F, model.plan.equations)
    out = [ev.residual_matrix(i) for i in range(1, order + 1)]
    # a derivative that depends on no seed has no seed axis
    return ev, [r if r.shape == shape else np.broadcast_to(r, shape) for r in out]


def closure_jets(
    model: KinematicModel,
    q: FloatArray,
    t: FloatArray,
    K: Modes | None = None,
    rates: FloatArray | None = None,
    only: tuple[int, ...] | None = None,
) -> tuple[FloatArray, FloatArray, FloatArray | None]:
    """R (F, e), dR/dt (F, e, k) and, given ``rates``, dR/dτ at fixed t: one evaluation.

    One seed per unknown (and one along ``rates`` with t' = 0 when given) on the
    evaluation's seed axis: the positions are computed once, and a Newton iteration
    or a tangent costs one call of :func:`~mjstruct.kinematics.evaluate.evaluate`
    whatever the number of unknowns; the first derivative along each seed is a column
    exactly.
    """
    ev, (R1,) = _seeded(model, q, t, K, only, rates)
    first = 0 if rates is None else 1
    # (seed, frame, equation) -> (frame, equation, seed): np.moveaxis(·, 0, -1) as a
    # plain transpose
    return ev.residual_matrix(0), R1[first:].transpose(1, 2, 0), (R1[0] if first else None)


def closure_jacobian(
    model: KinematicModel, q: FloatArray, t: FloatArray, K: Modes | None = None
) -> tuple[FloatArray, FloatArray]:
    """Residuals R (F, e) and the analytic Jacobian dR/dt (F, e, k) at unknowns ``t``."""
    R, J, _ = closure_jets(model, q, t, K, only=closing_steps(model))
    return R, J


def _solve(J: FloatArray, b: FloatArray) -> FloatArray:
    """Solve the stacked systems J x = b (least squares when not square)."""
    if J.shape[-1] == 1 and J.shape[-2] == 1:
        with np.errstate(divide="ignore", invalid="ignore"):
            x: FloatArray = b / J[..., 0]
        return x
    if J.shape[-1] == J.shape[-2]:
        try:
            return np.asarray(np.linalg.solve(J, b[..., None])[..., 0], dtype=np.float64)
        except np.linalg.LinAlgError:
            pass
    # singular or not square: least squares per frame; frames with non-finite entries
    # (a step that does not assemble) have no solution
    out = np.full((*J.shape[:-2], J.shape[-1]), np.nan)
    finite = np.isfinite(J).all(axis=(-2, -1)) & np.isfinite(b).all(axis=-1)
    for i in np.flatnonzero(finite):
        out[i] = np.linalg.lstsq(J[i], b[i], rcond=None)[0]
    return out


def _newton_step(J: FloatArray, R: FloatArray) -> FloatArray:
    """Newton step -J⁻¹R, non-finite parts zeroed, at most half a radian."""
    step = -_solve(J, R)
    step = np.where(np.isfinite(step), step, 0.0)
    big = np.abs(step).max(axis=1, keepdims=True)
    out: FloatArray = step * np.minimum(1.0, 0.5 / np.maximum(big, 1e-300))
    return out


def newton(
    model: KinematicModel,
    q: FloatArray,
    t0: FloatArray,
    K: Modes | None = None,
    tol: float = NEWTON_TOL,
    maxiter: int = 30,
) -> tuple[FloatArray, FloatArray, int, BoolArray]:
    """Vectorised Newton with per-frame masks; returns t, error, iterations, converged.

    A frame converges when its closure error (max |R| / scale) is at most ``tol``, or
    when an iteration no longer halves it while it is within :data:`STALL_ERROR` times
    ``tol``: the rounding floor of a long chain of ill-conditioned groups (the error
    achieved is what is reported).  ``iterations`` counts the evaluations over the
    frames still iterating (a step halved where it would not assemble or would more
    than double the error is one more).
    """
    t, err, rounds, ok, _, _ = _newton(model, q, t0, K, tol, maxiter, closing_steps(model))
    return t, err, rounds, ok


def _newton(
    model: KinematicModel,
    q: FloatArray,
    t0: FloatArray,
    K: Modes | None,
    tol: float,
    maxiter: int,
    only: tuple[int, ...] | None,
    rates: FloatArray | None = None,
) -> tuple[FloatArray, FloatArray, int, BoolArray, FloatArray, FloatArray | None]:
    """:func:`newton`, also returning dR/dt at the final t and, with ``rates``, dt/dτ.

    One evaluation per round gives the residual at the trial point and its Jacobian:
    the line search is the next round (a trial that does not assemble, or more than
    doubles max |R| while outside ``tol``, is halved back toward the last accepted
    point, at most 8 times).  With ``rates``, the rounds from the second on carry one
    more seed, dR/dτ, so the tangent at the final point costs no evaluation of its
    own; no frame stops at the first round then (its step is at the rounding level
    where the guess is already closed).  A frame stops after ``2 * maxiter`` evaluations,
    halvings included, or where even the halved trial does not assemble.
    """
    F = t0.shape[0]
    scale = model.geometry.scale
    t, base = t0.copy(), t0.copy()
    step = np.zeros_like(t0)
    alpha = np.ones(F)
    halved = np.zeros(F, np.int64)
    evals = np.zeros(F, np.int64)
    tries = np.zeros(F, np.int64)
    rbase = np.full(F, np.inf)
    err = np.full(F, np.inf)
    active = np.ones(F, bool)
    ok = np.zeros(F, bool)
    last: FloatArray | None = None  # dR/dt at each frame's final point
    tangent = None if rates is None else np.full_like(t0, np.nan)  # dt/dτ there
    rounds = 0
    while active.any():
        rounds += 1
        # while every frame iterates (the usual first rounds) the selections are
        # slices: views, not copies of the frames' arrays
        every = bool(active.all())
        idx = np.arange(F) if every else np.flatnonzero(active)
        sel: slice | npt.NDArray[np.intp] = slice(None) if every else idx
        tries[sel] += 1
        seed = None if rounds == 1 else rates
        if every:
            R, J, Rd = closure_jets(model, q, t, K, seed, only)
        else:
            R, J, Rd = closure_jets(model, q[idx], t[idx], _subset_modes(K, idx), seed, only)
        rmax = np.abs(R).max(axis=1)
        bad = ~np.isfinite(rmax) | ((rmax > 2.0 * rbase[sel]) & (rmax > tol * scale))
        bad &= (halved[sel] < 8) & (evals[sel] > 0)
        g: slice | npt.NDArray[np.intp] = sel
        if bad.any():
            b = idx[bad]
            alpha[b] *= 0.5
            halved[b] += 1
            t[b] = base[b] + alpha[b, None] * step[b]
            good = ~bad
            g, idx, R, J, rmax = idx[good], idx[good], R[good], J[good], rmax[good]
            Rd = None if Rd is None else Rd[good]
        e = rmax / scale
        stalled = e >= 0.5 * err[g]
        err[g] = e
        base[g] = t[g]
        rbase[g] = rmax
        evals[g] += 1
        if last is None:
            last = np.full((F, *J.shape[1:]), np.nan)
        last[g] = J
        if tangent is not None and Rd is not None:
            tangent[g] = -_solve(J, Rd)
        done = (e <= tol) | (stalled & (e <= STALL_ERROR * tol))
        if rates is not None and rounds == 1:
            done[:] = False
        spent = ~done & ((evals[g] >= maxiter) | (tries[g] >= 2 * maxiter) | ~np.isfinite(e))
        stop = done | spent
        if stop.any():
            ok[idx[done]] = True
            active[idx[stop]] = False
            go = ~stop
            if not go.any():
                continue
            g, J, R = idx[go], J[go], R[go]
        step[g] = _newton_step(J, R)
        alpha[g], halved[g] = 1.0, 0
        t[g] = base[g] + step[g]
    assert last is not None
    return base, err, rounds, ok | (err <= tol), last, tangent


def _station(
    model: KinematicModel,
    q: FloatArray,
    guess: FloatArray,
    K: Modes | None,
    tol: float,
    maxiter: int,
    only: tuple[int, ...] | None,
    dirn: FloatArray,
) -> tuple[FloatArray, FloatArray | None]:
    """Newton at one continuation station: the unknowns and their tangent along ``dirn``.

    :func:`_newton` for one frame without the per-frame bookkeeping (stations are
    many small calls): one evaluation per iteration gives R, dR/dt and dR/dτ, so the
    tangent at the converged point costs nothing more.  None: it did not close (as in
    :func:`_newton`, at most ``2 * maxiter`` evaluations, and a trial that does not
    assemble even halved ends it), or it stopped converging: three iterations that
    did not halve the best error before them (past a fold Newton wanders about the
    residual's positive minimum; near one inside, it still gains at least that).
    """
    scale = model.geometry.scale
    q1 = q[None, :]
    t = guess.copy()
    base, step = t, np.zeros_like(t)
    alpha, halved, evals = 1.0, 0, 0
    rbase = err = np.inf
    errors: list[float] = []
    for _ in range(2 * maxiter):
        R, J, Rd = closure_jets(model, q1, t[None, :], K, dirn, only)
        r = R[0]
        rmax = float(np.abs(r).max())
        finite = bool(np.isfinite(r).all())
        if evals and halved < 8 and (not finite or (rmax > 2.0 * rbase and rmax > tol * scale)):
            alpha *= 0.5
            halved += 1
            t = base + alpha * step
            continue
        evals += 1
        if not finite:
            return t, None
        e = rmax / scale
        stalled = e >= 0.5 * err
        err = e
        if e <= tol or (stalled and e <= STALL_ERROR * tol):
            assert Rd is not None
            return t, -_solve(J, Rd)[0]
        errors.append(e)
        if evals >= maxiter or (evals > 3 and min(errors[-3:]) > 0.5 * min(errors[:-3])):
            return t, None
        base, rbase = t, rmax
        step = _newton_step(J, R)[0]
        alpha, halved = 1.0, 0
        t = base + step
    return t, None


def _subset_modes(K: Modes | None, idx: npt.NDArray[np.intp]) -> Modes | None:
    if K is None:
        return None
    return {k: (v[idx] if isinstance(v, np.ndarray) else v) for k, v in K.items()}


class _Path:
    """The reference followed by the frames, parametrised by arc length in q.

    Arc length is the max norm of the driver steps, so a direction's largest component
    is 1; a position on a segment's end takes that segment's direction, and the
    assembly modes of the last frame reached.  Consecutive segments of one direction
    form a run (a sweep is one run).
    """

    def __init__(self, q_ref: FloatArray, q: FloatArray) -> None:
        self.points = np.vstack([q_ref[None, :], q])
        seg = np.abs(np.diff(self.points, axis=0)).max(axis=1)
        self.arc = np.concatenate([[0.0], np.cumsum(seg)])
        self.total = float(self.arc[-1])
        self.moving = np.flatnonzero(seg > 0)
        self.ends = self.arc[self.moving + 1]
        self.frames = int(q.shape[0])
        d = self.points[self.moving + 1] - self.points[self.moving]
        self.dirs: FloatArray = d / np.abs(d).max(axis=1, keepdims=True)
        # where each moving segment's run of one direction ends (none: a path at rest)
        change = (self.dirs[1:] != self.dirs[:-1]).any(axis=1)
        starts = np.flatnonzero(np.r_[True, change]) if self.moving.size else self.moving
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
        out: npt.NDArray[np.intp] = np.clip(
            np.searchsorted(self.arc, sv, side="right") - 2, 0, self.frames - 1
        )
        return out


def _cubic(
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


def _agreement(
    t0: FloatArray, d0: FloatArray, t1: FloatArray, d1: FloatArray, ds: FloatArray
) -> BoolArray:
    """Whether each station's change of the unknowns agrees with the trapezoid of t'.

    Rows are station pairs (from ``t0``, slope ``d0``, to ``t1``, ``d1``, ``ds``
    apart).  The test that keeps the continuation on its branch: a hop to another root
    changes the unknowns by much more than the tangent integrates to.
    """
    pred = 0.5 * (d0 + d1) * ds[:, None]
    with np.errstate(invalid="ignore"):  # a tangent that is not finite: disagrees
        out: BoolArray = (
            np.abs(t1 - t0 - pred).max(axis=1) <= 0.05 * np.abs(pred).max(axis=1) + 1e-4
        )
    return out


def _finite(d: FloatArray) -> FloatArray:
    out: FloatArray = np.where(np.isfinite(d), d, 0.0)
    return out


def _tail(
    S: list[float], TT: list[FloatArray], DD: list[FloatArray]
) -> tuple[list[float], list[FloatArray], list[FloatArray]]:
    """The last two stations, or the last alone when the one before is its twin at a turn."""
    n = 2 if len(S) > 1 and S[-2] < S[-1] else 1
    return S[-n:], TT[-n:], DD[-n:]


def _continue(
    model: KinematicModel,
    path: _Path,
    K: Modes | None,
    tol: float,
    maxiter: int,
    only: tuple[int, ...] | None,
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray | None, float]:
    """Stations along ``path`` from the reference: arc positions, unknowns and tangents.

    Also returns the tangent at the reference (None: the reference does not close) and
    the arc where the stations stopped closing (inf: never): past the edge of the
    feasible range the frames are not connected to the reference by the path (they
    are left to :func:`_reseed`).  A station sits on every turn of the path, twice:
    with the tangent along the run it ends and along the one it starts (stations
    never cross a turn: the unknowns retrace their way back there).
    Stations are accepted in order: one that closes to ``tol`` and agrees with the
    trapezoid of the tangent from the last one (:func:`_agreement`).  Up to
    :data:`MAX_BLOCK` stations :data:`WINDOW_STEP` apart along a run of the path are
    solved together (:class:`_Window`), one evaluation per round, each from a guess
    by the cubic through the nearest stations known on either side (held beyond
    :data:`REACH` when there is none ahead); a closed pair that disagrees gets a
    station halfway, at once.  A station at the front that is refused gets one halfway
    before it (a second refusal guesses it again); one that is stuck (it does not
    assemble, cannot be halved or is still open after :data:`BLOCK_ROUNDS`) with
    nothing new known is sought alone by :func:`_station` (the step halving down to
    1e-4 until it agrees; one that does not close there ends the continuation).
    """
    k, scale, total = model.plan.unknowns, model.geometry.scale, path.total

    def modes(sv: FloatArray) -> Modes | None:
        return None if K is None else _subset_modes(K, path.frames_at(sv))

    def station(sv: float, guess: FloatArray) -> tuple[FloatArray, FloatArray | None]:
        s1 = np.array([sv])
        dirn = path.directions(s1)[0]
        iters = min(maxiter, STATION_ITERATIONS)
        return _station(model, path.at(s1)[0], guess, modes(s1), tol, iters, only, dirn)

    _, D0 = station(0.0, np.zeros(k))
    S, TT, DD = [0.0], [np.zeros(k)], [np.zeros(k) if D0 is None else _finite(D0)]
    win = _Window(k, path.points.shape[1])
    wdir, wend = np.zeros(0), total
    s_last, step = 0.0, STATION_STEP
    alone = False  # True from a stuck window station until the step grows back
    for _ in range(20000):
        if s_last >= total:
            break
        if S[-1] == s_last and s_last in path.turns and not (len(S) > 1 and S[-2] == s_last):
            # a turn: the station again, its tangent along the new run's direction
            new, old = path.direction_after(s_last), path.directions(np.array([s_last]))[0]
            if new.size == 1:  # one driver: the tangent is linear in its rate
                d = DD[-1] * (new[0] / old[0])
            else:
                s1 = np.array([s_last])
                d = _finite(_tangent(model, path.at(s1), TT[-1][None, :], modes(s1), new)[0])
            S.append(s_last)
            TT.append(TT[-1])
            DD.append(d)
        if MAX_BLOCK > 1 and not alone:
            if win.size == 0:
                first = min(s_last + WINDOW_STEP, path.next_turn(s_last))
                wdir = path.directions(np.array([first]))[0]
                wend = min(path.run_end(first), total)
            tail = float(win.s[-1]) if win.size else s_last
            room = MAX_BLOCK - win.size
            if room > 0 and tail < wend:
                sv = np.minimum(tail + WINDOW_STEP * np.arange(1, room + 1), wend)
                sv = sv[: int(np.searchsorted(sv, wend)) + 1]
                g = win.guess(sv, S, TT, DD)
                win.insert(np.full(sv.size, win.size), sv, path.at(sv), g)
            R, J, Rd = closure_jets(model, win.q, win.t, modes(win.s), wdir, only)
            assert Rd is not None
            rmax = np.abs(R).max(axis=1)
            finite = np.isfinite(rmax)
            e = rmax / scale
            # a trial that does not assemble or more than doubles max |R| (outside the
            # tolerance: not its rounding) is halved back
            bad = (~finite | ((rmax > 2.0 * win.rbase) & (e > tol))) & (win.evals > 0)
            stalled = (e >= 0.5 * win.err) & (e <= STALL_ERROR * tol)
            closed = ~bad & finite & ((e <= tol) | stalled)
            D = -_solve(J, Rd)
            newton = _newton_step(J, R)
            with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
                near = ~bad & finite & (e <= NEAR) & (e <= 1e-2 * win.err)
                near &= e * e * e <= PREDICTED * tol * win.err * win.err
            at = np.where(near[:, None] & ~closed[:, None], win.t + newton, win.t)
            ready = closed | near
            # accept the closed stations at the front while each agrees with the last
            c = win.size if ready.all() else int(np.argmin(ready))
            taken = 0
            if c:
                ds = win.s[:c] - np.append(s_last, win.s[: c - 1])
                fits = _agreement(
                    np.vstack([TT[-1], at[: c - 1]]),
                    np.vstack([DD[-1], _finite(D[: c - 1])]),
                    at[:c],
                    D[:c],
                    ds,
                )
                taken = c if fits.all() else int(np.argmin(fits))
                S.extend(win.s[:taken].tolist())
                TT.extend(at[:taken])
                DD.extend(_finite(D[:taken]))
                s_last = S[-1]
            refused = taken < c
            stuck = ~ready & (
                (~finite & (win.evals == 0))
                | (bad & (win.halved >= 8))
                | (win.evals + 1 >= BLOCK_ROUNDS)
            )
            live = ~stuck
            live[:taken] = False
            win.advance(newton, D, rmax, e, bad, ready, live)
            win.drop_front(taken)
            if refused and float(win.s[0]) - s_last > 1e-4:
                # closed, but too far along a curved path (or on another branch): a
                # station halfway first; a second refusal guesses it again
                mid = np.array([0.5 * (s_last + float(win.s[0]))])
                if win.refused[0]:
                    win.renew(np.arange(win.size) == 0, S, TT, DD, ahead=False)
                win.refused[0] = True
                g = win.guess(mid, S, TT, DD, ahead=False)
                win.insert(np.zeros(1, np.intp), mid, path.at(mid), g)
                continue
            if not refused:
                front_stuck = win.size > 0 and bool(stuck[taken])
                renewed = win.renew(stuck[taken:], S, TT, DD)
                if not front_stuck or renewed[0]:
                    win.split_disagreeing()
                    continue
            # refused at the smallest step (a root of another branch near a fold), or
            # stuck at the front with nothing new known: sought alone, the step halving
            # (one station at a time) until one closes or the edge is reached, where a
            # refusal at the smallest step is the edge
            step = float(win.s[0]) - s_last
            win.drop_front(win.size)
            alone = True
        # one station alone (after a stuck window station, or outside the feasible range)
        s_new = min(s_last + step, path.next_turn(s_last))
        ds1 = s_new - s_last
        s2, t2, d2 = _tail(S, TT, DD)
        if len(s2) > 1:  # cubic through the last two stations, extrapolated
            g = _cubic(s2[0], t2[0], d2[0], s2[1], t2[1], d2[1], np.array([s_new]))[0]
        else:
            g = TT[-1] + DD[-1] * ds1
        tn, Dn = station(s_new, g)
        # (after skipped stations the trapezoid spans only the last step: as before)
        fine = Dn is not None and bool(
            _agreement(TT[-1][None], DD[-1][None], tn[None], Dn[None], np.array([ds1]))[0]
        )
        if not fine and step <= 1e-4:
            # the edge of the feasible range: no station closes, or the one that does
            # is not on the branch followed (across a fold, where the two meet)
            return np.array(S), np.array(TT), np.array(DD), D0, s_new
        if fine and Dn is not None:
            S.append(s_new)
            TT.append(tn)
            DD.append(_finite(Dn))
            step = min(2.0 * step, STATION_STEP)
            # back to the window once the step has grown to its spacing (near an edge
            # a fresh window would only get stuck again at its front)
            alone = step < WINDOW_STEP
            s_last = s_new
        else:
            step *= 0.5
    return np.array(S), np.array(TT), np.array(DD), D0, np.inf


class _Window:
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
        return {
            "s": sv,
            "q": qv,
            "t": g,
            "base": g.copy(),
            "step": np.zeros_like(g),
            "d": np.zeros_like(g),
            "alpha": np.ones(n),
            "halved": np.zeros(n, np.int64),
            "rbase": np.full(n, np.inf),
            "err": np.full(n, np.inf),
            "evals": np.zeros(n, np.int64),
            "closed": np.zeros(n, bool),
            "refused": np.zeros(n, bool),
            "known": np.full(n, known),
            "renewals": np.zeros(n, np.int64),
        }

    def _anchors(
        self, S: list[float], TT: list[FloatArray], DD: list[FloatArray]
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        # the last two accepted stations and the window's closed stations
        c = self.closed
        S, TT, DD = _tail(S, TT, DD)
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
            x, y, dy = (np.asarray(v) for v in _tail(S, TT, DD))
        if x.size == 1:
            line: FloatArray = y[0] + dy[0] * (np.minimum(sv, x[0] + REACH) - x[0])[:, None]
            return line
        j = np.clip(np.searchsorted(x, sv), 1, x.size - 1)
        inside = sv < x[-1]
        i0 = np.where(inside, j - 1, x.size - 2)
        i1 = np.where(inside, j, x.size - 1)
        held = np.where(inside, sv, np.minimum(sv, x[-1] + REACH))
        return _cubic(x[i0], y[i0], dy[i0], x[i1], y[i1], dy[i1], held)

    def insert(
        self,
        at: npt.NDArray[np.intp],
        sv: FloatArray,
        qv: FloatArray,
        g: FloatArray,
        known: int = 0,
    ) -> None:
        """New stations at ``sv`` (driver values ``qv``), guesses ``g``, before ``at``."""
        # np.insert's result in one gather per field: new station j lands at at[j] + j
        n, m = self.size, sv.size
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
        if not mask.any():
            return mask
        known = len(S) + int(self.closed.sum())
        # at most RENEWALS times each: the count of closed stations can go up and down
        redo = mask & (self.known < known) & (self.renewals < RENEWALS)
        if redo.any():
            self.renewals[redo] += 1
            for name, v in self._fresh(
                self.s[redo], self.q[redo], self.guess(self.s[redo], S, TT, DD, ahead), known
            ).items():
                if name not in ("s", "q", "renewals"):
                    getattr(self, name)[redo] = v
        return redo

    def split_disagreeing(self) -> None:
        """A station halfway between each closed neighbour pair that disagrees."""
        settled = int(self.closed.sum())
        if settled == self.checked:  # no station settled since the last look
            return
        self.checked = settled
        ds = np.diff(self.s)
        pair = self.closed[1:] & self.closed[:-1] & (ds > 1e-4)
        if not pair.any():
            return
        # every neighbour pair at once (slices: cheaper than gathering the closed ones)
        far = pair & ~_agreement(self.base[:-1], self.d[:-1], self.base[1:], self.d[1:], ds)
        if far.any():
            i = np.flatnonzero(far)
            mid = 0.5 * (self.s[i] + self.s[i + 1])
            # within a run the path is straight in q: the midpoint in arc is in q too
            qmid = 0.5 * (self.q[i] + self.q[i + 1])
            g = _cubic(
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
        D: FloatArray,
        rmax: FloatArray,
        e: FloatArray,
        bad: BoolArray,
        closed: BoolArray,
        live: BoolArray,
    ) -> None:
        """One round for the ``live`` stations: ``bad`` trials halved, the rest take
        their Newton step (``newton``, the step from each station's trial point)."""
        first = int(np.argmax(live)) if live.any() else live.size
        g: slice | BoolArray
        if live[first:].all() and not bad[first:].any():
            g = slice(first, None)  # the usual round: every station from the first steps
        else:
            b = bad & live
            if b.any():
                self.alpha[b] *= 0.5
                self.halved[b] += 1
                self.t[b] = self.base[b] + self.alpha[b, None] * self.step[b]
            g = ~bad & live
            if not g.any():
                return
        self.err[g] = e[g]
        self.base[g] = self.t[g]
        self.rbase[g] = rmax[g]
        self.d[g] = _finite(D[g])
        self.closed[g] = closed[g] | (e[g] <= SETTLED)
        self.evals[g] += 1
        self.step[g] = newton[g]
        self.alpha[g], self.halved[g] = 1.0, 0
        self.t[g] = self.base[g] + self.step[g]


def close(
    model: KinematicModel,
    q: FloatArray,
    rates: npt.ArrayLike | None = None,
    K: Modes | None = None,
    tol: float = NEWTON_TOL,
    maxiter: int = 30,
    reseed: bool = True,
    order: int = 2,
) -> Closure:
    """Solve the closure unknowns on frames ``q`` (frames × drivers), then their derivatives.

    The frames are taken as a path: continuation runs from the reference configuration
    to frame 0, then along the frames (:func:`_continue`: stations :data:`WINDOW_STEP`
    apart, solved a window at a time, or at most :data:`STATION_STEP` apart one at a
    time), a Hermite prediction fills in every frame (quintic with the stations' t'',
    :func:`_station_curvature`), and one vectorised Newton polishes the frames the
    stations reached (not those past the edge of the feasible range, where the
    continuation stops).  Each Newton iteration, at the stations or over all frames, is one
    evaluation of the steps the closure reads (:func:`closing_steps`); a station's last
    one also gives its tangent, so the number of evaluations depends on the path's
    length and curvature, not on the number of frames.

    Frames equal to the reference close there (unknowns 0).  With ``reseed``, frames
    the path did not reach (beyond an infeasible stretch) are sought by continuation
    from the reference the other way (:func:`_reseed`); ``reseeded`` lists them.
    ``order`` 2 gives t''; below 2, ``t2`` is NaN (t' is always computed: the
    branch-jump test reads it).
    """
    k = model.plan.unknowns
    q_ref = model.q_ref
    rate = np.ones(q.shape[1]) if rates is None else np.asarray(rates, float)
    only = closing_steps(model)
    # 1. continuation along the path reference -> frame 0 -> ... -> last frame
    path = _Path(q_ref, q)
    tight = min(tol, STATION_TOL)  # stations are few: always close them tightly
    S, TT, DD, D0, gap = _continue(model, path, K, tight, maxiter, only)
    dir0 = path.directions(np.zeros(1))[0]
    # 3. Hermite guess on every frame from the stations that closed (quintic, with the
    # stations' t'', along a single run), then Newton on the frames the stations reached
    DD2 = _station_curvature(model, path, S, TT, DD, K, only)
    guess = _hermite(S, TT, DD, path.arc[1:], DD2)
    reached = path.arc[1:] < gap
    # (Newton's rounds from the second also give dt/dτ: t' costs no evaluation more)
    t1: FloatArray | None
    if reached.all():
        t, err, iters, ok, J, t1 = _newton(model, q, guess, K, tol, maxiter, only, rate)
    else:
        F, r = q.shape[0], np.flatnonzero(reached)
        t, err, ok = np.full((F, k), np.nan), np.full(F, np.nan), np.zeros(F, bool)
        J = np.full((F, model.plan.equations, k), np.nan)
        t1 = np.full((F, k), np.nan)
        iters = 0
        if r.size:
            t[r], err[r], iters, ok[r], J[r], t1[r] = _newton(
                model, q[r], guess[r], _subset_modes(K, r), tol, maxiter, only, rate
            )
    assert t1 is not None
    # frames Newton missed among those reached (a prefix of the frames: the arc grows
    # along them) are walked to from a closed neighbour; past the gap it would only
    # walk the same path into the same edge
    n = int(reached.sum())
    if not ok[:n].all() and ok[:n].any():
        Kn = K if n == q.shape[0] else _subset_modes(K, np.arange(n))
        fixed = _repair(model, q[:n], t[:n], err[:n], ok[:n], Kn, tol, maxiter)
        if fixed.size:
            _, J[fixed], Rd = closure_jets(
                model, q[fixed], t[fixed], _subset_modes(K, fixed), rate, only
            )
            assert Rd is not None
            t1[fixed] = -_solve(J[fixed], Rd)
    t2 = _curvature(model, q, t, t1, rate, K, J, only) if order >= 2 else np.full_like(t, np.nan)
    # 4. the reference configuration closes by construction (every unknown 0), and
    # frames the path from frame 0 did not reach are sought from the reference again
    at_ref = np.flatnonzero(~ok & (np.abs(q - q_ref).max(axis=1) == 0))
    if at_ref.size:
        R0, _, _ = closure_jets(
            model, q[at_ref], np.zeros((at_ref.size, k)), _subset_modes(K, at_ref), None, only
        )
        e0 = np.abs(R0).max(axis=1) / model.geometry.scale
        t[at_ref], err[at_ref], t1[at_ref], t2[at_ref] = 0.0, e0, np.nan, np.nan
        ok[at_ref] = e0 <= STALL_ERROR * tol
        if ok[at_ref].any():
            r = at_ref[ok[at_ref]]
            t1[r], t2[r] = derivatives(model, q[r], t[r], rate, _subset_modes(K, r), order)
    reseeded: tuple[int, ...] = ()
    if reseed and not ok.all():
        # where the path's first run from the reference met the edge, continuing from
        # the reference along that ray again would only meet it again
        edge = (dir0, gap) if K is None and gap <= path.run_end(0.0) else None
        reseeded = _reseed(model, q, rate, K, tol, maxiter, t, t1, t2, err, ok, order, edge)
    if q.shape[1] == 1 and D0 is not None and dir0[0] != 0:
        d0 = D0 * (rate[0] / dir0[0])  # the tangent is linear in the driver rates
    else:
        d0 = _tangent(
            model, q_ref[None, :], np.zeros((1, k)), _subset_modes(K, np.array([0])), rate
        )[0]
    jumps = branch_jumps(q, q_ref, t, t1, d0, ok, rate)
    return Closure(t, t1, t2, err, iters, ok, tol, jumps, reseeded)


def _reseed(
    model: KinematicModel,
    q: FloatArray,
    rate: FloatArray,
    K: Modes | None,
    tol: float,
    maxiter: int,
    t: FloatArray,
    t1: FloatArray,
    t2: FloatArray,
    err: FloatArray,
    ok: BoolArray,
    order: int = 2,
    edge: tuple[FloatArray, float] | None = None,
) -> tuple[int, ...]:
    """Continue from the reference again to the frames the path did not reach.

    Past an infeasible stretch the path's continuation has nothing to follow, yet the
    frames beyond may lie on the reference's branch, reached from the reference the
    other way (a rocking input).  A revolute driver's angle is taken modulo 2π
    (within π of the reference: the mechanism is the same), the missed frames are
    sorted by their distance from the reference on each side, and each side is
    closed by continuation from the reference.  ``edge`` (dq/ds, arc): the path left
    the reference along that direction and met the edge of the feasible range at that
    arc; frames on that ray at least as far are not sought again (the same
    continuation would stop at the same edge).  Fills ``t``, ``t1``, ``t2``, ``err``
    and ``ok`` in place; returns the frames it closed.
    """
    miss = np.flatnonzero(~ok)
    q_ref = model.q_ref
    turns = np.array([model.mechanism.joint(d).kind == "R" for d in model.drivers])
    d = q[miss] - q_ref
    d[:, turns] -= 2 * np.pi * np.round(d[:, turns] / (2 * np.pi))
    lead = np.abs(d).argmax(axis=1)
    side = np.sign(d[np.arange(miss.size), lead])
    dist = np.abs(d).max(axis=1)
    seek = np.ones(miss.size, bool)
    if edge is not None:
        with np.errstate(invalid="ignore", divide="ignore"):
            ray = np.abs(d / dist[:, None] - edge[0]).max(axis=1) <= 1e-12
        seek = ~(ray & (dist >= edge[1]))
    found: list[int] = []
    for sgn in (1.0, -1.0):
        pick = np.flatnonzero((side == sgn) & seek)
        if pick.size == 0:
            continue
        pick = pick[np.argsort(dist[pick], kind="stable")]
        frames = miss[pick]
        sol = close(
            model,
            q_ref + d[pick],
            rate,
            _subset_modes(K, frames),
            tol,
            maxiter,
            reseed=False,
            order=order,
        )
        got = sol.converged
        fr = frames[got]
        t[fr], t1[fr], t2[fr], err[fr] = sol.t[got], sol.t1[got], sol.t2[got], sol.error[got]
        ok[fr] = True
        found += [int(i) for i in fr]
    return tuple(sorted(found))


def branch_jumps(
    q: FloatArray,
    q_ref: FloatArray,
    t: FloatArray,
    t1: FloatArray,
    d0: FloatArray,
    ok: BoolArray,
    rate: FloatArray,
) -> tuple[int, ...]:
    """Frames where Δt disagrees with the trapezoid of t' along the path (branch jumps).

    ``q`` frames × drivers and ``t``, ``t1`` the unknowns and their derivatives on them;
    the path starts at ``q_ref`` (unknowns 0, derivative ``d0``); ``ok`` the frames that
    closed; ``rate`` dq/dτ.

    >>> q = np.linspace(0.1, 1.0, 10)[:, None]
    >>> t = 0.5 * q; t[6:] += 1.0                     # another branch from frame 6 on
    >>> ones = np.ones(1)
    >>> branch_jumps(q, 0 * ones, t, np.full((10, 1), 0.5), 0.5 * ones, q[:, 0] > 0, ones)
    (6,)
    """
    qs = np.vstack([q_ref[None, :], q])
    ts = np.vstack([np.zeros((1, t.shape[1])), t])
    ds = np.vstack([d0[None, :], t1])
    good = np.concatenate([[True], ok])
    # path parameter: dq/dτ = rate, so Δτ = Δq / rate (on the fastest driver)
    j = int(np.abs(rate).argmax())
    dtau = np.diff(qs[:, j]) / rate[j]
    pred = 0.5 * (ds[:-1] + ds[1:]) * dtau[:, None]
    real = np.diff(ts, axis=0)
    bad = np.abs(real - pred).max(axis=1) > 0.1 * np.abs(pred).max(axis=1) + 1e-3
    bad &= good[:-1] & good[1:]
    return tuple(int(i) for i in np.flatnonzero(bad))


def _repair(
    model: KinematicModel,
    q: FloatArray,
    t: FloatArray,
    err: FloatArray,
    ok: BoolArray,
    K: Modes | None,
    tol: float,
    maxiter: int,
) -> npt.NDArray[np.intp]:
    """Frames the vectorised pass missed: walk to each from a closed neighbour.

    Sequential, but only over the failed frames (near singular stretches where the
    interpolated guess is poor); substeps halve until Newton follows the branch.
    Returns the frames it closed.
    """
    F = q.shape[0]
    fixed: list[int] = []
    for order in (range(1, F), range(F - 2, -1, -1)):
        for i in order:
            j = i - 1 if order.step == 1 else i + 1
            if ok[i] or not ok[j]:
                continue
            for n in (1, 2, 4, 8, 16, 32):
                cur = t[j].copy()
                good = True
                for s in range(1, n + 1):
                    qs = q[j] + (q[i] - q[j]) * (s / n)
                    Ks = _subset_modes(K, np.array([i]))
                    tn, en, _, okn = newton(model, qs[None, :], cur[None, :], Ks, tol, maxiter)
                    if not okn[0]:
                        good = False
                        break
                    cur = tn[0]
                if good:
                    t[i], err[i], ok[i] = cur, en[0], True
                    fixed.append(i)
                    break
    return np.array(fixed, dtype=np.intp)


def _tangent(
    model: KinematicModel,
    q: FloatArray,
    t: FloatArray,
    K: Modes | None,
    rate: FloatArray,
) -> FloatArray:
    """dt/dτ for dq/dτ = rate, from the differentiated closure equations."""
    _, J, Rd = closure_jets(model, q, t, K, rate, closing_steps(model))
    assert Rd is not None
    return -_solve(J, Rd)


def derivatives(
    model: KinematicModel,
    q: FloatArray,
    t: FloatArray,
    rate: FloatArray,
    K: Modes | None = None,
    order: int = 2,
) -> tuple[FloatArray, FloatArray]:
    """t' and t'' along the path: ``R_t t' = -R_q q'`` then ``R_t t'' = -R''|_{t''=0}``.

    With ``order`` below 2, t'' is not computed (NaN).
    """
    only = closing_steps(model)
    _, J, Rd = closure_jets(model, q, t, K, rate, only)
    assert Rd is not None
    t1 = -_solve(J, Rd)
    if order < 2:
        return t1, np.full_like(t1, np.nan)
    return t1, _curvature(model, q, t, t1, rate, K, J, only)


def _curvature(
    model: KinematicModel,
    q: FloatArray,
    t: FloatArray,
    t1: FloatArray,
    rate: FloatArray,
    K: Modes | None,
    J: FloatArray,
    only: tuple[int, ...] | None,
) -> FloatArray:
    """t'' given t' and the Jacobian dR/dt at ``t``: one evaluation of order 2."""
    ev = evaluate(model, q, order=2, rates=rate, t=t, t1=t1, K=K, only=only)
    return -_solve(J, ev.residual_matrix(2))


def _station_curvature(
    model: KinematicModel,
    path: _Path,
    S: FloatArray,
    TT: FloatArray,
    DD: FloatArray,
    K: Modes | None,
    only: tuple[int, ...] | None,
) -> FloatArray | None:
    """t'' at the stations, from one evaluation; None for one station, or off a single
    run of a path of several drivers.

    Seeds t' = DD along the path (seed 0) and t' = e_j at rest (seed j) at order 2:
    seed 0 gives R'' at t'' = 0, and seed j's first derivative column j of dR/dt, so
    ``R_t t'' = -R''`` is solved without another evaluation of the Jacobian.  With one
    driver the path turns only by reversing (dq/ds = ±1): t'' is the same both ways,
    and the tangents are taken along the first run's direction.
    """
    if S.size < 2 or path.moving.size == 0:
        return None
    if path.turns.size:
        if path.points.shape[1] > 1:
            return None
        # each station's run direction (the second of a pair at a turn: the new run's)
        sign = path.directions(S)[:, 0] * path.dirs[0, 0]
        twin = np.flatnonzero(np.r_[False, S[1:] == S[:-1]])
        sign[twin] = [path.direction_after(float(S[i]))[0] * path.dirs[0, 0] for i in twin]
        DD = DD * sign[:, None]
    K = None if K is None else _subset_modes(K, path.frames_at(S))
    _, (R1, R2) = _seeded(model, path.at(S), TT, K, only, path.dirs[0], DD, order=2)
    return _finite(-_solve(R1[1:].transpose(1, 2, 0), R2[0]))


def _hermite(
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
    i = np.clip(np.searchsorted(x, xi, side="right") - 1, 0, x.size - 2)
    h = (x[i + 1] - x[i])[:, None]
    s = ((xi - x[i])[:, None]) / h
    # the basis by products (numpy's power takes a slow general path for the cube)
    s2 = s * s
    s3 = s2 * s
    if d2y is not None:
        s4 = s3 * s
        s5 = s4 * s
        g0 = 10 * s3 - 15 * s4 + 6 * s5
        quintic: FloatArray = (
            (1 - g0) * y[i]
            + g0 * y[i + 1]
            + h
            * ((s - 6 * s3 + 8 * s4 - 3 * s5) * dy[i] + (-4 * s3 + 7 * s4 - 3 * s5) * dy[i + 1])
            + 0.5
            * h
            * h
            * ((s2 - 3 * s3 + 3 * s4 - s5) * d2y[i] + (s3 - 2 * s4 + s5) * d2y[i + 1])
        )
        return quintic
    h01 = 3 * s2 - 2 * s3
    h00 = 1 - h01
    h10 = s3 - 2 * s2 + s
    h11 = s3 - s2
    return h00 * y[i] + h10 * h * dy[i] + h01 * y[i + 1] + h11 * h * dy[i + 1]
