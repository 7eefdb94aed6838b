"""Newton stages of the closure: the residual jets, Newton on frames and on one station.

Owns what one Newton iteration of the closure is made of and the stages built on it:
the closure equations' residuals and their analytic Jacobian from one evaluation
(:func:`closure_jets`: the seeds sit on the evaluation's seed axis, positions computed
once for all), the vectorised Newton over frames with per-frame masks
(:func:`newton`; :func:`newton_with_tangent` also gives t' from its last round), Newton at one
continuation station (:func:`station_newton`), the walk to a frame Newton missed
(:func:`repair`) and the unknowns' derivatives from the differentiated closure
equations, ``R_t t' = -R_q`` and ``R_t t'' = -R''`` (:func:`derivatives`).  Every
evaluation the closure makes goes through this module's ``evaluate``.

Examples
--------
>>> import numpy as np
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.kinematics.model import KinematicModel
>>> model = KinematicModel.build(read_mechanism(example_path("class-iv-seed003")))
>>> q = model.q_ref[None, :] + 0.1
>>> t, err, iterations, ok = newton(model, q, np.zeros((1, model.plan.unknowns)))
>>> bool(ok[0]), bool(err[0] < 1e-12)
(True, True)
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from mjstruct.kinematics.closure_path import row_max
from mjstruct.kinematics.evaluate import Evaluation, evaluate
from mjstruct.kinematics.steps.base import Modes
from mjstruct.kinematics.tolerances import NEWTON_TOL, STALL_ERROR
from mjstruct.typing import BoolArray, FloatArray

if TYPE_CHECKING:
    from mjstruct.kinematics.model_view import ModelView


def closing_steps(model: ModelView) -> tuple[int, ...] | None:
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


def seeded_jets(
    model: ModelView,
    q: FloatArray,
    t: FloatArray,
    K: Modes | None,
    only: tuple[int, ...] | None,
    rates: FloatArray | None = None,
    lead: FloatArray | None = None,
    order: int = 1,
    keep_carried: bool = False,
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
    for j in range(k):  # seed first + j: t' = e_j (np.eye's values, without its cost)
        seeds[first + j, :, j] = 1.0
    dq = np.zeros((n, q.shape[1]))
    if rates is not None:
        dq[0] = rates
        if lead is not None:
            seeds[0] = lead
    ev = evaluate(
        model, q, order=order, rates=dq, t=t, t1=seeds, K=K, only=only, keep_carried=keep_carried
    )
    shape = (n, F, model.plan.equations)
    out = [ev.residual_matrix(i) for i in range(1, order + 1)]
    # a derivative that depends on no seed has no seed axis
    return ev, [r if r.shape == shape else np.broadcast_to(r, shape) for r in out]


def closure_jets(
    model: ModelView,
    q: FloatArray,
    t: FloatArray,
    K: Modes | None = None,
    rates: FloatArray | None = None,
    only: tuple[int, ...] | None = None,
    keep: list[Evaluation] | None = None,
) -> tuple[FloatArray, FloatArray, FloatArray | None]:
    """R (F, e), dR/dt (F, e, k) and, given ``rates``, dR/dτ at fixed t: one evaluation.

    One seed per unknown (and one along ``rates`` with t' = 0 when given) on the
    evaluation's seed axis: the positions are computed once, and a Newton iteration
    or a tangent costs one call of :func:`~mjstruct.kinematics.evaluate.evaluate`
    whatever the number of unknowns; the first derivative along each seed is a column
    exactly.  ``keep``: the evaluation is appended to it (its positions serve an
    evaluation of higher order at the same point).
    """
    ev, (R1,) = seeded_jets(model, q, t, K, only, rates, keep_carried=keep is not None)
    first = 0 if rates is None else 1
    # (seed, frame, equation) -> (frame, equation, seed): np.moveaxis(·, 0, -1) as a
    # plain transpose
    out = ev.residual_matrix(0), R1[first:].transpose(1, 2, 0), (R1[0] if first else None)
    if keep is not None:
        ev.truncate(0)  # the positions serve; the seeds' derivatives do not
        keep.append(ev)
    return out


def closure_jacobian(
    model: ModelView, q: FloatArray, t: FloatArray, K: Modes | None = None
) -> tuple[FloatArray, FloatArray]:
    """Residuals R (F, e) and the analytic Jacobian dR/dt (F, e, k) at unknowns ``t``."""
    R, J, _ = closure_jets(model, q, t, K, only=closing_steps(model))
    return R, J


def largest(R: FloatArray) -> FloatArray:
    """max |R| of each row (frames × equations): the closure error in lengths."""
    return row_max(np.abs(R))


def solve_stacked(J: FloatArray, b: FloatArray) -> FloatArray:
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


def newton_step(J: FloatArray, R: FloatArray) -> FloatArray:
    """Newton step -J⁻¹R, non-finite parts zeroed, at most half a radian."""
    step = -solve_stacked(J, R)
    step = np.where(np.isfinite(step), step, 0.0)
    big = row_max(np.abs(step))[:, None]
    out: FloatArray = step * np.minimum(1.0, 0.5 / np.maximum(big, 1e-300))
    return out


def newton(
    model: ModelView,
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
    t, err, rounds, ok, _, _ = newton_with_tangent(
        model, q, t0, K, tol, maxiter, closing_steps(model)
    )
    return t, err, rounds, ok


def newton_with_tangent(
    model: ModelView,
    q: FloatArray,
    t0: FloatArray,
    K: Modes | None,
    tol: float,
    maxiter: int,
    only: tuple[int, ...] | None,
    rates: FloatArray | None = None,
    keep: list[Evaluation] | None = None,
) -> tuple[FloatArray, FloatArray, int, BoolArray, FloatArray, FloatArray | None]:
    """:func:`newton`, also returning dR/dt at the final t and, with ``rates``, dt/dτ.

    One evaluation per round gives the residual at the trial point and its Jacobian:
    the line search is the next round (a trial that does not assemble, or more than
    doubles max |R| while outside ``tol``, is halved back toward the last accepted
    point, at most 8 times).  With ``rates``, the rounds from the second on carry one
    more seed, dR/dτ, so the tangent at the final point costs no evaluation of its
    own; no frame stops at the first round then (its step is at the rounding level
    where the guess is already closed).  A frame stops after ``2 * maxiter`` evaluations,
    halvings included, or where even the halved trial does not assemble.  ``keep``:
    when the last round evaluated every frame at the t returned, its evaluation is
    appended to it.
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
            held: list[Evaluation] | None = None if keep is None else []
            R, J, Rd = closure_jets(model, q, t, K, seed, only, held)
        else:
            held = None
            R, J, Rd = closure_jets(model, q[idx], t[idx], subset_modes(K, idx), seed, only)
        rmax = largest(R)
        g: slice | npt.NDArray[np.intp] = sel
        # no step to halve before a frame's first evaluation
        if rounds > 1:
            bad = ~np.isfinite(rmax) | ((rmax > 2.0 * rbase[sel]) & (rmax > tol * scale))
            bad &= (halved[sel] < 8) & (evals[sel] > 0)
        if rounds > 1 and bad.any():
            b = idx[bad]
            alpha[b] *= 0.5
            halved[b] += 1
            t[b] = base[b] + alpha[b, None] * step[b]
            good = ~bad
            g, idx, R, J, rmax = idx[good], idx[good], R[good], J[good], rmax[good]
            Rd = None if Rd is None else Rd[good]
        e = rmax / scale
        # with rates no frame stops at the first round (below): no test then
        first = rates is not None and rounds == 1
        stalled = None if first else e >= 0.5 * err[g]
        err[g] = e
        base[g] = t[g]
        rbase[g] = rmax
        evals[g] += 1
        if last is None:
            last = np.full((F, *J.shape[1:]), np.nan)
        last[g] = J
        if tangent is not None and Rd is not None:
            tangent[g] = -solve_stacked(J, Rd)
        if stalled is None:
            done = np.zeros(e.shape, bool)
        else:
            done = (e <= tol) | (stalled & (e <= STALL_ERROR * tol))
        spent = ~done & ((evals[g] >= maxiter) | (tries[g] >= 2 * maxiter) | ~np.isfinite(e))
        stop = done | spent
        if stop.any():
            ok[idx[done]] = True
            active[idx[stop]] = False
            go = ~stop
            if not go.any():
                if held and isinstance(g, slice) and keep is not None:
                    keep += held  # every frame evaluated at its final t in this round
                continue
            g, J, R = idx[go], J[go], R[go]
        step[g] = newton_step(J, R)
        alpha[g], halved[g] = 1.0, 0
        t[g] = base[g] + step[g]
    assert last is not None
    return base, err, rounds, ok | (err <= tol), last, tangent


def station_newton(
    model: ModelView,
    q: FloatArray,
    guess: FloatArray,
    K: Modes | None,
    tol: float,
    maxiter: int,
    only: tuple[int, ...] | None,
    dirn: FloatArray,
) -> tuple[FloatArray, FloatArray | None]:
    """Newton at one continuation station: the unknowns and their tangent along ``dirn``.

    :func:`newton_with_tangent` for one frame without the per-frame bookkeeping (stations are
    many small calls): one evaluation per iteration gives R, dR/dt and dR/dτ, so the
    tangent at the converged point costs nothing more.  None: it did not close (as in
    :func:`newton_with_tangent`, at most ``2 * maxiter`` evaluations, and a trial that does not
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
            return t, -solve_stacked(J, Rd)[0]
        errors.append(e)
        if evals >= maxiter or (evals > 3 and min(errors[-3:]) > 0.5 * min(errors[:-3])):
            return t, None
        base, rbase = t, rmax
        step = newton_step(J, R)[0]
        alpha, halved = 1.0, 0
        t = base + step
    return t, None


def subset_modes(K: Modes | None, idx: npt.NDArray[np.intp]) -> Modes | None:
    if K is None:
        return None
    return {k: (v[idx] if isinstance(v, np.ndarray) else v) for k, v in K.items()}


def repair(
    model: ModelView,
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
                    Ks = subset_modes(K, np.array([i]))
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


def tangent(
    model: ModelView,
    q: FloatArray,
    t: FloatArray,
    K: Modes | None,
    rate: FloatArray,
) -> FloatArray:
    """dt/dτ for dq/dτ = rate, from the differentiated closure equations."""
    _, J, Rd = closure_jets(model, q, t, K, rate, closing_steps(model))
    assert Rd is not None
    return -solve_stacked(J, Rd)


def derivatives(
    model: ModelView,
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
    t1 = -solve_stacked(J, Rd)
    if order < 2:
        return t1, np.full_like(t1, np.nan)
    return t1, curvature(model, q, t, t1, rate, K, J, only)


def curvature(
    model: ModelView,
    q: FloatArray,
    t: FloatArray,
    t1: FloatArray,
    rate: FloatArray,
    K: Modes | None,
    J: FloatArray,
    only: tuple[int, ...] | None,
    lower: Evaluation | None = None,
    keep: list[Evaluation] | None = None,
) -> FloatArray:
    """t'' given t' and the Jacobian dR/dt at ``t``: one evaluation of order 2.

    ``lower``: an evaluation of the same steps at ``t`` (kept by :func:`closure_jets`),
    whose positions it starts from; ``keep``: the evaluation is appended to it.
    """
    ev = evaluate(
        model,
        q,
        order=2,
        rates=rate,
        t=t,
        t1=t1,
        K=K,
        only=only,
        lower=lower,
        known=0,
        keep_carried=keep is not None,
    )
    t2 = -solve_stacked(J, ev.residual_matrix(2))
    if keep is not None:
        ev.truncate(1)  # positions and first derivatives serve (t'' was 0 here)
        keep.append(ev)
    return t2
