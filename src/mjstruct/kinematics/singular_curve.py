"""The configuration curve of a one-DOF linkage, traced by pseudo-arclength continuation.

Owns the closure equations in link coordinates (``x, y, phi`` of each moving link,
lengths over the mechanism's size), their Jacobian, and the tracing of every smooth
branch connected to the reference configuration: a branch is followed until it
closes, the change points on it (simple bifurcations: the determinant of the
Jacobian bordered by the tangent changes sign) are located by root refinement, and
the other branch through each one is found from the quadratic form of the closure
residual on the two-dimensional null space and traced in turn.

This is independent of the triangle-rule solver, so it passes through change points
and input limits that stop a driven sweep, and it checks that solver.

References
----------
.. [1] Singular positions and synthesis of hinged multi-joint mechanisms with
   clearances in their revolute pairs (in Russian; eLibrary document code EDN PBGDPR;
   authors, exact title, journal and year not given in the available copy).
   [Four-bar clearances] in docs/references.md.

Examples
--------
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> eq = ClosureEquations.build(read_mechanism(example_path("four-bar")), "O1")
>>> x0 = eq.reference()
>>> float(abs(eq.residual(x0)).max()), eq.jacobian(x0).shape
(0.0, (8, 9))
>>> branches, bif = trace_component(eq, x0)
>>> len(branches), len(bif)          # a crank-rocker: one closed branch, no change point
(1, 0)
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from mjstruct.errors import MechanismError, NumericalError
from mjstruct.kinematics.geometry import Geometry, geometry_of
from mjstruct.kinematics.tolerances import (
    CORRECT_ACCEPT,
    FD_STEP2,
    MIN_STEP,
    NEWTON_TOL,
    QUAD_DEGENERATE,
    QUAD_ZERO,
    RANK_DROP,
    REF_CLOSES,
    SAME_DIRECTION,
    SAME_POINT,
    STEP_CONVERGED,
    STEP_TURN,
)
from mjstruct.mechanism import Mechanism
from mjstruct.structure.drivers import validate_drivers
from mjstruct.typing import FloatArray

#: largest continuation step (in the normalised coordinates)
MAX_STEP = 0.05
#: steps after which a branch that has not closed is reported as trouble
MAX_STEPS = 40000


@dataclass(frozen=True)
class ClosureEquations:
    """Joint constraints of a mechanism in link coordinates, one driver, one output.

    A moving link ``k`` has coordinates ``(x_k, y_k, phi_k)`` and maps its reference
    point ``z`` to ``x_k + i y_k + exp(i phi_k) z``; the reference configuration is
    ``x = 0``.  Positions are measured from the driver's centre (:attr:`origin`) and
    divided by :attr:`size`.
    """

    mechanism: Mechanism
    geometry: Geometry
    driver: str
    output_link: str
    size: float
    moving: tuple[str, ...]
    centres: dict[str, complex]
    angle_cols: tuple[int, ...] = field(repr=False)
    origin: complex = 0j

    @classmethod
    def build(cls, m: Mechanism, driver: str, output: str | None = None) -> ClosureEquations:
        """Equations of ``m`` with ``driver`` as input and ``output`` (default: see
        :func:`default_output`)."""
        # the caller checked m (singular_analysis); the driver is checked here, once
        geom = geometry_of(m, validate_drivers(m, (driver,), balance=False))
        out = default_output(m, driver) if output is None else output
        moving = tuple(x for x in m.links if x != m.frame)
        size = geom.scale
        z0 = geom.centres[m.joint(driver).id]
        centres = {j: (z - z0) / size for j, z in geom.centres.items()}
        cols = tuple(3 * i + 2 for i in range(len(moving)))
        return cls(m, geom, driver, out, size, moving, centres, cols, z0)

    @property
    def n(self) -> int:
        """Number of coordinates."""
        return 3 * len(self.moving)

    def reference(self) -> FloatArray:
        """The reference configuration (all links at rest)."""
        return np.zeros(self.n)

    def _pose(self, x: FloatArray, link: str) -> tuple[complex, complex, int]:
        if link == self.mechanism.frame:
            return 0j, 1 + 0j, -1
        k = self.moving.index(link)
        return (
            complex(x[3 * k], x[3 * k + 1]),
            complex(math.cos(x[3 * k + 2]), math.sin(x[3 * k + 2])),
            3 * k,
        )

    def point(self, x: FloatArray, link: str, z: complex) -> complex:
        """Where the point of ``link`` with (normalised) reference position ``z`` is."""
        p, r, _ = self._pose(x, link)
        return p + r * z

    def joint_position(self, x: FloatArray, joint: str) -> complex:
        """Centre of a joint (on its first link), normalised."""
        j = self.mechanism.joint(joint)
        return self.point(x, j.links[0], self.centres[joint])

    def in_file_units(self, z: complex) -> complex:
        """A normalised position in the file's coordinates."""
        return self.origin + z * self.size

    def residual_blocks(self, x: FloatArray) -> list[tuple[str, FloatArray]]:
        """Residual of each joint constraint, labelled by joint id (2 or 1 rows each)."""
        out: list[tuple[str, FloatArray]] = []
        for j in self.mechanism.joints:
            z = self.centres[j.id]
            if j.kind == "R":
                a = self.point(x, j.links[0], z)
                for other in j.links[1:]:
                    d = a - self.point(x, other, z)
                    out.append((j.id, np.array([d.real, d.imag])))
            else:
                la, lb = j.links
                _, ra, ca = self._pose(x, la)
                _, _, cb = self._pose(x, lb)
                pa = x[ca + 2] if ca >= 0 else 0.0
                pb = x[cb + 2] if cb >= 0 else 0.0
                u = ra * self.geometry.axes[j.id]
                d = self.point(x, lb, z) - self.point(x, la, z)
                out.append((j.id, np.array([pa - pb, (u.conjugate() * d).imag])))
        return out

    def residual(self, x: FloatArray) -> FloatArray:
        """All constraint residuals, stacked."""
        return np.concatenate([r for _, r in self.residual_blocks(x)])

    def _point_grad(
        self, x: FloatArray, link: str, z: complex, sign: float, g: npt.NDArray[np.complex128]
    ) -> None:
        _, r, c = self._pose(x, link)
        if c < 0:
            return
        g[c] += sign
        g[c + 1] += sign * 1j
        g[c + 2] += sign * 1j * r * z

    def jacobian(self, x: FloatArray) -> FloatArray:
        """d residual / d x (rows as :meth:`residual`)."""
        rows: list[FloatArray] = []
        for j in self.mechanism.joints:
            z = self.centres[j.id]
            if j.kind == "R":
                for other in j.links[1:]:
                    g = np.zeros(self.n, complex)
                    self._point_grad(x, j.links[0], z, 1.0, g)
                    self._point_grad(x, other, z, -1.0, g)
                    rows += [g.real.copy(), g.imag.copy()]
            else:
                rows += list(self._slide_rows(x, j.id))
        return np.array(rows).reshape(len(rows), self.n)

    def _slide_rows(self, x: FloatArray, jid: str) -> tuple[FloatArray, FloatArray]:
        j = self.mechanism.joint(jid)
        la, lb = j.links
        z = self.centres[jid]
        _, ra, ca = self._pose(x, la)
        _, _, cb = self._pose(x, lb)
        r1 = np.zeros(self.n)
        if ca >= 0:
            r1[ca + 2] += 1.0
        if cb >= 0:
            r1[cb + 2] -= 1.0
        u = ra * self.geometry.axes[jid]
        d = self.point(x, lb, z) - self.point(x, la, z)
        gd = np.zeros(self.n, complex)
        self._point_grad(x, lb, z, 1.0, gd)
        self._point_grad(x, la, z, -1.0, gd)
        r2 = (u.conjugate() * gd).imag
        if ca >= 0:
            r2[ca + 2] += ((1j * u).conjugate() * d).imag
        return r1, r2

    def _relative(self, x: FloatArray, jid: str) -> tuple[float, FloatArray]:
        """Relative coordinate of a joint (angle, or slide over :attr:`size`) and its gradient."""
        j = self.mechanism.joint(jid)
        la, lb = j.links[0], j.links[1]
        g = np.zeros(self.n)
        _, ra, ca = self._pose(x, la)
        _, _, cb = self._pose(x, lb)
        if j.kind == "R":
            val = (x[cb + 2] if cb >= 0 else 0.0) - (x[ca + 2] if ca >= 0 else 0.0)
            if cb >= 0:
                g[cb + 2] += 1.0
            if ca >= 0:
                g[ca + 2] -= 1.0
            return val, g
        z = self.centres[jid]
        u = ra * self.geometry.axes[jid]
        d = self.point(x, lb, z) - self.point(x, la, z)
        gd = np.zeros(self.n, complex)
        self._point_grad(x, lb, z, 1.0, gd)
        self._point_grad(x, la, z, -1.0, gd)
        g = (u.conjugate() * gd).real
        if ca >= 0:
            g[ca + 2] += ((1j * u).conjugate() * d).real
        return float((u.conjugate() * d).real), g

    def input(self, x: FloatArray) -> tuple[float, FloatArray]:
        """The driver coordinate q (as the kinematic model defines it) and its gradient."""
        val, g = self._relative(x, self.driver)
        if self.mechanism.joint(self.driver).kind == "P":
            return val * self.size, g * self.size
        return self.geometry.driver_ref[self.driver] + val, g

    def output(self, x: FloatArray) -> tuple[float, FloatArray]:
        """The output link's coordinate whose extremes are sought, and its gradient.

        The relative coordinate of the output's joint with the frame (an angle, or a
        slide in the mechanism's units) when it has one, else the link's angle.
        """
        jid = output_joint(self.mechanism, self.driver, self.output_link)
        if jid is not None:
            val, g = self._relative(x, jid)
            if self.mechanism.joint(jid).kind == "P":
                return val * self.size, g * self.size
            return val, g
        return self.output_angle(x), self._angle_grad(self.output_link)

    def _angle_grad(self, link: str) -> FloatArray:
        g = np.zeros(self.n)
        if link != self.mechanism.frame:
            g[3 * self.moving.index(link) + 2] = 1.0
        return g

    def output_angle(self, x: FloatArray) -> float:
        """The output link's angle (characteristic angle, as the kinematic model gives it)."""
        return self.link_angle(x, self.output_link)

    def link_angle(self, x: FloatArray, link: str) -> float:
        """A link's characteristic angle in configuration ``x``."""
        base = self.geometry.char_angle[link]
        if link == self.mechanism.frame:
            return base
        return base + float(x[3 * self.moving.index(link) + 2])


