"""The equation of motion of a one-DOF mechanism and the integrals of the loads' work.

Owns ``V(q) = Σ I σ²`` (reduced inertia), ``W(q) = Σ I σ κ``, the generalised force
``Q(q, q̇) = Σ F σ`` (``V q̈ + W q̇² = Q``), the work integral ``A(q) = ∫ Q dq`` by
four methods, the unknown parameter of steady motion (cycle work = a given change of
kinetic energy) and the speed and acceleration along the motion,
``q̇² = (2A + V(q₀) q̇₀²)/V`` and ``q̈ = (Q − W q̇²)/V``.  A speed-dependent load
turns the energy integral into an ODE in q, solved with scipy.

The module works along a *path* ``q(u) = q_ref + s·u`` (every driver moves by u in the
direction s = ±1), so the same functions give the cycle work of several drivers moved
together.  :class:`PathForce` is what a time integrator needs: ``V``, ``W``, ``Q`` at
any q.

Integration methods (``method``):

``gauss``
    Gauss–Legendre (32 nodes on up to 200 pieces, else 6; half as many for the
    estimate) on pieces bounded by the output frames and the jumps of the load
    expressions (``Piecewise``, ``Heaviside``, ``sign``, ``Abs`` in q), pieces halved
    until they agree (vectorised: one call of the kinematics per round, its closure
    seeded from the frames' solution when there is one): piecewise loads are
    integrated piece by piece.
``trapezoid``
    the trapezoid rule on 2ⁿ equal steps of the cycle, interpolated linearly to the frames.
``fft``
    the 2ⁿ samples fitted by a Fourier series of ``harmonics`` terms and integrated
    analytically (the route of [Panasenko 2025] for periodic Q).
``adaptive``
    ``scipy.integrate.quad_vec`` between frames and jumps.

References
----------
.. [1] A. N. Panasenko, "Practical implementation…" (in Russian; the available copy
   gives only this beginning of the title), Systems. Methods. Technologies,
   no. 2 (66), pp. 32–42, 2025. [Panasenko 2025] in docs/references.md.

Examples
--------
>>> import numpy as np
>>> f = lambda u: np.stack([np.cos(u) ** 2])
>>> w = work_integral(f, 2 * np.pi, np.array([0.0, np.pi]), "gauss")
>>> round(float(w.cycle[0]), 12), round(float(w.A[0, 1]), 12)
(3.14159265359, 1.570796326795)
"""

from __future__ import annotations

import dataclasses
import functools
import itertools
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from mjstruct.dynamics.data import DynamicsData
from mjstruct.errors import MechanismError, NumericalError
from mjstruct.kinematics.model import KinematicModel, Motion

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]

METHODS = ("gauss", "trapezoid", "fft", "adaptive")

#: Gauss–Legendre nodes per piece (the estimate uses half as many): many nodes on few
#: pieces (each round of refinement is one call of the kinematics, costly for closures),
#: fewer once the frames make the pieces short
GAUSS_NODES = 6
#: Gauss–Legendre nodes of the stop point's energy integral
STOP_NODES = 24
GAUSS_NODES_FEW_PIECES = 32
GAUSS_FEW_PIECES = 200

#: starting pieces of the cycle, halving rounds, relative tolerance and point budget
GAUSS_PIECES = 16
GAUSS_ROUNDS = 30
GAUSS_RTOL = 1e-12
GAUSS_MAX_POINTS = 200_000

#: largest frame spacing (radians of the driver) from which the Gauss rounds are seeded:
#: the continuation's own station step
SEED_SPACING = 0.25

#: relative tolerance of the energy ODE (speed-dependent loads)
ODE_RTOL = 1e-10


def inertia(mo: Motion, data: DynamicsData, links: Sequence[str]) -> FloatArray:
    """``V = Σ m|σ_c|² + J σ_θ²`` alone (first derivatives suffice)."""
    V = np.zeros(mo.q.shape[0])
    for link in links:
        li = data.inertia[link]
        if li.mass:
            v = mo.point(link, li.com)[1]
            V += li.mass * (v.real**2 + v.imag**2)
        if li.J:
            V += li.J * mo.angle(link)[1] ** 2
    return V


def coefficients(
    mo: Motion, data: DynamicsData, links: Sequence[str]
) -> tuple[FloatArray, FloatArray]:
    """``V = Σ m|σ_c|² + J σ_θ²`` and ``W = Σ m σ_c·κ_c + J σ_θ κ_θ`` over the frames.

    ``mo`` must carry second derivatives along the path (order 2).
    """
    F = mo.q.shape[0]
    V, W = np.zeros(F), np.zeros(F)
    for link in links:
        li = data.inertia[link]
        if li.mass:
            c = mo.point(link, li.com)
            V += li.mass * (c[1].real ** 2 + c[1].imag ** 2)
            W += li.mass * (c[1].real * c[2].real + c[1].imag * c[2].imag)
        if li.J:
            t = mo.angle(link)
            V += li.J * t[1] ** 2
            W += li.J * t[1] * t[2]
    return V, W


