"""Closure of groups no triangle sequence solves: Newton on the fewest unknowns.

Owns the iteration for groups of class III and higher: assume the angle of one link
(the planner picks the fewest such unknowns), solve the class-II steps that follow,
and drive the closure equations (a computed length against the given one) to zero.
Newton runs on all frames at once with per-frame convergence masks; its Jacobian is
analytic (the same jet propagation as the analogs, seeded on the unknowns). Initial
values come from continuation along the frames starting at the reference configuration
(where every unknown is 0, the rotation from the reference).

Afterwards the unknowns' derivatives follow from the differentiated closure
equations, ``R_t t' = -R_q`` and ``R_t t'' = -R''``, so σ and κ stay exact.

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


def closure_jacobian(
    model: KinematicModel, q: FloatArray, t: FloatArray, K: Modes | None = None
) -> tuple[FloatArray, FloatArray]:
    """Residuals R (F, e) and the analytic Jacobian dR/dt (F, e, k) at unknowns ``t``."""
    F, k = t.shape
    cols = []
    R = None
    zero = np.zeros(q.shape[1])
    for j in range(k):
        seed = np.zeros((F, k))
        seed[:, j] = 1.0
        ev = evaluate(model, q, order=1, rates=zero, t=t, t1=seed, K=K)
        if R is None:
            R = ev.residual_matrix(0)
        cols.append(ev.residual_matrix(1))
    assert R is not None
    return R, np.stack(cols, axis=-1)


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
    achieved is what is reported).
    """
    t = t0.copy()
    F = t.shape[0]
    err = np.full(F, np.inf)
    active = np.ones(F, bool)
    scale = model.geometry.scale
    it = 0
    for it in range(1, maxiter + 1):  # noqa: B007 - the count is reported
        idx = np.flatnonzero(active)
        Ki = _subset_modes(K, idx)
        R, J = closure_jacobian(model, q[idx], t[idx], Ki)
        e = np.abs(R).max(axis=1) / scale
        stalled = e >= 0.5 * err[idx]
        err[idx] = e
        done = (e <= tol) | (stalled & (e <= STALL_ERROR * tol))
        active[idx[done]] = False
        idx, R, J = idx[~done], R[~done], J[~done]
        if idx.size == 0:
            break
        step = -_solve(J, R)
        step = np.where(np.isfinite(step), step, 0.0)
        # damp: at most half a radian per iteration, and back off where a dyad fails
        big = np.abs(step).max(axis=1, keepdims=True)
        step *= np.minimum(1.0, 0.5 / np.maximum(big, 1e-300))
        alpha = np.ones(idx.size)
        for _ in range(8):
            trial = t[idx] + alpha[:, None] * step
            ev = evaluate(model, q[idx], order=0, t=trial, K=_subset_modes(K, idx))
            Rn = ev.residual_matrix(0)
            bad = ~np.isfinite(Rn).all(axis=1) | (
                np.abs(Rn).max(axis=1) > 2.0 * np.abs(R).max(axis=1) + 1e-300
            )
            if not bad.any():
                break
            alpha[bad] *= 0.5
        t[idx] += alpha[:, None] * step
    ok = ~active | (err <= tol)
    return t, err, it, ok


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
) -> Closure:
    """Solve the closure unknowns on frames ``q`` (frames × drivers), then their derivatives.

    The frames are taken as a path: continuation runs from the reference configuration
    to frame 0, then along the frames (stations at most :data:`STATION_STEP` apart,
    cubic Hermite prediction in between), and one vectorised Newton polishes all frames.
    """
    F, k = q.shape[0], model.plan.unknowns
    q_ref = model.q_ref
    rate = np.ones(q.shape[1]) if rates is None else np.asarray(rates, float)
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

    T_last = np.zeros(k)
    K0 = _subset_modes(K, np.array([0]))
    D0 = _tangent(model, q_ref[None, :], T_last[None, :], K0, direction(0.0))[0]
    S, TT, DD = [0.0], [T_last], [np.where(np.isfinite(D0), D0, 0.0)]
    s_last, step, total = 0.0, STATION_STEP, float(arc[-1])
    lost = False  # True while the stations do not close (outside the feasible range)
    for _ in range(20000):
        if s_last >= total:
            break
        s_new = min(s_last + step, total)
        Ks = _subset_modes(K, np.array([frame_at(s_new)]))
        qn = q_at(s_new)[None, :]
        ds = s_new - s_last
        guess = (T_last + DD[-1] * ds)[None, :]
        tn, _, _, okn = newton(model, qn, guess, Ks, tight, maxiter)
        Dn = None
        if okn[0]:
            Dn = _tangent(model, qn, tn, Ks, direction(s_new))[0]
            pred = 0.5 * (DD[-1] + Dn) * ds
            fine = np.abs(tn[0] - T_last - pred).max() <= 0.05 * np.abs(pred).max() + 1e-4
        else:
            fine = False
        if fine or step <= 1e-4 or (lost and not okn[0]):
            if okn[0] and Dn is not None:
                T_last = tn[0]
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
    t, err, iters, ok = newton(model, q, guess, K, tol, maxiter)
    if not ok.all() and ok.any():
        _repair(model, q, t, err, ok, K, tol, maxiter)
    t1, t2 = derivatives(model, q, t, rate, K)
    d0 = _tangent(model, q_ref[None, :], np.zeros((1, k)), _subset_modes(K, np.array([0])), rate)[
        0
    ]
    jumps = branch_jumps(q, q_ref, t, t1, d0, ok, rate)
    return Closure(t, t1, t2, err, iters, ok, tol, jumps)


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
) -> None:
    """Frames the vectorised pass missed: walk to each from a closed neighbour.

    Sequential, but only over the failed frames (near singular stretches where the
    interpolated guess is poor); substeps halve until Newton follows the branch.
    """
    F = q.shape[0]
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
                    break


def _tangent(
    model: KinematicModel,
    q: FloatArray,
    t: FloatArray,
    K: Modes | None,
    rate: FloatArray,
) -> FloatArray:
    """dt/dτ for dq/dτ = rate, from the differentiated closure equations."""
    _, J = closure_jacobian(model, q, t, K)
    ev = evaluate(model, q, order=1, rates=rate, t=t, K=K)
    return -_solve(J, ev.residual_matrix(1))


def derivatives(
    model: KinematicModel,
    q: FloatArray,
    t: FloatArray,
    rate: FloatArray,
    K: Modes | None = None,
) -> tuple[FloatArray, FloatArray]:
    """t' and t'' along the path: ``R_t t' = -R_q q'`` then ``R_t t'' = -R''|_{t''=0}``."""
    _, J = closure_jacobian(model, q, t, K)
    ev = evaluate(model, q, order=1, rates=rate, t=t, K=K)
    t1 = -_solve(J, ev.residual_matrix(1))
    ev = evaluate(model, q, order=2, rates=rate, t=t, t1=t1, K=K)
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
