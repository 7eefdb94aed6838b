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
from functools import cached_property

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
from mjstruct.typing import ComplexArray, FloatArray

#: largest continuation step (in the normalised coordinates)
MAX_STEP = 0.05
#: steps after which a branch that has not closed is reported as trouble
MAX_STEPS = 40000
#: continuation stations corrected together (one batched Newton per block)
BLOCK = 16
#: a polished change point has J's second-smallest singular value below this (else
#: the determinant's sign flip was a jump to a branch passing close by)
CHANGE_POINT_RANK = 1e-8


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

    @cached_property
    def _kernel(self) -> _Kernel:
        return _Kernel.build(self)

    def poses(self, X: FloatArray) -> tuple[ComplexArray, ComplexArray, FloatArray]:
        """Translation, rotation and angle of every link (the frame last) for a batch
        of configurations ``X`` (K × n): three K × (links) arrays."""
        K = X.shape[0]
        Xp = np.concatenate([X, np.zeros((K, 3))], axis=1)  # the frame: at rest
        phi = Xp[:, 2::3]
        return Xp[:, 0::3] + 1j * Xp[:, 1::3], np.exp(1j * phi), phi

    def point(self, x: FloatArray, link: str, z: complex) -> complex:
        """Where the point of ``link`` with (normalised) reference position ``z`` is."""
        T, R, _ = self.poses(np.asarray(x, float)[None, :])
        k = self._kernel.index[link]
        return complex(T[0, k] + R[0, k] * z)

    def joint_positions(self, X: FloatArray) -> ComplexArray:
        """Centres of every joint (file order, each on its first link) over a batch of
        configurations: K × joints, normalised."""
        kern = self._kernel
        T, R, _ = self.poses(X)
        return T[:, kern.joint_link] + R[:, kern.joint_link] * kern.joint_z

    def joint_position(self, x: FloatArray, joint: str) -> complex:
        """Centre of a joint (on its first link), normalised."""
        k = self._kernel.joint_index[joint]
        return complex(self.joint_positions(np.asarray(x, float)[None, :])[0, k])

    def in_file_units(self, z: complex) -> complex:
        """A normalised position in the file's coordinates."""
        return self.origin + z * self.size

    def residuals(self, X: FloatArray) -> FloatArray:
        """All constraint residuals over a batch of configurations: K × rows."""
        kern = self._kernel
        T, R, phi = self.poses(X)
        out = np.empty((X.shape[0], kern.rows))
        ia, ib, z = kern.r_a, kern.r_b, kern.r_z
        d = (T[:, ia] + R[:, ia] * z) - (T[:, ib] + R[:, ib] * z)
        out[:, kern.r_rows] = d.real
        out[:, kern.r_rows + 1] = d.imag
        if kern.p_rows.size:
            ia, ib, z = kern.p_a, kern.p_b, kern.p_z
            u = R[:, ia] * kern.p_axis
            dp = (T[:, ib] + R[:, ib] * z) - (T[:, ia] + R[:, ia] * z)
            out[:, kern.p_rows] = phi[:, ia] - phi[:, ib]
            out[:, kern.p_rows + 1] = (u.conjugate() * dp).imag
        return out

    def residual(self, x: FloatArray) -> FloatArray:
        """All constraint residuals, stacked (joints in file order, 2 rows per pin)."""
        out: FloatArray = self.residuals(np.asarray(x, float)[None, :])[0]
        return out

    def residual_blocks(self, x: FloatArray) -> list[tuple[str, FloatArray]]:
        """Residual of each joint constraint, labelled by joint id (2 rows each)."""
        r = self.residual(x)
        return [(jid, r[k : k + 2]) for jid, k in self._kernel.blocks]

    def jacobians(self, X: FloatArray) -> FloatArray:
        """d residual / d x over a batch of configurations: K × rows × n."""
        kern = self._kernel
        K, n = X.shape[0], self.n
        T, R, _ = self.poses(X)
        # a pin's rows: +-1 in the x and y columns of its two links (constant), and
        # d(R_k z)/d phi_k = i R_k z in their angle columns
        out = np.repeat(kern.r_constant[None, :, :], K, axis=0)
        re, im = kern.r_rows, kern.r_rows + 1
        for links, sign in ((kern.r_a, 1.0), (kern.r_b, -1.0)):
            w = R[:, links] * kern.r_z
            out[:, re, 3 * links + 2] = -sign * w.imag
            out[:, im, 3 * links + 2] = sign * w.real
        if kern.p_rows.size:
            ia, ib, z = kern.p_a, kern.p_b, kern.p_z
            npr = ia.size
            jdx = np.arange(npr)
            u = R[:, ia] * kern.p_axis
            dp = (T[:, ib] + R[:, ib] * z) - (T[:, ia] + R[:, ia] * z)
            Gd = np.zeros((K, npr, n + 3), complex)
            for links, sign in ((ib, 1.0), (ia, -1.0)):
                Gd[:, jdx, 3 * links] += sign
                Gd[:, jdx, 3 * links + 1] += sign * 1j
                Gd[:, jdx, 3 * links + 2] += sign * 1j * R[:, links] * z
            rot = np.zeros((K, npr, n + 3))
            rot[:, jdx, 3 * ia + 2] = 1.0
            rot[:, jdx, 3 * ib + 2] -= 1.0
            slide = (u.conjugate()[:, :, None] * Gd).imag
            slide[:, jdx, 3 * ia + 2] += ((1j * u).conjugate() * dp).imag
            out[:, kern.p_rows] = rot
            out[:, kern.p_rows + 1] = slide
        return out[:, :, :n]  # the frame's columns dropped

    def jacobian(self, x: FloatArray) -> FloatArray:
        """d residual / d x (rows as :meth:`residual`)."""
        out: FloatArray = self.jacobians(np.asarray(x, float)[None, :])[0]
        return out

    def _relatives(self, X: FloatArray, jid: str) -> tuple[FloatArray, FloatArray]:
        """Relative coordinate of a joint (angle, or slide over :attr:`size`) and its
        gradient over a batch: K values and K × n gradients."""
        j = self.mechanism.joint(jid)
        kern = self._kernel
        ia, ib = kern.index[j.links[0]], kern.index[j.links[1]]
        n, K = self.n, X.shape[0]
        T, R, phi = self.poses(X)
        G = np.zeros((K, n + 3))
        if j.kind == "R":
            G[:, 3 * ib + 2] += 1.0
            G[:, 3 * ia + 2] -= 1.0
            return phi[:, ib] - phi[:, ia], G[:, :n]
        z = self.centres[jid]
        u = R[:, ia] * self.geometry.axes[jid]
        d = (T[:, ib] + R[:, ib] * z) - (T[:, ia] + R[:, ia] * z)
        Gd = np.zeros((K, n + 3), complex)
        Gd[:, 3 * ib] += 1.0
        Gd[:, 3 * ib + 1] += 1j
        Gd[:, 3 * ib + 2] += 1j * R[:, ib] * z
        Gd[:, 3 * ia] -= 1.0
        Gd[:, 3 * ia + 1] -= 1j
        Gd[:, 3 * ia + 2] -= 1j * R[:, ia] * z
        G = (u.conjugate()[:, None] * Gd).real
        G[:, 3 * ia + 2] += ((1j * u).conjugate() * d).real
        return (u.conjugate() * d).real, G[:, :n]

    def inputs(self, X: FloatArray) -> tuple[FloatArray, FloatArray]:
        """The driver coordinate q (as the kinematic model defines it) and its gradient
        over a batch (K values, K × n)."""
        val, g = self._relatives(X, self.driver)
        if self.mechanism.joint(self.driver).kind == "P":
            return val * self.size, g * self.size
        return self.geometry.driver_ref[self.driver] + val, g

    def input(self, x: FloatArray) -> tuple[float, FloatArray]:
        """The driver coordinate q and its gradient at one configuration."""
        v, g = self.inputs(np.asarray(x, float)[None, :])
        return float(v[0]), g[0]

    def outputs(self, X: FloatArray) -> tuple[FloatArray, FloatArray]:
        """The output link's coordinate whose extremes are sought, and its gradient,
        over a batch (K values, K × n).

        The relative coordinate of the output's joint with the frame (an angle, or a
        slide in the mechanism's units) when it has one, else the link's angle.
        """
        jid = output_joint(self.mechanism, self.driver, self.output_link)
        if jid is not None:
            val, g = self._relatives(X, jid)
            if self.mechanism.joint(jid).kind == "P":
                return val * self.size, g * self.size
            return val, g
        k = self.moving.index(self.output_link)
        g = np.zeros((X.shape[0], self.n))
        g[:, 3 * k + 2] = 1.0
        return self.geometry.char_angle[self.output_link] + X[:, 3 * k + 2], g

    def output(self, x: FloatArray) -> tuple[float, FloatArray]:
        """The output's coordinate and its gradient at one configuration."""
        v, g = self.outputs(np.asarray(x, float)[None, :])
        return float(v[0]), g[0]

    def output_angle(self, x: FloatArray) -> float:
        """The output link's angle (characteristic angle, as the kinematic model gives it)."""
        return self.link_angle(x, self.output_link)

    def link_angle(self, x: FloatArray, link: str) -> float:
        """A link's characteristic angle in configuration ``x``."""
        base = self.geometry.char_angle[link]
        if link == self.mechanism.frame:
            return base
        return base + float(x[3 * self.moving.index(link) + 2])