@dataclass(frozen=True)
class Slope:
    """A variant of the loads: their rate of change in the parameter ``name`` at
    ``values`` (gravity and the loads without ``name`` add nothing).

    The unknown of steady motion enters the loads affinely (usually): the work is then
    ``A(p) = A(0) + p·A'``, and integrating ``A'`` itself keeps its digits whatever the
    unit of p (a difference ``A(1) − A(0)`` loses them when one unit of p is small
    beside the other loads).
    """

    values: Mapping[str, float]
    name: str


#: a set of parameter values, or the loads' rate of change in one of them
Variant = Mapping[str, float] | Slope


def generalised_force(
    mo: Motion,
    data: DynamicsData,
    links: Sequence[str],
    qload: FloatArray,
    qdot: npt.ArrayLike,
    variants: Sequence[Variant],
) -> FloatArray:
    """``Q = Σ F·σ + M σ_θ`` (gravity included) for each variant: variants × frames.

    ``mo`` carries first derivatives along the path; ``qload`` and ``qdot`` are what the
    load expressions see.  A :class:`Slope` variant gives ``∂Q/∂p``.
    """
    F = mo.q.shape[0]
    base = np.zeros(F)
    g = data.gravity
    if g:
        for link in links:
            li = data.inertia[link]
            if li.mass:
                v = mo.point(link, li.com)[1]
                base += li.mass * (g.real * v.real + g.imag * v.imag)
    sig = []
    for load in data.loads:
        if load.kind == "force":
            v = mo.point(load.link, load.at)[1]
            sig.append((v.real, v.imag, np.zeros(F)))
        else:
            sig.append((np.zeros(F), np.zeros(F), mo.angle(load.link)[1]))
    out = np.empty((len(variants), F))
    for k, params in enumerate(variants):
        if isinstance(params, Slope):
            Q = np.zeros(F)
            for load, (sx, sy, st) in zip(data.loads, sig, strict=True):
                if params.name in load.arguments:
                    c = load.slope(params.name).evaluate(qload, qdot, params.values)
                    Q += c[0] * sx + c[1] * sy + c[2] * st
        else:
            Q = base.copy()
            for load, (sx, sy, st) in zip(data.loads, sig, strict=True):
                c = load.evaluate(qload, qdot, params)
                Q += c[0] * sx + c[1] * sy + c[2] * st
        out[k] = Q
    return out


@dataclass(frozen=True)
class PathForce:
    """``V``, ``W`` and ``Q`` at any point of the path ``q(u) = q_ref + s·u``.

    Attributes
    ----------
    model : the kinematic model.
    data : the dynamics data.
    direction : s = ±1.
    """

    model: KinematicModel
    data: DynamicsData
    direction: float
    table: Motion | None = None

    @property
    def links(self) -> tuple[str, ...]:
        return tuple(x for x in self.model.mechanism.links if x != self.model.frame)

    def with_table(self, mo: Motion) -> PathForce:
        """This path seeded from ``mo``, a solved motion of frames on it (one driver).

        The Gauss rounds then start each point's closure Newton from a Taylor step of
        the nearest frame's unknowns (t, t', t'' known there) instead of a fresh
        continuation from the reference, and skip the continuation when every point
        closes on the frames' branch; otherwise they fall back to ``model.motion``.
        """
        usable = (
            len(self.model.drivers) == 1
            and mo.closure is not None
            and not mo.events
            and bool(mo.valid.all())
            and mo.order >= 2
            and mo.q.shape[0] >= 2
            and float(np.abs(np.diff(mo.q[:, 0])).max()) <= SEED_SPACING
        )
        return dataclasses.replace(self, table=mo if usable else None)

    def q(self, u: npt.ArrayLike) -> FloatArray:
        """Driver values (frames × drivers) at path parameters ``u``."""
        ua = np.atleast_1d(np.asarray(u, float))
        return self.model.q_ref[None, :] + self.direction * ua[:, None]

    def motion(self, u: npt.ArrayLike, order: int) -> Motion:
        D = len(self.model.drivers)
        rates = self.direction * np.ones(D)
        seeded = None if self.table is None else _seeded(self.table, self.q(u), order, rates)
        mo = (
            seeded
            if seeded is not None
            else self.model.motion(self.q(u), order=order, rates=rates)
        )
        if not mo.valid.all():
            bad = float(self.q(u)[np.argmax(~mo.valid), 0])
            raise NumericalError(f"the mechanism does not assemble at q = {bad:.9g}")
        return mo

    def force(
        self, u: npt.ArrayLike, qdot: npt.ArrayLike, variants: Sequence[Variant]
    ) -> FloatArray:
        """Path generalised force ``Σ F · ds/du`` (variants × points)."""
        ua = np.atleast_1d(np.asarray(u, float))
        qd = np.broadcast_to(np.asarray(qdot, float), ua.shape)
        # the closure continues along increasing u: solve sorted, answer in the asked order
        order = np.argsort(ua, kind="stable")
        mo = self.motion(ua[order], 1)
        out = generalised_force(mo, self.data, self.links, mo.q[:, 0], qd[order], variants)
        back = np.empty_like(out)
        back[:, order] = out
        return back

    def coefficients(self, u: npt.ArrayLike) -> tuple[FloatArray, FloatArray]:
        """``V`` and ``W`` along the path (the reduced inertia of the path coordinate)."""
        ua = np.atleast_1d(np.asarray(u, float))
        order = np.argsort(ua, kind="stable")
        V, W = coefficients(self.motion(ua[order], 2), self.data, self.links)
        Vb, Wb = np.empty_like(V), np.empty_like(W)
        Vb[order], Wb[order] = V, W
        return Vb, Wb

    def switches(self, period: float) -> FloatArray:
        """Path parameters in (0, period) where a load expression jumps."""
        grid = np.linspace(0.0, period, 4097)
        qgrid = self.q(grid)[:, 0]
        out: list[float] = []
        for load in self.data.loads:
            # the roots of a load's switch functions on a path: kept with the load
            key = (float(self.model.q_ref[0]), self.direction, period)
            if key not in load.jumps:
                roots: list[float] = []
                for fn in load.switches:
                    vals = np.broadcast_to(np.asarray(fn(qgrid), float), grid.shape)
                    roots += _roots(fn, grid, vals, self.q)
                load.jumps[key] = tuple(roots)
            out += load.jumps[key]
        return np.unique(np.array([x for x in out if 0.0 < x < period]))


