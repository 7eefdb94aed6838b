"""Vectorised triangle steps with exact first and second derivatives.

Owns the numerics of one step over all frames at once: a position is a complex array
``x + iy`` of shape ``(frames,)``; a *jet* is the list ``[value, d/dq, d²/dq²]`` (as
long as the order asked for).  The derivatives are not finite differences: each step
solves its two differentiated constraint equations (a 2×2 linear system per frame,
by Cramer's rule), so σ and κ are exact up to rounding.  The system's determinant is
the step's singularity measure (zero at a dead or change point).

The functions below run inside :func:`~mjstruct.kinematics.evaluate.evaluate`, which
silences numpy's floating-point warnings once for all steps (a frame that does not
assemble or sits at a singular position gets NaN or inf, which the frame's validity
reports); called alone at such a frame they warn as numpy does.

Examples
--------
>>> import numpy as np
>>> one = np.ones(1, complex)
>>> X, disc, det = circle_circle([0 * one, 0 * one], [1.2 * one, 0 * one], 1.0, 1.0, 1, 1)
>>> X[0], X[1]             # the apex of an isosceles triangle on a fixed base
(array([0.6+0.8j]), array([0.+0.j]))
>>> round(float(disc[0]), 12), round(float(det[0]), 12)
(0.64, 0.96)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from mjstruct.kinematics.tolerances import CENTRES_APART, DISC_SLACK, PARALLEL

#: an array over the frames (complex positions or real angles and residuals)
Array = npt.NDArray[Any]
#: [value, first derivative, second derivative] (as long as the order asked for)
Jet = list[Array]
#: an assembly mode: ±1 for every frame, or one per frame
Mode = Array | int


@dataclass
class Pose:
    """Placement of a link: local (reference) point ``zA`` sits at ``A``, rotated by ``r``.

    ``r = exp(iθ)`` with θ the rotation from the reference configuration; ``w`` holds
    θ' and θ'' (as many as the order).
    """

    zA: complex
    A: Jet
    r: Array
    w: Jet
    #: the pose of the link the plan is solved in (r = 1, A and w zero): its points
    #: stand still
    fixed: bool = False

    def point(self, z: complex) -> Jet:
        """Jet of the link's point whose reference position is ``z``."""
        # at a singular frame ω is infinite: its point's rates are NaN there, which the
        # frame's validity reports (not a numpy warning)
        with np.errstate(invalid="ignore", over="ignore"):
            return self.carry(z)

    def carry(self, z: complex, lower: Jet | None = None) -> Jet:
        """:meth:`point` without its own floating-point error state (for the steps
        of :func:`~mjstruct.kinematics.evaluate.evaluate`, which sets it once).

        ``lower``: the point's derivatives of the lowest orders, already known (from an
        evaluation at the same configuration): only the orders above are computed.
        """
        # the anchor itself: nothing to compute (per-frame geometry, where the design
        # plug-in gives each frame its own reference positions, compares arrays)
        if z is self.zA or (_scalar(z) and _scalar(self.zA) and z == self.zA):
            return list(self.A)
        n = len(self.A)
        out = [] if lower is None else lower[:n]
        if len(out) == n:
            return out
        if self.fixed and _scalar(z):
            # what the general formula gives here, without its arithmetic over the
            # frames: z (a zero part +0, as 0 + 1·z makes it) and zero derivatives
            shape = self.r.shape
            if not out:
                out.append(np.full(shape, complex(z.real + 0.0, z.imag + 0.0)))
            out += self.A[len(out) : n]  # its zero arrays, shared
            return out
        rd = self.r * (z - self.zA)
        if not out:
            out.append(self.A[0] + rd)
        if n > 1 and len(out) == 1:
            out.append(self.A[1] + 1j * self.w[0] * rd)
        if n > 2 and len(out) == 2:
            out.append(self.A[2] + (1j * self.w[1] - self.w[0] ** 2) * rd)
        return out

    def vector(self, v: complex) -> Jet:
        """Jet of a direction fixed to the link (reference value ``v``)."""
        rv = self.r * v
        out = [rv]
        with np.errstate(invalid="ignore", over="ignore"):  # as in :meth:`point`
            if len(self.A) > 1:
                out.append(1j * self.w[0] * rv)
            if len(self.A) > 2:
                out.append((1j * self.w[1] - self.w[0] ** 2) * rv)
        return out


def _scalar(z: object) -> bool:
    return not isinstance(z, np.ndarray)


def dot(a: Array, b: Array) -> Array:
    """Scalar product of plane vectors stored as complex numbers."""
    out: Array = a.real * b.real + a.imag * b.imag
    return out


_dot = dot


