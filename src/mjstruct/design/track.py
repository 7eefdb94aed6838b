"""Targets along the motion: a point's positions, a link's angles, or both.

Owns :class:`TrackProblem`, the fitting problem behind path, function and motion
synthesis (:func:`mjstruct.design.search.solve` runs it):

* **what is fitted**: at target i, the position of a point (path, motion) and/or the
  angle of a link (function: the output link; motion: the point's link), the angle
  weighted by a length (motion) so that one error mixes both;
* **variables**: the positions of the free joints and points of the reference
  configuration (:class:`~mjstruct.design.population.DesignSpace`), plus the free
  offsets of relative driver values (``timing_offset``) and relative angles
  (function's ``angle_offset``);
* **timed targets**: each candidate is evaluated at the targets' driver values and
  over its required driver range in one batched call (P candidates × (T + S)
  frames);
* **untimed targets**: each candidate is sampled over one driver cycle (P × S frames)
  and the targets are matched in their order (:mod:`mjstruct.design.matching`); the
  local stage frees the T driver values, their Jacobian columns exact from the
  kinematics' analogs (the point's dP/dq, the link's dθ/dq);
* **constraints**: :mod:`mjstruct.design.constraints`; the verdict:
  :mod:`mjstruct.design.verify`.

Examples
--------
>>> from mjstruct.design.task import task_from_dict
>>> from mjstruct.io import mechanism_to_dict, read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> m = mechanism_to_dict(read_mechanism(example_path("four-bar")))
>>> t = task_from_dict({"task": "path", "mechanism": m, "point": "M",
...                     "targets": [[0.4, 0.6], [0.2, 0.9], [-0.1, 0.8]]})
>>> goal = t.targets[:, 0] + 1j * t.targets[:, 1]
>>> p = TrackProblem(t, "M", goal, None, None, 1.0, None)
>>> a = p.assess(p.start()[None, :])
>>> sorted(a.margins), bool(a.energy[0] < 1.0)
(['assembly'], True)
"""

from __future__ import annotations

import copy
import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from mjstruct.design.constraints import (
    MIN_SINE,
    assembly_margin,
    fourbar_lengths,
    fourbar_margin,
    length_margin,
    link_pairs,
)
from mjstruct.design.matching import match_indices, ordered_match
from mjstruct.design.memory import assess_in_chunks, chunk_rows
from mjstruct.design.population import DesignSpace, Population
from mjstruct.design.problem import PENALTY, Assessment, FitProblem, Outcome
from mjstruct.design.result import SYNTHESIS_KEY
from mjstruct.design.task import Task
from mjstruct.design.verify import check_motion, final_verdict
from mjstruct.io import mechanism_from_dict, mechanism_to_dict
from mjstruct.kinematics.evaluate import Evaluation
from mjstruct.kinematics.model import KinematicModel
from mjstruct.mechanism import Mechanism
from mjstruct.singular.fourbar import fourbar_theory
from mjstruct.typing import ComplexArray, FloatArray, IntArray

TWO_PI = 2 * math.pi
#: untimed targets matched per candidate by the global stage (more are thinned evenly
#: along their order; the local stage fits them all)
MATCHED_TARGETS = 32
#: central-difference step of the geometry columns, relative to the size
FD_STEP = 1e-6
#: how far inside each margin the local stage's penalties start.  The penalties are
#: exterior (zero where met): a least-squares optimum against a constraint sits just
#: outside it, which the verdict refuses; and the range is screened at samples, so a
#: dyad's sine may dip between them below what the samples show
LOCAL_INSET = {"assembly": 1e-2, "lengths": 1e-4, "motion": 1e-4}


def wrap(a: Any) -> Any:
    """Angles brought into [-pi, pi)."""
    return np.mod(np.asarray(a) + math.pi, TWO_PI) - math.pi