def _seeded(table: Motion, q: FloatArray, order: int, rates: FloatArray) -> Motion | None:
    """The motion on ``q`` by Newton from the frames of ``table`` (None: fall back).

    Each point starts from the cubic Hermite interpolation of the closure unknowns
    between its two frames (t and dt/dq known there; beyond the last frame, a Taylor
    step).  When a point does not close to the kinematics' tolerance, or the points
    and frames taken in order fail the kinematics' own branch-jump test (Δt against
    the trapezoid of dt/dq), the whole call falls back to ``model.motion``.
    """
    from mjstruct.kinematics.closure import Closure, derivatives, newton
    from mjstruct.kinematics.evaluate import evaluate
    from mjstruct.kinematics.tolerances import CLOSURE_TOL

    model, sol = table.model, table.closure
    assert sol is not None
    # the table was solved at unit rate along q (the frames of dynamic_analysis): its
    # t1, t2 are dt/dq and d²t/dq²
    by_q = np.argsort(table.q[:, 0], kind="stable")
    qt, tt, t1t, t2t = table.q[by_q, 0], sol.t[by_q], sol.t1[by_q], sol.t2[by_q]
    x = q[:, 0]
    a = np.clip(np.searchsorted(qt, x, side="right") - 1, 0, qt.size - 1)
    b = np.minimum(a + 1, qt.size - 1)
    h = (qt[b] - qt[a])[:, None]
    d = (x - qt[a])[:, None]
    with np.errstate(all="ignore"):
        u = np.where(h > 0, d / h, 0.0)
        hermite = (
            (2 * u**3 - 3 * u**2 + 1) * tt[a]
            + (u**3 - 2 * u**2 + u) * h * t1t[a]
            + (-2 * u**3 + 3 * u**2) * tt[b]
            + (u**3 - u**2) * h * t1t[b]
        )
        taylor = tt[a] + t1t[a] * d + t2t[a] * d**2 / 2
        inside = (h > 0) & (d >= 0)
        guess = np.where(inside, hermite, taylor)
        t, err, rounds, ok = newton(model, q, guess, None, CLOSURE_TOL, 30)
        if not ok.all():
            return None
        t1, t2 = derivatives(model, q, t, rates, order=order)
        # the kinematics' branch-jump test on frames and points in order of q (pairs of
        # two frames were the kinematics' to judge)
        qa = np.concatenate([qt, x])
        ta = np.concatenate([tt, t])
        da = np.concatenate([t1t, t1 / rates[0]])
        new = np.concatenate([np.zeros(qt.size, bool), np.ones(x.size, bool)])
        o = np.argsort(qa, kind="stable")
        qa, ta, da, new = qa[o], ta[o], da[o], new[o]
        pred = 0.5 * (da[1:] + da[:-1]) * np.diff(qa)[:, None]
        real = np.diff(ta, axis=0)
        jump = np.abs(real - pred).max(axis=1) > 0.1 * np.abs(pred).max(axis=1) + 1e-3
        if (jump & (new[1:] | new[:-1])).any():
            return None
        ev = evaluate(model, q, order=order, rates=rates, t=t, t1=t1, t2=t2)
        valid = np.ones(q.shape[0], bool)
        for pose in ev.poses.values():
            valid &= np.isfinite(pose.r + sum(pose.A) + sum(pose.w))
    if not valid.all():
        return None
    closure = Closure(t, t1, t2, err, rounds, ok, CLOSURE_TOL)
    return Motion(model, q, order, ev, valid, closure, (), ())


