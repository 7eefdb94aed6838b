"""Joint reactions and actuator loads: the per-frame linear system, solved on a stack.

Owns the force analysis.  For every moving link three equations (forces in x and y,
moment about the centre of mass) balance the active loads, the inertia loads
``−m a``, ``−J ε`` and the unknown joint loads; the unknowns are

* per revolute joint of m links, the force (x, y) it applies to each link but the
  carrier (its first listed link; the carrier takes minus their sum, so the loads of
  a multiple joint on its links sum to zero);
* per prismatic joint, the normal force and the moment about the joint's current
  centre applied to its second listed link (the first takes the opposite);
* per driver, the torque (revolute) or the force along the guide (prismatic) the
  actuator applies to the joint's second listed link.

All frames are solved at once (``np.linalg.solve`` on a frames × u × u stack), with
an estimate of each frame's condition number from the same factorisation.  The system
is written in units of the mechanism's size ℓ: moment equations and moment unknowns
are divided by ℓ, so that every entry of the matrix is a pure number (a unit force,
or an arm in sizes) and the solve, its condition number and the singular-frame test
do not depend on the unit of length (a mechanism scaled by s gives its loads scaled
by s and s², to round-off).  The
*excluded equation* is the equation of motion of each driver (virtual power with the
analogs σ, independent of the link equations): its residual, relative to the largest
load of the frame, is the final check.

References
----------
.. [1] A. N. Panasenko, "Practical implementation…" (in Russian; the available copy
   gives only this beginning of the title), Systems. Methods. Technologies,
   no. 2 (66), pp. 32–42, 2025. [Panasenko 2025] in docs/references.md.

Examples
--------
>>> import numpy as np
>>> A = np.stack([np.eye(3), 2 * np.eye(3)])
>>> solve_stack(A, np.ones((2, 3)))[0][1].tolist()
[-0.5, -0.5, -0.5]
"""

from __future__ import annotations

import contextlib
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from mjstruct.dynamics.matrices import LinkMotion
from mjstruct.kinematics.model import KinematicModel

FloatArray = npt.NDArray[np.float64]
ComplexArray = npt.NDArray[np.complex128]
BoolArray = npt.NDArray[np.bool_]

#: frames whose estimated condition number exceeds this are singular (their loads are
#: null): the solve's relative error, up to condition × machine epsilon (2.2e-16), would
#: reach 100 %
SINGULAR_CONDITION = 1e15


@dataclass(frozen=True)
class Unknown:
    """One unknown of the system: ``kind`` is ``x``/``y`` (pin force on ``link``),
    ``n``/``m`` (slider normal force / moment on its second link) or ``drive``."""

    joint: str
    link: str
    kind: str


def unknowns(model: KinematicModel) -> list[Unknown]:
    """The unknowns in column order: joints in file order, then the drivers."""
    out: list[Unknown] = []
    for j in model.mechanism.joints:
        if j.kind == "R":
            for link in j.links[1:]:
                out += [Unknown(j.id, link, "x"), Unknown(j.id, link, "y")]
        else:
            out += [Unknown(j.id, j.links[1], "n"), Unknown(j.id, j.links[1], "m")]
    out += [Unknown(d, model.mechanism.joint(d).links[1], "drive") for d in model.drivers]
    return out


def is_moment(model: KinematicModel, cols: Sequence[Unknown]) -> BoolArray:
    """Which unknowns are moments (a slider's moment, a revolute driver's torque)."""
    m = model.mechanism
    return np.array(
        [u.kind == "m" or (u.kind == "drive" and m.joint(u.joint).kind == "R") for u in cols],
        dtype=bool,
    )


def system_matrix(model: KinematicModel, lm: LinkMotion, cols: Sequence[Unknown]) -> FloatArray:
    """The stacked matrix ``A`` (frames × 3 links × unknowns) of the link equations.

    Row ``3j + i`` is equation i (Fx, Fy, moment about the centre of mass) of moving
    link j; a unit value of each unknown applies a wrench at the joint's centre to its
    link (sign +1) and to the joint's first listed link (sign −1).  In units of the
    mechanism's size ℓ (``model.scale``): the moment rows are divided by ℓ and the
    moment unknowns are in units of ℓ (a force times the size), so the arms enter as
    multiples of ℓ and every entry is a pure number.
    """
    m = model.mechanism
    row = {link: j for j, link in enumerate(lm.links)}
    jrow = {jid: k for k, jid in enumerate(lm.joints)}
    F = lm.q.shape[0]
    A = np.zeros((F, 3 * len(lm.links), len(cols)))
    ell = model.scale
    com = lm.com[0]
    for c, u in enumerate(cols):
        joint = m.joint(u.joint)
        P = lm.centre[jrow[u.joint]]
        if u.kind == "x":
            f, mu = np.ones(F, complex), np.zeros(F)
        elif u.kind == "y":
            f, mu = np.full(F, 1j), np.zeros(F)
        elif u.kind == "n":
            f, mu = 1j * lm.axis[u.joint], np.zeros(F)
        elif u.kind == "m" or joint.kind == "R":  # a slider's moment, a revolute drive's couple
            f, mu = np.zeros(F, complex), np.ones(F)
        else:  # prismatic drive: a force along the guide
            f, mu = lm.axis[u.joint].astype(complex), np.zeros(F)
        for link, sign in ((u.link, 1.0), (joint.links[0], -1.0)):
            if link not in row:  # the frame: no equations
                continue
            j = row[link]
            arm = (P - com[j]) / ell
            A[:, 3 * j, c] += sign * f.real
            A[:, 3 * j + 1, c] += sign * f.imag
            A[:, 3 * j + 2, c] += sign * (mu + arm.real * f.imag - arm.imag * f.real)
    return A


