"""Closure of groups no triangle sequence solves: Newton on the fewest unknowns.

Owns the iteration for groups of class III and higher: assume the angle of one link
(the planner picks the fewest such unknowns), solve the class-II steps that follow,
and drive the closure equations (a computed length against the given one) to zero.
Newton runs on all frames at once with per-frame convergence masks; its Jacobian is
analytic (the same jet propagation as the analogs, seeded on the unknowns; the seeds
are stacked along the frames, so one iteration is one evaluation of the steps the
closure reads).  Initial values come from continuation along the path starting at the
reference configuration (where every unknown is 0, the rotation from the reference):
stations not tied to the frames, solved in blocks by the same vectorised Newton, then
a cubic Hermite prediction on every frame.  The number of evaluations depends on the
path's length and curvature, not on the number of frames.

Afterwards the unknowns' derivatives follow from the differentiated closure
equations, ``R_t t' = -R_q`` and ``R_t t'' = -R''``, so σ and κ stay exact.

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
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from mjstruct.kinematics.evaluate import evaluate
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

#: continuation stations solved together at most (one evaluation per Newton round);
#: 1 is the one-station-at-a-time continuation
MAX_BLOCK = 8
#: evaluation rounds for a block of stations; a station still open is left to the next
BLOCK_ROUNDS = 5


@dataclass(frozen=True)
class Closure:
    """Closure unknowns over the frames and how well they close.

    ``t``, ``t1``, ``t2``: the unknowns (frames × unknowns) and their first and second
    derivatives along the path; ``error`` the achieved closure error per frame (max
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


def _tile_modes(K: Modes | None, n: int) -> Modes | None:
    if K is None or n == 1:
        return K
    return {k: (np.tile(v, n) if isinstance(v, np.ndarray) else v) for k, v in K.items()}


def closure_jets(
    model: KinematicModel,
    q: FloatArray,
    t: FloatArray,
    K: Modes | None = None,
    rates: FloatArray | None = None,
    only: tuple[int, ...] | None = None,
) -> tuple[FloatArray, FloatArray, FloatArray | None]:
    """R (F, e), dR/dt (F, e, k) and, given ``rates``, dR/dτ at fixed t: one evaluation.

    The seeds are stacked along the frames (one block per unknown, and one with
    t' = 0 when ``rates`` is given), so a Newton iteration or a tangent costs one call
    of :func:`~mjstruct.kinematics.evaluate.evaluate` whatever the number of unknowns.
    With ``rates`` the Jacobian is the difference of two blocks (rounding of the
    larger one); without, each block is a column exactly.
    """
    F, k = t.shape
    lead = 0 if rates is None else 1
    n = k + lead
    seeds = np.zeros((n, F, k))
    for j in range(k):
        seeds[lead + j, :, j] = 1.0
    if n == 1:
        qs, ts = q, t
    else:
        # n copies stacked along the frames (concatenate: less call overhead than
        # broadcast_to + reshape on the few frames of a continuation station)
        qs = np.concatenate([q] * n)
        ts = np.concatenate([t] * n)
    ev = evaluate(
        model,
        qs,
        order=1,
        rates=np.zeros(q.shape[1]) if rates is None else rates,
        t=ts,
        t1=seeds.reshape(n * F, k),
        K=_tile_modes(K, n),
        only=only,
    )
    R = ev.residual_matrix(0)[:F]
    R1 = ev.residual_matrix(1).reshape(n, F, -1)
    # (seed, frame, equation) -> (frame, equation, seed): np.moveaxis(·, 0, -1) as a
    # plain transpose
    if rates is None:
        return R, R1.transpose(1, 2, 0), None
    return R, (R1[1:] - R1[0]).transpose(1, 2, 0), R1[0]


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
    t, err, rounds, ok, _ = _newton(model, q, t0, K, tol, maxiter, closing_steps(model))
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
    max_rounds: int | None = None,
) -> tuple[FloatArray, FloatArray, int, BoolArray, FloatArray]:
    """:func:`newton`, also returning dR/dt at the final t (with ``rates``: dt/dτ).

    One evaluation per round gives the residual at the trial point and its Jacobian:
    the line search is the next round (a trial that does not assemble, or more than
    doubles max |R|, is halved back toward the last accepted point, at most 8 times).
    ``max_rounds`` stops every frame after that many rounds (open frames not converged).
    """
    F = t0.shape[0]
    scale = model.geometry.scale
    t, base = t0.copy(), t0.copy()
    step = np.zeros_like(t0)
    alpha = np.ones(F)
    halved = np.zeros(F, np.int64)
    evals = np.zeros(F, np.int64)
    rbase = np.full(F, np.inf)
    err = np.full(F, np.inf)
    active = np.ones(F, bool)
    ok = np.zeros(F, bool)
    last: FloatArray | None = None  # dR/dt (or dt/dτ) at each frame's final point
    rounds = 0
    while active.any() and (max_rounds is None or rounds < max_rounds):
        rounds += 1
        idx = np.flatnonzero(active)
        R, J, Rd = closure_jets(model, q[idx], t[idx], _subset_modes(K, idx), rates, only)
        rmax = np.abs(R).max(axis=1)
        finite = np.isfinite(R).all(axis=1)
        bad = (~finite | (rmax > 2.0 * rbase[idx] + 1e-300)) & (halved[idx] < 8)
        bad &= evals[idx] > 0
        # most rounds halve no step and end no frame: the masks are then all of idx,
        # and their selections are skipped (views instead of copies; none is written)
        if bad.any():
            b = idx[bad]
            alpha[b] *= 0.5
            halved[b] += 1
            t[b] = base[b] + alpha[b, None] * step[b]
            good = ~bad
            ia, R, J, e = idx[good], R[good], J[good], rmax[good] / scale
            rgood, Rdg = rmax[good], None if Rd is None else Rd[good]
        else:
            ia, e, rgood, Rdg = idx, rmax / scale, rmax, Rd
        stalled = e >= 0.5 * err[ia]
        err[ia] = e
        base[ia] = t[ia]
        rbase[ia] = rgood
        evals[ia] += 1
        if last is None:
            last = np.full((F, *(J.shape[1:] if rates is None else (J.shape[2],))), np.nan)
        last[ia] = J if rates is None or Rdg is None else -_solve(J, Rdg)
        done = (e <= tol) | (stalled & (e <= STALL_ERROR * tol))
        spent = ~done & (evals[ia] >= maxiter)
        stop = done | spent
        if not stop.any():
            ig = ia
            step[ig] = _newton_step(J, R)
            alpha[ig], halved[ig] = 1.0, 0
            t[ig] = base[ig] + step[ig]
            continue
        ok[ia[done]] = True
        active[ia[stop]] = False
        go = ~stop
        ig = ia[go]
        if ig.size:
            step[ig] = _newton_step(J[go], R[go])
            alpha[ig], halved[ig] = 1.0, 0
            t[ig] = base[ig] + step[ig]
    assert last is not None
    return base, err, rounds, ok | (err <= tol), last


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
    tangent at the converged point costs nothing more.  None: it did not close.
    """
    scale = model.geometry.scale
    q1 = q[None, :]
    t = guess.copy()
    base, step = t, np.zeros_like(t)
    alpha, halved, evals = 1.0, 0, 0
    rbase = err = np.inf
    while True:
        R, J, Rd = closure_jets(model, q1, t[None, :], K, dirn, only)
        r = R[0]
        rmax = float(np.abs(r).max())
        finite = bool(np.isfinite(r).all())
        if evals and halved < 8 and (not finite or rmax > 2.0 * rbase + 1e-300):
            alpha *= 0.5
            halved += 1
            t = base + alpha * step
            continue
        evals += 1
        e = rmax / scale if finite else np.nan
        stalled = e >= 0.5 * err
        err = e
        if e <= tol or (stalled and e <= STALL_ERROR * tol):
            assert Rd is not None
            return t, -_solve(J, Rd)[0]
        if evals >= maxiter:
            return t, None
        base, rbase = t, rmax
        step = _newton_step(J, R)[0]
        alpha, halved = 1.0, 0
        t = base + step


def _subset_modes(K: Modes | None, idx: npt.NDArray[np.intp]) -> Modes | None:
    if K is None:
        return None
    return {k: (v[idx] if isinstance(v, np.ndarray) else v) for k, v in K.items()}


def close(
    model: KinematicModel,
    q: FloatArray,
    rates: npt.ArrayLike | None = None,
    K: Modes | None = None,
    tol: float = NEWTON_TOL,
    maxiter: int = 30,
    reseed: bool = True,
) -> Closure:
    """Solve the closure unknowns on frames ``q`` (frames × drivers), then their derivatives.

    The frames are taken as a path: continuation runs from the reference configuration
    to frame 0, then along the frames (stations at most :data:`STATION_STEP` apart,
    cubic Hermite prediction in between), and one vectorised Newton polishes all frames.
    Each Newton iteration, at a station or over all frames, is one evaluation of the
    steps the closure reads (:func:`closing_steps`); a station's last one also gives its
    tangent, so the number of evaluations depends on the path's length and curvature,
    not on the number of frames.

    Frames equal to the reference close there (unknowns 0).  With ``reseed``, frames
    the path did not reach (beyond an infeasible stretch) are sought by continuation
    from the reference the other way (:func:`_reseed`); ``reseeded`` lists them.
    """
    F, k = q.shape[0], model.plan.unknowns
    q_ref = model.q_ref
    rate = np.ones(q.shape[1]) if rates is None else np.asarray(rates, float)
    only = closing_steps(model)
    # 1. continuation along the path reference -> frame 0 -> ... -> last frame, by arc
    # length in q, with stations not tied to the frames; the step halves until each
    # station agrees with the trapezoid of the tangent (no hop to another root)
    tight = min(tol, STATION_TOL)  # stations are few: always close them tightly
    path = np.vstack([q_ref[None, :], q])
    seg = np.abs(np.diff(path, axis=0)).max(axis=1)
    arc = np.concatenate([[0.0], np.cumsum(seg)])
    moving = np.flatnonzero(seg > 0)

    def q_at(sv: float) -> FloatArray:
        return np.array([np.interp(sv, arc, path[:, c]) for c in range(path.shape[1])])

    ends = arc[moving + 1]

    def qs_at(sv: FloatArray) -> FloatArray:
        # q_at at every station of a block (np.interp is elementwise: the same values)
        return np.stack([np.interp(sv, arc, path[:, c]) for c in range(path.shape[1])], axis=1)

    def directions(sv: FloatArray) -> FloatArray:
        # direction at every station of a block, vectorised (the same values)
        if moving.size == 0:
            return np.zeros((sv.size, path.shape[1]))
        pos = np.searchsorted(ends, sv, side="left")
        j = moving[np.minimum(pos, moving.size - 1)]
        d: FloatArray = path[j + 1] - path[j]
        out: FloatArray = d / np.abs(d).max(axis=1, keepdims=True)
        return out

    def direction(sv: float) -> FloatArray:
        if moving.size == 0:
            return np.zeros(path.shape[1])
        pos = int(np.searchsorted(arc[moving + 1], sv, side="left"))
        j = int(moving[min(pos, moving.size - 1)])
        d: FloatArray = path[j + 1] - path[j]
        out: FloatArray = d / np.abs(d).max()
        return out

    def frame_at(sv: float) -> int:
        return int(np.clip(np.searchsorted(arc, sv, side="right") - 2, 0, F - 1))

    def station(
        sv: float, guess: FloatArray, dirn: FloatArray
    ) -> tuple[FloatArray, FloatArray | None]:
        Ks = _subset_modes(K, np.array([frame_at(sv)]))
        return _station(model, q_at(sv), guess, Ks, tight, maxiter, only, dirn)

    T_last = np.zeros(k)
    dir0 = direction(0.0)
    _, D0 = station(0.0, T_last, dir0)
    S, TT = [0.0], [T_last]
    DD = [np.zeros(k) if D0 is None else np.where(np.isfinite(D0), D0, 0.0)]
    s_last, step, total = 0.0, STATION_STEP, float(arc[-1])
    lost = False  # True while the stations do not close (outside the feasible range)
    block = min(4, MAX_BLOCK)  # stations solved together (doubles while all pass)
    for _ in range(20000):
        if s_last >= total:
            break
        if block > 1 and not lost and s_last + step < total:
            # 2a. a block of stations at the current step, Newton on all at once from a
            # quadratic prediction; the stations are then taken in order while each
            # agrees with the trapezoid of the tangent, exactly as one at a time
            sv = np.minimum(s_last + step * np.arange(1, block + 1), total)
            sv = sv[: int(np.searchsorted(sv, total)) + 1]
            dirs = directions(sv)
            if (dirs == dirs[0]).all():
                dl = (sv - s_last)[:, None]
                curv = (DD[-1] - DD[-2]) / (S[-1] - S[-2]) if len(S) > 1 else 0.0 * T_last
                Kb = None if K is None else _subset_modes(K, np.array([frame_at(x) for x in sv]))
                tb, _, _, okb, Db = _newton(
                    model,
                    qs_at(sv),
                    T_last + dl * DD[-1] + 0.5 * dl**2 * curv,
                    Kb,
                    tight,
                    maxiter,
                    only,
                    dirs[0],
                    BLOCK_ROUNDS,
                )
                taken = 0
                for i in range(sv.size):
                    ds = sv[i] - s_last
                    pred = 0.5 * (DD[-1] + Db[i]) * ds
                    if not (
                        okb[i]
                        and np.abs(tb[i] - T_last - pred).max() <= 0.05 * np.abs(pred).max() + 1e-4
                    ):
                        break
                    T_last, s_last = tb[i], float(sv[i])
                    S.append(s_last)
                    TT.append(T_last)
                    DD.append(np.where(np.isfinite(Db[i]), Db[i], 0.0))
                    taken += 1
                if taken == sv.size:
                    block = min(2 * block, MAX_BLOCK)
                    step = min(2.0 * step, STATION_STEP)
                else:
                    block = min(max(2, taken), MAX_BLOCK)
                if taken:
                    continue
                if okb[0] and step > 1e-4:  # closed but too far along a curved path
                    step *= 0.5
                    continue
        # 2b. one station (after a rejected block, near trouble, or at a reduced step)
        s_new = min(s_last + step, total)
        ds = s_new - s_last
        if len(S) > 1:  # cubic through the last two stations, extrapolated
            h = S[-1] - S[-2]
            u = (s_new - S[-2]) / h
            guess = (
                (2 * u**3 - 3 * u**2 + 1) * TT[-2]
                + (u**3 - 2 * u**2 + u) * h * DD[-2]
                + (-2 * u**3 + 3 * u**2) * TT[-1]
                + (u**3 - u**2) * h * DD[-1]
            )
        else:
            guess = T_last + DD[-1] * ds
        tn, Dn = station(s_new, guess, direction(s_new))
        if Dn is not None:
            pred = 0.5 * (DD[-1] + Dn) * ds
            fine = np.abs(tn - T_last - pred).max() <= 0.05 * np.abs(pred).max() + 1e-4
        else:
            fine = False
        if fine or step <= 1e-4 or (lost and Dn is None):
            if Dn is not None:
                T_last = tn
                S.append(s_new)
                TT.append(T_last)
                DD.append(np.where(np.isfinite(Dn), Dn, 0.0))
                lost = False
                step = min(2.0 * step, STATION_STEP)
            else:
                # a station that does not close is skipped (reported later); past the
                # edge of the feasible range stride on at the full step, not by crawling
                lost = True
                step = STATION_STEP
            s_last = s_new
        else:
            step *= 0.5
    # 3. cubic Hermite guess on every frame from the stations that closed, then Newton
    guess = _hermite(np.array(S), np.array(TT), np.array(DD), arc[1:])
    t, err, iters, ok, J = _newton(model, q, guess, K, tol, maxiter, only)
    if not ok.all() and ok.any():
        fixed = _repair(model, q, t, err, ok, K, tol, maxiter)
        if fixed.size:
            J[fixed] = closure_jets(
                model, q[fixed], t[fixed], _subset_modes(K, fixed), None, only
            )[1]
    t1, t2 = _derivatives(model, q, t, rate, K, J, only)
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
            t1[r], t2[r] = derivatives(model, q[r], t[r], rate, _subset_modes(K, r))
    reseeded: tuple[int, ...] = ()
    if reseed and not ok.all():
        reseeded = _reseed(model, q, rate, K, tol, maxiter, t, t1, t2, err, ok)
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
) -> tuple[int, ...]:
    """Continue from the reference again to the frames the path did not reach.

    Past an infeasible stretch the path's continuation has nothing to follow, yet the
    frames beyond may lie on the reference's branch, reached from the reference the
    other way (a rocking input).  A revolute driver's angle is taken modulo 2π
    (within π of the reference: the mechanism is the same), the missed frames are
    sorted by their distance from the reference on each side, and each side is
    closed by continuation from the reference.  Fills ``t``, ``t1``, ``t2``, ``err``
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
    found: list[int] = []
    for sgn in (1.0, -1.0):
        pick = np.flatnonzero(side == sgn)
        if pick.size == 0:
            continue
        pick = pick[np.argsort(dist[pick], kind="stable")]
        frames = miss[pick]
        sol = close(
            model, q_ref + d[pick], rate, _subset_modes(K, frames), tol, maxiter, reseed=False
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
) -> tuple[FloatArray, FloatArray]:
    """t' and t'' along the path: ``R_t t' = -R_q q'`` then ``R_t t'' = -R''|_{t''=0}``."""
    only = closing_steps(model)
    _, J, _ = closure_jets(model, q, t, K, None, only)
    return _derivatives(model, q, t, rate, K, J, only)


