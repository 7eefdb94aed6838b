"""Closure of groups no triangle sequence solves: Newton on the fewest unknowns.

Owns the entry point :func:`close` and its result :class:`Closure`: the iteration
for groups of class III and higher: assume the angle of one link (the planner picks
the fewest such unknowns), solve the class-II steps that follow, and drive the closure
equations (a computed length against the given one) to zero.  Initial values come
from continuation along the path starting at the reference configuration (where every
unknown is 0, the rotation from the reference), then a quintic Hermite prediction on
every frame (the stations' t and t', and t'' from one more evaluation), close enough
that Newton on the frames takes two rounds (the second also seeded along the path: it
gives t').  Frames the path did not reach are sought from the reference again
(:func:`_reseed`), and a change of the unknowns that their derivative does not allow
is reported (:func:`branch_jumps`).

The parts live beside it, one topic each:

* :mod:`~mjstruct.kinematics.closure_newton`: the residual jets and their analytic
  Jacobian (one evaluation per iteration, seeds on the evaluation's seed axis),
  Newton on all frames with per-frame masks, Newton at one station, the derivatives
  ``R_t t' = -R_q`` and ``R_t t'' = -R''`` (so σ and κ stay exact);
* :mod:`~mjstruct.kinematics.closure_continuation`: the stations along the path;
* :mod:`~mjstruct.kinematics.closure_window`: the bookkeeping of the window of
  stations solved together;
* :mod:`~mjstruct.kinematics.closure_path`: the path in driver space, the cubic and
  Hermite interpolation along it, the stations' agreement test.

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

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from mjstruct.kinematics.closure_continuation import continue_stations, station_curvature
from mjstruct.kinematics.closure_modes import ModeFlips, inner_mode_steps, reference_modes
from mjstruct.kinematics.closure_newton import (
    closing_steps,
    closure_jacobian,
    closure_jets,
    curvature,
    derivatives,
    newton,
    newton_with_tangent,
    repair,
    solve_stacked,
    subset_modes,
    tangent,
)
from mjstruct.kinematics.closure_path import ClosurePath, hermite
from mjstruct.kinematics.evaluate import Evaluation
from mjstruct.kinematics.steps.base import Modes
from mjstruct.kinematics.tolerances import NEWTON_TOL, STALL_ERROR, STATION_TOL
from mjstruct.typing import BoolArray, FloatArray

if TYPE_CHECKING:
    from mjstruct.kinematics.model_view import ModelView

__all__ = [
    "Closure",
    "branch_jumps",
    "close",
    "closing_steps",
    "closure_jacobian",
    "closure_jets",
    "derivatives",
    "newton",
]


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
    #: assembly mode (±1) per frame of each dyad inside a closure group (step index ->
    #: frames): an inner dyad's mode flips where it passes its own dead point while the
    #: group passes smoothly
    modes: dict[int, npt.NDArray[np.int8]] = field(default_factory=dict)
    #: where continuations from the reference stopped: the last station before each
    #: edge (driver values, unknowns, modes there); the closure group's limit lies
    #: within 1e-4 beyond it
    stops: tuple[tuple[FloatArray, FloatArray, Modes | None], ...] = ()
    #: dR/dt (frames × equations × unknowns) at ``t`` in the frames' ``modes``, from
    #: Newton's last round; NaN on the frames where it is not known there (not
    #: converged, closed at the reference or by reseeding): the checks' plan
    #: determinant reads it instead of evaluating the closure again
    jacobian: FloatArray | None = None


def close(
    model: ModelView,
    q: FloatArray,
    rates: npt.ArrayLike | None = None,
    K: Modes | None = None,
    tol: float = NEWTON_TOL,
    maxiter: int = 30,
    reseed: bool = True,
    order: int = 2,
    keep: list[tuple[Evaluation, Modes | None]] | None = None,
) -> Closure:
    """Solve the closure unknowns on frames ``q`` (frames × drivers), then their derivatives.

    The frames are taken as a path: continuation runs from the reference configuration
    to frame 0, then along the frames
    (:func:`~mjstruct.kinematics.closure_continuation.continue_stations`: stations
    :data:`~mjstruct.kinematics.closure_continuation.WINDOW_STEP` apart, solved a
    window at a time, or at most :data:`STATION_STEP` apart one at a time), a Hermite
    prediction fills in every frame (quintic with the stations' t'',
    :func:`~mjstruct.kinematics.closure_continuation.station_curvature`), and one
    vectorised Newton polishes the frames the stations reached (not those past the edge
    of the feasible range, where the continuation stops).  Each Newton iteration, at
    the stations or over all frames, is one evaluation of the steps the closure reads
    (:func:`closing_steps`); a station's last one also gives its tangent, so the number
    of evaluations depends on the path's length and curvature, not on the number of
    frames.

    Frames equal to the reference close there (unknowns 0).  With ``reseed``, frames
    the path did not reach (beyond an infeasible stretch) are sought by continuation
    from the reference the other way (:func:`_reseed`); ``reseeded`` lists them.
    ``order`` 2 gives t''; below 2, ``t2`` is NaN (t' is always computed: the
    branch-jump test reads it).

    ``keep``: where every frame closed in one run of Newton (nothing reseeded, none
    at the reference), the evaluation of order 2 that gave t'' (at ``t`` and ``t1``,
    ``t2`` = 0, with the steps' centres kept) and the modes it ran in are appended to
    it: an evaluation of the whole plan on the frames starts from its positions and
    first derivatives (:func:`~mjstruct.kinematics.evaluate.evaluate`'s ``lower``).
    """
    k = model.plan.unknowns
    q_ref = model.q_ref
    rate = np.ones(q.shape[1]) if rates is None else np.asarray(rates, float)
    only = closing_steps(model)
    # 1. continuation along the path reference -> frame 0 -> ... -> last frame
    path = ClosurePath(q_ref, q)
    tight = min(tol, STATION_TOL)  # stations are few: always close them tightly
    inner = inner_mode_steps(model, only)
    flips = ModeFlips(reference_modes(model, inner)) if inner else None
    S, TT, DD, D0, gap = continue_stations(model, path, K, tight, maxiter, only, flips)
    dir0 = path.directions(np.zeros(1))[0]
    # 2. the frames' modes: the inner dyads' flips met by the stations
    K0, F = K, q.shape[0]
    framed: dict[int, npt.NDArray[np.int8]] | None = None
    if flips:
        framed = _frame_modes(model, flips.modes(K, path.arc[1:], np.arange(F)), inner, F)
        K = framed
    # 3. Hermite guess on every frame from the stations that closed (quintic, with the
    # stations' t'', along a single run), then Newton on the frames the stations reached
    DD2 = station_curvature(model, path, S, TT, DD, K0, only, flips)
    guess = hermite(S, TT, DD, path.arc[1:], DD2)
    reached = path.arc[1:] < gap
    # (Newton's rounds from the second also give dt/dτ: t' costs no evaluation more)
    t1: FloatArray | None
    # Newton's last evaluation, when it was at every frame's final t (its positions
    # start the evaluation of t'')
    last: list[Evaluation] | None = [] if order >= 2 else None
    if reached.all():
        t, err, iters, ok, J, t1 = newton_with_tangent(
            model, q, guess, K, tol, maxiter, only, rate, last
        )
    else:
        r = np.flatnonzero(reached)
        t, err, ok = np.full((F, k), np.nan), np.full(F, np.nan), np.zeros(F, bool)
        J = np.full((F, model.plan.equations, k), np.nan)
        t1 = np.full((F, k), np.nan)
        iters = 0
        if r.size:
            t[r], err[r], iters, ok[r], J[r], t1[r] = newton_with_tangent(
                model, q[r], guess[r], subset_modes(K, r), tol, maxiter, only, rate
            )
    assert t1 is not None
    # frames Newton missed among those reached (a prefix of the frames: the arc grows
    # along them) are walked to from a closed neighbour; past the gap it would only
    # walk the same path into the same edge
    n = int(reached.sum())
    if not ok[:n].all() and ok[:n].any():
        Kn = K if n == q.shape[0] else subset_modes(K, np.arange(n))
        fixed = repair(model, q[:n], t[:n], err[:n], ok[:n], Kn, tol, maxiter)
        if fixed.size:
            _, J[fixed], Rd = closure_jets(
                model, q[fixed], t[fixed], subset_modes(K, fixed), rate, only
            )
            assert Rd is not None
            t1[fixed] = -solve_stacked(J[fixed], Rd)
    if flips and not ok[:n].all():
        # a frame next to a flip whose arc the two stations' sines place on the wrong
        # side: the other mode
        K = _flip_side(
            model,
            q,
            S,
            path.arc[1:],
            flips,
            K,
            guess,
            t,
            err,
            ok,
            J,
            t1,
            n,
            tol,
            maxiter,
            rate,
            only,
        )
    held: list[Evaluation] = []
    if order >= 2:
        every = bool(ok.all())
        lower = last[-1] if last and every else None
        kept = held if every and keep is not None else None
        t2 = curvature(model, q, t, t1, rate, K, J, only, lower, kept)
    else:
        t2 = np.full_like(t, np.nan)
    # 4. the reference configuration closes by construction (every unknown 0), and
    # frames the path from frame 0 did not reach are sought from the reference again
    at_ref = np.flatnonzero(~ok & (np.abs(q - q_ref).max(axis=1) == 0))
    if at_ref.size:
        if framed is not None:
            # the reference configuration itself: the reference's modes
            for kk, v in _frame_modes(model, K0, inner, F).items():
                framed[kk][at_ref] = v[at_ref]
        R0, _, _ = closure_jets(
            model, q[at_ref], np.zeros((at_ref.size, k)), subset_modes(K, at_ref), None, only
        )
        e0 = np.abs(R0).max(axis=1) / model.geometry.scale
        t[at_ref], err[at_ref], t1[at_ref], t2[at_ref] = 0.0, e0, np.nan, np.nan
        J[at_ref] = np.nan
        ok[at_ref] = e0 <= STALL_ERROR * tol
        if ok[at_ref].any():
            r = at_ref[ok[at_ref]]
            t1[r], t2[r] = derivatives(model, q[r], t[r], rate, subset_modes(K, r), order)
    reseeded: tuple[int, ...] = ()
    more: list[tuple[FloatArray, FloatArray, Modes | None]] = []
    if reseed and not ok.all():
        # where the path's first run from the reference met the edge, continuing from
        # the reference along that ray again would only meet it again
        edge = (dir0, gap) if K0 is None and gap <= path.run_end(0.0) else None
        K = _frame_modes(model, K, inner, F)
        reseeded = _reseed(
            model, q, rate, K0, tol, maxiter, t, t1, t2, err, ok, order, edge, K, more
        )
    if q.shape[1] == 1 and D0 is not None and dir0[0] != 0:
        d0 = D0 * (rate[0] / dir0[0])  # the tangent is linear in the driver rates
    else:
        d0 = tangent(
            model, q_ref[None, :], np.zeros((1, k)), subset_modes(K0, np.array([0])), rate
        )[0]
    jumps = branch_jumps(q, q_ref, t, t1, d0, ok, rate)
    modes = _frame_modes(model, K, inner, F)
    stops = [] if flips is None or flips.stop is None else [flips.stop]
    # the Jacobian at the final t only where Newton's last round (or the repair) left it
    J[~ok] = np.nan
    if reseeded:
        J[list(reseeded)] = np.nan
    if keep is not None and held and not at_ref.size and not reseeded:
        keep.append((held[0], K))
    return Closure(t, t1, t2, err, iters, ok, tol, jumps, reseeded, modes, tuple(stops + more), J)


def _frame_modes(
    model: ModelView, K: Modes | None, inner: tuple[int, ...], frames: int
) -> dict[int, npt.NDArray[np.int8]]:
    """Each inner dyad's mode on every frame (``K``'s, else the reference's)."""
    refs = reference_modes(model, inner)
    out: dict[int, npt.NDArray[np.int8]] = {}
    for k in inner:
        v = refs[k] if K is None or k not in K else K[k]
        out[k] = np.array(np.broadcast_to(np.asarray(v, dtype=np.int8), (frames,)))
    return out


def _flip_side(
    model: ModelView,
    q: FloatArray,
    S: FloatArray,
    arc: FloatArray,
    flips: ModeFlips,
    K: Modes | None,
    guess: FloatArray,
    t: FloatArray,
    err: FloatArray,
    ok: BoolArray,
    J: FloatArray,
    t1: FloatArray,
    n: int,
    tol: float,
    maxiter: int,
    rate: FloatArray,
    only: tuple[int, ...] | None,
) -> dict[int, npt.NDArray[np.int8]]:
    """Frames Newton missed between the two stations around a flip, tried with that
    dyad's other mode (kept where Newton closes near the Hermite guess).

    Fills ``t``, ``err``, ``ok``, ``J`` and ``t1`` in place; returns the frames' modes.
    """
    modes = _frame_modes(model, K, tuple(flips.reference), q.shape[0])
    for a, k in zip(flips.arcs, flips.steps, strict=True):
        j = int(np.searchsorted(S, a))
        lo, hi = S[max(j - 1, 0)], S[min(j, S.size - 1)]
        idx = np.flatnonzero(~ok[:n] & (arc[:n] >= lo) & (arc[:n] <= hi))
        if idx.size == 0:
            continue
        trial = {kk: v[idx].copy() for kk, v in modes.items()}
        trial[k] = -trial[k]
        tn, en, _, okn = newton(model, q[idx], guess[idx], trial, tol, maxiter)
        near = np.abs(tn - guess[idx]).max(axis=1) <= 1e-3
        good = okn & near
        if not good.any():
            continue
        f = idx[good]
        modes[k][f] = trial[k][good]
        t[f], err[f], ok[f] = tn[good], en[good], True
        sub = {kk: v[f] for kk, v in modes.items()}
        _, J[f], Rd = closure_jets(model, q[f], t[f], sub, rate, only)
        assert Rd is not None
        t1[f] = -solve_stacked(J[f], Rd)
    return modes


def _reseed(
    model: ModelView,
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
    modes: dict[int, npt.NDArray[np.int8]] | None = None,
    stops: list[tuple[FloatArray, FloatArray, Modes | None]] | None = None,
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
            subset_modes(K, frames),
            tol,
            maxiter,
            reseed=False,
            order=order,
        )
        got = sol.converged
        fr = frames[got]
        t[fr], t1[fr], t2[fr], err[fr] = sol.t[got], sol.t1[got], sol.t2[got], sol.error[got]
        ok[fr] = True
        if modes is not None:
            for kk, v in sol.modes.items():
                modes[kk][fr] = v[got]
        if stops is not None:
            stops += sol.stops
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
    qs = np.concatenate([q_ref[None, :], q])
    ts = np.concatenate([np.zeros((1, t.shape[1])), t])
    ds = np.concatenate([d0[None, :], t1])
    good = np.concatenate([[True], ok])
    # path parameter: dq/dτ = rate, so Δτ = Δq / rate (on the fastest driver)
    j = int(np.abs(rate).argmax())
    dtau = (qs[1:, j] - qs[:-1, j]) / rate[j]
    pred = 0.5 * (ds[:-1] + ds[1:]) * dtau[:, None]
    real = ts[1:] - ts[:-1]
    bad = np.abs(real - pred).max(axis=1) > 0.1 * np.abs(pred).max(axis=1) + 1e-3
    bad &= good[:-1] & good[1:]
    return tuple(int(i) for i in np.flatnonzero(bad))