@dataclass(frozen=True)
class _Kernel:
    """Index arrays of the closure equations, for batched evaluation.

    Links are numbered as the coordinates (moving links in order, the frame last); a
    revolute pin joining the first link of a joint to another gives two rows (real and
    imaginary part of the difference of the two links' images of the centre), a slider
    two (relative angle, offset across the guide).
    """

    index: dict[str, int]
    rows: int
    r_rows: npt.NDArray[np.intp]
    r_a: npt.NDArray[np.intp]
    r_b: npt.NDArray[np.intp]
    r_z: ComplexArray
    p_rows: npt.NDArray[np.intp]
    p_a: npt.NDArray[np.intp]
    p_b: npt.NDArray[np.intp]
    p_z: ComplexArray
    p_axis: ComplexArray
    r_constant: FloatArray
    blocks: tuple[tuple[str, int], ...]
    joint_index: dict[str, int]
    joint_link: npt.NDArray[np.intp]
    joint_z: ComplexArray

    @classmethod
    def build(cls, eq: ClosureEquations) -> _Kernel:
        m = eq.mechanism
        index = {link: k for k, link in enumerate(eq.moving)}
        index[str(m.frame)] = len(eq.moving)
        r: list[tuple[int, int, int, complex]] = []
        p: list[tuple[int, int, int, complex, complex]] = []
        blocks: list[tuple[str, int]] = []
        row = 0
        for j in m.joints:
            z = eq.centres[j.id]
            if j.kind == "R":
                for other in j.links[1:]:
                    r.append((row, index[j.links[0]], index[other], z))
                    blocks.append((j.id, row))
                    row += 2
            else:
                la, lb = j.links
                p.append((row, index[la], index[lb], z, eq.geometry.axes[j.id]))
                blocks.append((j.id, row))
                row += 2

        constant = np.zeros((row, eq.n + 3))
        for r_row, a, b, _ in r:
            for link, sign in ((a, 1.0), (b, -1.0)):
                constant[r_row, 3 * link] = sign
                constant[r_row + 1, 3 * link + 1] = sign

        def ints(v: list[int]) -> npt.NDArray[np.intp]:
            return np.array(v, dtype=np.intp)

        def cplx(v: list[complex]) -> ComplexArray:
            return np.array(v, dtype=complex)

        return cls(
            index,
            row,
            ints([x[0] for x in r]),
            ints([x[1] for x in r]),
            ints([x[2] for x in r]),
            cplx([x[3] for x in r]),
            ints([x[0] for x in p]),
            ints([x[1] for x in p]),
            ints([x[2] for x in p]),
            cplx([x[3] for x in p]),
            cplx([x[4] for x in p]),
            constant,
            tuple(blocks),
            {j.id: k for k, j in enumerate(m.joints)},
            ints([index[j.links[0]] for j in m.joints]),
            cplx([eq.centres[j.id] for j in m.joints]),
        )


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
    """A difference of configurations (or a stack of them, last axis the coordinates)
    with link angles taken to (-pi, pi]."""
    out = np.array(d, dtype=np.float64)
    cols = list(eq.angle_cols)
    out[..., cols] = (out[..., cols] + np.pi) % (2 * np.pi) - np.pi
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


