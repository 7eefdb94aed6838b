"""Continuation of the closure along the path from the reference configuration.

Owns :func:`continue_stations`: stations not tied to the frames, from the reference (where
every unknown is 0) along the path, a window of up to :data:`MAX_BLOCK` of them solved
together by the vectorised Newton (:class:`~mjstruct.kinematics.closure_window.StationWindow`:
stations far ahead start from rough guesses (on a long run of a single unknown angle,
the roots of one coarse scan: :func:`scanned_roots`) and close while the ones before
them are accepted, in order, each checked against the tangent from the last), or one at a time
with the step halving near the edge of the feasible range, where the continuation
stops; and the stations' t'' from one more evaluation (:func:`station_curvature`), for
the quintic Hermite guess on the frames.  The number of evaluations depends on the
path's length and curvature, not on the number of frames.

Examples
--------
>>> import numpy as np
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.kinematics.model import KinematicModel
>>> from mjstruct.kinematics.closure_newton import closing_steps
>>> model = KinematicModel.build(read_mechanism(example_path("class-iv-seed003")))
>>> path = ClosurePath(model.q_ref, model.q_ref[None, :] + np.linspace(0, 1, 5)[:, None])
>>> S, TT, DD, D0, gap = continue_stations(model, path, None, 1e-13, 30, closing_steps(model))
>>> float(S[-1]), gap                   # the last station at the path's end; no edge met
(1.0, inf)
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from mjstruct.kinematics.closure_modes import ModeFlips, inner_mode_steps, try_flip
from mjstruct.kinematics.closure_newton import (
    closure_jets,
    largest,
    newton_step,
    seeded_jets,
    solve_stacked,
    station_newton,
    subset_modes,
    tangent,
)
from mjstruct.kinematics.closure_path import (
    ClosurePath,
    agreement,
    cubic,
    finite_or_zero,
    last_two,
)
from mjstruct.kinematics.closure_window import StationWindow
from mjstruct.kinematics.evaluate import evaluate
from mjstruct.kinematics.steps.base import Modes
from mjstruct.kinematics.tolerances import STALL_ERROR, STATION_STEP
from mjstruct.typing import FloatArray

if TYPE_CHECKING:
    from mjstruct.kinematics.model_view import ModelView


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
#: a window station converging quadratically (error e at most NEAR and 1/100 of the
#: last, so the next is about e³/e_last²) whose next point is predicted within this
#: fraction of the tolerance is taken at that point without evaluating it: a round
#: less for most windows.  Its tangent is the one at the point evaluated (off by
#: about the step, ~1e-7 at most): stations only guide the frames' own Newton
PREDICTED = 1e-2
NEAR = 1e-8
#: the smallest step of the first station beyond the reference (elsewhere 1e-4 ends
#: the continuation: the edge of the feasible range)
FIRST_STEP = 1e-12
#: Newton iterations of a station sought alone: from the cubic through the last two it
#: converges in a few, and one that does not is tried again from half the step (near
#: the edge of the feasible range a full maxiter per try made a sweep take seconds)
STATION_ITERATIONS = 12


#: a window reaching further than this beyond the last accepted station (arc, radians
#: of the driver) first guesses its stations from a scan of the residual: its held
#: guesses far from anything known cost rounds that make no progress, and on a sweep
#: some do not assemble at all.  Shorter windows (a rocking input's runs) converge
#: from their guesses in about the rounds the scan would cost
SCAN_AHEAD = 2.0
#: points of the scan over one turn of a single unknown (radians): fine enough to
#: bracket the roots of a stretch near a fold, where the range that assembles narrows
SCAN_POINTS = 48


def scanned_roots(
    model: ModelView,
    qv: FloatArray,
    K: Modes | None,
    only: tuple[int, ...] | None,
    start: float,
) -> FloatArray | None:
    """First guesses of a single unknown angle at stations ``qv`` from one scan of the residual.

    One evaluation of order 0 on :data:`SCAN_POINTS` values over one turn about
    ``start`` at every other station (and the last); the roots are bracketed by sign
    changes, placed by the quadratic through the bracket and its neighbours, and
    followed from ``start`` station by station by the one nearest the last (a coarse
    continuation).  A scanned station with no sign change (its range that assembles
    narrower than the scan's step) is guessed between its neighbours' roots; the
    stations between, by the cubic through the four scanned around them.  None: no
    root anywhere.  Only guesses: each station is still accepted by Newton and
    :func:`agreement`.

    Examples
    --------
    >>> from mjstruct.io import read_mechanism
    >>> from mjstruct.catalog_files import example_path
    >>> from mjstruct.kinematics.model import KinematicModel
    >>> model = KinematicModel.build(read_mechanism(example_path("class-iv-seed003")))
    >>> qv = model.q_ref[None, :] + 0.125 * np.arange(1, 9)[:, None]  # stations
    >>> g = scanned_roots(model, qv, None, None, 0.0)
    >>> from mjstruct.kinematics.closure import close
    >>> bool(np.abs(g - close(model, qv).t).max() < 1e-2)  # near the roots
    True
    """
    n_all = qv.shape[0]
    idx = np.arange(0, n_all + 1, 2)
    idx[-1] = min(int(idx[-1]), n_all - 1)
    idx = idx[: int(np.searchsorted(idx, n_all - 1)) + 1]
    n, G = idx.size, SCAN_POINTS
    grid = start + np.linspace(-np.pi, np.pi, G, endpoint=False)
    h = float(grid[1] - grid[0])
    Ks = None
    if K is not None:  # each scanned station's modes at its points of the scan
        Ks = {c: np.repeat(v[idx], G) if isinstance(v, np.ndarray) else v for c, v in K.items()}
    tg = np.tile(grid, n)[:, None]
    qs = np.repeat(qv[idx], G, axis=0)
    ev = evaluate(model, qs, order=0, t=tg, K=Ks, only=only)
    r = ev.residual_matrix(0)[:, 0].reshape(n, G)
    r0, r1 = r[:, :-1], r[:, 1:]
    # second differences at each grid value (NaN at the ends: none)
    d2 = np.empty((n, G + 1))
    d2.fill(np.nan)
    d2[:, 1 : G - 1] = r[:, :-2] - 2.0 * r[:, 1:-1] + r[:, 2:]
    with np.errstate(invalid="ignore", divide="ignore"):
        i, j = (r0 * r1 <= 0.0).nonzero()  # (NaN: the scan's point does not assemble)
        a, b = r0[i, j], r1[i, j]
        u = a / (a - b)  # the secant's root, a fraction of the bracket
        dl, dr = d2[i, j], d2[i, j + 1]
        okl, okr = dl == dl, dr == dr
        c2 = np.where(okl & okr, 0.5 * (dl + dr), np.where(okl, dl, np.where(okr, dr, 0.0)))
        # the quadratic a + (b - a) u + c2 u (u - 1) / 2: one Newton step from u
        u -= 0.5 * c2 * u * (u - 1.0) / ((b - a) + 0.5 * c2 * (2.0 * u - 1.0))
        root = grid[j] + h * u
    rows, roots = i.tolist(), root.tolist()
    last, m = start, 0
    at: list[int] = []
    val: list[float] = []
    for st in range(n):  # (rows are in order)
        best = None
        while m < len(rows) and rows[m] == st:
            x = roots[m]
            if x == x and (best is None or abs(x - last) < abs(best - last)):
                best = x
            m += 1
        if best is not None:
            at.append(st)
            val.append(best)
            last = best
    if not at:
        return None
    y = np.interp(np.arange(n), at, val)
    out: FloatArray = np.interp(np.arange(n_all), idx, y)[:, None]
    if n >= 4:  # a station between two scanned 2 apart: the cubic through four
        inner = idx[2:-1] - idx[1:-2] == 2
        mid = (9.0 * (y[1:-2] + y[2:-1]) - y[:-3] - y[3:]) / 16.0
        out[idx[1:-2][inner] + 1, 0] = mid[inner]
    return out


def continue_stations(
    model: ModelView,
    path: ClosurePath,
    K: Modes | None,
    tol: float,
    maxiter: int,
    only: tuple[int, ...] | None,
    flips: ModeFlips | None = None,
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray | None, float]:
    """Stations along ``path`` from the reference: arc positions, unknowns and tangents.

    Also returns the tangent at the reference (None: the reference does not close) and
    the arc where the stations stopped closing (inf: never): past the edge of the
    feasible range the frames are not connected to the reference by the path (they are
    left to the reseeding of :func:`mjstruct.kinematics.closure.close`).  A station
    sits on every turn of the path, twice: with the tangent along the run it ends and
    along the one it starts (stations never cross a turn: the unknowns retrace their
    way back there).  Stations are accepted in order: one that closes to ``tol`` and
    agrees with the trapezoid of the tangent from the last one (:func:`agreement`).  Up
    to :data:`MAX_BLOCK` stations :data:`WINDOW_STEP` apart along a run of the path are
    solved together (:class:`StationWindow`), one evaluation per round, each from a
    guess by the cubic through the nearest stations known on either side (held beyond
    :data:`~mjstruct.kinematics.closure_window.REACH` when there is none ahead; for a
    single unknown angle, a new window reaching beyond :data:`SCAN_AHEAD` is guessed from
    one scan of the residual, :func:`scanned_roots`); a
    closed pair that disagrees gets a station halfway, at once.  A station at the front
    that is refused gets one halfway before it (a second refusal guesses it again); one
    that is stuck (it does not assemble, cannot be halved or is still open after
    :data:`BLOCK_ROUNDS`) with nothing new known is sought alone by
    :func:`station_newton` (the step halving down to 1e-4 until it agrees; one that
    does not close there ends the continuation), unless, given ``flips``, an inner
    dyad at its own dead point flips its mode there and the stations go on
    (:func:`~mjstruct.kinematics.closure_modes.try_flip`; the flips are added to
    ``flips``, and every station beyond takes them).  The tangent at the reference in
    the reference's modes is the model's own: it is found once per model, tolerance and
    direction (kept on the model, like its plan) and read by later calls.
    """
    k, scale, total = model.plan.unknowns, model.geometry.scale, path.total
    # the scan covers one turn: for a single unknown that is an angle (not a slide)
    angle = k == 1 and any(s.kind == "assume" for s in model.plan.steps)

    def modes(sv: FloatArray) -> Modes | None:
        if K is None and not flips:  # no base modes, no flip met: the reference's
            return None
        if flips is not None:
            return flips.modes(K, sv, path.frames_at(sv))
        return None if K is None else subset_modes(K, path.frames_at(sv))

    def flipped(
        sv: float, guess: FloatArray, Kf: Modes | None
    ) -> tuple[FloatArray, FloatArray | None]:
        s1 = np.array([sv])
        dirn = path.directions(s1)[0]
        iters = min(maxiter, STATION_ITERATIONS)
        return station_newton(model, path.at(s1)[0], guess, Kf, tol, iters, only, dirn)

    def station(sv: float, guess: FloatArray) -> tuple[FloatArray, FloatArray | None]:
        s1 = np.array([sv])
        dirn = path.directions(s1)[0]
        iters = min(maxiter, STATION_ITERATIONS)
        return station_newton(model, path.at(s1)[0], guess, modes(s1), tol, iters, only, dirn)

    if K is None and (flips is None or not flips):
        # the reference's tangent is the model's (at the reference's modes): found once
        memo = model.__dict__.setdefault("_reference_tangent", {})
        key = (tol, maxiter, only, path.direction_after(0.0).tobytes())
        if key not in memo:
            memo[key] = station(0.0, np.zeros(k))[1]
        D0 = None if memo[key] is None else memo[key].copy()
    else:
        _, D0 = station(0.0, np.zeros(k))
    S, TT, DD = [0.0], [np.zeros(k)], [np.zeros(k) if D0 is None else finite_or_zero(D0)]
    win = StationWindow(k, path.points.shape[1])
    wdir, wend = np.zeros(0), total
    s_last, step = 0.0, STATION_STEP
    alone = False  # True from a stuck window station until the step grows back
    turns = set(path.turns.tolist())
    for _ in range(20000):
        if s_last >= total:
            break
        if S[-1] == s_last and s_last in turns and not (len(S) > 1 and S[-2] == s_last):
            # a turn: the station again, its tangent along the new run's direction
            new, old = path.direction_after(s_last), path.directions(np.array([s_last]))[0]
            if new.size == 1:  # one driver: the tangent is linear in its rate
                d = DD[-1] * (new[0] / old[0])
            else:
                s1 = np.array([s_last])
                d = finite_or_zero(tangent(model, path.at(s1), TT[-1][None, :], modes(s1), new)[0])
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
                qv = path.at(sv)
                g = None
                if angle and win.size == 0 and float(sv[-1]) - s_last > SCAN_AHEAD:
                    g = scanned_roots(model, qv, modes(sv), only, float(TT[-1][0]))
                if g is None:
                    g = win.guess(sv, S, TT, DD)
                win.insert(np.full(sv.size, win.size), sv, qv, g)
            R, J, Rd = closure_jets(model, win.q, win.t, modes(win.s), wdir, only)
            assert Rd is not None
            rmax = largest(R)
            finite = np.isfinite(rmax)
            e = rmax / scale
            tried = win.evals > 0
            # a trial that does not assemble or more than doubles max |R| (outside the
            # tolerance: not its rounding) is halved back
            bad = (~finite | ((rmax > 2.0 * win.rbase) & (e > tol))) & tried
            some_bad = np.count_nonzero(bad) > 0
            stalled = (e >= 0.5 * win.err) & (e <= STALL_ERROR * tol)
            # (a non-finite error is neither within the tolerance nor stalled, nor near)
            closed = (e <= tol) | stalled
            if some_bad:
                closed &= ~bad
            D = -solve_stacked(J, Rd)
            dz = finite_or_zero(D)
            newton = newton_step(J, R)
            near = (e <= NEAR) & (e <= 1e-2 * win.err)
            if np.count_nonzero(near):  # (none in a window's first rounds)
                with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
                    near &= e * e * e <= PREDICTED * tol * win.err * win.err
            if some_bad:
                near &= ~bad
            step_taken = near & ~closed
            if np.count_nonzero(step_taken):
                at = np.where(step_taken[:, None], win.t + newton, win.t)
            else:
                at = win.t.copy()  # (accepted rows must not share the window's trials)
            ready = closed | near
            # accept the closed stations at the front while each agrees with the last
            # (argmin: the first not ready, or 0 when all are)
            c = int(ready.argmin())
            if ready[c]:
                c = win.size
            taken = 0
            if c:
                ds = win.s[:c] - np.concatenate(([s_last], win.s[: c - 1]))
                fits = agreement(
                    np.concatenate([TT[-1][None], at[: c - 1]]),
                    np.concatenate([DD[-1][None], dz[: c - 1]]),
                    at[:c],
                    D[:c],
                    ds,
                )
                taken = int(fits.argmin())
                if fits[taken]:
                    taken = c
                S.extend(win.s[:taken].tolist())
                TT.extend(at[:taken])
                DD.extend(dz[:taken])
                s_last = S[-1]
            refused = taken < c
            stuck = ~(finite | tried) | (win.evals >= BLOCK_ROUNDS - 1)
            if some_bad:
                stuck |= bad & (win.halved >= 8)
            stuck &= ~ready
            live = ~stuck
            live[:taken] = False
            win.advance(newton, dz, rmax, e, bad, ready, live, taken)
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
        s2, t2, d2 = last_two(S, TT, DD)
        if len(s2) > 1:  # cubic through the last two stations, extrapolated
            g = cubic(s2[0], t2[0], d2[0], s2[1], t2[1], d2[1], np.array([s_new]))[0]
        else:
            g = TT[-1] + DD[-1] * ds1
        tn, Dn = station(s_new, g)
        # (after skipped stations the trapezoid spans only the last step: as before)
        fine = Dn is not None and bool(
            agreement(TT[-1][None], DD[-1][None], tn[None], Dn[None], np.array([ds1]))[0]
        )
        # at the reference itself the step halves much further: a reference next to a
        # fold (the unknowns grow like the root of the distance to it) is left in steps
        # that double from about that distance
        if not fine and step <= (1e-4 if s_last > 0 else FIRST_STEP):
            # the edge of the feasible range: no station closes, or the one that does
            # is not on the branch followed (across a fold, where the two meet); or an
            # inner dyad at its own dead point, whose mode flips there
            got = None
            # (the inner dyads only here: the rest of the continuation does not read them)
            inner = () if flips is None else inner_mode_steps(model, only)
            if flips is not None and inner:
                got = try_flip(
                    model,
                    flips,
                    inner,
                    lambda sv: path.at(np.array([sv]))[0],
                    lambda sv: modes(np.array([sv])),
                    flipped,
                    (S[-1], TT[-1], DD[-1]),
                    path.next_turn(s_last),
                    only,
                )
            if got is None:
                if flips is not None:
                    s_end = np.array([S[-1]])
                    flips.stop = (path.at(s_end)[0], TT[-1], modes(s_end))
                return np.array(S), np.array(TT), np.array(DD), D0, s_new
            s_new, tn, Dn = got
            S.append(s_new)
            TT.append(tn)
            DD.append(finite_or_zero(Dn))
            step, alone, s_last = s_new - s_last, True, s_new
            continue
        if fine and Dn is not None:
            S.append(s_new)
            TT.append(tn)
            DD.append(finite_or_zero(Dn))
            step = min(2.0 * step, STATION_STEP)
            # back to the window once the step has grown to its spacing (near an edge
            # a fresh window would only get stuck again at its front)
            alone = step < WINDOW_STEP
            s_last = s_new
        else:
            step *= 0.5
    return np.array(S), np.array(TT), np.array(DD), D0, np.inf


def station_curvature(
    model: ModelView,
    path: ClosurePath,
    S: FloatArray,
    TT: FloatArray,
    DD: FloatArray,
    K: Modes | None,
    only: tuple[int, ...] | None,
    flips: ModeFlips | None = None,
) -> FloatArray | None:
    """t'' at the stations, from one evaluation; None for one station, or off a single
    run of a path of several drivers (``flips``: the inner dyads' flips along it).

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
    if flips is not None:
        K = flips.modes(K, S, path.frames_at(S))
    else:
        K = None if K is None else subset_modes(K, path.frames_at(S))
    _, (R1, R2) = seeded_jets(model, path.at(S), TT, K, only, path.dirs[0], DD, order=2)
    return finite_or_zero(-solve_stacked(R1[1:].transpose(1, 2, 0), R2[0]))