def _probes(u: int) -> FloatArray:
    """Two fixed ±1 vectors (u × 2) for the condition estimate (deterministic)."""
    rng = np.random.default_rng(20250)
    out: FloatArray = rng.choice([-1.0, 1.0], size=(u, 2))
    return out


def solve_stack(A: FloatArray, S: FloatArray) -> tuple[FloatArray, BoolArray, FloatArray]:
    """Solve ``A x + S = 0`` on every frame, with an estimate of each frame's condition.

    The condition number ``κ∞ = ‖A‖∞ ‖A⁻¹‖∞`` is estimated from the same LU: two fixed
    ±1 vectors b are solved beside ``S`` (one factorisation, three right-hand sides),
    and ``‖A⁻¹ b‖∞ ≤ ‖A⁻¹‖∞`` (‖b‖∞ = 1) gives a lower bound that is within a small
    factor of ``κ∞`` unless b is orthogonal to A's weakest direction (an SVD per frame
    would cost 7× the solve).  Frames with a non-finite ``A`` or ``S``, or an estimated
    condition above :data:`SINGULAR_CONDITION` (no digit of the result would be right),
    are NaN.

    Returns
    -------
    x : the solutions (frames × u), NaN where not solved.
    solved : the frames solved.
    condition : the condition estimate per frame (NaN where ``A`` is not finite or is
        exactly singular).
    """
    F, u = A.shape[0], A.shape[1]
    ok: BoolArray = np.asarray(np.isfinite(A).all(axis=(1, 2)) & np.isfinite(S).all(axis=1))
    if ok.all():
        A_ok, S_ok = A, S
    else:
        A_ok = np.where(ok[:, None, None], A, np.eye(u)[None])
        S_ok = np.where(ok[:, None], S, 0.0)
    rhs = np.concatenate([-S_ok[..., None], np.broadcast_to(_probes(u), (F, u, 2))], axis=2)
    try:
        X = np.linalg.solve(A_ok, rhs)
    except np.linalg.LinAlgError:
        # a zero pivot (a frame singular exactly or in rounding): frame by frame, those
        # frames unsolved (an infinite condition)
        X = np.full(rhs.shape, np.inf)
        for i in range(F):
            with contextlib.suppress(np.linalg.LinAlgError):
                X[i] = np.linalg.solve(A_ok[i], rhs[i])
    with np.errstate(all="ignore"):
        inv = np.abs(X[..., 1:]).max(axis=(1, 2))
        cond = np.abs(A_ok).sum(axis=2).max(axis=1) * inv
    cond = np.where(ok, cond, np.nan)
    ok = ok & (cond <= SINGULAR_CONDITION)
    x = X[..., 0]
    x[~ok] = np.nan
    return x, ok, cond


def inertia_loads(
    lm: LinkMotion, mass: FloatArray, J: FloatArray
) -> tuple[ComplexArray, FloatArray]:
    """Inertia loads ``Φ = −I a`` at the centres of mass: force (complex) and moment."""
    return -mass[:, None] * lm.com[2], -J[:, None] * lm.angle[2]


def stack_loads(force: ComplexArray, moment: FloatArray, size: float) -> FloatArray:
    """The load vector ``S`` per frame (frames × 3 links), rows Fx, Fy, M per link.

    The moments are divided by the mechanism's ``size`` (the rows of
    :func:`system_matrix`).
    """
    L, F = moment.shape
    S = np.empty((F, 3 * L))
    S[:, 0::3] = force.real.T
    S[:, 1::3] = force.imag.T
    S[:, 2::3] = moment.T / size
    return S


def generalised_drive(lm: LinkMotion, force: ComplexArray, moment: FloatArray) -> FloatArray:
    """The actuator loads from the equations of motion: ``τ_i = −Σ_j S_j · σ_ij``.

    ``force``, ``moment`` are the total (active + inertia) loads at the centres of mass;
    the result is drivers × frames.
    """
    work = (force[None].real * lm.sigma_com.real + force[None].imag * lm.sigma_com.imag).sum(
        axis=1
    )
    work += (moment[None] * lm.sigma_angle).sum(axis=1)
    out: FloatArray = -work
    return out
