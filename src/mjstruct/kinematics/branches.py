"""Branches of the position functions: assembly modes, branch points, feasibility.

Owns the continuity rules of the position functions and the assembly coefficient
K = ±1 of each dyad.
Each dyad step starts in the mode that reproduces the reference configuration.  Along
the frames a step's Jacobian (the sine at its solved joint) is watched:

* where it dips towards zero between frames, the minimum is refined by evaluating
  the plan on finer q; if it reaches zero the two branches *meet* (a change point, a
  dead point passed through) and switching is legal: the branch whose motion
  continues smoothly (extrapolated from the frames before) is taken — switched or
  kept, it is reported;
* if the minimum stays above zero it is a *near* branch point: the mode is kept
  (switching there would be a jump) and the point is reported;
* where the dyad cannot assemble the frames are infeasible; the limits of the
  feasible intervals (dead positions) are reported with their q.

Examples
--------
>>> import numpy as np
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.kinematics.model import KinematicModel
>>> model = KinematicModel.build(read_mechanism(example_path("four-bar")))
>>> q = np.linspace(0, 2 * np.pi, 37)[:-1, None]
>>> K, events = track_branches(model, q)
>>> events                         # a Grashof crank-rocker has no branch point
[]
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from mjstruct.kinematics.evaluate import Evaluation, evaluate, reference_mode
from mjstruct.kinematics.steps.base import Modes
from mjstruct.kinematics.tolerances import DISC_SLACK, MEET, WATCH

if TYPE_CHECKING:
    from mjstruct.kinematics.model_view import ModelView

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]
#: assembly mode per dyad step and frame
FrameModes = dict[int, npt.NDArray[np.int8]]


@dataclass(frozen=True)
class BranchEvent:
    """A branch point met along the frames.

    ``kind``: "change point" (branches meet; ``action`` "switched" or "kept"), "near
    branch point" (closest approach, mode kept), "dead point" (limit of a feasible
    interval), "singular frame" (the step is undefined exactly there).
    """

    q: float
    frame: int
    step: int
    joint: str
    kind: str
    sine: float
    action: str
    #: the joints of the closure group whose limit this is (empty: one step's event)
    group: tuple[str, ...] = ()

    def message(self) -> str:
        """The event in words (one line)."""
        if self.kind == "mode flip":
            return (
                f"assembly mode flip at q = {self.q:.9g} (frame {self.frame}, step "
                f"{self.step + 1}, joint {self.joint}): the dyad passes its own dead point "
                f"inside a closure group that passes smoothly (|sin| = {self.sine:.3g} at the "
                "nearest frame); its assembly mode flips there, the motion goes on"
            )
        if self.group:
            joints = ", ".join(self.group)
            if self.kind == "dead point":
                return (
                    f"dead point at q = {self.q:.9g} (frame {self.frame}): input limit of the "
                    f"closure group of joints {joints}, the smallest singular value of the "
                    f"mechanism's Jacobian (drivers fixed, relative) {self.sine:.3g}"
                )
            return (
                f"closure stops at q = {self.q:.9g} (frame {self.frame}): the closure group of "
                f"joints {joints} is not continued beyond, although the mechanism's Jacobian "
                f"is regular there (smallest singular value, relative, {self.sine:.3g}): "
                "not a dead point; the frames beyond are null"
            )
        if self.kind == "change point":
            # whether the dyad's mode flips is bookkeeping: the motion itself continues
            flips = (
                "the triangle's assembly mode flips there"
                if self.action == "switched"
                else "the triangle keeps its assembly mode"
            )
            return (
                f"change point at q = {self.q:.9g} (frame {self.frame}, step {self.step + 1}, "
                f"joint {self.joint}): branches meet, |sin| = {self.sine:.3g}; the sweep "
                f"continues smoothly on its branch ({flips})"
            )
        what = {
            "change point": "branches meet",
            "near branch point": "closest approach of the two branches",
            "dead point": "limit of the feasible range",
            "singular frame": "the dyad is undefined here",
        }[self.kind]
        return (
            f"{self.kind} at q = {self.q:.9g} (frame {self.frame}, step {self.step + 1}, "
            f"joint {self.joint}): {what}, |sin| = {self.sine:.3g}; assembly mode "
            f"{self.action}"
        )


def _sine(
    model: ModelView, q: FloatArray, K: Modes, k: int, t: FloatArray | None = None
) -> FloatArray:
    ev = evaluate(model, q, order=0, K=K, t=t, only=model.step_dependencies[k])
    return masked_sine(*ev.diag[k])


def masked_sine(disc: FloatArray, det: FloatArray) -> FloatArray:
    """|sine| of a dyad step, nan where it does not assemble."""
    s = np.abs(det)
    s[~np.isfinite(s) | (disc < -DISC_SLACK)] = np.nan
    return s


def _modes_at(K: Modes, i: int, steps: Sequence[int] | None = None) -> dict[int, int]:
    """The modes at frame ``i`` (only of ``steps``, when given: what one step's
    evaluation with its dependencies reads; all of them cost O(steps) per call)."""
    keys = K.keys() if steps is None else [k for k in steps if k in K]
    return {k: (int(v[i]) if isinstance(v, np.ndarray) else int(v)) for k in keys for v in (K[k],)}


def _refine_min(model: ModelView, q: FloatArray, K: Modes, k: int, i: int) -> tuple[float, float]:
    """Smallest |sine| of step k between frames i-1 and i+1 (zooming, vectorised)."""
    lo, hi = q[i - 1], q[i + 1]
    Ki = _modes_at(K, i, model.step_dependencies[k])
    best_s, best_q = np.inf, float(q[i, 0])
    for _ in range(5):
        qs = lo + (hi - lo) * np.linspace(0.0, 1.0, 33)[:, None]
        s = _sine(model, qs, Ki, k)
        if not np.isfinite(s).any():
            return 0.0, best_q
        j = int(np.nanargmin(s))
        if s[j] < best_s:
            best_s, best_q = float(s[j]), float(qs[j, 0])
        lo, hi = qs[max(j - 1, 0)], qs[min(j + 1, 32)]
    return best_s, best_q


def _boundary(model: ModelView, a: FloatArray, b: FloatArray, K: Modes, k: int) -> float:
    """q where step k stops assembling between a (feasible) and b (not), by bisection."""
    for _ in range(3):
        qs = a + (b - a) * np.linspace(0.0, 1.0, 65)[:, None]
        s = _sine(model, qs, K, k)
        ok = np.isfinite(s)
        j = int(np.argmin(ok)) if not ok.all() else 64
        a, b = qs[max(j - 1, 0)], qs[min(j, 64)]
    return float(a[0])


#: bisections locating a dead point of a plan with closure unknowns (2^-36 of a frame
#: step: 1e-13 rad at 3600 frames a turn)
CLOSURE_BISECTIONS = 36
#: Newton iterations at a bisection point (from the last closed point, a few suffice;
#: past the fold it does not converge, and more iterations only cost time)
CLOSURE_ITERATIONS = 10


#: the closure solved at a bisection point: (edge's feasible end, point) -> (t, closed)
ClosureSolves = dict[tuple[bytes, bytes], tuple[FloatArray, bool]]


def _closure_boundary(
    model: ModelView,
    a: FloatArray,
    b: FloatArray,
    ta: FloatArray,
    K: Modes,
    k: int,
    solved: ClosureSolves | None = None,
) -> float:
    """q where a plan with closure unknowns stops assembling between a and b.

    Bisection on whether the closure still closes (Newton from the last closed point,
    so that it follows the branch into the fold) and step k assembles there: the
    fold of the closure, the input limit of the singular analysis.  ``solved`` keeps
    the Newton solves by point: where the closure fails at b, every step after it has
    an edge there, and their bisections visit the same points as long as they agree
    (a point of the bisection fixes the path that led to it).
    """
    from mjstruct.kinematics.closure import newton

    memo: ClosureSolves = {} if solved is None else solved
    lo, hi, t = a.copy(), b.copy(), ta.copy()
    for _ in range(CLOSURE_BISECTIONS):
        mid = 0.5 * (lo + hi)
        key = (a.tobytes(), mid.tobytes())
        if key not in memo:
            tn, _, _, okn = newton(model, mid[None, :], t[None, :], K, maxiter=CLOSURE_ITERATIONS)
            memo[key] = (tn, bool(okn[0]))
        tn, ok = memo[key]
        if ok and np.isfinite(_sine(model, mid[None, :], K, k, tn)).all():
            lo, t = mid, tn[0]
        else:
            hi = mid
    return float(lo[0])


def track_branches(
    model: ModelView,
    q: FloatArray,
    t: FloatArray | None = None,
    first: Evaluation | None = None,
    modes: Modes | None = None,
    stops: Sequence[tuple[FloatArray, FloatArray, Modes | None]] = (),
) -> tuple[FrameModes, list[BranchEvent]]:
    """Assembly mode per dyad step and frame, and the branch points met.

    With closure unknowns ``t`` (class III/IV plans) the modes are kept and events are
    only reported (the closure fixes the branch by continuation): ``modes`` are the
    closure's modes of its inner dyads per frame (each flip of one is an informational
    "mode flip" event), and where the closure stops one event names the closure group,
    a dead point (input limit of the group) where the mechanism's Jacobian loses rank
    (located from the closure's ``stops``, the last stations before its edges, where
    one lies between the two frames: it carries the modes the continuation had there).
    ``first``: an evaluation with these modes (the reference's for the other steps) on
    the same frames, reused until a mode flips.
    """
    plan = model.plan
    F = q.shape[0]
    K: FrameModes = {}
    events: list[BranchEvent] = []
    switchable = plan.unknowns == 0
    flipped = False
    solved: ClosureSolves = {}
    closed: BoolArray | None = None
    if t is not None and not switchable:
        closed = np.asarray(np.isfinite(t).all(axis=1), dtype=bool)
    inside = _closure_dependent(model) if closed is not None else frozenset()
    for k, s in enumerate(plan.steps):
        if not s.step_kind.has_modes:
            continue
        base_mode = reference_mode(plan, model.geometry, k)
        if modes is not None and k in modes:
            K[k] = np.array(np.broadcast_to(np.asarray(modes[k], np.int8), (F,)))
        else:
            K[k] = np.full(F, base_mode, dtype=np.int8)
        flips = np.flatnonzero(K[k][1:] != K[k][:-1])
        for f in flips:
            # the flip lies between frames f and f + 1: at the later one
            j = int(f) + 1
            events.append(BranchEvent(float(q[j, 0]), j, k, s.joint, "mode flip", 0.0, "flipped"))
        if first is not None and not flipped:
            sine = masked_sine(*first.diag[k])
        else:
            sine = _sine(model, q, K, k, t)
        ok = np.isfinite(sine)
        i = 1
        while True:
            nxt = _next_candidate(sine, ok, i)
            if nxt is None:
                break
            cand, after, singular = nxt
            if flips.size and np.abs(flips + 0.5 - cand).min() <= 2:
                i = after + 1  # the dip of a flip: reported above
                continue
            if singular:
                smin, qstar, kind = 0.0, float(q[cand, 0]), "singular frame"
            else:
                if switchable:
                    smin, qstar = _refine_min(model, q, K, k, cand)
                else:
                    smin, qstar = float(sine[cand]), float(q[cand, 0])
                kind = "change point" if smin < MEET else "near branch point"
            action = "kept"
            # the first frame beyond the branch point (the dip's frame may already be)
            start = after
            if not singular and (q[cand, 0] - qstar) * (q[after, 0] - q[cand, 0]) > 0:
                start = cand
            legal = kind != "near branch point" and switchable and start >= 3 and start < F
            # at an undefined frame the fit must use the frames before it, not the gap
            fit_end = cand if singular else start
            if legal and _smoother_flipped(model, q, K, k, s.joint, start, fit_end):
                K[k][start:] *= -1
                action = "switched"
                flipped = True
                sine = _sine(model, q, K, k, t)
                ok = np.isfinite(sine)
            events.append(BranchEvent(qstar, cand, k, s.joint, kind, smin, action))
            i = after + 1
        # limits of feasible intervals (dead positions)
        for edge in np.flatnonzero(ok[:-1] != ok[1:]):
            e = int(edge)
            if _near_event(events, k, e):
                continue
            a, b = (e, e + 1) if ok[e] else (e + 1, e)
            if closed is not None and k in inside and closed[a] != closed[b]:
                continue  # the closure stops here: one event for its group, below
            if switchable:
                qb = _boundary(model, q[a], q[b], _modes_at(K, a, model.step_dependencies[k]), k)
            elif t is not None and np.isfinite(t[a]).all():
                qb = _closure_boundary(model, q[a], q[b], t[a], _modes_at(K, a), k, solved)
            else:
                qb = float(q[a, 0])
            events.append(BranchEvent(qb, int(a), k, s.joint, "dead point", 0.0, "kept"))
    if closed is not None and t is not None:
        events += _closure_limits(model, q, t, closed, K, stops)
    _sines_of_flips(events, K, first)
    events.sort(key=lambda e: (e.frame, e.step))
    return K, events


def _sines_of_flips(events: list[BranchEvent], K: FrameModes, ev: Evaluation | None) -> None:
    """Each mode flip's |sine| at its frame, from ``ev`` (in place)."""
    if ev is None:
        return
    for n, e in enumerate(events):
        if e.kind == "mode flip" and e.step in ev.diag:
            sine = float(abs(ev.diag[e.step][1][e.frame]))
            events[n] = dataclasses.replace(e, sine=sine)


def _closure_dependent(model: ModelView) -> frozenset[int]:
    """Steps that depend on a closure unknown (they have no value where it does not close)."""
    steps = model.plan.steps
    assumed = {k for k, s in enumerate(steps) if s.kind in ("assume", "assume-slide")}
    return frozenset(
        k for k in range(len(steps)) if assumed.intersection(model.step_dependencies[k])
    )


def _stop_between(
    model: ModelView,
    stops: Sequence[tuple[FloatArray, FloatArray, Modes | None]],
    a: FloatArray,
    b: FloatArray,
) -> tuple[FloatArray, FloatArray, Modes | None] | None:
    """The stop whose driver values lie between frames ``a`` and ``b`` (a revolute
    driver's angle taken modulo 2π), moved onto their turn; None if none does."""
    turns = np.array([model.mechanism.joint(d).kind == "R" for d in model.drivers])
    for qs, ts, Ks in stops:
        d = qs - a
        d[turns] -= 2 * np.pi * np.round(d[turns] / (2 * np.pi))
        span = b - a
        with np.errstate(divide="ignore", invalid="ignore"):
            u = np.where(span != 0, d / span, 0.0)
        moving = u[span != 0]
        one_point = moving.size == 0 or float(moving.max() - moving.min()) <= 1e-9
        if bool(np.all((u >= 0) & (u <= 1))) and one_point:
            return a + d, ts, Ks
    return None


#: the smallest singular value of the mechanism's Jacobian (drivers fixed, relative to
#: the largest) below which a closure's limit is a dead point of the mechanism
GROUP_SINGULAR = 1e-4


def _closure_limits(
    model: ModelView,
    q: FloatArray,
    t: FloatArray,
    closed: BoolArray,
    K: FrameModes,
    stops: Sequence[tuple[FloatArray, FloatArray, Modes | None]] = (),
) -> list[BranchEvent]:
    """One event where the closure stops between two frames: the closure group's limit.

    The limit is bisected on whether Newton, from the last closed point, still closes;
    there the mechanism's Jacobian with the drivers fixed (every joint constraint, in
    link coordinates) gives its smallest singular value: a dead point (input limit of
    the group) where it vanishes, else the closure's stop is named as such.
    """
    edges = np.flatnonzero(closed[:-1] != closed[1:])
    if edges.size == 0:  # closed on every frame, or on none (the usual sweeps)
        return []
    from mjstruct.kinematics.closure import newton
    from mjstruct.kinematics.jacobian import constraint_jacobian, one_blas_thread

    steps, m = model.plan.steps, model.mechanism
    links = {
        x for k in _closure_dependent(model) for x in steps[k].links if not steps[k].is_closure
    }
    group = tuple(j.id for j in m.joints if any(x in links for x in j.links))
    out = []
    for edge in edges:
        e = int(edge)
        a, b = (e, e + 1) if closed[e] else (e + 1, e)
        Ka: Modes = _modes_at(K, a)
        lo, hi, ta = q[a].copy(), q[b].copy(), t[a].copy()
        near = _stop_between(model, stops, q[a], q[b])
        if near is not None:
            lo, ta, Ks = near
            Ka = {**Ka, **{kk: int(np.asarray(v).ravel()[0]) for kk, v in (Ks or {}).items()}}
        for _ in range(CLOSURE_BISECTIONS):
            mid = 0.5 * (lo + hi)
            tn, _, _, okn = newton(
                model, mid[None, :], ta[None, :], Ka, maxiter=CLOSURE_ITERATIONS
            )
            if okn[0]:
                lo, ta = mid, tn[0]
            else:
                hi = mid
        ev = evaluate(model, lo[None, :], order=0, t=ta[None, :], K=Ka)
        J, D = constraint_jacobian(m, model.geometry, ev.poses, model.drivers)
        A = np.concatenate([J[0], D[0]])
        # a step placed after the group that stops assembling there too: no Jacobian,
        # its own dead point
        smin = 0.0
        if np.isfinite(A).all():
            with one_blas_thread():  # a small matrix: threads only wait
                sv = np.linalg.svd(A, compute_uv=False)
            smin = float(sv[-1] / sv[0]) if sv[0] > 0 else 0.0
        kind = "dead point" if smin < GROUP_SINGULAR else "closure stop"
        first = min(k for k in _closure_dependent(model))
        joints = ", ".join(group)
        out.append(BranchEvent(float(lo[0]), a, first, joints, kind, smin, "kept", group))
    return out


def _next_candidate(sine: FloatArray, ok: BoolArray, start: int) -> tuple[int, int, bool] | None:
    """First frame >= start where a step's |sine| dips (or a short undefined run sits).

    Returns (frame, first frame after it, singular); found with array operations.
    """
    F = sine.size
    if F < 3 or start >= F - 1:
        return None
    if not (sine[max(start, 1) : F - 1] < WATCH).any() and ok.all():
        return None  # no undefined frame, none low enough to be a dip: the common case
    s = np.where(ok, sine, np.inf)
    inner = np.arange(1, F - 1)
    dip = (
        ok[1:-1] & ok[:-2] & ok[2:]
        & (s[1:-1] <= np.minimum(s[:-2], s[2:]))
        & (s[1:-1] < WATCH)
    )  # fmt: skip
    # runs of at most two undefined frames between defined ones
    gap1 = ~ok[1:-1] & ok[:-2] & ok[2:]
    gap2 = np.zeros(F - 2, bool)
    if F >= 4:
        gap2[:-1] = ~ok[1:-2] & ~ok[2:-1] & ok[:-3] & ok[3:]
    hit = (dip | gap1 | gap2) & (inner >= start)
    if not hit.any():
        return None
    j = int(np.argmax(hit))
    i = int(inner[j])
    if dip[j]:
        return i, i + 1, False
    return i, i + (2 if gap2[j] else 1), True


def _near_event(events: list[BranchEvent], k: int, i: int) -> bool:
    return any(
        e.step == k and abs(e.frame - i) <= 3 and e.kind == "singular frame" for e in events
    )


def _smoother_flipped(
    model: ModelView,
    q: FloatArray,
    K: FrameModes,
    k: int,
    joint: str,
    start: int,
    fit_end: int | None = None,
) -> bool:
    """True when flipping step k's mode from frame ``start`` continues the motion smoothly.

    The motion is extrapolated from the three frames before ``fit_end`` (default
    ``start``; before an undefined frame, the frames before it).
    """
    end = start if fit_end is None else fit_end
    idx = np.array([end - 3, end - 2, end - 1, start])
    sub = q[idx]
    same = {kk: v[idx] for kk, v in K.items()}
    flip = {kk: v[idx].copy() for kk, v in K.items()}
    flip[k][-1] *= -1
    pts: list[npt.NDArray[Any]] = []
    for modes in (same, flip):
        ev = evaluate(model, sub, order=0, K=modes, only=model.step_dependencies[k])
        pts.append(ev.centre(joint)[0])
    x = idx.astype(float)
    known = pts[0][:3]
    # quadratic through the three frames before, evaluated at the frame after
    coef = np.polyfit(x[:3], np.c_[known.real, known.imag], 2)
    pred = np.polyval(coef[:, 0], x[3]) + 1j * np.polyval(coef[:, 1], x[3])
    return bool(abs(pts[1][3] - pred) < abs(pts[0][3] - pred))


#: half-width of the two-sided limit at an undefined frame, relative to its two frame
#: steps: the dyad's base direction there is good to ~1e-16/width, the extrapolated
#: mean to ~width⁴
LIMIT_WIDTH = 1e-3
#: the two one-sided values (2·width apart in q, so they differ by about that times the
#: rates) must agree to this, relative to the size, to be one configuration; another
#: branch sits a finite distance away
LIMIT_AGREE = 1e-2


def fill_change_frames(
    model: ModelView, q: FloatArray, events: Sequence[BranchEvent], ev: Evaluation
) -> list[BranchEvent]:
    """Positions at frames where a dyad is undefined but the motion passes through.

    A frame exactly at a change point where the dyad's base vanishes (MS5's A on O2)
    has no triangle, yet the configuration exists: the limit of the branch from both
    sides.  Where the two one-sided limits (the modes of the frames before and after)
    agree, ``ev``'s poses at that frame are set to their mean (positions only: the
    derivatives stay undefined, the frame is a singular position) and the event
    becomes a change point.  Plans with closure unknowns are left alone.
    """
    out = list(events)
    F = q.shape[0]
    todo = [
        n
        for n, e in enumerate(out)
        if e.kind == "singular frame" and 1 <= e.frame < F - 1 and model.plan.unknowns == 0
    ]
    if not todo:
        return out
    # the motion's modes on every frame (deterministic: the same as the motion's)
    K, _ = track_branches(model, q)
    for n in todo:
        e = out[n]
        i = e.frame
        d = LIMIT_WIDTH * (q[i + 1] - q[i - 1])
        # at -2d, -d, +d, +2d: the means at d and 2d extrapolated (Richardson) to d = 0
        qs = np.stack([q[i] - 2 * d, q[i] - d, q[i] + d, q[i] + 2 * d])
        modes: Modes = {
            kk: np.array([v[i - 1]] * 2 + [v[i + 1]] * 2, dtype=np.int8) for kk, v in K.items()
        }
        side = evaluate(model, qs, order=0, K=modes)

        def lim(x: npt.NDArray[Any]) -> complex:
            return complex((4 * (x[1] + x[2]) - (x[0] + x[3])) / 6)

        limit: dict[str, tuple[complex, complex]] = {}
        agree = True
        for link, pose in side.poses.items():
            A, r = pose.A[0], pose.r
            if not (np.isfinite(A).all() and np.isfinite(r).all()):
                agree = False
                break
            agree &= bool(abs(A[1] - A[2]) <= LIMIT_AGREE * model.geometry.scale)
            agree &= bool(abs(r[1] - r[2]) <= LIMIT_AGREE)
            m = lim(r)
            limit[link] = (lim(A), m / abs(m))
        if not agree or set(limit) != set(ev.poses):
            continue
        for link, (A0, r0) in limit.items():
            pose = ev.poses[link]
            # copies: the arrays may be shared between poses
            newA, newr = pose.A[0].copy(), pose.r.copy()
            newA[i], newr[i] = A0, r0
            ev.poses[link] = dataclasses.replace(pose, A=[newA, *pose.A[1:]], r=newr)
        for j, jet in list(ev.solved.items()):
            if j in side.solved:
                val = jet[0].copy()
                val[i] = lim(side.solved[j][0])
                ev.solved[j] = [val, *jet[1:]]
        flipped = K[e.step][i - 1] != K[e.step][i + 1]
        out[n] = dataclasses.replace(
            e, kind="change point", action="switched" if flipped else "kept"
        )
    return out