def _derivatives(
    model: KinematicModel,
    q: FloatArray,
    t: FloatArray,
    rate: FloatArray,
    K: Modes | None,
    J: FloatArray,
    only: tuple[int, ...] | None,
) -> tuple[FloatArray, FloatArray]:
    """:func:`derivatives` given the Jacobian dR/dt at ``t``."""
    ev = evaluate(model, q, order=1, rates=rate, t=t, K=K, only=only)
    t1 = -_solve(J, ev.residual_matrix(1))
    ev = evaluate(model, q, order=2, rates=rate, t=t, t1=t1, K=K, only=only)
    t2 = -_solve(J, ev.residual_matrix(2))
    return t1, t2


def _hermite(x: FloatArray, y: FloatArray, dy: FloatArray, xi: FloatArray) -> FloatArray:
    """Cubic Hermite interpolation of columns of y (slopes dy) at xi."""
    if x.size == 1:
        line: FloatArray = np.repeat(y, xi.size, axis=0) + (xi - x[0])[:, None] * dy
        return line
    i = np.clip(np.searchsorted(x, xi, side="right") - 1, 0, x.size - 2)
    h = (x[i + 1] - x[i])[:, None]
    s = ((xi - x[i])[:, None]) / h
    h00 = 2 * s**3 - 3 * s**2 + 1
    h10 = s**3 - 2 * s**2 + s
    h01 = -2 * s**3 + 3 * s**2
    h11 = s**3 - s**2
    return h00 * y[i] + h10 * h * dy[i] + h01 * y[i + 1] + h11 * h * dy[i + 1]