def _roots(
    fn: Callable[..., object],
    grid: FloatArray,
    vals: FloatArray,
    qmap: Callable[[npt.ArrayLike], FloatArray],
) -> list[float]:
    from scipy.optimize import brentq

    out: list[float] = [float(x) for x in grid[vals == 0]]
    flips = np.nonzero(np.sign(vals[:-1]) * np.sign(vals[1:]) < 0)[0]
    for i in flips:

        def g(u: float) -> float:
            return float(np.asarray(fn(qmap([u])[0, 0]), float))

        out.append(float(brentq(g, grid[i], grid[i + 1], xtol=1e-15, rtol=1e-15)))
    return out


@dataclass(frozen=True)
class Integral:
    """The work integral ``A(u) = ∫_0^u f`` of each variant of the loads.

    Attributes
    ----------
    A : A at the targets (variants × targets).
    cycle : A over the whole cycle (variants).
    error : estimate of the cycle value's error (variants): the difference to a coarser
        run of the same method (half the nodes, or half the steps).
    evaluations : points where f was evaluated.
    slope : dA/du at the targets as the method represents it (the trapezoid's chord
        slope, the Fourier fit), or None when it is f itself (gauss, adaptive).
    grid, grid_A : the method's own points (piece ends, samples, Gauss nodes) and A
        there (variants × points): where the motion may stop between two targets.
    grid_exact : which grid values are the method's result (not a screening estimate).
    magnitude : the size of each variant's integral, ``period`` × the mean of |f| over
        the points evaluated (about ∫|f|): the scale of its round-off.
    """

    A: FloatArray
    cycle: FloatArray
    error: FloatArray
    evaluations: int
    slope: FloatArray | None
    grid: FloatArray
    grid_A: FloatArray
    grid_exact: BoolArray
    magnitude: FloatArray


@functools.cache
def gauss_legendre(nodes: int) -> tuple[FloatArray, FloatArray]:
    """Gauss–Legendre nodes and weights on [-1, 1] (computed once per count, read-only)."""
    x, w = np.polynomial.legendre.leggauss(nodes)
    x.flags.writeable = False
    w.flags.writeable = False
    return x, w