def _solve_many(A: FloatArray, b: FloatArray) -> FloatArray:
    """``A x = b`` for a stack of systems (least squares where one is not square or
    singular: the bordered matrix is singular exactly at a change point)."""
    if A.shape[-2] == A.shape[-1]:
        try:
            return np.asarray(np.linalg.solve(A, b[..., None])[..., 0], dtype=np.float64)
        except np.linalg.LinAlgError:
            pass
    return np.asarray((np.linalg.pinv(A) @ b[..., None])[..., 0], dtype=np.float64)


def correct_many(
    eq: ClosureEquations, X_pred: FloatArray, normals: FloatArray, iters: int = 40
) -> tuple[FloatArray, npt.NDArray[np.bool_]]:
    """Newton on the closure with ``normal_k . (x_k - x_pred_k) = 0``, all rows at once.

    Returns the corrected points and which of them converged (a row that did not
    keeps its last iterate).  ``normals``: one per row, or one for all.
    """
    X = np.array(X_pred, dtype=np.float64)
    K, n = X.shape
    N = np.broadcast_to(normals, (K, n))
    done = np.zeros(K, dtype=bool)
    small = np.zeros(K, dtype=bool)  # the last Newton step was below STEP_CONVERGED
    res = np.full(K, math.inf)
    for it in range(iters + 1):
        idx = np.flatnonzero(~done)
        if idx.size == 0:
            break
        Xa, Na = X[idx], N[idx]
        R = eq.residuals(Xa)
        res[idx] = np.abs(R).max(axis=1)
        # quadratic convergence: after a step below 1e-7 the error is ~1e-14
        conv = small[idx] & (res[idx] < NEWTON_TOL)
        done[idx[conv]] = True
        if conv.all() or it == iters:  # res now holds every open row's residual
            break
        keep = ~conv
        idx, Xa, Na, R = idx[keep], Xa[keep], Na[keep], R[keep]
        r = np.concatenate([R, np.einsum("kn,kn->k", Na, Xa - X_pred[idx])[:, None]], axis=1)
        A = np.concatenate([eq.jacobians(Xa), Na[:, None, :]], axis=1)
        dx = _solve_many(A, -r)
        X[idx] = Xa + dx
        small[idx] = np.abs(dx).max(axis=1) < STEP_CONVERGED
        res[idx] = math.inf
    # out of iterations: near a change point J is nearly singular and Newton slows
    done |= res < CORRECT_ACCEPT
    return X, done