def solve2(g1: Array, h1: Array, g2: Array, h2: Array) -> Array:
    """X with ``g1·X = h1`` and ``g2·X = h2`` (plane vectors as complex numbers)."""
    det = g1.real * g2.imag - g1.imag * g2.real
    X: Array = -1j * (h1 * g2 - h2 * g1) / det
    return X


def circle_circle(
    P1: Jet,
    P2: Jet,
    r1: float,
    r2: float,
    K: Mode,
    order: int,
    lower: tuple[Jet, Array, Array] | None = None,
) -> tuple[Jet, Array, Array]:
    """Dyad RRR: the point at distances r1 from P1 and r2 from P2 on side K (±1).

    Returns the jet of the point, the discriminant h² / r1² (negative: the dyad does
    not assemble) and the signed sine of the angle at the point between the two sides
    (zero at a dead point).  ``lower``: the point's known derivatives of the lowest
    orders with the discriminant and the sine, as returned at the same configuration:
    only the orders above are computed.
    """
    if lower is None:
        d = P2[0] - P1[0]
        D = np.abs(d)
        # coincident centres: the dyad is undefined (a change point of a hinged square)
        D = np.where(CENTRES_APART * (r1 + r2) < D, D, np.nan)
        a = (D * D + r1 * r1 - r2 * r2) / (2.0 * D)
        disc = (r1 * r1 - a * a) / (r1 * r1)
        h = r1 * np.sqrt(np.where((disc < 0) & (disc > -DISC_SLACK), 0.0, disc))
        X = [P1[0] + (a + 1j * K * h) * d / D]
    else:
        X, disc, det = lower[0][: order + 1], lower[1], lower[2]
        if len(X) == order + 1:
            return X, disc, det
    X0 = X[0]
    g1, g2 = X0 - P1[0], X0 - P2[0]
    if order >= 1 and len(X) == 1:
        X.append(solve2(g1, _dot(g1, P1[1]), g2, _dot(g2, P2[1])))
    if order >= 2 and len(X) == 2:
        t1, t2 = X[1] - P1[1], X[1] - P2[1]
        X.append(solve2(g1, _dot(g1, P1[2]) - _dot(t1, t1), g2, _dot(g2, P2[2]) - _dot(t2, t2)))
    if lower is None:
        det = (g1.real * g2.imag - g1.imag * g2.real) / (r1 * r2)
    return X, disc, det


def circle_line(
    P1: Jet, r1: float, L: Jet, n: Jet, K: Mode, order: int
) -> tuple[Jet, Array, Array]:
    """Dyad RRP: the point at distance r1 from P1 on the line through L with normal n.

    ``n`` is a unit normal (jet: it turns with the guide's link).  Returns the point's
    jet, the discriminant h² / r1² and the signed sine of the angle between the side
    and the guide (zero at a dead point: the side is perpendicular to the guide).
    """
    u = -1j * n[0]
    w = L[0] - P1[0]
    beta = _dot(u, w)
    disc = (beta * beta - (_dot(w, w) - r1 * r1)) / (r1 * r1)
    root = r1 * np.sqrt(np.where((disc < 0) & (disc > -DISC_SLACK), 0.0, disc))
    s = -beta + K * root
    X0 = L[0] + s * u
    X = [X0]
    g1 = X0 - P1[0]
    if order >= 1:
        e = X0 - L[0]
        X.append(solve2(g1, _dot(g1, P1[1]), n[0], _dot(n[0], L[1]) - _dot(n[1], e)))
    if order >= 2:
        t1 = X[1] - P1[1]
        X.append(
            solve2(
                g1,
                _dot(g1, P1[2]) - _dot(t1, t1),
                n[0],
                _dot(n[0], L[2]) - _dot(n[2], e) - 2.0 * _dot(n[1], X[1] - L[1]),
            )
        )
    det = (g1.real * n[0].imag - g1.imag * n[0].real) / r1
    return X, disc, det


