"""Error estimates of the kinematics per frame: positions, velocities, accelerations.

Owns :class:`ErrorEstimate` and :func:`error_estimate`.  Every number the sweep gives
is computed in doubles from the plan's steps; its error comes from rounding (about
``u = 2.2e-16`` of the size per step), from the closure equations' residual (iterated
groups close to ``tol``) and from the driver value itself (``q − q_ref`` rounds by
``u |q|``), each amplified by the conditioning of the steps it passes through:

* a dyad's solve is a 2 × 2 system whose rows meet at the angle of its joint: an error
  in its inputs grows by at most ``2 / |sin|`` (the dyad's own sine);
* a closure group's unknowns solve ``R(t) = 0``: an error (the residual ``|R|``
  included) grows by ``1 / σmin`` of its Jacobian dR/dt in units of the size (an
  angle's column times the size), at least 1.

Along the plan each step's amplification is its own times one plus the largest of the
steps it reads (``A_k = g_k (1 + max_j A_j)``), and the frame's is the largest over
the steps (``A``).  With ``S`` and ``K`` the largest velocity and acceleration
analogs of the frame (joints and points, lengths per radian) and ``L`` the size:

* position: ``e_x = C ((n u L + |R|) A + u |q| S)``;
* velocity analog: ``e_σ = C (A (u S + (e_x / L) (S + L)) + u |q| K)`` (the analog
  solves the same systems, their matrices perturbed by the position error relative to
  the size);
* acceleration analog: ``e_κ = C A (u K + (e_x / L) (K + L) + 2 e_σ S / L)``;

with ``n`` the plan's steps and the safety factor ``C`` = :data:`SAFETY`.  Velocities
and accelerations at constant speed W are ``e_σ |W|`` and ``e_κ W²``.  The
``conditioning`` reported is ``1 / A`` (1 where every group is well conditioned, down
to 0 at a dead point).  These bounds are measured against an independent solve in 60
digits (``tests/high_precision.py``) in ``tests/kinematics/test_error_estimate.py``,
from regular frames to 1e-8 rad from a fold (docs/kinematics.md, *Error estimates*).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from mjstruct.kinematics.closure import closure_jacobian
from mjstruct.typing import FloatArray

if TYPE_CHECKING:
    from mjstruct.kinematics.model import Motion


#: the safety factor of every estimate (measured bounds hold with it; see the module)
SAFETY = 8.0
#: unit roundoff of a double
UNIT = float(np.finfo(float).eps)


@dataclass(frozen=True)
class ErrorEstimate:
    """Per frame, an estimate of the largest error of any joint's or point's position
    (length), velocity (length/s) and acceleration (length/s²), and the conditioning
    ``1 / A`` they come from; NaN where the frame has no value."""

    position: FloatArray
    velocity: FloatArray
    acceleration: FloatArray
    conditioning: FloatArray


def amplification(motion: Motion) -> FloatArray:
    """``A`` per frame: the largest amplification of an error along the plan."""
    model, ev = motion.model, motion.evaluation
    steps, deps = model.plan.steps, model.step_dependencies
    F = motion.q.shape[0]
    own: dict[int, FloatArray] = {}
    with np.errstate(divide="ignore", invalid="ignore"):
        for k, (_, det) in ev.diag.items():
            own[k] = 2.0 / np.abs(det)
        if motion.closure is not None and steps:
            group = _closure_conditioning(motion)
            for k, s in enumerate(steps):
                if s.kind in ("assume", "assume-slide"):
                    own[k] = group
    amp: dict[int, FloatArray] = {}
    worst = np.ones(F)
    for k in range(len(steps)):
        before = [amp[j] for j in deps[k] if j != k and j in amp]
        inner = np.maximum.reduce(before) if before else None
        if k in own:
            a = own[k] * (1.0 + (inner if inner is not None else 1.0))
        elif inner is not None:
            a = inner
        else:
            continue
        amp[k] = a
        with np.errstate(invalid="ignore"):
            worst = np.fmax(worst, a)
    return worst


def _closure_conditioning(motion: Motion) -> FloatArray:
    """1 / σmin (a bound from above) of the closure equations' Jacobian dR/dt per
    frame, in units of the
    size (an angle's column times the size: a change of a length per length moved),
    at least 1: how much a residual (or an error of the group's inputs) grows in the
    unknowns' positions."""
    model = motion.model
    Rt = closure_jacobian_of(motion)
    lever = np.array(
        [1.0 if s.kind == "assume-slide" else model.scale for s in model.plan.steps
         if s.kind in ("assume", "assume-slide")]
    )  # fmt: skip
    if lever.size == Rt.shape[2]:
        Rt = Rt / lever[None, None, :]
    ok = np.isfinite(Rt).all(axis=(1, 2))
    out = np.full(Rt.shape[0], np.inf)
    if ok.any():
        # 1 / σmin² ≤ ‖(JᵀJ)⁻¹‖_F (equal for one unknown): no SVD per frame
        G = np.einsum("fei,fej->fij", Rt[ok], Rt[ok])
        with np.errstate(all="ignore"):
            det_ok = np.abs(np.linalg.det(G)) > 0
            inv_norm = np.full(G.shape[0], np.inf)
            if det_ok.any():
                inv_norm[det_ok] = np.sqrt((np.linalg.inv(G[det_ok]) ** 2).sum(axis=(1, 2)))
            out[ok] = np.maximum(np.sqrt(inv_norm), 1.0)
    return out


def error_estimate(
    motion: Motion, speed: float, S: FloatArray, K: FloatArray, valid: npt.NDArray[np.bool_]
) -> ErrorEstimate:
    """The estimates of the module docstring; ``S``, ``K``: the largest velocity and
    acceleration analogs per frame, ``valid`` the frames with values."""
    model = motion.model
    L = model.scale
    n = max(len(model.plan.steps), 1)
    A = amplification(motion)
    res = np.zeros_like(A)
    if motion.closure is not None:
        # the closure's achieved error is relative to the size
        err = motion.closure.error
        res = np.where(np.isfinite(err), err, 0.0) * L
    q = np.abs(motion.q).max(axis=1)
    with np.errstate(all="ignore"):
        ex = SAFETY * ((n * UNIT * L + res) * A + UNIT * q * S)
        rel = ex / L
        es = SAFETY * (A * (UNIT * S + rel * (S + L)) + UNIT * q * K)
        ek = SAFETY * A * (UNIT * K + rel * (K + L) + 2 * es * S / L)
        W = abs(float(speed))
        # a rate that underflows to a subnormal double rounds by its spacing (4.9e-324)
        floor = float(np.finfo(float).smallest_subnormal)
        out = ErrorEstimate(ex, es * W + floor, ek * W * W + floor, 1.0 / A)
    for a in (out.position, out.velocity, out.acceleration, out.conditioning):
        a[~valid] = np.nan
    return out


def analog_relative_error(motion: Motion) -> FloatArray:
    """Per frame, the estimated relative error of the velocity and acceleration analogs
    of the joint centres (the larger of ``e_σ / S`` and ``e_κ / K``, unit speed): what
    the dynamics' loads inherit from the kinematics; NaN where a frame has no value."""
    centres = [motion.centre(j.id) for j in motion.model.mechanism.joints]
    with np.errstate(invalid="ignore"):
        S = np.abs(np.stack([c[1] for c in centres])).max(axis=0)
        K = np.abs(np.stack([c[2] for c in centres])).max(axis=0)
    e = error_estimate(motion, 1.0, S, K, motion.valid)
    tiny = UNIT * motion.model.scale
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.asarray(
            np.fmax(e.velocity / np.maximum(S, tiny), e.acceleration / np.maximum(K, tiny)),
            dtype=float,
        )


def closure_jacobian_of(motion: Motion) -> FloatArray:
    """dR/dt of the closure equations on every frame, in the closure's modes.

    The closure's own (from Newton's last round, at the final unknowns) where it has
    it; evaluated afresh only on the other frames (closed at the reference or by
    reseeding, or not closed: there at the unknowns it ended with, else 0).
    """
    sol, q = motion.closure, motion.q
    assert sol is not None
    have = sol.jacobian
    if have is not None and have.shape[0] == q.shape[0]:
        miss = np.flatnonzero(~np.isfinite(have).all(axis=(1, 2)))
        if miss.size == 0:
            return have
        Rt = have.copy()
    else:
        miss = np.arange(q.shape[0])
        Rt = np.empty((q.shape[0], motion.model.plan.equations, motion.model.plan.unknowns))
    t = sol.t[miss]
    t = np.where(np.isfinite(t), t, 0.0)
    # the closure's inner dyads in their modes of each frame
    modes = {k: v[miss] for k, v in sol.modes.items()} or None
    _, Rt[miss] = closure_jacobian(motion.model, q[miss], t, modes)
    return Rt