def correct(
    eq: ClosureEquations, x_pred: FloatArray, normal: FloatArray, iters: int = 40
) -> FloatArray | None:
    """Newton on the closure with ``normal . (x - x_pred) = 0``; None if it fails."""
    X, ok = correct_many(eq, np.asarray(x_pred, float)[None, :], normal, iters)
    return X[0] if ok[0] else None


def tangents(
    eq: ClosureEquations, X: FloatArray, along: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Unit tangents of the curve at the points ``X``, oriented along ``along`` (one
    direction per row, or one for all), and ``det [J; along]`` there (NaN where the
    system has redundant rows).

    The tangent solves ``[J; along] v = e_n`` (so ``along . v = 1 > 0``).
    """
    K, n = X.shape
    J = eq.jacobians(X)
    a = np.broadcast_to(along, (K, n))
    if J.shape[1] != n - 1:
        _, _, vt = np.linalg.svd(J)
        V = vt[:, -1, :]
        V = V * np.where(np.einsum("kn,kn->k", V, a) < 0, -1.0, 1.0)[:, None]
        return V, np.full(K, math.nan)
    A = np.concatenate([J, a[:, None, :]], axis=1)
    e = np.zeros((K, n))
    e[:, -1] = 1.0
    V = _solve_many(A, e)
    norm = np.linalg.norm(V, axis=1)
    bad = ~(np.isfinite(norm) & (norm > 0))
    if bad.any():  # exactly singular (a change point itself): the null vector of J
        _, _, vt = np.linalg.svd(J[bad])
        W = vt[:, -1, :]
        V[bad] = W * np.where(np.einsum("kn,kn->k", W, a[bad]) < 0, -1.0, 1.0)[:, None]
        norm[bad] = 1.0
    return V / norm[:, None], np.linalg.det(A)


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
    shifts = eps * np.eye(n)
    last = math.inf
    for _ in range(20):
        J = eq.jacobian(x)
        r = np.concatenate([eq.residual(x), J.T @ w, [w @ w - 1.0]])
        # d(J^T w)/dx by central differences, all 2n shifted Jacobians in one batch
        Js = eq.jacobians(np.concatenate([x + shifts, x - shifts]))
        Jw = np.einsum("kmn,m->kn", Js, w)
        H = ((Jw[:n] - Jw[n:]) / (2 * eps)).T
        A = np.zeros((m + n + 1, n + m))
        A[:m, :n] = J
        A[m : m + n, :n] = H
        A[m : m + n, n:] = J.T
        A[-1, n:] = 2 * w
        d = np.linalg.lstsq(A, -r, rcond=None)[0]
        x, w = x + d[:n], w + d[n:]
        size = float(np.abs(d).max())
        if size < 1e-15 or size >= last >= 1e-13:  # converged, or stalled at rounding
            break
        last = size
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

    Stations are taken BLOCK at a time: the curve's crossings with the hyperplanes
    normal to the block's first tangent at distances h, 2h, ... (predicted along the
    tangent, bent by the last curvature) are corrected together by one batched Newton,
    with their tangents and bordered determinants; the block is kept up to the first
    station that failed, jumped (more than 2h from the one before) or turned too far.
    Change points crossed are located and appended to ``bifs`` (a new one gets the
    tangents of both branches through it).
    """
    X, T = [x0[None, :]], [t0[None, :]]
    x, t = x0, t0
    h = MAX_STEP / 4
    dist = 0.0
    det_prev = bordered_det(eq, x, t)
    steps = np.arange(1, BLOCK + 1, dtype=np.float64)
    curv = np.zeros_like(t0)  # dt/ds from the last block: the predictor's bend
    for _ in range(MAX_STEPS // BLOCK):
        s = h * steps
        pred = x + s[:, None] * t + 0.5 * (s * s)[:, None] * curv
        Y, ok = correct_many(eq, pred, t, iters=12)
        V, dets = tangents(eq, np.where(ok[:, None], Y, pred), t)
        prev_x = np.vstack([x, Y[:-1]])
        prev_t = np.vstack([t, V[:-1]])
        step = np.linalg.norm(Y - prev_x, axis=1)
        good = (
            ok
            & (np.einsum("kn,kn->k", V, prev_t) >= STEP_TURN)
            & (V @ t >= STEP_TURN)
            & (step <= 2 * h)
        )
        kept = BLOCK if good.all() else int(np.argmin(good))
        if kept == 0:
            h /= 2
            if h < MIN_STEP:
                raise NumericalError("configuration curve: continuation step underflow")
            continue
        # closing: back within a step of the start, heading towards it
        back = wrap_delta(eq, x0 - Y[:kept])
        travelled = dist + np.cumsum(step[:kept])
        closes = (
            (travelled > 4 * h)
            & (np.linalg.norm(back, axis=1) < 1.5 * h)
            & (np.einsum("kn,kn->k", back, V[:kept]) > -1e-12)
        )
        end = int(np.argmax(closes)) + 1 if closes.any() else kept
        jumped = False
        for k in range(end):  # change points: sign changes of det [J; t]
            det_n = float(dets[k])
            if det_prev * det_n < 0 and not _crossing(eq, prev_x[k], prev_t[k], Y[k], bifs):
                end, jumped = k, True  # no crossing there: retrace from station k - 1
                break
            det_prev = det_n if det_n != 0 else det_prev
        X.append(Y[:end])
        T.append(V[:end])
        if jumped:
            if end:
                dist = float(travelled[end - 1])
                x, t = Y[end - 1], V[end - 1]
            h = float(step[end]) / 8
            if h < MIN_STEP:
                raise NumericalError("configuration curve: continuation step underflow")
            curv = np.zeros_like(t0)
            continue
        if closes.any():
            X.append((Y[end - 1] + back[end - 1])[None, :])
            T.append(t0[None, :])
            return Branch(np.concatenate(X), np.concatenate(T))
        dist = float(travelled[-1])
        x, t = Y[kept - 1], V[kept - 1]
        if kept >= 2:
            curv = (V[kept - 1] - V[kept - 2]) / max(float(step[kept - 1]), 1e-300)
        if kept == BLOCK:
            h = min(MAX_STEP, h * 1.5)
    raise NumericalError("configuration curve: a branch did not close")


def _crossing(
    eq: ClosureEquations, x: FloatArray, t: FloatArray, xn: FloatArray, bifs: list[Bifurcation]
) -> bool:
    """A branch crosses between stations ``x`` and ``xn``: locate it with the step's own
    normal ``t``, polish it, and record it with its branch directions if new.

    False when no change point is there: the step jumped across to another branch
    passing close by (the determinant's sign flips with the jump), and the caller
    retraces it with shorter steps.
    """
    # the bordered determinant is linear across a simple crossing: one secant step
    # starts the Gauss-Newton polish close enough for quadratic convergence; Brent's
    # method on the determinant only where that lands outside the step
    d0, d1 = bordered_det(eq, x, t), bordered_det(eq, xn, t)
    s1 = float(t @ (xn - x))
    try:
        xb = refine_change_point(eq, point_on_step(eq, x, t, s1 * d0 / (d0 - d1)))
        if float(np.linalg.norm(wrap_delta(eq, xb - x))) > 2 * abs(s1) + SAME_POINT:

            def bd(s: float) -> float:
                return bordered_det(eq, point_on_step(eq, x, t, s), t)

            s_star = _locate(bd, 0.0, s1)
            xb = refine_change_point(eq, point_on_step(eq, x, t, s_star))
    except (NumericalError, ValueError):  # Newton lost inside the step, or no bracket
        return False
    _, sv = null_space(eq.jacobian(xb))
    if not (
        float(np.abs(eq.residual(xb)).max()) < CORRECT_ACCEPT
        and sv[-2] < CHANGE_POINT_RANK
        and float(np.linalg.norm(wrap_delta(eq, xb - x))) <= 2 * abs(s1) + SAME_POINT
    ):
        return False
    if _known(eq, bifs, xb) is None:
        bifs.append(Bifurcation(xb, branch_directions(eq, xb)))
    return True


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
    diff = wrap_delta(eq, br.x - x)
    near = np.linalg.norm(diff, axis=1) < 2 * MAX_STEP
    return bool(near.any() and (np.abs(br.t[near] @ d) > SAME_DIRECTION).any())