def line_line(L1: Jet, n1: Jet, L2: Jet, n2: Jet, order: int) -> tuple[Jet, Array, Array]:
    """Dyads PRP and RPP: the point on the line through L1 (unit normal n1) and on L2's (n2).

    Each line is a guide carried by a placed link (``L`` the link's image of the solved
    point's reference position, ``n`` the guide's normal turned with the link), so the
    step is linear: one intersection, no assembly mode.  Differentiating ``n·(X - L) = 0``
    gives ``n·X' = n·L' - n'·(X - L)`` and ``n·X'' = n·L'' - n''·(X - L) - 2 n'·(X' - L')``
    for both lines (Cramer's rule, as in :func:`circle_line`).  Returns the point's jet,
    a discriminant (1, or -1 where the guides are parallel and the point is undefined:
    those frames are nan) and the signed sine of the angle between the guides.

    >>> one = np.ones(1, complex)
    >>> X, disc, det = line_line([0 * one], [1j * one], [2 * one], [1 * one], 0)
    >>> complex(X[0][0]) == 2, float(det[0])   # the x axis meets the vertical line x = 2
    (True, -1.0)
    """
    a, b = n1[0], n2[0]
    det = a.real * b.imag - a.imag * b.real
    parallel = ~(np.abs(det) > PARALLEL)
    X0 = np.where(parallel, np.nan, solve2(a, _dot(a, L1[0]), b, _dot(b, L2[0])))
    X = [X0]
    e1, e2 = X0 - L1[0], X0 - L2[0]
    if order >= 1:
        X.append(solve2(a, _dot(a, L1[1]) - _dot(n1[1], e1), b, _dot(b, L2[1]) - _dot(n2[1], e2)))
    if order >= 2:
        X.append(
            solve2(
                a,
                _dot(a, L1[2]) - _dot(n1[2], e1) - 2.0 * _dot(n1[1], X[1] - L1[1]),
                b,
                _dot(b, L2[2]) - _dot(n2[2], e2) - 2.0 * _dot(n2[1], X[1] - L2[1]),
            )
        )
    return X, np.where(parallel, -1.0, 1.0), det


def guide_pair(
    P1: Jet, P2: Jet, z1: complex, z2: complex, axis: complex, K: Mode, order: int
) -> tuple[Array, Jet, Array, Array]:
    """Dyad RPR: common rotation of two links sliding on each other along ``axis``.

    Link b carries P1 (reference z1), link c carries P2 (reference z2); the guide keeps
    P2 on the line through b's image of z2 with direction ``axis`` turned with b.  With
    g = conj(axis) e^{-iθ} (P2 - P1) the constraint is Im g = e (the guide's offset);
    its derivatives give θ' and θ''.  Returns r = e^{iθ}, [θ', θ''], the discriminant
    1 - (e/|P2 - P1|)² and the cosine between the guide and P1P2 (zero: dead point).
    """
    e = ((z2 - z1) * axis.conjugate()).imag
    w = P2[0] - P1[0]
    W = np.abs(w)
    ratio = e / W
    disc = 1.0 - ratio * ratio
    # θ = arg w - arg axis - asin(e/|w|) on one side, π - asin on the other
    alpha = np.arcsin(np.clip(ratio, -1.0, 1.0))
    alpha = np.where(np.asarray(K) > 0, alpha, np.pi - alpha)
    theta = np.angle(w) - np.angle(axis) - alpha
    theta = np.where(disc >= -DISC_SLACK, theta, np.nan)
    r = np.exp(1j * theta)
    c = axis.conjugate() * r.conjugate()
    g = c * w
    out: Jet = []
    if order >= 1:
        t1 = (c * (P2[1] - P1[1])).imag / g.real
        out.append(t1)
    if order >= 2:
        w1, w2 = P2[1] - P1[1], P2[2] - P1[2]
        out.append((c * (w2 - 2j * t1 * w1 - t1 * t1 * w)).imag / g.real)
    return r, out, disc, g.real / W


def rotation_between(
    P: Jet, Q: Jet, zP: complex, zQ: complex, lower: tuple[Array, Jet] | None = None
) -> tuple[Array, Jet]:
    """Rotation of a link carrying P and Q (reference positions zP, zQ): ``r`` and θ', θ''.

    ``lower``: ``r`` and the known θ', θ'' of the lowest orders, as returned at the same
    configuration: only the orders above are computed.
    """
    n = len(P) - 1
    v = Q[0] - P[0]
    if lower is None:
        e = zQ - zP
        r = (v / np.abs(v)) / (e / abs(e))
        w: Jet = []
    else:
        r, w = lower[0], lower[1][:n]
        if len(w) == n:
            return r, w
    if n > 0:
        q1 = (Q[1] - P[1]) / v
        if not w:
            w.append(q1.imag)
    if n > 1:
        w.append(((Q[2] - P[2]) / v - q1 * q1).imag)
    return r, w


def distance_residual(P: Jet, Q: Jet, length: float) -> Jet:
    """Jet of ``|Q - P| - length`` (a loop-closure equation)."""
    v = [Q[k] - P[k] for k in range(len(P))]
    n = np.abs(v[0])
    out = [n - length]
    if len(v) > 1:
        p1 = _dot(v[0], v[1])
        out.append(p1 / n)
    if len(v) > 2:
        # n * n * n, not n**3: numpy's power takes the slow general path for 3
        out.append((_dot(v[0], v[2]) + _dot(v[1], v[1])) / n - p1 * p1 / (n * n * n))
    return out