def _gauss(
    f: Callable[[FloatArray], FloatArray], period: float, targets: FloatArray, brk: FloatArray
) -> Integral:
    """Gauss–Legendre on pieces between frames and jumps, halving pieces until converged.

    A piece is split while its n- and n/2-node values of some variant differ by more
    than its share of ``GAUSS_RTOL`` × that variant's ∫|f| (n = 32 on up to 200 pieces,
    else 6: pieces between many frames are short); all pending pieces are evaluated in
    one call of ``f``.  Each variant is judged against its own magnitude: variants in
    different units (the work and its rate in a parameter) converge alike.
    """
    edges = np.unique(np.concatenate([np.linspace(0.0, period, GAUSS_PIECES + 1), targets, brk]))
    edges = edges[(edges >= 0.0) & (edges <= period)]
    nodes = GAUSS_NODES_FEW_PIECES if edges.size <= GAUSS_FEW_PIECES else GAUSS_NODES
    x2, w2 = gauss_legendre(nodes)
    x1, w1 = gauss_legendre(nodes // 2)
    x = np.concatenate([x2, x1])
    todo_a, todo_b = edges[:-1], edges[1:]
    done_a: list[FloatArray] = []
    done_fine: list[FloatArray] = []
    done_err: list[FloatArray] = []
    done_vals: list[FloatArray] = []
    count = 0
    scale = np.zeros(0)
    for _ in range(GAUSS_ROUNDS):
        mid, half = (todo_a + todo_b) / 2, (todo_b - todo_a) / 2
        pts = (mid[:, None] + half[:, None] * x[None]).ravel()
        count += pts.size
        vals = f(pts).reshape(-1, len(todo_a), len(x))
        fine = (vals[:, :, : len(x2)] * w2).sum(axis=2) * half
        coarse = (vals[:, :, len(x2) :] * w1).sum(axis=2) * half
        err = np.abs(fine - coarse)
        mean = np.abs(vals).mean(axis=(1, 2)) * period
        scale = mean if scale.size == 0 else np.maximum(scale, mean)
        bad = (err > GAUSS_RTOL * scale[:, None] * (2 * half) / period).any(axis=0)
        if count > GAUSS_MAX_POINTS:
            bad[:] = False
        done_a.append(todo_a[~bad])
        done_fine.append(fine[:, ~bad])
        done_err.append(np.abs(fine - coarse)[:, ~bad])
        done_vals.append(vals[:, ~bad, : len(x2)])
        if not bad.any():
            break
        a, b = todo_a[bad], todo_b[bad]
        m = (a + b) / 2
        todo_a, todo_b = np.concatenate([a, m]), np.concatenate([m, b])
    starts = np.concatenate(done_a)
    order = np.argsort(starts)
    fine_all = np.concatenate(done_fine, axis=1)[:, order]
    err_all = np.concatenate(done_err, axis=1).sum(axis=1)
    starts = starts[order]
    cum = np.concatenate([np.zeros((fine_all.shape[0], 1)), np.cumsum(fine_all, axis=1)], axis=1)
    bounds = np.append(starts, period)
    idx = np.searchsorted(bounds, targets)
    # A at the nodes by the trapezoid rule inside each piece: only to screen for the
    # motion stopping between two piece ends (the root is then refined exactly)
    nv = np.concatenate(done_vals, axis=1)[:, order]
    half = (bounds[1:] - bounds[:-1]) / 2
    t = np.concatenate([[-1.0], x2, [1.0]])
    ext = np.concatenate([nv[:, :, :1], nv, nv[:, :, -1:]], axis=2)
    steps = (ext[:, :, 1:] + ext[:, :, :-1]) / 2 * np.diff(t) * half[None, :, None]
    node_A = cum[:, :-1, None] + np.cumsum(steps, axis=2)[:, :, :-1]
    node_u = (starts + half)[:, None] + half[:, None] * x2[None]
    grid = np.concatenate([bounds, node_u.ravel()])
    grid_A = np.concatenate([cum, node_A.reshape(cum.shape[0], -1)], axis=1)
    exact = np.arange(grid.size) < bounds.size
    return Integral(cum[:, idx], cum[:, -1], err_all, count, None, grid, grid_A, exact, scale)


def work_integral(
    f: Callable[[FloatArray], FloatArray],
    period: float,
    targets: FloatArray,
    method: str = "gauss",
    n: int = 10,
    harmonics: int | None = None,
    breaks: FloatArray | None = None,
) -> Integral:
    """``A(u) = ∫_0^u f`` at ``targets`` (sorted, in [0, period]) and over the cycle.

    Parameters
    ----------
    f : integrand over an array of u, returning variants × points.
    period : the cycle length.
    targets : points where A is wanted.
    method : one of :data:`METHODS`.
    n : 2ⁿ equal steps (trapezoid, fft).
    harmonics : Fourier terms kept (fft; default all 2ⁿ⁻¹).
    breaks : jumps of f (gauss, adaptive).
    """
    brk = np.zeros(0) if breaks is None else np.asarray(breaks, float)
    if method == "gauss":
        return _gauss(f, period, targets, brk)
    if method in ("trapezoid", "fft"):
        if not 1 <= n <= 24:
            raise MechanismError(f"n: 2^n steps needs 1 <= n <= 24, got {n}")
        N = 2**n
        u = period * np.arange(N + 1) / N
        vals = f(u[:-1])
        vals = np.concatenate([vals, vals[:, :1]], axis=1)  # periodic: f(T) = f(0)
        h = period / N
        steps = (vals[:, 1:] + vals[:, :-1]) * h / 2
        cum = np.concatenate([np.zeros((vals.shape[0], 1)), np.cumsum(steps, axis=1)], axis=1)
        coarse = vals[:, :-1:2].sum(axis=1) * 2 * h if N >= 2 else np.full(vals.shape[0], np.inf)
        err = np.abs(steps.sum(axis=1) - coarse)
        size = np.abs(vals[:, :-1]).mean(axis=1) * period
        if method == "trapezoid":
            A = np.stack([np.interp(targets, u, c) for c in cum])
            chord = np.diff(cum, axis=1) / h
            k = np.clip(np.searchsorted(u, targets, side="right") - 1, 0, N - 1)
            # the cycle by pairwise summation (a running sum loses digits over 2^16 steps)
            ones = np.ones(u.size, bool)
            return Integral(A, steps.sum(axis=1), err, N, chord[:, k], u, cum, ones, size)
        c = np.fft.rfft(vals[:, :-1], axis=1) / N
        H = N // 2 if harmonics is None else max(0, min(int(harmonics), N // 2))
        k = np.arange(1, H + 1)
        ck = c[:, 1 : H + 1].copy()
        if H == N // 2 and H > 0:
            ck[:, -1] /= 2  # the Nyquist term is counted once
        om = 2 * np.pi / period
        wave = np.exp(1j * om * np.outer(k, targets))
        A = c[:, :1].real * targets[None] + 2 * np.real((ck / (1j * k * om)) @ (wave - 1.0))
        slope = c[:, :1].real + 2 * np.real(ck @ wave)
        exact = np.ones(targets.size, bool)
        return Integral(A, c[:, 0].real * period, err, N, slope, targets, A, exact, size)
    if method == "adaptive":
        from scipy.integrate import quad_vec

        edges = np.unique(np.concatenate([[0.0, period], targets]))
        count = [0]
        total: list[FloatArray] = []

        def fs(u: float) -> FloatArray:
            count[0] += 1
            val = f(np.array([u]))[:, 0]
            total.append(np.abs(val))
            return val

        parts, errs = [], []
        for a0, b0 in itertools.pairwise(edges):
            inner = [float(x) for x in brk if a0 < x < b0]
            val, e = quad_vec(fs, a0, b0, epsabs=1e-13, epsrel=1e-12, points=inner or None)
            parts.append(val)
            errs.append(e)
        fine = np.stack(parts, axis=1)
        cum = np.concatenate([np.zeros((fine.shape[0], 1)), np.cumsum(fine, axis=1)], axis=1)
        idx = np.searchsorted(edges, targets)
        err_all = np.full(fine.shape[0], float(sum(errs)))
        exact = np.ones(edges.size, bool)
        size = np.mean(total, axis=0) * period
        return Integral(cum[:, idx], cum[:, -1], err_all, count[0], None, edges, cum, exact, size)
    raise MechanismError(
        f"method: unknown integration method {method!r} (one of {', '.join(METHODS)})"
    )


@dataclass(frozen=True)
class FreeMotion:
    """One-DOF motion under the loads, along the frames.

    Attributes
    ----------
    parameters : all parameters, the unknown filled in.
    A : work of the loads from the first frame (frames kept).
    qdot, qddot : speed and acceleration (frames kept).
    kept : how many frames are kept (the motion may stop earlier).
    stop : the q where q̇² turns negative, or None.
    cycle_work : work of the loads over the cycle (with the solved parameter).
    error : an estimate of the integration error of the cycle work.
    evaluations : points where the loads were evaluated.
    method : the integration method used (``ode`` for speed-dependent loads).
    """

    parameters: dict[str, float]
    A: FloatArray
    qdot: FloatArray
    qddot: FloatArray
    kept: int
    stop: float | None
    cycle_work: float
    error: float
    evaluations: int
    method: str


def _affine_variants(data: DynamicsData) -> list[Variant]:
    """The loads with the unknown at 0, and their rate of change in it."""
    assert data.unknown is not None
    base = data.parameter_values(**{data.unknown: 0.0})
    return [base, Slope(base, data.unknown)]


def _affine_unknown(data: DynamicsData, w: Integral) -> tuple[dict[str, float], FloatArray, float]:
    """The unknown from the cycle works of :func:`_affine_variants`: every parameter, the
    mix of the two variants that is the solved loads (``[1, p]``) and the cycle work's
    error estimate.

    Raises
    ------
    MechanismError
        naming the unknown when one unit of it changes the cycle work by no more than
        ``GAUSS_RTOL`` of the work its loads do (gross): nothing fixes it then.
    """
    p = data.unknown
    assert p is not None
    slope, gross = float(w.cycle[1]), float(w.magnitude[1])
    if not abs(slope) > GAUSS_RTOL * gross:
        why = (
            f" (one unit of {p} changes it by {abs(slope):.3g}, within the round-off of "
            f"the {gross:.3g} its loads do over the cycle, summed without sign)"
            if gross > 0
            else ""
        )
        raise MechanismError(
            f"parameters.{p}: the cycle work (one cycle in the direction of motion) "
            f"does not depend on {p}{why}"
        )
    value = float((data.energy_change - w.cycle[0]) / slope)
    err = float(w.error[0] + abs(value) * w.error[1])
    return data.parameter_values(**{p: value}), np.array([1.0, value]), err


def steady_parameter(
    path: PathForce,
    qdot: float,
    method: str = "gauss",
    n: int = 10,
    harmonics: int | None = None,
) -> tuple[dict[str, float], float, float]:
    """The parameters with the unknown solved for cycle work = ``energy_change``.

    The loads see the constant speed ``qdot``.  Returns the parameters, the cycle work
    and its error estimate.
    """
    data = path.data
    T = 2 * np.pi
    brk = path.switches(T) if method in ("gauss", "adaptive") else None

    def cycle(variants: Sequence[Variant]) -> Integral:
        return work_integral(
            lambda u: path.force(u, qdot, variants), T, np.zeros(0), method, n, harmonics, brk
        )

    if data.unknown is None:
        params = data.parameter_values()
        w = cycle([params])
        return params, float(w.cycle[0]), float(w.error[0])
    p = data.unknown
    if data.is_linear_in_unknown():
        params, _, err = _affine_unknown(data, cycle(_affine_variants(data)))
        return params, data.energy_change, err
    from scipy.optimize import root_scalar

    def residual(x: float) -> float:
        return float(cycle([data.parameter_values(**{p: x})]).cycle[0] - data.energy_change)

    # the secant starts from 0 and the Newton step from 0, which sets the unknown's
    # scale (its unit may be anything); from one unit, converged only relatively
    # (xtol the smallest double), where that step is not defined
    x1, xtol = 1.0, float(np.finfo(float).tiny)
    try:
        w = cycle(_affine_variants(data))
        with np.errstate(all="ignore"):
            step = float((data.energy_change - w.cycle[0]) / w.cycle[1])
        if np.isfinite(step) and step != 0.0:
            x1, xtol = step, 1e-14 * abs(step)
    except MechanismError:  # a derivative not finite at 0
        pass
    with warnings.catch_warnings():
        # "Tolerance reached": two iterates with equal residuals, reported below
        warnings.simplefilter("ignore", RuntimeWarning)
        sol = root_scalar(
            residual, x0=0.0, x1=x1, method="secant", xtol=xtol, rtol=1e-13, maxiter=100
        )
    if not sol.converged or not np.isfinite(sol.root):
        start = "from 0 and the Newton step from 0" if x1 != 1.0 else "from 0 and 1"
        raise NumericalError(
            f"parameters.{p}: no value makes the cycle work {data.energy_change:g} "
            f"(the loads are not affine in {p}; the secant method started {start})"
        )
    params = data.parameter_values(**{p: float(sol.root)})
    w = cycle([params])
    return params, float(w.cycle[0]), float(w.error[0])


def free_motion(
    path: PathForce,
    u: FloatArray,
    V: FloatArray,
    W: FloatArray,
    qdot0: float,
    method: str = "gauss",
    n: int = 10,
    harmonics: int | None = None,
    force_at_frames: Callable[[Mapping[str, float], FloatArray], FloatArray] | None = None,
) -> FreeMotion:
    """Speed and acceleration along the frames ``u`` (path parameters, u[0] = 0).

    ``V``, ``W`` are the inertia coefficients at the frames; ``qdot0`` the speed at
    the first frame (its sign is the path's direction).  ``force_at_frames(params,
    qdot)`` gives Q(q) at the first frames (default: a fresh kinematic solution).
    """
    if path.data.uses_qdot:
        return _free_motion_ode(path, u, V, W, qdot0)
    s = path.direction
    T = 2 * np.pi
    data = path.data
    brk = path.switches(T) if method in ("gauss", "adaptive") else None
    if data.unknown is not None and data.is_linear_in_unknown():
        # one pass with the unknown at 0 and the loads' rate in it: all is affine in it
        variants = _affine_variants(data)
        w = work_integral(lambda x: path.force(x, 0.0, variants), T, u, method, n, harmonics, brk)
        params, mix, err = _affine_unknown(data, w)
        A = mix @ w.A
        grid_A = mix @ w.grid_A
        cycle = float(data.energy_change)
        w_slope = None if w.slope is None else (mix @ w.slope)[None]
    else:
        if data.unknown is not None:
            params, _, _ = steady_parameter(path, 0.0, method, n, harmonics)
        else:
            params = data.parameter_values()
        w = work_integral(lambda x: path.force(x, 0.0, [params]), T, u, method, n, harmonics, brk)
        A, cycle, err, w_slope = w.A[0], float(w.cycle[0]), float(w.error[0]), w.slope
        grid_A = w.grid_A[0]
    e0 = V[0] * qdot0**2
    E2 = 2 * A + e0  # twice the kinetic energy
    # the first sign change of the energy, looked for on the method's own points too
    pts = np.concatenate([u, w.grid])
    vals = np.concatenate([E2, 2 * grid_A + e0])
    order = np.argsort(pts, kind="stable")
    pts, vals, Ap = pts[order], vals[order], np.concatenate([A, grid_A])[order]
    exact = np.concatenate([np.ones(u.size, bool), w.grid_exact])[order]
    stop = None
    kept = len(u)
    if e0 == 0.0 and s * path.force([0.0], 0.0, [params])[0, 0] < 0:
        stop, kept = float(path.q([0.0])[0, 0]), 1  # at rest, pushed backwards
    elif (vals < 0).any():
        g = int(np.argmax(vals < 0))
        a = int(np.nonzero(exact[:g])[0][-1])  # start from a value the method computed
        u_stop = _stop_point(path, params, pts[a], pts[g], e0, Ap[a])
        stop = float(path.q([u_stop])[0, 0])
        kept = max(1, int(np.searchsorted(u, u_stop, side="right")))
    qd = s * np.sqrt(np.maximum(E2[:kept], 0.0) / V[:kept])
    # q̈ = (dA/dq − W q̇²)/V with dA/dq as the method represents it: the excluded
    # equation then measures how far that representation is from the true force
    if w_slope is not None:
        slope = w_slope[0, :kept]
    elif force_at_frames is not None:
        slope = s * force_at_frames(params, qd)[:kept]
    else:
        slope = path.force(u[:kept], qd, [params])[0]
    qdd = (s * slope - W[:kept] * qd**2) / V[:kept]
    count = w.evaluations
    return FreeMotion(params, A[:kept], qd, qdd, kept, stop, cycle, err, count, method)


def _stop_point(
    path: PathForce, params: Mapping[str, float], a: float, b: float, e0: float, A_a: float
) -> float:
    """The path parameter in [a, b] where 2A + V₀q̇₀² reaches zero (q̇² turns negative)."""
    from scipy.optimize import brentq

    xg, wg = gauss_legendre(STOP_NODES)

    def energy(x: float) -> float:
        if x <= a:
            return float(2 * A_a + e0)
        half = (x - a) / 2
        vals = path.force(a + half * (xg + 1), 0.0, [params])[0]
        return float(2 * (A_a + half * (vals * wg).sum()) + e0)

    return float(brentq(energy, a, b, xtol=1e-13)) if energy(a) > 0 and energy(b) < 0 else b


def _free_motion_ode(
    path: PathForce, u: FloatArray, V: FloatArray, W: FloatArray, qdot0: float
) -> FreeMotion:
    """Speed-dependent loads: ``dE/du = Q(q, q̇)`` with ``E = V q̇²/2``, by scipy's DOP853.

    The interval is split at the loads' jumps (each piece integrated on its own, so
    the step control never straddles a jump); the unknown parameter is found by the
    secant method on the cycle's energy change, starting from the loads frozen at the
    initial speed.
    """
    from scipy.integrate import solve_ivp

    data = path.data
    s = path.direction
    T = 2 * np.pi
    E0 = V[0] * qdot0**2 / 2
    calls = [0]
    edges = np.concatenate([[0.0], path.switches(T), [T]])
    rtol = ODE_RTOL
    guess = None
    if data.unknown is not None:
        guess = steady_parameter(path, qdot0)[0][data.unknown]
        frozen = data.parameter_values(**{data.unknown: guess})
    else:
        frozen = data.parameter_values()
    # E's absolute tolerance in its own scale (E may be 1e-90 or 1e90): the kinetic
    # energy and the work of the loads (frozen at the initial speed) over a cycle
    work = T * float(np.abs(path.force(u, qdot0, [frozen])[0]).max())
    atol = max(1e-14 * (abs(E0) + work), float(np.finfo(float).tiny))

    def run(params: Mapping[str, float]) -> tuple[FloatArray, float, float | None]:
        """E at the frames (until a stop), E at the cycle's end, the stop's u."""

        def rhs(x: float, y: FloatArray) -> FloatArray:
            calls[0] += 1
            mo = path.motion([x], 1)
            Vx = inertia(mo, data, path.links)[0]
            qd = s * np.sqrt(max(2 * y[0], 0.0) / Vx)
            dE: FloatArray = generalised_force(mo, data, path.links, mo.q[:, 0], qd, [params])[0]
            return dE

        def stopped(x: float, y: FloatArray) -> float:
            return float(y[0])

        stopped.terminal = True  # type: ignore[attr-defined]
        stopped.direction = -1  # type: ignore[attr-defined]
        y = E0
        out: list[float] = []
        for a, b in itertools.pairwise(edges):
            sol = solve_ivp(
                rhs,
                (a, b),
                [y],
                method="DOP853",
                rtol=rtol,
                atol=atol,
                events=stopped,
                dense_output=True,
            )
            inside = u[(u >= a) & ((u < b) | ((b == T) & (u <= b)))]
            if sol.status == 1 and len(sol.t_events[0]):
                t_stop = float(sol.t_events[0][0])
                out += [float(v) for v in sol.sol(inside[inside <= t_stop])[0]]
                return np.array(out), float("nan"), t_stop
            out += [float(v) for v in sol.sol(inside)[0]]
            y = float(sol.y[0, -1])
        return np.array(out), y, None

    if data.unknown is not None:
        from scipy.optimize import root_scalar

        p = data.unknown

        def residual(x: float) -> float:
            _, end, stop_u = run(data.parameter_values(**{p: x}))
            if stop_u is not None:
                q_stop = float(path.q([stop_u])[0, 0])
                raise NumericalError(
                    f"parameters.{p}: the motion stops at q = {q_stop:.9g} before the cycle ends "
                    f"for {p} = {x:.9g} (give a larger qdot0)"
                )
            return float(end - E0 - data.energy_change)

        assert guess is not None
        # steps relative to the guess: the unknown's unit may be anything (one unit
        # only when the frozen loads give exactly 0)
        root = root_scalar(
            residual,
            x0=guess,
            x1=guess * (1 + 1e-3) if guess != 0 else 1e-3,
            method="secant",
            xtol=max(1e-13 * abs(guess), float(np.finfo(float).tiny)),
            rtol=1e-12,
        )
        if not root.converged:
            raise NumericalError(
                f"parameters.{p}: no value gives the cycle work {data.energy_change:g}"
            )
        params = data.parameter_values(**{p: float(root.root)})
    else:
        params = data.parameter_values()
    if E0 == 0.0 and s * path.force([0.0], 0.0, [params])[0, 0] < 0:
        stop_u: float | None = 0.0  # at rest, pushed backwards
        E, end = np.zeros(1), float("nan")
    else:
        E, end, stop_u = run(params)
    kept = len(E)
    stop = None if stop_u is None else float(path.q([stop_u])[0, 0])
    cycle = end - E0
    qd = s * np.sqrt(np.maximum(2 * E, 0.0) / V[:kept])
    Q = path.force(u[:kept], qd, [params])[0] * s
    qdd = (Q - W[:kept] * qd**2) / V[:kept]
    err = rtol * (abs(E0) + abs(cycle)) if np.isfinite(cycle) else float("nan")
    return FreeMotion(params, E - E0, qd, qdd, kept, stop, cycle, err, calls[0], "ode")
