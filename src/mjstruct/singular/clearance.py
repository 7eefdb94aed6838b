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

References
----------
.. [1] Singular positions and synthesis of hinged multi-joint mechanisms with
   clearances in their revolute pairs (in Russian; eLibrary document code EDN PBGDPR;
   authors, exact title, journal and year not given in the available copy).
   [Four-bar clearances] in docs/references.md.

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

from mjstruct.errors import MechanismError, NumericalError
from mjstruct.kinematics.tolerances import (
    FD_STEP2,
    TURNS,
    ZONE_CLOSURE,
    ZONE_DISC,
    ZONE_FLAT,
)
from mjstruct.singular.curve import ClosureEquations
from mjstruct.typing import FloatArray


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
    if abs(v[col]) < TURNS:
        return None
    v = v / v[col]
    g = _fixed_coordinate(eq, fixed)
    g0 = g(x)[0]
    e = FD_STEP2

    def F(y: FloatArray) -> FloatArray:
        return np.append(eq.residual(y), g(y)[0] - g0)

    c = float(w @ (F(x + e * v) + F(x - e * v) - 2 * F(x))) / e**2
    E = 0.0
    for jid, rows, _ in _blocks(eq):
        E += float(np.linalg.norm(w[rows])) * clearances.get(jid, 0.0) / eq.size
    if abs(c) < ZONE_FLAT:
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
    """The zone by a feasibility search: every pin centre free in a disc of its clearance.

    With the coordinate ``fixed`` held, the pins' offsets ``e_j`` (``|e_j| <= D_j``)
    are free and the closure ``Phi(y) = e`` is solved exactly; the largest and the
    smallest turn of ``link`` over all such placements (SLSQP from the leading-order
    estimate) bound the zone.  Prismatic joints are taken without clearance.
    """
    from scipy.optimize import minimize

    g = _fixed_coordinate(eq, fixed)
    g0 = g(x)[0]
    col = 3 * eq.moving.index(link) + 2
    blocks = _blocks(eq)
    free = [
        (jid, rows) for jid, rows, kind in blocks if kind == "R" and clearances.get(jid, 0) > 0
    ]
    radius = np.zeros(sum(r.stop - r.start for _, r, _ in blocks))
    for jid, rows in free:
        radius[rows] = clearances[jid] / eq.size
    n, m = eq.n, radius.size
    v, _ = singular_direction(eq, x, fixed)
    v = v / v[col] if abs(v[col]) > TURNS else np.eye(n)[col]
    beta0 = 0.25 * (guess if guess and guess > 0 else 0.01)
    ends = []
    for sign in (1.0, -1.0):
        # z = (y, u): offsets e = radius * u, |u_j| <= 1 for each free pin
        y0 = x + sign * beta0 * v
        with np.errstate(divide="ignore", invalid="ignore"):
            u0 = np.where(radius > 0, eq.residual(y0) / np.where(radius > 0, radius, 1), 0.0)
        for _, rows in free:  # start inside the discs
            k = float(np.linalg.norm(u0[rows]))
            if k > 0.9:
                u0[rows] *= 0.9 / k

        def closure(z: FloatArray) -> FloatArray:
            y, u = z[:n], z[n:]
            return np.concatenate([eq.residual(y) - radius * u, [g(y)[0] - g0]])

        def closure_jac(z: FloatArray) -> FloatArray:
            y = z[:n]
            top = np.hstack([eq.jacobian(y), -np.diag(radius)])
            return np.vstack([top, np.append(g(y)[1], np.zeros(m))])

        def discs(z: FloatArray) -> FloatArray:
            u = z[n:]
            return np.array([1.0 - float(u[rows] @ u[rows]) for _, rows in free])

        def discs_jac(z: FloatArray) -> FloatArray:
            out = np.zeros((len(free), n + m))
            for k, (_, rows) in enumerate(free):
                out[k, n + rows.start : n + rows.stop] = -2 * z[n:][rows]
            return out

        grad = np.zeros(n + m)
        grad[col] = -sign
        # the turn is sought within half a turn each way: where the pair's pivots can
        # meet the link turns freely, and the search ends at a bound (a full turn)
        bounds = [(None, None)] * (n + m)
        bounds[col] = (x[col] - math.pi, x[col] + math.pi)
        res = minimize(
            lambda z, sg=sign: -sg * z[col],
            np.concatenate([y0, u0]),
            jac=lambda z, gr=grad: gr,
            constraints=[
                {"type": "eq", "fun": closure, "jac": closure_jac},
                {"type": "ineq", "fun": discs, "jac": discs_jac},
            ],
            bounds=bounds,
            method="SLSQP",
            options={"ftol": 1e-12, "maxiter": 100},
        )
        z = res.x
        miss = float(np.abs(closure(z)).max())
        out = -float(discs(z).min())
        if not (miss <= ZONE_CLOSURE and out <= ZONE_DISC):
            raise NumericalError(
                f"exact zone: the search (SLSQP, {res.nit} iterations) ended on no placement "
                f"that closes within the pins' clearances (closure error {miss:.1e}, pin "
                f"offset beyond its clearance {max(out, 0.0):.1e})"
            )
        ends.append(float(z[col] - x[col]))
    psi = ends[0] - ends[1]
    if not math.isfinite(psi):
        raise NumericalError("exact zone: the search ended on no finite turn")
    return min(psi, 2 * math.pi)
