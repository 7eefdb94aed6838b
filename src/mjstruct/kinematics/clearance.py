"""Clearance zones: how far a singular position spreads when the pins have clearance.

Owns formula (3) (the zone angle of a collinear pair of links, exact for a
pin-in-hole chain), the leading-order zone ``psi ~ 2 sqrt(2E/|c|)`` of any singular
position of a one-DOF linkage, and the exact zone by a small feasibility search in
which every pin centre is free in a disc of its clearance.

Formula (3): two links of lengths ``l >= r`` share a joint; their outer pivots are
``l + r`` apart (first kind, stretched) or ``l - r`` (second kind, folded).  With a
total radial clearance ``D`` in the chain the longer link can turn by ``psi`` about
its pivot while the chain still closes:
``cos(psi/2) = [(l +- r)^2 + l^2 - (r + D)^2] / [2 l (l +- r)]`` (clipped to [-1, 1]).

Examples
--------
>>> import math
>>> round(math.degrees(formula3(1.0, 0.5, 0.01, stretched=True)), 2)
9.41
>>> round(math.degrees(formula3(1.0, 0.5, 0.01, stretched=False)), 2)
16.3
>>> round(math.degrees(formula3_small(1.0, 0.5, 0.01, stretched=True)), 2)
9.36
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping

import numpy as np
import numpy.typing as npt

from mjstruct.errors import MechanismError, NumericalError
from mjstruct.kinematics.singular_curve import ClosureEquations

FloatArray = npt.NDArray[np.float64]


def formula3(l: float, r: float, clearance: float, stretched: bool) -> float:  # noqa: E741
    """Zone angle ``psi`` (rad) of formula (3) for a pair of links ``l >= r``.

    Parameters
    ----------
    l, r : the longer and the shorter link (any length unit).
    clearance : total radial clearance of the chain (same unit), >= 0.
    stretched : first kind (outer pivots ``l + r`` apart) or second (``l - r``).

    Returns
    -------
    float
        ``2 arccos`` of the clipped argument: 0 at zero clearance, ``2 pi`` when the
        folded pair's pivots coincide (``l = r``).
    """
    if clearance < 0 or not math.isfinite(clearance):
        raise MechanismError(f"clearance: must be a finite number >= 0, got {clearance}")
    if r > l:
        l, r = r, l  # noqa: E741
    d = l + r if stretched else l - r
    if d <= 1e-15 * l:
        return 2 * math.pi if clearance > 0 else 0.0
    arg = (d * d + l * l - (r + clearance) ** 2) / (2 * l * d)
    return 2 * math.acos(max(-1.0, min(1.0, arg)))


def formula3_small(l: float, r: float, clearance: float, stretched: bool) -> float:  # noqa: E741
    """Small-clearance form of (3): ``psi ~ 2 sqrt(2 lambda delta / (1 +- lambda))``."""
    if r > l:
        l, r = r, l  # noqa: E741
    lam, delta = r / l, clearance / l
    den = 1 + lam if stretched else 1 - lam
    return 2 * math.sqrt(2 * lam * delta / den) if den > 0 else 2 * math.pi


def _blocks(eq: ClosureEquations) -> list[tuple[str, slice, str]]:
    """(joint id, residual rows, kind) of each pin of the closure."""
    out, k = [], 0
    for jid, r in eq.residual_blocks(eq.reference()):
        out.append((jid, slice(k, k + r.size), eq.mechanism.joint(jid).kind))
        k += r.size
    return out


def _fixed_coordinate(
    eq: ClosureEquations, fixed: str
) -> Callable[[FloatArray], tuple[float, FloatArray]]:
    return eq.input if fixed == "input" else eq.output


def singular_direction(
    eq: ClosureEquations, x: FloatArray, fixed: str
) -> tuple[FloatArray, FloatArray]:
    """Null vector ``v`` and left null vector ``w`` of ``[J; grad g]`` at ``x``.

    ``g`` is the coordinate held (``"input"`` or ``"output"``); ``w`` has one entry
    per closure row and a last one for ``g``.
    """
    g = _fixed_coordinate(eq, fixed)
    A = np.vstack([eq.jacobian(x), g(x)[1]])
    U, _, vt = np.linalg.svd(A)
    return vt[-1], U[:, -1]


def leading_order_zone(
    eq: ClosureEquations,
    x: FloatArray,
    fixed: str,
    link: str,
    clearances: Mapping[str, float],
) -> float | None:
    """``psi ~ 2 sqrt(2E/|c|)``: the turn of ``link`` over the zone, to leading order.

    Along the singular direction ``v`` (normalised to a unit turn of ``link``) the
    closure residual grows as ``c s^2 / 2`` in the left null direction ``w``; the
    pins absorb up to ``E = sum |w_j| D_j``.  ``None`` when ``link`` does not turn
    along ``v``.
    """
    v, w = singular_direction(eq, x, fixed)
    col = 3 * eq.moving.index(link) + 2
    if abs(v[col]) < 1e-9:
        return None
    v = v / v[col]
    g = _fixed_coordinate(eq, fixed)
    g0 = g(x)[0]
    e = 1e-4

    def F(y: FloatArray) -> FloatArray:
        return np.append(eq.residual(y), g(y)[0] - g0)

    c = float(w @ (F(x + e * v) + F(x - e * v) - 2 * F(x))) / e**2
    E = 0.0
    for jid, rows, _ in _blocks(eq):
        E += float(np.linalg.norm(w[rows])) * clearances.get(jid, 0.0) / eq.size
    if abs(c) < 1e-12:
        return 2 * math.pi
    return min(2 * math.pi, 2 * math.sqrt(2 * E / abs(c)))


def exact_zone(
    eq: ClosureEquations,
    x: FloatArray,
    fixed: str,
    link: str,
    clearances: Mapping[str, float],
    guess: float | None = None,
) -> float:
    """The zone by feasibility search: every pin centre free in a disc of its clearance.

    With the coordinate ``fixed`` held, ``link`` is turned by ``beta`` and the
    smallest ``t = max_j |offset_j|^2 / D_j^2`` over all placements is found
    (SLSQP); the zone is where ``t <= 1``, its ends located by root finding.
    Prismatic joints are taken without clearance.
    """
    from scipy.optimize import brentq, minimize

    g = _fixed_coordinate(eq, fixed)
    g0 = g(x)[0]
    col = 3 * eq.moving.index(link) + 2
    blocks = _blocks(eq)
    v, _ = singular_direction(eq, x, fixed)
    v = v / v[col] if abs(v[col]) > 1e-9 else np.eye(eq.n)[col]
    n = eq.n
    d2 = {jid: (clearances.get(jid, 0.0) / eq.size) ** 2 for jid, _, _ in blocks}

    eq_blocks = [(jid, rows) for jid, rows, kind in blocks if kind == "P" or d2[jid] == 0.0]
    in_blocks = [(jid, rows) for jid, rows, kind in blocks if kind == "R" and d2[jid] > 0.0]
    e_col = np.eye(n + 1)[col]
    e_t = np.eye(n + 1)[n]

    def worst(beta: float) -> float:
        target = x[col] + beta

        def cons_eq(z: FloatArray) -> FloatArray:
            y = z[:n]
            r = eq.residual(y)
            head = [g(y)[0] - g0, y[col] - target]
            return np.concatenate([head, *(r[rows] for _, rows in eq_blocks)])

        def cons_eq_jac(z: FloatArray) -> FloatArray:
            y = z[:n]
            J = eq.jacobian(y)
            rows_ = [np.append(g(y)[1], 0.0), e_col]
            rows_ += [
                np.hstack([J[rows], np.zeros((J[rows].shape[0], 1))]) for _, rows in eq_blocks
            ]
            return np.vstack(rows_)

        def cons_in(z: FloatArray) -> FloatArray:
            y, t = z[:n], z[n]
            r = eq.residual(y)
            return np.array([t * d2[jid] - float(r[rows] @ r[rows]) for jid, rows in in_blocks])

        def cons_in_jac(z: FloatArray) -> FloatArray:
            y = z[:n]
            r, J = eq.residual(y), eq.jacobian(y)
            return np.array(
                [np.append(-2 * r[rows] @ J[rows], d2[jid]) for jid, rows in in_blocks]
            )

        y0 = x + beta * v
        r0 = eq.residual(y0)
        t0 = max([float(r0[rows] @ r0[rows]) / d2[jid] for jid, rows in in_blocks] or [0.0])
        res = minimize(
            lambda z: z[n],
            np.append(y0, t0),
            jac=lambda z: e_t,
            constraints=[
                {"type": "eq", "fun": cons_eq, "jac": cons_eq_jac},
                {"type": "ineq", "fun": cons_in, "jac": cons_in_jac},
            ],
            method="SLSQP",
            options={"ftol": 1e-15, "maxiter": 500},
        )
        y = res.x[:n]
        if float(np.abs(cons_eq(res.x)).max()) > 1e-9:
            raise NumericalError(f"exact zone: the feasibility search failed ({res.message})")
        r = eq.residual(y)  # the placement's true worst pin, not SLSQP's bound
        return max([float(r[rows] @ r[rows]) / d2[jid] for jid, rows in in_blocks] or [0.0])

    step = guess / 2 if guess and guess > 0 else 0.01
    ends = []
    for sign in (1.0, -1.0):
        hi = step * 1.5
        while worst(sign * hi) <= 1.0:
            hi *= 1.6
            if hi > math.pi:
                ends.append(sign * math.pi)
                break
        else:
            lo = 0.0
            root = brentq(lambda b, sg=sign: worst(sg * b) - 1.0, lo, hi, xtol=1e-11)
            ends.append(sign * float(root))
    psi = ends[0] - ends[1]
    if not math.isfinite(psi):
        raise NumericalError("exact zone: the feasibility search failed")
    return min(psi, 2 * math.pi)