class TrackProblem(FitProblem):
    """A fitting task whose targets are positions of a point and/or angles of a link.

    Parameters
    ----------
    task : the checked task (path, function or motion).
    point : the point (or joint) whose positions are fitted, or None.
    positions : the target positions (complex, T), with ``point``.
    link : the link whose angles are fitted, or None.
    angles : the target angles (T), with ``link``.
    weight : length per radian of an angle error (1 without positions).
    timing : the driver values of the targets (relative with ``task.timing_offset``),
        or None (untimed).
    angle_offset : the target angles are relative (a free common offset).
    starts : further global variable vectors to start from (exact solutions).
    """

    def __init__(
        self,
        task: Task,
        point: str | None,
        positions: ComplexArray | None,
        link: str | None,
        angles: FloatArray | None,
        weight: float,
        timing: FloatArray | None,
        angle_offset: bool = False,
        starts: Sequence[FloatArray] = (),
        space: DesignSpace | None = None,
    ) -> None:
        assert task.mechanism is not None
        self.kind = task.kind
        self.task = task
        self.point, self.positions = point, positions
        self.link, self.angles = link, angles
        self.weight = weight
        self.timing = timing
        self.timed = timing is not None
        self.offset = bool(task.timing_offset)
        self.angle_offset = angle_offset
        n = len(positions) if positions is not None else len(angles)  # type: ignore[arg-type]
        self.targets = n
        if space is None:
            model = KinematicModel.build(task.mechanism)
            around = list(positions) if positions is not None else []
            space = DesignSpace.build(
                model, task.region, task.fixed, margin=1.0, around=around, points=[point or ""]
            )
        self.space = space
        self.scale = space.model.scale
        # untimed: the cycle's samples the targets are matched to; timed: the range's
        # samples (dead points are only screened here: the verdict sweeps finely)
        samples = int(task.solver["samples"])
        self.samples = max(samples, 4 * n) if timing is None else max(samples // 4, 8)
        # untimed: the global stage matches at most MATCHED_TARGETS of the targets,
        # spread along their order, on a cycle sampled for them: its cost per candidate
        # does not grow with the number of targets (the local stage fits every one)
        spread = np.round(np.linspace(0, n - 1, min(n, MATCHED_TARGETS)))
        self.matched: IntArray = np.unique(spread).astype(int)
        self.screen_samples = (
            max(samples, 4 * len(self.matched)) if timing is None else self.samples
        )
        self.screen_frames = self.screen_samples + (n if timing is not None else 0)
        self.pairs = link_pairs(space.model.mechanism) if task.lengths else []
        self.ng = space.size
        self.extra_starts = list(starts)
        #: function over the range: dense (driver values, angles) between the targets,
        #: and whether they are fitted (``objective: "range"``: they follow the task's
        #: targets in ``angles``) or only reported (``"points"``)
        self.range_check: tuple[FloatArray, FloatArray] | None = None
        self.range_fitted = False
        self.evaluations = 0
        #: the last residuals' point and margins (the Jacobian's next question)
        self._last: tuple[bytes, dict[str, FloatArray]] | None = None

    # -- variables ------------------------------------------------------------------------
    @property
    def n_offsets(self) -> int:
        return int(self.offset) + int(self.angle_offset)

    def bounds(self) -> tuple[FloatArray, FloatArray]:
        k = self.n_offsets
        lo = np.concatenate([self.space.lower, np.full(k, -math.pi)])
        hi = np.concatenate([self.space.upper, np.full(k, math.pi)])
        return lo, hi

    def start(self) -> FloatArray:
        x = list(self.space.x0)
        q_ref = float(self.space.model.q_ref[0])
        if self.offset:
            assert self.timing is not None
            x.append(float(wrap(q_ref - self.timing[0])))
        if self.angle_offset:
            assert self.angles is not None and self.link is not None
            x.append(float(wrap(self.space.model.geometry.char_angle[self.link] - self.angles[0])))
        return np.array(x)

    def starts(self) -> list[FloatArray]:
        return [self.start(), *self.extra_starts]

    def coarse(self) -> TrackProblem:
        """Untimed with more than ``MATCHED_TARGETS`` targets: the same problem on the
        targets the global stage matches (its local solves then cost the same whatever
        the number of targets); otherwise itself."""
        if self.timed or len(self.matched) == self.targets:
            return self
        out = copy.copy(self)
        idx = self.matched
        out.positions = None if self.positions is None else self.positions[idx]
        out.angles = None if self.angles is None else self.angles[idx]
        out.targets = len(idx)
        out.matched = np.arange(len(idx))
        out.samples = self.screen_samples
        out.evaluations = 0
        out._last = None
        return out

    def _offsets(self, X: FloatArray) -> tuple[FloatArray, FloatArray]:
        P = len(X)
        k = self.ng
        qoff = X[:, k] if self.offset else np.zeros(P)
        aoff = X[:, k + int(self.offset)] if self.angle_offset else np.zeros(P)
        return qoff, aoff

    def _timing(self, qoff: FloatArray, Xg: FloatArray) -> FloatArray | None:
        """The targets' driver values per candidate: the timing, plus the free offset,
        plus (``timing_from``) the direction of the candidate's own frame line."""
        if self.timing is None:
            return None
        out: FloatArray = self.timing[None, :] + qoff[:, None]
        if self.task.timing_from is not None:
            j1, j2 = self.task.timing_from
            P = self.space.positions(Xg)
            out = out + np.angle(P[j2] - P[j1])[:, None]
        return out

    def _driver_values(
        self, q_ref: FloatArray, qt: FloatArray | None, M: int | None = None
    ) -> tuple[FloatArray, slice]:
        """Per candidate: the targets' values (timed) then ``M`` range samples."""
        M = self.samples if M is None else M
        k = np.arange(M)[None, :]
        if qt is None:
            return q_ref[:, None] + TWO_PI * k / M, slice(0, 0)
        T = qt.shape[1]
        if self.task.full_turn:
            qr = q_ref[:, None] + TWO_PI * k / M
        else:
            mid = 0.5 * (qt.min(axis=1) + qt.max(axis=1))
            ref = q_ref + TWO_PI * np.round((mid - q_ref) / TWO_PI)
            lo = np.minimum(ref, qt.min(axis=1))
            hi = np.maximum(ref, qt.max(axis=1))
            qr = lo[:, None] + (hi - lo)[:, None] * k / (M - 1)
        return np.hstack([qt, qr]), slice(0, T)

    # -- what is fitted -------------------------------------------------------------------
    def _fitted(
        self, pop: Population, ev: Evaluation, order: int
    ) -> tuple[list[ComplexArray] | None, list[FloatArray] | None]:
        """Jets (P × S each) of the point's position and of the link's angle."""
        zj = pop.jet(ev, self.point) if self.point is not None else None
        aj = None
        if self.link is not None:
            pose = ev.poses[self.link]
            ref = np.asarray(pop.model.geometry.char_angle[self.link], float)
            theta = np.angle(pose.r) + ref
            aj = [pop.reshape(theta)]
            if order >= 1:
                aj.append(pop.reshape(np.broadcast_to(pose.w[0], theta.shape)))
        return zj, aj

    def _costs(
        self,
        z: ComplexArray | None,
        a: FloatArray | None,
        aoff: FloatArray,
        which: Any = slice(None),
    ) -> FloatArray:
        """P × T × S squared errors of the targets ``which`` (all) at every frame."""
        D: Any = 0.0
        if z is not None:
            assert self.positions is not None
            D = D + np.abs(z[:, None, :] - self.positions[which][None, :, None]) ** 2
        if a is not None:
            assert self.angles is not None
            goal = self.angles[which][None, :, None] + aoff[:, None, None]
            D = D + (self.weight * wrap(a[:, None, :] - goal)) ** 2
        out: FloatArray = np.asarray(D, float)
        out[~np.isfinite(out)] = np.inf
        return out

    def _margins(
        self, ev: Evaluation, shape: tuple[int, int], pop: Population
    ) -> dict[str, FloatArray]:
        t = self.task
        out = {"assembly": assembly_margin(ev, shape, t.transmission_deg, slice(None))}
        if t.lengths is not None:
            out["lengths"] = length_margin(pop.positions, self.pairs, t.lengths, self.scale)
        if t.motion is not None:
            lengths = fourbar_lengths(self.space.model.mechanism, pop.positions)
            out["motion"] = fourbar_margin(lengths, t.motion)
        return out

    # -- global stage ---------------------------------------------------------------------
    def assess(self, X: FloatArray) -> Assessment:
        # a bounded number of frames at a time: bounded memory, prompt interrupts
        return assess_in_chunks(self._assess, np.atleast_2d(X), chunk_rows(self))

    def _assess(self, X: FloatArray) -> Assessment:
        Xg = X[:, : self.ng]
        qoff, aoff = self._offsets(X)
        qt = self._timing(qoff, Xg)
        S = self.screen_frames
        pop = self.space.population(Xg, S)
        q, tcols = self._driver_values(pop.q_ref(), qt, self.screen_samples)
        ev = pop.evaluate(q, order=0)
        zj, aj = self._fitted(pop, ev, 0)
        z = None if zj is None else zj[0]
        a = None if aj is None else aj[0]
        if qt is None:
            energy, _ = ordered_match(self._costs(z, a, aoff, self.matched))
            energy = energy * (self.targets / len(self.matched))
        else:
            zt = None if z is None else z[:, tcols]
            at = None if a is None else a[:, tcols]
            D = self._costs(zt, at, aoff)  # P × T × T: the diagonal is target i at q_i
            energy = np.einsum("pii->p", D)
        energy = np.where(np.isfinite(energy), energy, np.inf)
        return Assessment(energy, self._margins(ev, (len(X), S), pop))

    # -- local stage ----------------------------------------------------------------------
    def local_start(self, x: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        lo, hi = self.bounds()
        if self.timed:
            return x.copy(), lo, hi
        # untimed: the matched samples become the targets' driver values
        X = x[None, :]
        _, aoff = self._offsets(X)
        pop = self.space.population(X[:, : self.ng], self.samples)
        q = pop.cycle()
        zj, aj = self._fitted(pop, pop.evaluate(q, order=0), 0)
        D = self._costs(None if zj is None else zj[0], None if aj is None else aj[0], aoff)
        _, start = ordered_match(D)
        idx = np.array(match_indices(D[0], int(start[0])))
        qs = q[0, 0] + TWO_PI * idx / self.samples
        width = 3 * TWO_PI
        return (
            np.concatenate([x, qs]),
            np.concatenate([lo, qs - width]),
            np.concatenate([hi, qs + width]),
        )

    def _split(self, Z: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """Geometry, offsets and the targets' driver values of local variables (rows)."""
        Xg = Z[:, : self.ng]
        qoff, aoff = self._offsets(Z)
        if self.timed:
            qt = self._timing(qoff, Xg)
            assert qt is not None
        else:
            qt = Z[:, self.ng + self.n_offsets :]
        return Xg, qoff, aoff, qt

    def _local(
        self, Z: FloatArray, order: int, with_range: bool = True
    ) -> tuple[FloatArray, dict[str, FloatArray], Any]:
        """Target residuals (P × rows) and margins of rows ``Z``; the jets at the targets.

        ``with_range=False``: the targets' frames only (no margins; for the columns of a
        Jacobian whose penalties are all inactive).
        """
        Xg, _qoff, aoff, qt = self._split(Z)
        T = self.targets
        S = T + self.samples if with_range else T
        pop = self.space.population(Xg, S)
        q_ref = pop.q_ref()
        if not with_range:
            q = qt
        elif self.timed:
            q, _ = self._driver_values(q_ref, qt)
        else:
            cycle = q_ref[:, None] + TWO_PI * np.arange(self.samples)[None, :] / self.samples
            q = np.hstack([qt, cycle])
        ev = pop.evaluate(q, order=order)
        zj, aj = self._fitted(pop, ev, order)
        self.evaluations += len(Z)
        parts = []
        if zj is not None:
            assert self.positions is not None
            err = zj[0][:, :T] - self.positions[None, :]
            parts += [err.real, err.imag]
        if aj is not None:
            assert self.angles is not None
            parts.append(self.weight * wrap(aj[0][:, :T] - self.angles[None, :] - aoff[:, None]))
        jets = (
            None if zj is None else [j[:, :T] for j in zj],
            None if aj is None else [j[:, :T] for j in aj],
        )
        margins = {}
        if with_range:  # the penalties start inside the feasible side (see LOCAL_INSET)
            margins = {
                k: v - LOCAL_INSET[k] for k, v in self._margins(ev, (len(Z), S), pop).items()
            }
        return np.hstack(parts), margins, jets

    def _rows(self, Z: FloatArray, fit: FloatArray, margins: dict[str, FloatArray]) -> FloatArray:
        parts = [fit]
        for name in sorted(margins):
            parts.append(PENALTY * self.scale * np.minimum(margins[name], 0.0)[:, None])
        if not self.timed:
            qs = Z[:, self.ng + self.n_offsets :]
            span = TWO_PI - (qs[:, -1] - qs[:, 0])
            parts.append(self.scale * np.minimum(np.diff(qs, axis=1), 0.0))
            parts.append(self.scale * np.minimum(span, 0.0)[:, None])
        out = np.hstack(parts)
        out = np.where(np.isfinite(out), out, 1e3 * self.scale)
        return out

    def residuals(self, z: FloatArray) -> FloatArray:
        Z = z[None, :]
        fit, margins, _ = self._local(Z, order=0)
        self._last = (z.tobytes(), margins)
        out: FloatArray = self._rows(Z, fit, margins)[0]
        return out

    def jacobian(self, z: FloatArray) -> FloatArray:
        h = FD_STEP * self.scale
        rows = [z]
        for i in range(self.ng):
            for sgn in (1.0, -1.0):
                w = z.copy()
                w[i] += sgn * h
                rows.append(w)
        Z = np.array(rows)
        # the penalties' columns only where one is active (least squares asks for the
        # Jacobian where it has just asked for the residuals: their margins are known)
        last = self._last
        if last is not None and last[0] == z.tobytes():
            known = last[1]
        else:
            known = self._local(z[None, :], order=0)[1]
        active = any(float(v[0]) < 0 for v in known.values())
        fit, margins, (zj, aj) = self._local(Z, order=1, with_range=active)
        if not active:
            margins = {k: np.zeros(len(Z)) + v[0] for k, v in known.items()}
        R = self._rows(Z, fit, margins)
        J = np.zeros((R.shape[1], len(z)))
        J[:, : self.ng] = ((R[1::2] - R[2::2]) / (2 * h)).T  # rows: base, +h, -h, ...
        T = self.targets
        # d(fitted)/dq at each target, exact: the analogs of the base row
        dq: list[FloatArray] = []
        if zj is not None:
            dq += [zj[1][0].real, zj[1][0].imag]
        if aj is not None:
            dq.append(self.weight * aj[1][0])
        k = self.ng
        if self.offset:
            for r, block in enumerate(dq):
                J[r * T : (r + 1) * T, k] = block
            k += 1
        if self.angle_offset:
            J[(len(dq) - 1) * T : len(dq) * T, k] = -self.weight
            k += 1
        if not self.timed:
            for r, block in enumerate(dq):
                for t in range(T):
                    J[r * T + t, k + t] = block[t]
            base = len(dq) * T + len(margins)
            qs = z[k:]
            for t in range(T - 1):
                if qs[t + 1] - qs[t] < 0:
                    J[base + t, k + t] = -self.scale
                    J[base + t, k + t + 1] = self.scale
            if TWO_PI - (qs[-1] - qs[0]) < 0:
                J[base + T - 1, k] = self.scale
                J[base + T - 1, k + T - 1] = -self.scale
        return J

    # -- verdict --------------------------------------------------------------------------
    def finish(self, z: FloatArray, local: bool) -> Outcome:
        if not local and not self.timed:
            z, _, _ = self.local_start(z)  # the matched samples' driver values
        Z = z[None, :]
        Xg, qoff, aoff, qt = self._split(Z)
        q = qt[0]
        goal_angles = self.angles
        n_task = len(self.task.targets)
        if self.range_check is not None and len(q) == n_task:  # objective "points"
            q = np.concatenate([q, self.range_check[0] + qoff[0]])
            assert goal_angles is not None
            goal_angles = np.concatenate([goal_angles, self.range_check[1]])
        m = self.space.mechanism(Xg[0])
        ids = (self.point,) if self.point is not None else ()
        links = (self.link,) if self.link is not None else ()
        frames = max(360, 4 * self.samples)
        check = check_motion(m, q, self.task.full_turn, frames, ids, links, ordered=not self.timed)
        sq = np.zeros(len(q))
        if self.point is not None:
            assert self.positions is not None
            track = check.track.get(self.point, np.full(len(q), np.nan + 0j))
            sq = sq + np.abs(track - self.positions) ** 2
        if self.link is not None:
            assert self.angles is not None
            ang = check.angles.get(self.link, np.full(len(q), np.nan))
            sq = sq + (self.weight * wrap(ang - goal_angles - aoff[0])) ** 2
        errors = np.sqrt(sq)
        range_error = float(np.max(errors)) if len(q) > n_task else None
        if self.range_check is not None and not self.range_fitted:
            sq = sq[:n_task]  # objective "points": the range is reported, not fitted
        t = self.task
        margins: dict[str, float] = {}
        need = 0.0 if t.transmission_deg is None else math.sin(math.radians(t.transmission_deg))
        margins["assembly"] = (check.sine - max(need, MIN_SINE)) if check.ok else -1.0
        if t.lengths is not None:
            margins["lengths"] = float(
                length_margin(self.space.positions(Xg), self.pairs, t.lengths, self.scale)[0]
            )
        details: dict[str, Any] = {
            "stage": "local" if local else "global",
            "timing": [float(v) for v in check.q[:n_task]],
            "q_range": [float(v) for v in check.range],
            "min_transmission_deg": math.degrees(math.asin(min(1.0, check.sine))),
        }
        details["on_bound"] = self.space.on_bound(Xg[0])
        if range_error is not None:
            details["max_error_range"] = range_error
        if t.timing_from is not None:
            P = self.space.positions(Xg)
            j1, j2 = t.timing_from
            details["frame_angle"] = float(np.angle(P[j2][0] - P[j1][0]))
        if self.angle_offset:
            details["angle_offset"] = float(aoff[0])
        reason = check.reason
        if t.motion is not None:
            L = fourbar_lengths(self.space.model.mechanism, self.space.positions(Xg))
            margins["motion"] = float(fourbar_margin(L, t.motion)[0])
            a, b, c, d = (float(L[k][0]) for k in "abcd")
            try:
                got = fourbar_theory(a / d, b / d, c / d).motion
            except Exception:  # a four-bar that cannot close: not this motion
                got = "none"
            details["motion"] = got
            same = got == t.motion or (t.motion == "double-rocker" and got == "triple-rocker")
            if not same:
                margins["motion"] = min(margins["motion"], -1e-6)
                reason = reason or f"the four-bar is a {got}, not a {t.motion}"
        rms = float(np.sqrt(np.mean(sq))) if np.isfinite(sq).all() else math.inf
        feasible = check.ok and all(v >= -1e-9 for v in margins.values()) and math.isfinite(rms)
        offset = float(aoff[0]) if self.angle_offset else None
        out = with_synthesis(m, t, [float(v) for v in check.q[:n_task]], offset)
        errs = tuple(float(e) for e in errors[:n_task])
        if feasible:  # the contract's promises, re-checked from the design's own geometry
            broken = final_verdict(t, out, check.q[:n_task], errs, float(aoff[0]), frames)
            feasible, reason = not broken, reason or "; ".join(broken)
        return Outcome(out, rms, feasible, errs, margins, details, reason)


def with_synthesis(
    m: Mechanism, task: Task, timing: list[float], angle_offset: float | None = None
) -> Mechanism:
    """``m`` carrying the task's targets under ``synthesis`` (what a drawing shows):
    ``timing`` as met, ``timed`` (whether the task prescribed it: a function task's
    targets carry their driver values) and a function task's ``angle_offset``."""
    d = mechanism_to_dict(m)
    entry: dict[str, Any] = {"task": task.kind}
    if task.point is not None:
        entry["point"] = task.point
    if task.link is not None:
        entry["link"] = task.link
    entry["targets"] = [[float(v) for v in row] for row in task.targets]
    entry["timing"] = timing
    entry["timed"] = task.timing is not None or task.kind == "function"
    if angle_offset is not None:
        entry["angle_offset"] = angle_offset
    d[SYNTHESIS_KEY] = entry
    name = task.data.get("name") or (task.mechanism.name if task.mechanism else None)
    if name:
        d["name"] = name
    return mechanism_from_dict(d)
