"""Path synthesis: a point of a one-DOF mechanism through target points.

Owns :class:`PathProblem`, the path task for :func:`mjstruct.design.search.solve`:

* **variables**: the positions of the free joints and points of the reference
  configuration (:class:`~mjstruct.design.population.DesignSpace`), plus the common
  offset of a relative timing (``timing_offset``);
* **timed targets**: each candidate is evaluated at the targets' driver values and
  over its required driver range in one batched call (P candidates × (T + S)
  frames); the energy is the sum of squared distances;
* **untimed targets**: each candidate's path is sampled over one driver cycle (P × S
  frames) and the targets are matched to it in their order
  (:mod:`mjstruct.design.matching`); the local stage then frees the T driver values
  and refines them with the geometry, their Jacobian columns exact from the
  kinematics' velocity analogs;
* **constraints**: assembly on one branch over the range, without a dead point and
  with the transmission bound (:mod:`mjstruct.design.constraints`), link lengths,
  the four-bar motion type; the verdict by the kinematics (:mod:`mjstruct.design.verify`).

Examples
--------
>>> from mjstruct.design.task import task_from_dict
>>> from mjstruct.io import mechanism_to_dict, read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> m = mechanism_to_dict(read_mechanism(example_path("four-bar")))
>>> t = task_from_dict({"task": "path", "mechanism": m, "point": "M",
...                     "targets": [[0.4, 0.6], [0.2, 0.9], [-0.1, 0.8]]})
>>> p = PathProblem(t)
>>> a = p.assess(p.start()[None, :])
>>> sorted(a.margins), bool(a.energy[0] < 1.0)
(['assembly'], True)
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from mjstruct.design.constraints import (
    assembly_margin,
    fourbar_lengths,
    fourbar_margin,
    length_margin,
    link_pairs,
)
from mjstruct.design.matching import match_indices, ordered_match
from mjstruct.design.population import DesignSpace
from mjstruct.design.result import SYNTHESIS_KEY
from mjstruct.design.search import PENALTY, Assessment, FitProblem, Outcome
from mjstruct.design.task import Task
from mjstruct.design.verify import check_motion
from mjstruct.io import mechanism_from_dict, mechanism_to_dict
from mjstruct.kinematics.fourbar import fourbar_theory
from mjstruct.kinematics.model import KinematicModel
from mjstruct.mechanism import Mechanism
from mjstruct.typing import ComplexArray, FloatArray

TWO_PI = 2 * math.pi
#: central-difference step of the geometry columns, relative to the size
FD_STEP = 1e-6


class PathProblem(FitProblem):
    """The path task of ``task`` (kind ``"path"``), ready for the search."""

    kind = "path"

    def __init__(self, task: Task, space: DesignSpace | None = None) -> None:
        assert task.mechanism is not None and task.point is not None
        self.task = task
        self.point = task.point
        self.target = task.targets[:, 0] + 1j * task.targets[:, 1]
        self.targets = len(self.target)
        if space is None:
            model = KinematicModel.build(task.mechanism)
            space = DesignSpace.build(
                model, task.region, task.fixed, margin=1.0, around=list(self.target)
            )
        self.space = space
        self.scale = space.model.scale
        self.samples = max(int(task.solver["samples"]), 4 * self.targets)
        self.pairs = link_pairs(space.model.mechanism) if task.lengths else []
        self.ng = space.size
        self.offset = task.timing_offset
        self.timed = task.timing is not None
        self.evaluations = 0

    # -- global stage -------------------------------------------------------------------
    def bounds(self) -> tuple[FloatArray, FloatArray]:
        lo, hi = self.space.lower, self.space.upper
        if self.offset:
            lo, hi = np.append(lo, -math.pi), np.append(hi, math.pi)
        return lo, hi

    def start(self) -> FloatArray:
        x = self.space.x0
        if self.offset:
            assert self.task.timing is not None
            q_ref = float(self.space.model.q_ref[0])
            off = q_ref - float(self.task.timing[0])
            x = np.append(x, math.remainder(off, TWO_PI))
        return x

    def _driver_values(
        self, q_ref: FloatArray, qt: FloatArray | None
    ) -> tuple[FloatArray, slice, slice]:
        """Per candidate: the targets' values (timed) then the range samples."""
        M = self.samples
        k = np.arange(M)[None, :]
        if qt is None:
            return q_ref[:, None] + TWO_PI * k / M, slice(0, 0), slice(0, M)
        T = qt.shape[1]
        if self.task.full_turn:
            qr = q_ref[:, None] + TWO_PI * k / M
        else:
            mid = 0.5 * (qt.min(axis=1) + qt.max(axis=1))
            ref = q_ref + TWO_PI * np.round((mid - q_ref) / TWO_PI)
            lo = np.minimum(ref, qt.min(axis=1))
            hi = np.maximum(ref, qt.max(axis=1))
            qr = lo[:, None] + (hi - lo)[:, None] * k / (M - 1)
        return np.hstack([qt, qr]), slice(0, T), slice(T, T + M)

    def _timing(self, off: FloatArray) -> FloatArray | None:
        if self.task.timing is None:
            return None
        return self.task.timing[None, :] + off[:, None]

    def _margins(self, ev: Any, shape: tuple[int, int], Xg: FloatArray) -> dict[str, FloatArray]:
        t = self.task
        out = {"assembly": assembly_margin(ev, shape, t.transmission_deg, slice(None))}
        if t.lengths is not None:
            out["lengths"] = length_margin(
                self.space.positions(Xg), self.pairs, t.lengths, self.scale
            )
        if t.motion is not None:
            lengths = fourbar_lengths(self.space.model.mechanism, self.space.positions(Xg))
            out["motion"] = fourbar_margin(lengths, t.motion)
        return out

    def assess(self, X: FloatArray) -> Assessment:
        X = np.atleast_2d(X)
        Xg = X[:, : self.ng]
        off = X[:, self.ng] if self.offset else np.zeros(len(X))
        qt = self._timing(off)
        S = self.samples + (self.targets if qt is not None else 0)
        pop = self.space.population(Xg, S)
        q, tcols, _ = self._driver_values(pop.q_ref(), qt)
        ev = pop.evaluate(q, order=0)
        z = pop.where(ev, self.point)
        if qt is None:
            energy, _ = ordered_match(z, self.target)
        else:
            d2 = np.abs(z[:, tcols] - self.target[None, :]) ** 2
            energy = d2.sum(axis=1)
        energy = np.where(np.isfinite(energy), energy, np.inf)
        return Assessment(energy, self._margins(ev, (len(X), S), Xg))

    # -- local stage --------------------------------------------------------------------
    def local_start(self, x: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        lo, hi = self.bounds()
        if self.timed:
            return x.copy(), lo, hi
        # untimed: the matched samples become the targets' driver values
        pop = self.space.population(x[None, : self.ng], self.samples)
        q = pop.cycle()
        z = pop.where(pop.evaluate(q, order=0), self.point)[0]
        _, start = ordered_match(z[None, :], self.target)
        idx = np.array(match_indices(z, self.target, int(start[0])))
        qs = q[0, 0] + TWO_PI * idx / self.samples
        width = TWO_PI * 3
        zlo = np.concatenate([lo, qs - width])
        zhi = np.concatenate([hi, qs + width])
        return np.concatenate([x, qs]), zlo, zhi

    def _split(self, Z: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray | None]:
        """Geometry, offset and target driver values of local variables (rows)."""
        Xg = Z[:, : self.ng]
        off = Z[:, self.ng] if self.offset else np.zeros(len(Z))
        qs = None if self.timed else Z[:, self.ng :]
        return Xg, off, qs

    def _local(
        self, Z: FloatArray, order: int
    ) -> tuple[Any, ComplexArray, dict[str, FloatArray], list[ComplexArray]]:
        """Targets' positions (and their jets) and margins of rows ``Z``."""
        Xg, off, qs = self._split(Z)
        qt = self._timing(off) if qs is None else qs
        assert qt is not None
        S = self.targets + self.samples
        pop = self.space.population(Xg, S)
        q_ref = pop.q_ref()
        if qs is None:
            q, _, _ = self._driver_values(q_ref, qt)
        else:
            cycle = q_ref[:, None] + TWO_PI * np.arange(self.samples)[None, :] / self.samples
            q = np.hstack([qt, cycle])
        ev = pop.evaluate(q, order=order)
        jet = pop.jet(ev, self.point)
        self.evaluations += len(Z)
        margins = self._margins(ev, (len(Z), S), Xg)
        return ev, jet[0][:, : self.targets], margins, [j[:, : self.targets] for j in jet]

    def _residual_rows(
        self, Z: FloatArray, zt: ComplexArray, margins: dict[str, FloatArray]
    ) -> FloatArray:
        err = zt - self.target[None, :]
        parts = [err.real, err.imag]
        for name in sorted(margins):
            parts.append(PENALTY * self.scale * np.minimum(margins[name], 0.0)[:, None])
        if not self.timed:
            qs = Z[:, self.ng :]
            gaps = np.diff(qs, axis=1)
            span = TWO_PI - (qs[:, -1] - qs[:, 0])
            parts.append(self.scale * np.minimum(gaps, 0.0))
            parts.append(self.scale * np.minimum(span, 0.0)[:, None])
        out = np.hstack(parts)
        return np.where(np.isfinite(out), out, 1e3 * self.scale)

    def residuals(self, z: FloatArray) -> FloatArray:
        Z = z[None, :]
        _, zt, margins, _ = self._local(Z, order=0)
        out: FloatArray = self._residual_rows(Z, zt, margins)[0]
        return out

    def jacobian(self, z: FloatArray) -> FloatArray:
        h = FD_STEP * self.scale
        n = len(z)
        rows = [z]
        for i in range(self.ng):
            for sgn in (1.0, -1.0):
                w = z.copy()
                w[i] += sgn * h
                rows.append(w)
        Z = np.array(rows)
        _, zt, margins, jet = self._local(Z, order=1)
        R = self._residual_rows(Z, zt, margins)
        J = np.zeros((R.shape[1], n))
        J[:, : self.ng] = ((R[1::2] - R[2::2]) / (2 * h)).T  # rows: base, +h, -h, ...
        T = self.targets
        sigma = jet[1][0]  # d(point)/dq at each target, exact (velocity analog)
        if self.offset:
            J[:T, self.ng] = sigma.real
            J[T : 2 * T, self.ng] = sigma.imag
        if not self.timed:
            for t in range(T):
                J[t, self.ng + t] = sigma[t].real
                J[T + t, self.ng + t] = sigma[t].imag
            base = 2 * T + len(margins)
            qs = z[self.ng :]
            for t in range(T - 1):
                if qs[t + 1] - qs[t] < 0:
                    J[base + t, self.ng + t] = -self.scale
                    J[base + t, self.ng + t + 1] = self.scale
            if TWO_PI - (qs[-1] - qs[0]) < 0:
                J[base + T - 1, self.ng] = self.scale
                J[base + T - 1, self.ng + T - 1] = -self.scale
        return J

    # -- verdict ------------------------------------------------------------------------
    def finish(self, z: FloatArray, local: bool) -> Outcome:
        Z = z[None, :]
        Xg, off, qs = self._split(Z)
        if local and not self.timed:
            assert qs is not None
            q = qs[0]
        elif self.timed:
            qt = self._timing(off)
            assert qt is not None
            q = qt[0]
        else:  # untimed, from the global stage: the matched samples
            zl, _, _ = self.local_start(z)
            q = zl[self.ng :]
        m = self.space.mechanism(Xg[0])
        check = check_motion(m, q, self.task.full_turn, max(360, 4 * self.samples), (self.point,))
        track = check.track.get(self.point, np.full(len(q), np.nan + 0j))
        errors = np.abs(track - self.target)
        t = self.task
        margins: dict[str, float] = {}
        need = 0.0 if t.transmission_deg is None else math.sin(math.radians(t.transmission_deg))
        margins["assembly"] = (check.sine - max(need, 1e-3)) if check.ok else -1.0
        if t.lengths is not None:
            margins["lengths"] = float(
                length_margin(self.space.positions(Xg), self.pairs, t.lengths, self.scale)[0]
            )
        details: dict[str, Any] = {
            "stage": "local" if local else "global",
            "timing": [float(v) for v in check.q],
            "q_range": [float(v) for v in check.range],
            "min_transmission_deg": math.degrees(math.asin(min(1.0, check.sine))),
        }
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
            want = t.motion
            same = got == want or (want == "double-rocker" and got == "triple-rocker")
            if not same:
                margins["motion"] = min(margins["motion"], -1e-6)
                reason = reason or f"the four-bar is a {got}, not a {want}"
        rms = float(np.sqrt(np.mean(errors**2))) if np.isfinite(errors).all() else math.inf
        feasible = check.ok and all(v >= -1e-9 for v in margins.values()) and math.isfinite(rms)
        out = with_synthesis(m, t, [float(v) for v in check.q])
        return Outcome(
            out, rms, feasible, tuple(float(e) for e in errors), margins, details, reason
        )


def with_synthesis(m: Mechanism, task: Task, timing: list[float]) -> Mechanism:
    """``m`` carrying the task's targets under ``synthesis`` (what a drawing shows)."""
    d = mechanism_to_dict(m)
    entry: dict[str, Any] = {"task": task.kind}
    if task.point is not None:
        entry["point"] = task.point
    if task.link is not None:
        entry["link"] = task.link
    entry["targets"] = [[float(v) for v in row] for row in task.targets]
    entry["timing"] = timing
    d[SYNTHESIS_KEY] = entry
    if task.mechanism is not None and task.mechanism.name:
        d["name"] = task.mechanism.name
    return mechanism_from_dict(d)