def default_output(m: Mechanism, driver: str) -> str:
    """The link of the last frame joint that is not the driver (contract's default)."""
    for j in reversed(m.joints):
        if j.id != driver and m.frame in j.links:
            return next(x for x in j.links if x != m.frame)
    moving = [x for x in m.links if x != m.frame]
    return moving[-1]


def output_joint(m: Mechanism, driver: str, output: str) -> str | None:
    """The joint (not the driver) that joins the output link to the frame, if any."""
    for j in reversed(m.joints):
        if j.id != driver and m.frame in j.links and output in j.links:
            return j.id
    return None


# --------------------------------------------------------------------------- tracing


def wrap_delta(eq: ClosureEquations, d: FloatArray) -> FloatArray:
    """A difference of configurations with link angles taken to (-pi, pi]."""
    out = d.copy()
    cols = list(eq.angle_cols)
    out[cols] = (out[cols] + np.pi) % (2 * np.pi) - np.pi
    return out


def null_space(J: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Right singular vectors (as columns, smallest last) and singular values of J.

    Padded so that a wide J has as many singular values as columns.
    """
    _, s, vt = np.linalg.svd(J)
    s_full = np.zeros(J.shape[1])
    s_full[: s.size] = s
    return vt.T, s_full


def tangent(eq: ClosureEquations, x: FloatArray, prev: FloatArray | None) -> FloatArray:
    """Unit tangent of the curve at ``x``, oriented along ``prev``."""
    V, _ = null_space(eq.jacobian(x))
    t = V[:, -1]
    if prev is not None and float(t @ prev) < 0:
        t = -t
    return t


def bordered_det(eq: ClosureEquations, x: FloatArray, t: FloatArray) -> float:
    """det [J; t^T]: changes sign where a branch crosses another (a change point)."""
    J = eq.jacobian(x)
    return float(np.linalg.det(np.vstack([J, t]))) if J.shape[0] == eq.n - 1 else math.nan


def correct(
    eq: ClosureEquations, x_pred: FloatArray, normal: FloatArray, iters: int = 40
) -> FloatArray | None:
    """Newton on the closure with ``normal . (x - x_pred) = 0``; None if it fails."""
    x = x_pred.copy()
    for _ in range(iters):
        r = np.append(eq.residual(x), float(normal @ (x - x_pred)))
        A = np.vstack([eq.jacobian(x), normal])
        dx = np.linalg.lstsq(A, -r, rcond=None)[0]
        x = np.asarray(x + dx, dtype=np.float64)
        # quadratic convergence: after a step below 1e-7 the error is ~1e-14
        if (
            float(np.abs(dx).max()) < STEP_CONVERGED
            and float(np.abs(eq.residual(x)).max()) < NEWTON_TOL
        ):
            return x
    if float(np.abs(eq.residual(x)).max()) < CORRECT_ACCEPT:
        return x
    return None


@dataclass(frozen=True)
class Branch:
    """A smooth closed branch: points (unwrapped angles) and unit tangents along it."""

    x: FloatArray
    t: FloatArray


@dataclass
class Bifurcation:
    """A change point: its configuration and the branch tangents met there."""

    x: FloatArray
    tangents: list[FloatArray]


def _quadratic(eq: ClosureEquations, x: FloatArray, u: FloatArray, w: FloatArray) -> float:
    """w . Phi''(x)[u, u] by central differences."""
    e = FD_STEP2
    return float(w @ (eq.residual(x + e * u) + eq.residual(x - e * u) - 2 * eq.residual(x))) / e**2


def branch_directions(eq: ClosureEquations, x: FloatArray) -> list[FloatArray]:
    """Tangents of the branches through a point where J drops rank by one.

    The tangent ``a u1 + b u2`` (``u1, u2`` spanning the null space) makes the
    residual's second-order term vanish along the left null vector ``w``.
    """
    J = eq.jacobian(x)
    U, _, vt = np.linalg.svd(J)
    u1, u2 = vt[-1], vt[-2]
    w = U[:, -1]
    A = _quadratic(eq, x, u1, w)
    C = _quadratic(eq, x, u2, w)
    B = (_quadratic(eq, x, (u1 + u2) / math.sqrt(2), w) * 2 - A - C) / 2
    scale = max(abs(A), abs(B), abs(C))
    if scale < QUAD_DEGENERATE:
        raise MechanismError(
            "mechanism: it moves with more than one degree of freedom at a configuration "
            "(every direction of the two-dimensional null space closes)"
        )
    A, B, C = A / scale, B / scale, C / scale
    disc = B * B - A * C
    if disc < -QUAD_ZERO:
        return []
    disc = max(disc, 0.0)
    dirs: list[tuple[float, float]] = []
    if abs(C) > QUAD_ZERO:
        for sgn in (1.0, -1.0):
            tg = (-B + sgn * math.sqrt(disc)) / C
            dirs.append((1.0, tg))
    else:
        dirs.append((0.0, 1.0))
        dirs.append((1.0, -A / (2 * B)) if abs(B) > QUAD_ZERO else (1.0, 0.0))
    out = []
    for a, b in dirs:
        v = a * u1 + b * u2
        out.append(v / np.linalg.norm(v))
    return out


def _known(eq: ClosureEquations, bifs: list[Bifurcation], x: FloatArray) -> Bifurcation | None:
    for b in bifs:
        if float(np.abs(wrap_delta(eq, x - b.x)).max()) < SAME_POINT:
            return b
    return None


def _locate(f: Callable[[float], float], lo: float, hi: float) -> float:
    """A sign change of ``f`` to 1e-10 (:func:`refine_change_point` polishes it)."""
    from scipy.optimize import brentq

    return float(brentq(f, lo, hi, xtol=1e-10, maxiter=200))


def refine_change_point(eq: ClosureEquations, x: FloatArray) -> FloatArray:
    """Gauss-Newton on ``Phi(x) = 0, J(x)^T w = 0, |w| = 1`` from a located estimate.

    The bordered matrix is singular at a change point, so the continuation's own
    corrector only reaches it to about the square root of the machine precision;
    this system is regular there and converges quadratically.
    """
    U, _, _ = np.linalg.svd(eq.jacobian(x))
    w = U[:, -1]
    n, m = eq.n, w.size
    eps = 1e-7
    for _ in range(20):
        J = eq.jacobian(x)
        r = np.concatenate([eq.residual(x), J.T @ w, [w @ w - 1.0]])
        H = np.empty((n, n))
        for k in range(n):
            e = np.zeros(n)
            e[k] = eps
            H[:, k] = (eq.jacobian(x + e).T @ w - eq.jacobian(x - e).T @ w) / (2 * eps)
        A = np.zeros((m + n + 1, n + m))
        A[:m, :n] = J
        A[m : m + n, :n] = H
        A[m : m + n, n:] = J.T
        A[-1, n:] = 2 * w
        d = np.linalg.lstsq(A, -r, rcond=None)[0]
        x, w = x + d[:n], w + d[n:]
        if float(np.abs(d).max()) < 1e-15:
            break
    return x


def point_on_step(eq: ClosureEquations, x0: FloatArray, t0: FloatArray, s: float) -> FloatArray:
    """The curve point at distance ``s`` along ``t0`` from ``x0`` (corrected)."""
    if s == 0.0:
        return x0
    x = correct(eq, x0 + s * t0, t0)
    if x is None:
        raise NumericalError("configuration curve: Newton failed inside a located step")
    return x


def trace_branch(
    eq: ClosureEquations, x0: FloatArray, t0: FloatArray, bifs: list[Bifurcation]
) -> Branch:
    """Follow the smooth branch from ``x0`` along ``t0`` until it closes.

    Change points crossed are located and appended to ``bifs`` (a new one gets the
    tangents of both branches through it).
    """
    xs, ts = [x0], [t0]
    x, t = x0, t0
    h = MAX_STEP / 4
    dist = 0.0
    det_prev = bordered_det(eq, x, t)
    for _ in range(MAX_STEPS):
        xn = correct(eq, x + h * t, t)
        tn = None if xn is None else tangent(eq, xn, t)
        if xn is None or tn is None or float(tn @ t) < STEP_TURN or np.linalg.norm(xn - x) > 2 * h:
            h /= 2
            if h < MIN_STEP:
                raise NumericalError("configuration curve: continuation step underflow")
            continue
        det_n = bordered_det(eq, xn, t)
        if det_prev * det_n < 0:
            # a branch crosses between x and xn: locate it with the step's own normal
            def bd(s: float, x: FloatArray = x, t: FloatArray = t) -> float:
                return bordered_det(eq, point_on_step(eq, x, t, s), t)

            s_star = _locate(bd, 0.0, float(t @ (xn - x)))
            xb = refine_change_point(eq, point_on_step(eq, x, t, s_star))
            known = _known(eq, bifs, xb)
            if known is None:
                dirs = branch_directions(eq, xb)
                bifs.append(Bifurcation(xb, dirs))
            tn = tangent(eq, xn, t)
        det_prev = det_n if det_n != 0 else det_prev
        dist += float(np.linalg.norm(xn - x))
        x, t = xn, tn
        xs.append(x)
        ts.append(t)
        back = wrap_delta(eq, x0 - x)
        if dist > 4 * h and float(np.linalg.norm(back)) < 1.5 * h and float(back @ t) > -1e-12:
            xs.append(x + back)
            ts.append(t0)
            return Branch(np.array(xs), np.array(ts))
        h = min(MAX_STEP, h * 1.25)
    raise NumericalError("configuration curve: a branch did not close")


def trace_component(
    eq: ClosureEquations, x0: FloatArray
) -> tuple[list[Branch], list[Bifurcation]]:
    """Every smooth branch connected to ``x0`` through change points, and those points.

    Raises
    ------
    MechanismError
        the linkage cannot move from ``x0`` (an isolated configuration).
    """
    J = eq.jacobian(x0)
    if float(np.abs(eq.residual(x0)).max()) > REF_CLOSES:
        raise MechanismError("joints.at: the reference configuration does not close")
    _, s = null_space(J)
    bifs: list[Bifurcation] = []
    starts: list[tuple[FloatArray, FloatArray]] = []
    if s[-2] < RANK_DROP:  # the reference is itself a change point
        dirs = branch_directions(eq, x0)
        if not dirs:
            raise MechanismError(
                "joints.at: the linkage cannot move from its reference configuration "
                "(an isolated, locked position)"
            )
        bifs.append(Bifurcation(x0.copy(), list(dirs)))
    else:
        t0 = tangent(eq, x0, None)
        _, gq = eq.input(x0)
        if float(gq @ t0) < 0:
            t0 = -t0
        starts.append((x0, t0))
    branches: list[Branch] = []
    while True:
        if not starts:
            pending = _untraced(eq, branches, bifs)
            if pending is None:
                break
            starts.append(pending)
        xs, ts = starts.pop()
        br = trace_branch(eq, xs, ts, bifs)
        branches.append(br)
        if len(branches) > 64:
            raise NumericalError("configuration curve: more than 64 branches; giving up")
    return branches, bifs


def _untraced(
    eq: ClosureEquations, branches: list[Branch], bifs: list[Bifurcation]
) -> tuple[FloatArray, FloatArray] | None:
    """A change point and a tangent there that no traced branch follows."""
    for b in bifs:
        for d in b.tangents:
            if not any(_passes(eq, br, b.x, d) for br in branches):
                x1 = correct(eq, b.x + 0.2 * MAX_STEP * d, d)
                if x1 is None:
                    raise NumericalError("configuration curve: cannot leave a change point")
                return x1, tangent(eq, x1, d)
    return None


def _passes(eq: ClosureEquations, br: Branch, x: FloatArray, d: FloatArray) -> bool:
    """Does branch ``br`` pass through ``x`` with tangent parallel to ``d``?"""
    diff = np.array([wrap_delta(eq, p - x) for p in br.x])
    near = np.linalg.norm(diff, axis=1) < 2 * MAX_STEP
    return bool(near.any() and (np.abs(br.t[near] @ d) > SAME_DIRECTION).any())
